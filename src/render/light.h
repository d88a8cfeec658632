// Light sampling for next-event estimation, and the matching densities for MIS.
#pragma once

#include "core/math.h"
#include "render/render_scene.h"
#include "scene/scene.h"

namespace kr {

// How a point is chosen on a spherical light:
// - brief: the estimator the brief's reference images were rendered with (measured, see
//   docs/fidelity.md): a uniform point on the hemisphere facing the shading point, with the
//   light-side cosine taken about that hemisphere's axis instead of towards the shading
//   point. It overestimates irradiance within a few radii of a light (x1.6 at 3 radii) and
//   matches the references; it is the default so renders reproduce them.
// - cone: uniform over the cone of directions the sphere subtends. Exact, converges fastest.
// - area: uniform over the sphere's area (the brief's stated baseline, pdf 1/A). Exact.
// Cone and area are combined with BSDF sampling by multiple importance sampling.
enum class LightSampling { brief, cone, area };
inline constexpr EnumNames<LightSampling, 3> light_sampling_names{{"brief", "cone", "area"}};

// Exact strategies are MIS-weighted against BSDF sampling; brief is used on its own.
inline bool is_exact(LightSampling s) { return s != LightSampling::brief; }

struct LightSample {
    Vec3 wi;          // unit direction from the shading point to the light
    double distance;  // to the sampled point
    double pdf;       // solid-angle density of wi (light selection not included); for the
                      // brief strategy, the density its estimator divides by
};

// Samples a direction towards the spherical light from p. False when the sample carries no
// light (uniform area sampling picked a point on the side facing away from p).
bool sample_sphere_light(const SphereGeom& light, const Vec3& p, LightSampling strategy, double u1,
                         double u2, LightSample& out);

// Solid-angle density with which sample_sphere_light picks direction wi from p, given that the
// ray along wi meets the light at distance `distance` where its outward normal is `n_light`.
double sphere_light_pdf(const SphereGeom& light, const Vec3& p, const Vec3& wi, double distance,
                        const Vec3& n_light, LightSampling strategy);

}  // namespace kr
