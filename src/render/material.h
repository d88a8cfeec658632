// Material scattering: the BSDF of each material type, as sampling and evaluation, for one
// path (the physics itself is vertex.h's, which the SIMD lanes share).
#pragma once

#include "core/math.h"
#include "core/sampling.h"
#include "render/lanes/vertex.h"
#include "scene/scene.h"

namespace kr {

// Geometry of a surface interaction as a material sees it.
struct SurfacePoint {
    Vec3 n;      // outward geometric normal of the sphere
    bool front;  // the incoming ray arrived from outside the sphere
    Vec3 ns() const { return front ? n : -n; }  // normal on the incident side
};

// One sampled continuation of a path.
struct ScatterSample {
    Vec3 direction;
    Color weight;        // f cos / pdf: what the path throughput is multiplied by
    double pdf = 0;      // solid-angle density, for smooth lobes that also get light samples
    bool smooth = false; // true: a density the light sampler can match (MIS); false: a delta or
                         // a lobe sampled only through its own distribution (no light samples)
    bool transmitted = false;  // crossed a dielectric's surface (see MediumScale)
};

// Radiance crossing a refractive interface scales by (eta_i / eta_t)^2 (pbrt's radiance
// transport): radiance inside glass of index eta is eta^2 times that outside for the same
// flux. A camera path keeps its throughput free of that factor (so Russian roulette decides
// as without it, pbrt's etaScale) and scales only the light it gathers: by (eta of the camera's
// medium / eta of the medium it is in)^2. `eta` is that ratio's inverse, kept as a product of
// the materials' etas so that entering and leaving one dielectric gives exactly 1 again.
struct MediumScale {
    double eta = 1;       // index of the path's medium relative to the camera's
    double radiance = 1;  // 1 / eta^2: what gathered light is multiplied by
    // After a transmission through material `m` (`entering`: from outside its sphere).
    void cross(const Material& m, bool entering) {
        vertex::cross_medium<vertex::OnePath>(eta, radiance, true, entering, m.eta);
    }
    // Light gathered in this medium as the camera sees it. Most paths never enter a
    // dielectric: the test costs less than the multiply it skips (measured, WRT).
    Color seen(const Color& c) const { return radiance == 1 ? c : c * radiance; }
};

// Only the smooth lobe is evaluated for next-event estimation; the others are reached
// through sampling. True if the material has such a lobe (vertex.inc's material_lobes).
inline bool has_smooth_lobe(const Material& m) { return vertex::material_lobes(m.type).smooth; }
// Which random numbers sample_material reads: the reflect-or-transmit choice, and the 2-D
// direction sample (a diffuse bounce, or a direction perturbed by roughness; a perfect
// mirror or sharp dielectric needs none).
inline bool uses_lobe_choice(const Material& m) { return vertex::material_lobes(m.type).fresnel_split; }
inline bool uses_direction_sample(const Material& m) {
    const vertex::MaterialLobes lobes = vertex::material_lobes(m.type);
    return lobes.smooth || (lobes.rough && m.roughness > 0);
}

// f * |cos(wo)| of the smooth lobe (vertex.inc's smooth_lobe; 0 for a material without one),
// for wo a unit direction away from the surface.
Color eval_smooth(const Material& m, const SurfacePoint& sp, const Vec3& wo);

// Samples an outgoing direction for a ray arriving along `wi` (unit, pointing at the surface),
// from uniform numbers: `u_lobe` picks reflection or transmission, `u` the direction.
// False when the path is absorbed (a perturbed direction fell on the wrong side).
bool sample_material(const Material& m, const SurfacePoint& sp, const Vec3& wi, double u_lobe,
                     Vec2 u, ScatterSample& out);

// Fresnel split of a dielectric for a ray arriving along wi: reflectance and the two directions.
struct DielectricSplit {
    double reflectance;   // 1 on total internal reflection
    Vec3 reflected;
    Vec3 transmitted;     // valid only if reflectance < 1
};
DielectricSplit split_dielectric(const Material& m, const SurfacePoint& sp, const Vec3& wi);

}  // namespace kr
