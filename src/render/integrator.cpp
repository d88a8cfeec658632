// The two integrators: Whitted-style recursive ray tracing and iterative path tracing, one
// sample at a time. Path tracing of eight (float) or four (double) samples at once is
// packet.cpp; the steps both path tracers share are here (path.h) and in vertex.h.
#include <algorithm>

#include "render/material.h"
#include "render/path.h"
#include "render/trace.h"
#include "render/vertex.h"

namespace kr {

using vertex::OnePath;

// A ray leaving hit point `hit` along `dir`, written field by field into `r`: copying a
// whole Ray just after its fields were stored stalls on store forwarding (measured: a
// tenth of the path loop's time).
void respawn(Ray& r, const Hit& hit, const Vec3& dir, double tmax, int to_sphere) {
    r.o = hit.p;
    r.d = dir;
    r.tmin = 0;
    r.tmax = tmax;
    r.from_sphere = hit.sphere;
    r.into_from_sphere = dot(dir, hit.n) < 0;
    r.to_sphere = to_sphere;
}

namespace {

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
    if (!has_smooth_lobe(m)) return false;          // eval_smooth is 0
    LightSample ls;
    const SphereGeom& geom = scene.spheres[light.sphere];
    if (!sample_sphere_light(geom, hit.p, sampling, u.x, u.y, ls)) return false;
    const vertex::DirectLight<OnePath> d = vertex::direct_light<OnePath>(
        {ls.wi, ls.distance, ls.pdf, ls.mis_pdf, true}, m.rho, sp.ns(), light.radiance, select_prob, mis);
    if (!d.lit) return false;
    respawn(shadow, hit, ls.wi, ls.distance, light.sphere);
    direct = d.light;
    return true;
}

}  // namespace

double emission_weight(const RenderScene& scene, LightSampling sampling, const AreaLight& light, const Hit& hit,
                       const Vec3& incoming, const PathHistory& history) {
    if (history.full_emission || hit.sphere == history.last_sphere) return 1;
    // The light sample at the last vertex counted all of this light, or could have found this
    // point too: then the two strategies are weighed by the power heuristic.
    if (!combines_with_bsdf(sampling)) return 0;
    const SphereGeom& geom = scene.spheres[hit.sphere];
    const double p_light = light.select_prob * sphere_light_pdf(geom, history.last_p, incoming, hit.t, hit.n, sampling);
    const double p_bsdf = history.last_bsdf_pdf;
    return light_emission_scale(geom, history.last_p, incoming, hit.n, sampling) * p_bsdf * p_bsdf /
           (p_bsdf * p_bsdf + p_light * p_light);
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

namespace {

struct Tracer {
    const RenderScene& scene;
    const RenderSettings& settings;
    Sampler& sampler;
    uint64_t rays = 0;
    MediumScale medium;  // WRT: the dielectrics the current ray has crossed

    bool intersect(const Ray& ray, Hit& hit) {
        ++rays;
        return scene.intersects(ray, hit);
    }
    bool visible(const Ray& ray) {
        ++rays;
        return !scene.is_occluded(ray);
    }

    static Ray spawn(const Hit& hit, const Vec3& dir, double tmax = kInfinity, int to_sphere = -1) {
        Ray r;
        respawn(r, hit, dir, tmax, to_sphere);
        return r;
    }

    // point_light_direct and area_light_direct with their shadow ray cast at once.
    Color point_light_now(const PointLight& light, const Material& m, const Hit& hit, const SurfacePoint& sp) {
        Ray shadow;
        Color direct;
        return point_light_direct(light, m, hit, sp, shadow, direct) && visible(shadow) ? direct : Color();
    }
    Color area_light_now(const AreaLight& light, const Material& m, const Hit& hit, const SurfacePoint& sp, Vec2 u) {
        Ray shadow;
        Color direct;
        const bool lit = area_light_direct(scene, settings.light_sampling, light, m, hit, sp, false, 1.0, u, shadow, direct);
        return lit && visible(shadow) ? direct : Color();
    }

    // ---- Whitted-style ray tracing: L D S* E, recursive. ----
    // `event` counts scattering events; the camera ray's hit is event 1. The light gathered
    // here takes the radiance scale of the dielectrics the ray has crossed (`medium`).
    Color whitted(const Ray& ray, int event, double* primary_distance) {
        Hit hit;
        if (!intersect(ray, hit)) return {};  // nothing hit: black
        if (primary_distance) *primary_distance = hit.t;
        Color L;
        const int light_index = scene.sphere_light[hit.sphere];
        if (light_index >= 0) L += medium.seen(scene.area_lights[light_index].radiance);
        if (event > settings.max_depth) return L;
        const Material& m = scene.materials[scene.sphere_material[hit.sphere]];
        const SurfacePoint sp{hit.n, dot(ray.d, hit.n) < 0};
        // By the material's lobes (vertex.inc's material_lobes), not its type.
        const vertex::MaterialLobes lobes = vertex::material_lobes(m.type);
        if (lobes.smooth) {
            // Every point light exactly; every area light with one sample (distributed RT).
            for (const PointLight& light : scene.point_lights) L += medium.seen(point_light_now(light, m, hit, sp));
            for (const AreaLight& light : scene.area_lights)
                L += medium.seen(area_light_now(light, m, hit, sp, sampler.next_2d()));
        } else if (lobes.fresnel_split) {
            // Both branches, weighted by Fresnel: F rhoR L_r + (1 - F) rhoT L_t.
            const DielectricSplit split = split_dielectric(m, sp, ray.d);
            const double beta = lobes.rough ? m.roughness : 0.0;
            const Vec3 ns = sp.ns();
            const Vec2 u_reflect = sampler.next_2d(), u_transmit = sampler.next_2d();
            Vec3 dir = perturb_direction(split.reflected, beta, u_reflect.x, u_reflect.y);
            if (dot(dir, ns) > 0) L += (split.reflectance * m.rho_r) * whitted(spawn(hit, dir), event + 1, nullptr);
            if (split.reflectance < 1) {
                dir = perturb_direction(split.transmitted, beta, u_transmit.x, u_transmit.y);
                if (dot(dir, ns) < 0) {
                    const MediumScale here = medium;
                    medium.cross(m, sp.front);
                    L += ((1 - split.reflectance) * m.rho_t) * whitted(spawn(hit, dir), event + 1, nullptr);
                    medium = here;
                }
            }
        } else if (lobes.rough) {
            // One direction, as path tracing samples it.
            ScatterSample s;
            const double u_lobe = sampler.next_1d();
            if (sample_material(m, sp, ray.d, u_lobe, sampler.next_2d(), s))
                L += s.weight * whitted(spawn(hit, s.direction), event + 1, nullptr);
        } else {
            L += m.rho * whitted(spawn(hit, reflect(ray.d, sp.ns())), event + 1, nullptr);  // a mirror
        }
        return L;
    }

    // ---- Path tracing: L (D|S)* E, iterative, with next-event estimation and MIS. ----
    Color path(Ray ray, double* primary_distance) {
        Color L, throughput(1.0);  // without the dielectrics' radiance scale (medium)
        medium = {};
        PathHistory history;
        for (int bounce = 0;; ++bounce) {
            Hit hit;
            if (!intersect(ray, hit)) break;
            if (bounce == 0 && primary_distance) *primary_distance = hit.t;

            // Emission seen along the path, MIS-weighted where a light sample could have found it.
            const int light_index = scene.sphere_light[hit.sphere];
            if (light_index >= 0) {
                const AreaLight& light = scene.area_lights[light_index];
                L += medium.seen(throughput) * light.radiance *
                     emission_weight(scene, settings.light_sampling, light, hit, ray.d, history);
            }
            if (bounce >= settings.max_depth) break;

            const Material& m = scene.materials[scene.sphere_material[hit.sphere]];
            const SurfacePoint sp{hit.n, dot(ray.d, hit.n) < 0};

            // Every vertex draws the same dimensions whatever its material, so each dimension
            // of a low-discrepancy sampler keeps one meaning across the pixel's samples; only
            // those this vertex reads are computed.
            const Sampler::VertexNumbers u =
                sampler.next_vertex(vertex_numbers_used(scene, m, bounce, settings.rr_depth));

            // Next-event estimation: one light, chosen in proportion to its power.
            if (has_smooth_lobe(m) && scene.light_count() > 0) {
                Ray shadow;
                Color direct;
                if (sample_one_light(scene, settings, m, hit, sp, u.light_pick, u.light, shadow, direct) &&
                    visible(shadow))
                    L += medium.seen(throughput) * direct;
            }

            ScatterSample s;
            if (!sample_material(m, sp, ray.d, u.lobe, u.bsdf, s)) break;
            throughput *= s.weight;
            if (s.transmitted) medium.cross(m, sp.front);
            history.full_emission = settings.integrator == Integrator::pt_naive || !s.smooth;
            history.last_bsdf_pdf = s.pdf;
            history.last_p = hit.p;
            history.last_sphere = hit.sphere;
            respawn(ray, hit, s.direction);

            // Russian roulette past the threshold depth.
            if (bounce + 1 >= settings.rr_depth) {
                bool alive = true;
                vertex::russian_roulette<OnePath>(throughput, alive, true, u.roulette);
                if (!alive) break;
            }
        }
        return L;
    }
};

}  // namespace

SampleResult trace_sample(const RenderScene& scene, const RenderSettings& settings, const Ray& ray,
                          Sampler& sampler) {
    Tracer tracer{scene, settings, sampler, 0, {}};
    SampleResult result;
    result.radiance = settings.integrator == Integrator::wrt ? tracer.whitted(ray, 1, &result.primary_distance)
                                                             : tracer.path(ray, &result.primary_distance);
    result.rays = tracer.rays;
    return result;
}

}  // namespace kr
