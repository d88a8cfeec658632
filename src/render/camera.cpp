#include "render/camera.h"

#include <stdexcept>

#include "core/sampling.h"

namespace kr {

CameraModel CameraModel::from(const Camera& camera) {
    CameraModel m;
    const Vec3 view = camera.target - camera.position;
    const double view_length = length(view);
    if (!(view_length > 0) || !std::isfinite(view_length))
        throw std::invalid_argument("camera position equals target (no view direction)");
    m.position = camera.position;
    m.forward = view / view_length;
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
    // Point on the image plane at distance 1 along forward.
    const double px = (2.0 * fx - 1.0) * tan_half_fov * aspect;
    const double py = (1.0 - 2.0 * fy) * tan_half_fov;
    const Vec3 dir = normalize(forward + px * right + py * up);
    if (lens_radius <= 0) return {position, dir};
    // Thin lens: every ray through the lens point meets the pinhole ray on the focal plane.
    const Vec2 lens = sample_concentric_disk(u1, u2);
    const Vec3 origin = position + (lens_radius * lens.x) * right + (lens_radius * lens.y) * up;
    const Vec3 focus = position + dir * (focal_distance / dot(dir, forward));
    return {origin, normalize(focus - origin)};
}

}  // namespace kr
