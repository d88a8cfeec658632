// Camera navigation and click-to-focus on the authored camera; no GL, no window.
#pragma once

#include <optional>
#include <string>
#include <utility>

#include "render/render_scene.h"
#include "scene/scene.h"

namespace kr::viewer {

// Mouse-drag scales shared by the window and the scripted --orbit option.
inline constexpr double kOrbitDegreesPerPixel = 0.25;

// How the mouse and keys move the camera (the Navigation panel; not saved with the scene).
struct NavigationSettings {
    bool fly = false;              // left drag looks around, W/A/S/D/Q/E fly; else orbit, pan, dolly
    double speed = 1;              // factor on every drag, key and wheel motion (0.05 .. 20)
    bool stop_at_surfaces = true;  // a move that would cross a sphere's surface stops before it
    bool orbit_picked = true;      // a left drag orbits about the surface under the pointer
};
inline constexpr double kMinSpeed = 0.05, kMaxSpeed = 20;
// Fly mode: the distance per second at speed 1 is this fraction of the camera's distance
// to its target (the scene's scale as the file frames it).
inline constexpr double kFlyFractionPerSecond = 0.5;

// Turntable orbit about the target: yaw about +y, pitch towards the poles (kept 1 degree
// short of them so the camera frame never degenerates). The distance is kept.
void orbit(Camera& camera, double yaw_degrees, double pitch_degrees);
// A drag of (dx, dy) pixels: right turns the view to the right, down tilts it down.
void orbit_drag(Camera& camera, double dx_pixels, double dy_pixels);
// The same about `pivot` (orbit_about).
void orbit_drag(Camera& camera, double dx_pixels, double dy_pixels, const Vec3& pivot);

// Turntable orbit about `pivot`: yaw about +y, then pitch about the camera's right axis
// (the view kept 1 degree short of the poles). Position and view direction turn together,
// so the pivot stays where it is in the image; orbiting about the target keeps the target.
void orbit_about(Camera& camera, const Vec3& pivot, double yaw_degrees, double pitch_degrees);
// Turns the view about the camera's position (fly mode's mouse look): a drag of (dx, dy)
// pixels turns it right / down.
void look_drag(Camera& camera, double dx_pixels, double dy_pixels);
// Fly mode's keys: forward (+1 W, -1 S), right (D/A), up (E/Q), `distance` each; the
// target moves along, so the view direction is kept.
void fly(Camera& camera, int forward, int right, int up, double distance);

// The first crossing of a sphere's surface (entering or leaving) on the segment from `from`
// to `to`, as a fraction of it in (0, 1]; none when the segment crosses no surface.
std::optional<double> first_crossing(const Scene& scene, const Vec3& from, const Vec3& to);
// Stop at surfaces: `moved` is `before` after a navigation step. If its position's way from
// before's crosses a surface, the position stops just short of it; with a `pivot` (an
// orbit) the camera is first drawn towards the pivot, so an orbit slides along a wall
// instead of stopping. The view direction is kept. True when the move was changed.
bool keep_outside(const Scene& scene, const Camera& before, Camera& moved, const Vec3* pivot = nullptr);

// An orbit drag's camera for its whole offset (dx, dy) from where it started: `start` (the
// camera when the drag started) orbited about `pivot`. With stop_at_surfaces the orbit is
// walked from the start along the straight line to (dx, dy) in fixed steps of at most
// kOrbitStepPixels (at most kMaxOrbitSteps of them), each stopped at surfaces (sliding along
// a wall towards the pivot) from the step before: the result is a function of the offset
// alone, never of how many frames the pointer's moves reached. The window, the held arrow
// keys, the scripted --orbit and the tests go through this.
inline constexpr double kOrbitStepPixels = 2;
inline constexpr int kMaxOrbitSteps = 256;
Camera orbit_step(const Scene& scene, const Camera& start, const Vec3& pivot, double dx_pixels, double dy_pixels,
                  bool stop_at_surfaces);

// The surface point seen through image point (fx, fy) by the pinhole ray, if any.
std::optional<Vec3> surface_point(const RenderScene& scene, double fx, double fy);

// A mouse button held on the image. A press and release with small jitter, or a pointer
// that jumps between events, is a click, not a drag: the drag starts only once the pointer
// is more than kDragThresholdPixels from the press, and its offset is measured from where
// it started, so each update applies the whole offset to the camera as it was then.
inline constexpr double kDragThresholdPixels = 4;
struct DragGesture {
    bool pressed = false, dragging = false;
    double press_x = 0, press_y = 0;  // where the button went down
    double start_x = 0, start_y = 0;  // where the drag started (past the threshold)
    double last_x = 0, last_y = 0;    // the pointer at the last move
    Camera start_camera;              // the camera when the drag started

    void press(double x, double y);
    // The pointer is at (x, y): true while dragging, with the offset from the drag's start.
    // `camera` is recorded as start_camera when the drag starts. `started_at`, where the
    // pointer's events first went past the threshold (the window knows it), starts the drag
    // there, so its start does not depend on which of the events a frame saw.
    bool move(double x, double y, const Camera& camera, double& dx, double& dy,
              const std::optional<std::pair<double, double>>& started_at = std::nullopt);
    void release() { pressed = dragging = false; }
};

// Keys held for camera motion (-1, 0 or +1 each); rates are per second, so the motion is
// the same whatever the frame rate.
struct KeyMotion {
    int orbit_x = 0, orbit_y = 0;  // arrows: yaw, pitch
    int pan_x = 0, pan_y = 0;      // A/D; Page Up/Down (fly mode: Q/E)
    int dolly = 0;                 // W (in, -1) / S (out, +1)
    bool any() const { return orbit_x || orbit_y || pan_x || pan_y || dolly; }
};
inline constexpr double kKeyOrbitDegreesPerSecond = 60;
inline constexpr double kKeyPanPixelsPerSecond = 240;
inline constexpr double kKeyDollyPerSecond = 0.8;  // the distance shrinks by e^-0.8 per second
// Held arrow keys (orbit mode) as one orbit gesture about the target, as a drag is: the
// whole turn since they went down, from the camera then (orbit_step), so stopping at a wall
// slides the camera the same however the hold is cut into frames, and turning back undoes
// the slide. `hold` adds `seconds` with the arrows (orbit_x, orbit_y) held and gives the camera.
struct KeyOrbitGesture {
    Camera start;
    double dx = 0, dy = 0;  // the turn so far, in drag pixels
    Camera hold(const Scene& scene, int orbit_x, int orbit_y, double seconds, const NavigationSettings& nav);
};
// In fly mode the same keys fly (W/S forward, A/D strafe, Q/E down/up) and the arrows look.
void apply_key_motion(Camera& camera, const KeyMotion& keys, double seconds, int image_height,
                      const NavigationSettings& nav = {});

// The id of an authored sphere (one the scene block renders) that contains `point`, if any:
// a camera there sees only the sphere's inside.
std::optional<std::string> sphere_containing(const Scene& scene, const Vec3& point);

// Moves position and target together along the camera's right and up axes by a drag of
// (dx, dy) pixels, so the point at the target's depth follows the cursor.
void pan_drag(Camera& camera, double dx_pixels, double dy_pixels, int image_height);

// Moves the position towards (factor < 1) or away from (factor > 1) the target.
void dolly(Camera& camera, double factor);

// Distance along the camera's view axis (the convention of CameraModel::focal_distance:
// the plane in focus is perpendicular to forward) to the surface seen through image
// point (fx, fy) in [0,1)^2, found with a pinhole ray cast by RenderScene::intersects.
// None when the ray hits nothing.
std::optional<double> focus_distance(const RenderScene& scene, double fx, double fy);

}  // namespace kr::viewer
