// The auxiliary layers (AOVs) of an HDR output: depth, albedo and normal of the first
// non-specular hit, samples per pixel and the variance of the mean, beside the radiance.
#pragma once

#include "core/image_hdr.h"
#include "render/progressive.h"

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

// The HDR image of a render: `radiance` (the mean, possibly blurred, as the 8-bit output has
// it) and the layers. `with_variance` false leaves the variance layer out (a blurred radiance
// is not the mean the variance belongs to).
HdrImage hdr_from_render(const RenderScene& scene, const RenderState& state, const Image& radiance,
                         bool with_variance);

}  // namespace kr
