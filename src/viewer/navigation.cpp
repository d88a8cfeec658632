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

namespace {

// `v` turned by `degrees` about the unit `axis` (Rodrigues).
Vec3 rotate(const Vec3& v, const Vec3& axis, double degrees) {
    const double a = degrees * kDegrees, c = std::cos(a), s = std::sin(a);
    return v * c + cross(axis, v) * s + axis * (dot(axis, v) * (1 - c));
}

double elevation_degrees(const Vec3& v) {
    const double r = length(v);
    return r > 0 ? std::asin(std::clamp(v.y / r, -1.0, 1.0)) / kDegrees : 0.0;
}

// The pitch that turns `view` by `pitch_degrees` downwards (camera rising about a pivot),
// kept kMaxPitch short of the poles; with the axis it turns about.
bool pitch_axis(const Vec3& view, double& pitch_degrees, Vec3& axis) {
    const Vec3 h = cross(view, Vec3(0, 1, 0));
    if (!(length(h) > 1e-12)) return false;
    axis = h / length(h);
    const double e = elevation_degrees(view);
    const double wanted = std::clamp(e - pitch_degrees, -kMaxPitch, kMaxPitch);
    // Turning about `axis` by +1 degree raises or lowers the view: pick the sign that lowers.
    const double sign = elevation_degrees(rotate(view, axis, 1)) > e ? -1 : 1;
    pitch_degrees = sign * (e - wanted);
    return true;
}

}  // namespace

void orbit_about(Camera& camera, const Vec3& pivot, double yaw_degrees, double pitch_degrees) {
    const Vec3 up(0, 1, 0);
    Vec3 offset = rotate(camera.position - pivot, up, yaw_degrees);
    Vec3 view = rotate(camera.target - camera.position, up, yaw_degrees);
    Vec3 axis;
    if (pitch_axis(view, pitch_degrees, axis)) {
        offset = rotate(offset, axis, pitch_degrees);
        view = rotate(view, axis, pitch_degrees);
    }
    camera.position = pivot + offset;
    camera.target = camera.position + view;
}

void look_drag(Camera& camera, double dx_pixels, double dy_pixels) {
    // The scene moves against the drag as in a first-person game: right drag turns right.
    orbit_about(camera, camera.position, dx_pixels * kOrbitDegreesPerPixel, dy_pixels * kOrbitDegreesPerPixel);
}

void fly(Camera& camera, int forward, int right, int up, double distance) {
    const CameraModel m = CameraModel::from(camera);
    const Vec3 shift = (m.forward * double(forward) + m.right * double(right) + Vec3(0, 1, 0) * double(up)) * distance;
    camera.position += shift;
    camera.target += shift;
}

std::optional<double> first_crossing(const Scene& scene, const Vec3& from, const Vec3& to) {
    const Vec3 d = to - from;
    const double len2 = dot(d, d);
    if (!(len2 > 0)) return std::nullopt;
    std::optional<double> first;
    for (const Primitive& p : scene.primitives) {
        if (p.shape < 0) continue;
        const Shape& s = scene.shapes[size_t(p.shape)];
        // |from + f d - c|^2 = r^2 for f in (0, 1].
        const Vec3 oc = from - s.centre;
        const double b = dot(oc, d), c = dot(oc, oc) - s.radius * s.radius;
        const double disc = b * b - len2 * c;
        if (disc < 0) continue;
        const double root = std::sqrt(disc);
        for (const double f : {(-b - root) / len2, (-b + root) / len2})
            if (f > 1e-9 && f <= 1 && (!first || f < *first)) first = f;
    }
    return first;
}

bool keep_outside(const Scene& scene, const Camera& before, Camera& moved, const Vec3* pivot) {
    const Vec3 from = before.position;
    const auto crossing = first_crossing(scene, from, moved.position);
    if (!crossing) return false;
    const Vec3 view = moved.target - moved.position;
    auto stop_short = [&](const Vec3& a, const Vec3& b, double f) {
        // Just short of the surface: a gap of 1e-4 of the way, at least 1e-6.
        const double len = length(b - a);
        const double keep = std::max(0.0, f * len - std::max(1e-4 * len, 1e-6));
        return len > 0 ? a + (b - a) * (keep / len) : a;
    };
    if (pivot) {
        // Drawn towards the pivot, to where the line from it first meets a surface.
        const Vec3 p = *pivot;
        const auto hit = first_crossing(scene, p, moved.position);
        const Vec3 drawn = hit ? stop_short(p, moved.position, *hit) : moved.position;
        if (length(drawn - p) > 1e-3 * length(moved.position - p) && !first_crossing(scene, from, drawn) &&
            dot(moved.target - drawn, view) > 0) {
            moved.position = drawn;
            // Orbiting about the target keeps looking at it; else the view direction is kept.
            if (length(moved.target - p) > 1e-9 * (1 + length(p))) moved.target = drawn + view;
            return true;
        }
    }
    moved.position = stop_short(from, moved.position, *crossing);
    moved.target = moved.position + view;
    return true;
}

std::optional<Vec3> surface_point(const RenderScene& scene, double fx, double fy) {
    CameraModel pinhole = scene.camera;
    pinhole.lens_radius = 0;  // the ray through the lens centre
    const CameraRay cr = pinhole.generate(fx, fy, 0.5, 0.5);
    Ray ray;
    ray.o = cr.origin;
    ray.d = cr.direction;
    Hit hit;
    if (!scene.intersects(ray, hit)) return std::nullopt;
    return ray.o + ray.d * hit.t;
}

void orbit_drag(Camera& camera, double dx_pixels, double dy_pixels, const Vec3& pivot) {
    orbit_about(camera, pivot, -dx_pixels * kOrbitDegreesPerPixel, dy_pixels * kOrbitDegreesPerPixel);
}

Camera orbit_step(const Scene& scene, const Camera& start, const Vec3& pivot, double dx_pixels, double dy_pixels,
                  bool stop_at_surfaces) {
    Camera cam = start;
    if (!stop_at_surfaces) {
        orbit_drag(cam, dx_pixels, dy_pixels, pivot);
        return cam;
    }
    // Every position a step can reach lies in the ball about the pivot through the start
    // (an orbit keeps the distance to the pivot, stopping draws the camera towards it, and
    // each stop is on a segment between two such points): only the spheres that meet that
    // ball can stop it.
    const double reach = length(start.position - pivot);
    Scene near;
    for (const Primitive& p : scene.primitives) {
        if (p.shape < 0) continue;
        const Shape& s = scene.shapes[size_t(p.shape)];
        if (length(s.centre - pivot) > reach + s.radius + 1e-9 * (1 + reach)) continue;
        near.shapes.push_back(s);
        Primitive q;
        q.shape = int(near.shapes.size()) - 1;
        near.primitives.push_back(q);
    }
    // (Less a hair, so an offset summed from held-key frames, a rounding off a whole step,
    // takes the same steps.)
    const int steps =
        std::clamp(int(std::ceil(std::hypot(dx_pixels, dy_pixels) / kOrbitStepPixels - 1e-9)), 1, kMaxOrbitSteps);
    for (int i = 1; i <= steps; ++i) {
        const double f = double(i) / steps;
        Camera next = start;
        orbit_drag(next, dx_pixels * f, dy_pixels * f, pivot);
        keep_outside(near, cam, next, &pivot);
        cam = next;
    }
    return cam;
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

bool DragGesture::move(double x, double y, const Camera& camera, double& dx, double& dy,
                       const std::optional<std::pair<double, double>>& started_at) {
    if (!pressed) return false;
    last_x = x;
    last_y = y;
    if (!dragging) {
        if (!started_at && std::hypot(x - press_x, y - press_y) <= kDragThresholdPixels) return false;
        dragging = true;
        start_x = started_at ? started_at->first : x;
        start_y = started_at ? started_at->second : y;
        start_camera = camera;
    }
    dx = x - start_x;
    dy = y - start_y;
    return true;
}

void apply_key_motion(Camera& camera, const KeyMotion& keys, double seconds, int image_height,
                      const NavigationSettings& nav) {
    seconds *= nav.speed;
    const double orbit_pixels = kKeyOrbitDegreesPerSecond / kOrbitDegreesPerPixel * seconds;
    if (nav.fly) {
        // The arrows look (not faster with the speed), W/S A/D Q/E fly.
        const double look = orbit_pixels / nav.speed;
        if (keys.orbit_x || keys.orbit_y) look_drag(camera, keys.orbit_x * look, keys.orbit_y * look);
        const double step = kFlyFractionPerSecond * length(camera.target - camera.position) * seconds;
        if (keys.pan_x || keys.pan_y || keys.dolly) fly(camera, -keys.dolly, -keys.pan_x, keys.pan_y, step);
        return;
    }
    if (keys.orbit_x || keys.orbit_y) orbit_drag(camera, keys.orbit_x * orbit_pixels, keys.orbit_y * orbit_pixels);
    const double pan_pixels = kKeyPanPixelsPerSecond * seconds;
    if (keys.pan_x || keys.pan_y) pan_drag(camera, keys.pan_x * pan_pixels, keys.pan_y * pan_pixels, image_height);
    if (keys.dolly) dolly(camera, std::exp(keys.dolly * kKeyDollyPerSecond * seconds));
}

Camera KeyOrbitGesture::hold(const Scene& scene, int orbit_x, int orbit_y, double seconds, const NavigationSettings& nav) {
    // apply_key_motion's rate, as drag pixels (an arrow turns the view as a drag does).
    const double pixels = kKeyOrbitDegreesPerSecond / kOrbitDegreesPerPixel * seconds * nav.speed;
    dx += orbit_x * pixels;
    dy += orbit_y * pixels;
    return orbit_step(scene, start, start.target, dx, dy, nav.stop_at_surfaces);
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
    const std::optional<Vec3> p = surface_point(scene, fx, fy);
    if (!p) return std::nullopt;
    return dot(*p - scene.camera.position, scene.camera.forward);
}

}  // namespace kr::viewer
