#include "render/camera.h"

#include <stdexcept>

#include "core/sampling.h"
#include "render/lanes/vertex.h"

namespace kr {

namespace {

// v / |v| without overflow or underflow in |v|^2: scaled by its largest component first, so
// any finite non-zero vector has a direction (a view of 1e-310 or of 1e308). Returns false
// for a zero or non-finite vector.
bool unit_direction(const Vec3& v, Vec3& out) {
    const double scale = max_abs_component(v);
    if (!(scale > 0) || !std::isfinite(scale)) return false;
    const Vec3 w(v.x / scale, v.y / scale, v.z / scale);  // not v * (1 / scale): 1 / 1e-310 overflows
    out = w / length(w);
    return true;
}

}  // namespace

CameraModel CameraModel::from(const Camera& camera) {
    CameraModel m;
    if (!is_finite(camera.position) || !is_finite(camera.target))
        throw std::invalid_argument("camera position and target must be finite");
    if (camera.position == camera.target)
        throw std::invalid_argument("camera position equals target (no view direction)");
    // Halves first: target - position overflows for points near +-1.8e308.
    if (!unit_direction(0.5 * camera.target - 0.5 * camera.position, m.forward))
        throw std::invalid_argument("camera position and target are too close to give a finite view direction");
    m.position = camera.position;
    // Left-handed: right = up x forward with up = +y. Looking straight up or down, that
    // cross product vanishes; then take the up the camera would have after tilting there
    // from a +z view (-z when looking up, +z when looking down).
    const Vec3 world_up(0, 1, 0);
    Vec3 right = cross(world_up, m.forward);
    if (length(right) < 1e-9) right = cross(Vec3(0, 0, m.forward.y > 0 ? -1 : 1), m.forward);
    m.right = normalize(right);
    m.up = cross(m.forward, m.right);
    m.tan_half_fov = std::tan(0.5 * camera.fov * kPi / 180.0);
    m.aspect = camera.aspect;
    if (camera.type == CameraType::lens) {
        m.lens_radius = camera.alpha;
        m.focal_distance = camera.focal_distance;
    }
    return m;
}

CameraRay CameraModel::generate(double fx, double fy, double u1, double u2) const {
    const Vec3 dir = vertex::pinhole_direction<vertex::OnePath>(*this, fx, fy);
    if (lens_radius <= 0) return {position, dir};
    CameraRay ray;
    vertex::thin_lens_ray<vertex::OnePath>(*this, dir, u1, u2, ray.origin, ray.direction);
    return ray;
}

}  // namespace kr
