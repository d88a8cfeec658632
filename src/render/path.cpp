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

// Direct light from one point light at a surface with a smooth lobe (no selection pdf):
// the shadow ray to cast and what it brings if nothing blocks it. False: nothing to bring.
bool point_light_direct(const PointLight& light, const Material& m, const Hit& hit, const SurfacePoint& sp,
                        Ray& shadow, Color& direct) {
    Vec3 wi = light.position - hit.p;
    const double d2 = dot(wi, wi);
    if (!(d2 > 0)) return false;
    const double d = std::sqrt(d2);
    wi = wi / d;
    const Color f_cos = eval_smooth(m, sp, wi);
    if (is_black(f_cos)) return false;
    // Irradiance = I cos / d^2 (the power of a point light is its intensity).
    respawn(shadow, hit, wi, d);
    direct = f_cos * light.intensity / d2;
    return true;
}

// Light sample towards one area light; `mis` weights it against BSDF sampling. The shadow
// ray to cast and what it brings if nothing blocks it; false: nothing to bring.
bool area_light_direct(const RenderScene& scene, LightSampling sampling, const AreaLight& light, const Material& m,
                       const Hit& hit, const SurfacePoint& sp, bool mis, double select_prob, Vec2 u, Ray& shadow,
                       Color& direct) {
    if (light.sphere == hit.sphere) return false;  // a convex emitter cannot light itself
    if (!has_smooth_lobe(m)) return false;          // nothing for a light sample to evaluate
    LightSample ls;
    const SphereGeom& geom = scene.spheres[light.sphere];
    if (!sample_sphere_light(geom, hit.p, sampling, u.x, u.y, ls)) return false;
    const vertex::DirectLight<OnePath> d = vertex::direct_light<OnePath>(
        {ls.wi, ls.distance, ls.pdf, ls.mis_pdf, true}, vertex::OneMaterial{m}, sp.ns(), light.radiance, select_prob,
        mis);
    if (!d.lit) return false;
    respawn(shadow, hit, ls.wi, ls.distance, light.sphere);
    direct = d.light;
    return true;
}

double emission_weight(const RenderScene& scene, LightSampling sampling, const AreaLight& light, const Hit& hit,
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
    const vertex::LightChoice<OnePath> choice =
        vertex::choose_light<OnePath>(scene, settings.integrator == Integrator::pt_naive, u);
    if (choice.point >= 0) {
        const PointLight& light = scene.point_lights[size_t(choice.point)];
        if (!point_light_direct(light, m, hit, sp, shadow, direct)) return false;
        direct = direct / light.select_prob;
        return true;
    }
    if (choice.area < 0) return false;
    const AreaLight& light = scene.area_lights[size_t(choice.area)];
    return light.select_prob > 0 && area_light_direct(scene, settings.light_sampling, light, m, hit, sp, true,
                                                       light.select_prob, u_point, shadow, direct);
}

unsigned vertex_numbers_used(const RenderScene& scene, const Material& m, int bounce, int rr_depth) {
    const bool next_event = has_smooth_lobe(m) && scene.light_count() > 0;
    return (next_event && scene.light_count() > 1 ? Sampler::use_light_pick : 0u) |
           (next_event && !scene.area_lights.empty() ? Sampler::use_light : 0u) |
           (uses_lobe_choice(m) ? Sampler::use_lobe : 0u) | (uses_direction_sample(m) ? Sampler::use_bsdf : 0u) |
           (bounce + 1 >= rr_depth ? Sampler::use_roulette : 0u);
}

}  // namespace kr
