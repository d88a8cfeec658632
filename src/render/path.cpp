// The steps of path tracing that the one-path integrator (integrator.cpp) and the lanes
// (lanes/kernels.cpp) share: a ray's respawn, the weight of emission hit by chance, next-event
// estimation of one light, and which numbers a vertex draws.
#include "render/path.h"

#include <cmath>

#include "render/light.h"
#include "render/sampler.h"
#include "render/lanes/vertex.h"

namespace kr {

using vertex::OnePath;

double emission_weight(const RenderScene& scene, LightSampling sampling, const RenderLight& light, const Hit& hit,
                       const Vec3& incoming, const PathHistory& history) {
    if (history.full_emission || hit.sphere == history.last_sphere) return 1;
    // The light sample at the last vertex counted all of this light, or could have found this
    // point too: then the two strategies are weighed by the power heuristic.
    const SphereGeom& geom = scene.spheres[hit.sphere];
    return vertex::emission_mis_weight<vertex::OnePath>(sampling, geom.centre, geom.radius, light.select_prob,
                                                        history.last_p, incoming, hit.t, hit.n,
                                                        history.last_bsdf_pdf, true);
}

bool sample_one_light(const RenderScene& scene, const RenderSettings& settings, const Material& m, const Hit& hit,
                      const SurfacePoint& sp, double u, Vec2 u_point, Ray& shadow, Color& direct) {
    const int chosen = vertex::choose_light<OnePath>(scene, settings.integrator == Integrator::pt_naive, u);
    if (chosen < 0) return false;
    const RenderLight& light = scene.lights[size_t(chosen)];
    vertex::OneLightSample sample;
    if (!(light.select_prob > 0) || !vertex::light_direct<true>(scene, settings.light_sampling, light, m, hit.p,
                                                                 sp.ns(), hit.sphere, true, u_point, sample))
        return false;
    respawn(shadow, hit, sample.wi, sample.distance, sample.to_sphere);
    direct = sample.light;
    return true;
}

unsigned vertex_numbers_used(const RenderScene& scene, const Material& m, int bounce, int rr_depth) {
    const bool next_event = has_smooth_lobe(m) && scene.light_count() > 0;
    return (next_event && scene.light_count() > 1 ? Sampler::use_light_pick : 0u) |
           (next_event && scene.lights_off_spheres < scene.light_count() ? Sampler::use_light : 0u) |
           (uses_lobe_choice(m) ? Sampler::use_lobe : 0u) | (uses_direction_sample(m) ? Sampler::use_bsdf : 0u) |
           (bounce + 1 >= rr_depth ? Sampler::use_roulette : 0u);
}

}  // namespace kr
