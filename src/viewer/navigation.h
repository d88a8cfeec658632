// Camera navigation and click-to-focus on the authored camera; no GL, no window.
#pragma once

#include <optional>
#include <string>

#include "render/render_scene.h"
#include "scene/scene.h"

namespace kr::viewer {

// Mouse-drag scales shared by the window and the scripted --orbit option.
inline constexpr double kOrbitDegreesPerPixel = 0.25;

// Turntable orbit about the target: yaw about +y, pitch towards the poles (kept 1 degree
// short of them so the camera frame never degenerates). The distance is kept.
void orbit(Camera& camera, double yaw_degrees, double pitch_degrees);
// A drag of (dx, dy) pixels: right turns the view to the right, down tilts it down.
void orbit_drag(Camera& camera, double dx_pixels, double dy_pixels);

// A mouse button held on the image. A press and release with small jitter, or a pointer
// that jumps between events, is a click, not a drag: the drag starts only once the pointer
// is more than kDragThresholdPixels from the press, and its offset is measured from where
// it started, so each update applies the whole offset to the camera as it was then.
inline constexpr double kDragThresholdPixels = 4;
struct DragGesture {
    bool pressed = false, dragging = false;
    double press_x = 0, press_y = 0;  // where the button went down
    double start_x = 0, start_y = 0;  // where the drag started (past the threshold)
    Camera start_camera;              // the camera when the drag started

    void press(double x, double y);
    // The pointer is at (x, y): true while dragging, with the offset from the drag's start.
    // `camera` is recorded as start_camera when the drag starts.
    bool move(double x, double y, const Camera& camera, double& dx, double& dy);
    void release() { pressed = dragging = false; }
};

// Keys held for camera motion (-1, 0 or +1 each); rates are per second, so the motion is
// the same whatever the frame rate.
struct KeyMotion {
    int orbit_x = 0, orbit_y = 0;  // arrows: yaw, pitch
    int pan_x = 0, pan_y = 0;      // A/D, Q/E
    int dolly = 0;                 // W (in, -1) / S (out, +1)
    bool any() const { return orbit_x || orbit_y || pan_x || pan_y || dolly; }
};
inline constexpr double kKeyOrbitDegreesPerSecond = 60;
inline constexpr double kKeyPanPixelsPerSecond = 240;
inline constexpr double kKeyDollyPerSecond = 0.8;  // the distance shrinks by e^-0.8 per second
void apply_key_motion(Camera& camera, const KeyMotion& keys, double seconds, int image_height);

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
