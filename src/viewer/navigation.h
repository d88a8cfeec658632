// Camera navigation and click-to-focus on the authored camera; no GL, no window.
#pragma once

#include <optional>

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
