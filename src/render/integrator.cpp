// The two integrators: Whitted-style recursive ray tracing and iterative path tracing, one
// sample at a time. Path tracing of eight (float) or four (double) samples at once is
// lanes/kernels.cpp; the steps both path tracers share are in path.cpp and vertex.h.
#include <algorithm>

#include "render/material.h"
#include "render/path.h"
#include "render/trace.h"
#include "render/lanes/vertex.h"

namespace kr {

using vertex::OnePath;

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

    // A light's sample (vertex::light_direct, every light taken: no selection, no MIS) with its
    // shadow ray cast at once. u: the vertex's light numbers, for a light on a sphere.
    Color light_now(const RenderLight& light, const Material& m, const Hit& hit, const SurfacePoint& sp, Vec2 u) {
        vertex::OneLightSample sample;
        if (!vertex::light_direct<false>(scene, settings.light_sampling, light, m, hit.p, sp.ns(), hit.sphere, false, u,
                                         sample))
            return {};
        return visible(spawn(hit, sample.wi, sample.distance, sample.to_sphere)) ? sample.light : Color();
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
        if (light_index >= 0) L += medium.seen(scene.lights[light_index].power);
        if (event > settings.max_depth) return L;
        const Material& m = scene.materials[scene.sphere_material[hit.sphere]];
        const SurfacePoint sp{hit.n, dot(ray.d, hit.n) < 0};
        // By the material's lobes (vertex.inc's material_lobes), not its type.
        const vertex::MaterialLobes lobes = vertex::material_lobes(m.type);
        if (lobes.smooth) {
            // Every light off the spheres exactly; every light on a sphere with one sample
            // (distributed RT), which draws the vertex's next two numbers.
            for (const RenderLight& light : scene.lights)
                L += medium.seen(light_now(light, m, hit, sp,
                                           vertex::light_kind(light.type).on_sphere ? sampler.next_2d() : Vec2{}));
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
    // Not inlined into trace_sample: its registers and frame would be saved on every call,
    // a Whitted sample's too (about 15 instructions a sample).
    [[gnu::noinline]] Color path(Ray ray, double* primary_distance) {
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
                const RenderLight& light = scene.lights[light_index];
                L += medium.seen(throughput) * light.power *
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
