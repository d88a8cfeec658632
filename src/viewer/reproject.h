// The picture of an earlier view carried across a camera move (GL-free). The scenes are static
// spheres: after an orbit, a pan or a dolly most surfaces the new view sees were on screen
// before, and a diffuse surface sends the same radiance to every view. So each pixel of the
// new view whose first surface is diffuse, and was seen unoccluded by the earlier view's pixels
// around where it lands there, takes the earlier picture's colour as a prior worth as many
// samples as that picture had; the new view's own frames are blended with it, the prior's share
// falling to nothing by the job's target. Pixels on a silhouette, on glossy, mirror or glass
// surfaces, or newly seen, keep the new view's own image. Pinhole cameras only: through a lens
// a pixel's colour is a blur over many surface points.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/image.h"
#include "core/sampling.h"
#include "render/render_scene.h"
#include "render/settings.h"

namespace kr::viewer {

// A view's first surfaces: per pixel, the sphere its centre ray hits first (-1: none) and how
// far along the ray; cast in the lanes `settings` trace the scene with (camera_hits,
// render/trace.h), a row at a time. Once `cancel` is set (by another thread) the rows not yet
// begun are left without hits: the caller drops the result.
struct ViewHits {
    int width = 0, height = 0;
    CameraModel camera;
    std::vector<int> sphere;
    std::vector<float> distance;
};
ViewHits view_hits(const RenderScene& scene, int width, int height, const RenderSettings& settings = {},
                   const std::atomic<bool>* cancel = nullptr);

// Where a world point lands in a view: its continuous pixel coordinates (pixel (i, j)'s centre
// ray at (i, j)), or none behind the camera.
std::optional<Vec2> project_to_pixel(const CameraModel& camera, int width, int height, const Vec3& point);

// An earlier view's picture as shown (the display's image), its per-pixel sample counts and
// its first surfaces.
struct ViewHistory {
    uint64_t generation = 0;  // the job it was made for
    ViewHits hits;
    Image picture;
    std::vector<uint32_t> samples;
};

// The history's colour at each pixel of the new view and what it is worth in samples (0: the
// pixel takes nothing from it).
struct Reprojection {
    Image colour;
    std::vector<float> weight;
};
// `scene` is the new view's (the same world as the history's: same_world, render_scene.h), `now`
// its hits. Once `cancel` is set, the rows not yet begun take nothing (view_hits' rule).
Reprojection reproject(const RenderScene& scene, const ViewHits& now, const ViewHistory& history,
                       const std::atomic<bool>* cancel = nullptr);

// Whether a view can take or give a history: a pinhole camera.
inline bool reprojectable(const RenderScene& scene) { return scene.camera.lens_radius <= 0; }

// Blends `shown` (the new view's own image after `spp` samples a pixel) with the prior: at
// each pixel, (spp * shown + w * prior) / (spp + w), where the prior's worth w falls linearly
// from its weight at 0 samples to nothing at `end_spp` (the job's target, or four times the
// weight where that is sooner or the job has none).
// Returns the pixels that took some of the prior.
size_t blend_history(Image& shown, const Reprojection& prior, int spp, int end_spp);

}  // namespace kr::viewer
