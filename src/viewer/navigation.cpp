#include "viewer/navigation.h"

#include <algorithm>
#include <cmath>

#include "render/camera.h"

namespace kr::viewer {

namespace {

constexpr double kDegrees = kPi / 180.0;
constexpr double kMaxPitch = 89.0;  // degrees

}  // namespace

void orbit(Camera& camera, double yaw_degrees, double pitch_degrees) {
    const Vec3 offset = camera.position - camera.target;
    const double r = length(offset);
    if (!(r > 0)) return;
    // Left-handed, y up: yaw 0 looks along +z from -z, as the scenes' cameras do.
    double yaw = std::atan2(offset.x, offset.z) / kDegrees;
    double pitch = std::asin(std::clamp(offset.y / r, -1.0, 1.0)) / kDegrees;
    yaw += yaw_degrees;
    pitch = std::clamp(pitch + pitch_degrees, -kMaxPitch, kMaxPitch);
    const double cp = std::cos(pitch * kDegrees);
    camera.position = camera.target + r * Vec3(cp * std::sin(yaw * kDegrees), std::sin(pitch * kDegrees),
                                                cp * std::cos(yaw * kDegrees));
}

void orbit_drag(Camera& camera, double dx_pixels, double dy_pixels) {
    // Dragging moves the scene with the cursor: right drag swings the camera left.
    orbit(camera, -dx_pixels * kOrbitDegreesPerPixel, dy_pixels * kOrbitDegreesPerPixel);
}

void pan_drag(Camera& camera, double dx_pixels, double dy_pixels, int image_height) {
    const CameraModel m = CameraModel::from(camera);
    const double depth = length(camera.target - camera.position);
    // World size of one pixel at the target's depth.
    const double per_pixel = 2.0 * depth * m.tan_half_fov / std::max(1, image_height);
    const Vec3 shift = m.right * (-dx_pixels * per_pixel) + m.up * (dy_pixels * per_pixel);
    camera.position += shift;
    camera.target += shift;
}

void dolly(Camera& camera, double factor) {
    const Vec3 offset = camera.position - camera.target;
    const double r = length(offset);
    // Never onto the target: the camera frame needs a view direction.
    const double new_r = std::max(r * factor, 1e-6);
    if (r > 0) camera.position = camera.target + offset * (new_r / r);
}

void DragGesture::press(double x, double y) {
    pressed = true;
    dragging = false;
    press_x = x;
    press_y = y;
}

bool DragGesture::move(double x, double y, const Camera& camera, double& dx, double& dy) {
    if (!pressed) return false;
    if (!dragging) {
        if (std::hypot(x - press_x, y - press_y) <= kDragThresholdPixels) return false;
        dragging = true;
        start_x = x;
        start_y = y;
        start_camera = camera;
    }
    dx = x - start_x;
    dy = y - start_y;
    return true;
}

void apply_key_motion(Camera& camera, const KeyMotion& keys, double seconds, int image_height) {
    const double orbit_pixels = kKeyOrbitDegreesPerSecond / kOrbitDegreesPerPixel * seconds;
    if (keys.orbit_x || keys.orbit_y) orbit_drag(camera, keys.orbit_x * orbit_pixels, keys.orbit_y * orbit_pixels);
    const double pan_pixels = kKeyPanPixelsPerSecond * seconds;
    if (keys.pan_x || keys.pan_y) pan_drag(camera, keys.pan_x * pan_pixels, keys.pan_y * pan_pixels, image_height);
    if (keys.dolly) dolly(camera, std::exp(keys.dolly * kKeyDollyPerSecond * seconds));
}

std::optional<std::string> sphere_containing(const Scene& scene, const Vec3& point) {
    for (const Primitive& p : scene.primitives) {
        if (p.shape < 0) continue;
        const Shape& s = scene.shapes[size_t(p.shape)];
        if (dot(point - s.centre, point - s.centre) < s.radius * s.radius) return s.id;
    }
    return std::nullopt;
}

std::optional<double> focus_distance(const RenderScene& scene, double fx, double fy) {
    CameraModel pinhole = scene.camera;
    pinhole.lens_radius = 0;  // the ray through the lens centre
    const CameraRay cr = pinhole.generate(fx, fy, 0.5, 0.5);
    Ray ray;
    ray.o = cr.origin;
    ray.d = cr.direction;
    Hit hit;
    if (!scene.intersects(ray, hit)) return std::nullopt;
    return hit.t * dot(cr.direction, pinhole.forward);
}

}  // namespace kr::viewer
