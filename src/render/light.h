// Light sampling for next-event estimation, and the matching densities for MIS.
#pragma once

#include "core/math.h"
#include "render/render_scene.h"
#include "scene/scene.h"

namespace kr {

// How a point is chosen on a spherical light. Two integrals: the exact one, and the brief's,
// which the brief's reference images were rendered with (measured, see docs/fidelity.md): over
// the hemisphere of the light facing the shading point, with the light-side cosine taken about
// that hemisphere's axis instead of towards the shading point. The brief's is brighter within a
// few radii of a light (x1.6 at 3 radii) and matches the references, so it is the default.
// - brief: the brief's integral, points drawn in proportion to cos_axis / dist^2 (bounded
//   weights however close the light), combined with BSDF sampling (light_emission_scale).
// - brief-area: the brief's integral as the brief's own renderer drew it: uniform over the
//   facing hemisphere's area, not combined with BSDF sampling. Heavy-tailed near lights; the
//   baseline the brief estimator is measured against (docs/accuracy.md).
// - cone: the exact integral, uniform over the cone of directions the sphere subtends.
// - area: the exact integral, uniform over the sphere's area (the brief's stated baseline).
// All but brief-area are combined with BSDF sampling by multiple importance sampling.
enum class LightSampling { brief, cone, area, brief_area };
inline constexpr EnumNames<LightSampling, 4> light_sampling_names{{"brief", "cone", "area", "brief-area"}};

// False for the one strategy used on its own: BSDF-sampled hits of a light then count nothing.
inline bool combines_with_bsdf(LightSampling s) { return s != LightSampling::brief_area; }

// True for the strategies that estimate the brief's integral.
inline bool is_brief(LightSampling s) { return s == LightSampling::brief || s == LightSampling::brief_area; }

struct LightSample {
    Vec3 wi;          // unit direction from the shading point to the light
    double distance;  // to the sampled point
    double pdf;       // solid-angle density of wi (light selection not included); for the
                      // brief strategy, the density its estimator divides by
    double mis_pdf;   // solid-angle density to weigh against BSDF sampling; 0: BSDF sampling
                      // cannot produce this point, weight 1
};

// Samples a direction towards the spherical light from p. False when the sample carries no
// light (uniform area sampling picked a point on the side facing away from p).
bool sample_sphere_light(const SphereGeom& light, const Vec3& p, LightSampling strategy, double u1,
                         double u2, LightSample& out);

// Solid-angle density with which sample_sphere_light picks direction wi from p, given that the
// ray along wi meets the light at distance `distance` where its outward normal is `n_light`
// (the first hit, seen from outside).
double sphere_light_pdf(const SphereGeom& light, const Vec3& p, const Vec3& wi, double distance,
                        const Vec3& n_light, LightSampling strategy);

// The factor on the light's radiance in the integral the strategy estimates, for a BSDF-sampled
// ray from p along wi that hits the light where its normal is n_light: 1 for the exact
// strategies; cos_axis / cos_light for the brief's (whose integral has the light-side cosine
// about the axis from the light's centre to p).
double light_emission_scale(const SphereGeom& light, const Vec3& p, const Vec3& wi, const Vec3& n_light,
                            LightSampling strategy);

}  // namespace kr
