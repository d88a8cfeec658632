// The first-surface layers (AOVs): albedo and normal of the first non-specular hit, for an
// HDR output and as the denoiser's feature buffers. The other layers come from the render's
// state (render/outputs.h).
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "core/image.h"
#include "core/math.h"
#include "render/render_scene.h"
#include "render/settings.h"

namespace kr {

// Albedo and unit normal of the first non-specular surface a ray meets: perfect mirrors and
// sharp dielectrics are followed, up to `max_chain` of them, reflecting or (where it does not
// totally reflect) refracting, and their tint multiplies the albedo. A diffuse or glossy
// surface gives its rho, a translucent (rough) dielectric its Fresnel-weighted rhoR and rhoT.
// The normal faces the incoming ray, in world space. A miss (or a chain cut off) gives zero
// for both and hit = false.
struct FirstSurface {
    Color albedo, normal;
    bool hit = false;
};
FirstSurface first_surface(const RenderScene& scene, Ray ray, int max_chain = 16);
// The same where the ray's first hit is known (`hit.sphere` -1: a miss), cast in lanes with
// others (camera_hits, render/trace.h).
FirstSurface first_surface_from(const RenderScene& scene, Ray ray, Hit hit, int max_chain = 16);

// The layers of every pixel: first_surface of the pixel centre's camera ray through the lens
// centre. One ray chain per pixel, parallel over rows: a small fraction of one render pass.
struct SurfaceLayers {
    std::vector<Color> albedo, normal;
};
SurfaceLayers first_surface_layers(const RenderScene& scene, int width, int height, int max_chain = 16);

// The layers averaged over `samples` camera rays per pixel, drawn as the pixel's first
// `samples` camera samples are (settings' estimator and seed: the same sub-pixel and lens
// positions), so anti-aliased edges and depth of field come out as in the radiance. Their
// first hits are cast in lanes (camera_hits). The
// normals are averaged, not renormalised: a pixel half on a sphere and half on nothing has a
// normal of length 1/2. The denoiser's feature buffers; parallel over rows.
SurfaceLayers averaged_surface_layers(const RenderScene& scene, const RenderSettings& settings, int width, int height,
                                      int samples);

// The same layers made a few samples at a time (the viewer's display refines them frame by
// frame): adds the first-surface albedo and normal of the pixels' camera samples
// [first, first + count) to `sums`, sized here on the first call. Sums over samples 0..n-1 in
// any number of calls, divided by n, are averaged_surface_layers(n) bit for bit.
void add_surface_samples(const RenderScene& scene, const RenderSettings& settings, int width, int height, int first,
                         int count, SurfaceLayers& sums);
// The same for the pixels of `box` only (clipped to the image), each refined from its own
// count of samples (`counts`, one per pixel, sized and zeroed here on the first call) to
// `total`: a render region's pixels first, the others when they are asked for. Once every
// pixel is at n, the sums are those of samples 0..n-1, bit for bit. Once `cancel` is set (by
// another thread) the rows not yet begun are left as they were, their counts with them, and
// the call returns false.
bool add_surface_samples(const RenderScene& scene, const RenderSettings& settings, int width, int height,
                         const PixelBox& box, int total, std::vector<uint8_t>& counts, SurfaceLayers& sums,
                         const std::atomic<bool>* cancel = nullptr);

}  // namespace kr
