// Light sampling for next-event estimation, and the matching densities for MIS.
#pragma once

#include "core/math.h"
#include "render/render_scene.h"
#include "scene/scene.h"

namespace kr {

// How a point is chosen on a spherical light: uniformly over its area (the brief's
// baseline, pdf 1/A) or uniformly over the cone of directions it subtends (no samples
// wasted on its far side; converges faster).
enum class LightSampling { cone, area };
inline constexpr EnumNames<LightSampling, 2> light_sampling_names{{"cone", "area"}};

struct LightSample {
    Vec3 wi;          // unit direction from the shading point to the light
    double distance;  // to the sampled point
    double pdf;       // solid-angle density of wi (light selection not included)
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
