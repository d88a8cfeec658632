// The first-surface layers (AOVs) of an HDR output: albedo and normal of the first
// non-specular hit. The other layers come from the render's state (render/outputs.h).
#pragma once

#include <vector>

#include "core/math.h"
#include "render/render_scene.h"

namespace kr {

// Albedo and unit normal of the first non-specular surface each pixel's centre sees (its
// camera ray through the lens centre): perfect mirrors and sharp dielectrics are followed,
// up to `max_chain` of them, reflecting or (where it does not totally reflect) refracting,
// and their tint multiplies the albedo. A diffuse or glossy surface gives its rho, a
// translucent (rough) dielectric its Fresnel-weighted rhoR and rhoT. The normal faces the
// incoming ray, in world space. Misses (and chains cut off) give zero for both.
// One ray chain per pixel, parallel over rows: a small fraction of one render pass.
struct SurfaceLayers {
    std::vector<Color> albedo, normal;
};
SurfaceLayers first_surface_layers(const RenderScene& scene, int width, int height, int max_chain = 16);

}  // namespace kr
