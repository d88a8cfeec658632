// Analytic scenes: furnaces and direct lighting with known answers, for every integrator.
#include <gtest/gtest.h>

#include <cmath>
#include <omp.h>

#include "render/material.h"
#include "render/progressive.h"
#include "render/trace.h"
#include "test_util.h"

using namespace kr;

namespace {

struct Estimate {
    Color mean;
    double stderr_lum = 0;  // standard error of the luminance mean
};

// Mean radiance of n independent samples along one ray.
Estimate estimate(const RenderScene& scene, const RenderSettings& settings, const Ray& ray, int n) {
    Color sum;
    double sum_l = 0, sum_l2 = 0;
    for (int i = 0; i < n; ++i) {
        Sampler sampler(Rng::for_sample(settings.seed, 0, uint64_t(i)));
        const SampleResult r = trace_sample(scene, settings, ray, sampler);
        sum += r.radiance;
        const double l = luminance(r.radiance);
        sum_l += l;
        sum_l2 += l * l;
    }
    const double mean_l = sum_l / n;
    return {sum / double(n), std::sqrt(std::max(0.0, sum_l2 / n - mean_l * mean_l) / n)};
}

Ray ray_towards(Vec3 from, Vec3 to) {
    Ray r;
    r.o = from;
    r.d = normalize(to - from);
    return r;
}

RenderSettings settings_for(Integrator integrator, LightSampling ls = LightSampling::cone, int depth = 6) {
    RenderSettings s;
    s.integrator = integrator;
    s.light_sampling = ls;
    s.max_depth = depth;
    return s;
}

using test::furnace;

}  // namespace

// The brief's furnace: a diffuse sphere of albedo rho inside an emitter of radiance Le shows
// rho * Le, whichever integrator or light sampling strategy renders it.
TEST(Furnace, DiffuseSphereShowsRhoTimesLe) {
    const Color rho(0.2, 0.5, 0.8);
    const RenderScene scene = furnace(MaterialType::diffuse, rho, 2.0).build();
    const Ray ray = ray_towards({0, 0, -5}, {0.3, 0.2, 0});
    for (Integrator integrator : {Integrator::pt, Integrator::pt_naive, Integrator::wrt})
        for (LightSampling ls : {LightSampling::brief, LightSampling::cone, LightSampling::area}) {
            const Estimate e = estimate(scene, settings_for(integrator, ls), ray, 20000);
            const Color expected = rho * 2.0;
            for (int k = 0; k < 3; ++k)
                EXPECT_NEAR(e.mean[k], expected[k], 5 * e.stderr_lum + 1e-3)
                    << integrator_names.name(integrator) << " " << light_sampling_names.name(ls) << " channel " << k;
        }
}

// A wrong convention (BRDF rho instead of rho/pi, or missing the emission) fails this test:
// check it is sensitive by also requiring the camera-facing emitter to show exactly Le.
TEST(Furnace, EmitterSeenDirectlyShowsLe) {
    const RenderScene scene = furnace(MaterialType::diffuse, Color(0.5), 3.0).build();
    const Ray ray = ray_towards({0, 0, -5}, {0, 10, -5});  // misses the inner sphere
    for (Integrator integrator : {Integrator::pt, Integrator::pt_naive, Integrator::wrt}) {
        const Estimate e = estimate(scene, settings_for(integrator), ray, 100);
        EXPECT_NEAR(e.mean.x, 3.0, 1e-12);
    }
}

// Mirrors and clear glass with rho = 1 lose nothing: in the furnace they show Le exactly
// (glass: up to the energy still inside the sphere when the depth cap cuts the path).
TEST(Furnace, SpecularAndGlassConserveEnergy) {
    const Ray ray = ray_towards({0, 0, -5}, {0.4, -0.3, 0});
    {
        const RenderScene scene = furnace(MaterialType::specular, Color(0.9), 1.0).build();
        for (Integrator integrator : {Integrator::pt, Integrator::wrt})
            EXPECT_NEAR(estimate(scene, settings_for(integrator), ray, 100).mean.x, 0.9, 1e-12);
    }
    {
        const RenderScene scene = furnace(MaterialType::dielectric, Color(1.0), 1.0).build();
        EXPECT_NEAR(estimate(scene, settings_for(Integrator::wrt, LightSampling::cone, 20), ray, 1).mean.x, 1.0, 1e-6);
        const Estimate e = estimate(scene, settings_for(Integrator::pt, LightSampling::cone, 20), ray, 20000);
        EXPECT_NEAR(e.mean.x, 1.0, 1e-6);  // every path escapes with weight exactly 1
    }
    {
        // rhoR/rhoT scale the two Fresnel branches: 0.5 everywhere halves each escape
        // after 2 events (in, out) at least; the value stays within (0, 0.5].
        const RenderScene scene = furnace(MaterialType::dielectric, Color(0.5), 1.0).build();
        const double v = estimate(scene, settings_for(Integrator::wrt, LightSampling::cone, 20), ray, 1).mean.x;
        EXPECT_GT(v, 0.25 - 1e-9);
        EXPECT_LE(v, 0.5);
    }
}

// Roughness 0 reduces the glossy and translucent materials to the mirror and clear glass.
TEST(Furnace, ZeroRoughnessEqualsDeltaMaterials) {
    const Ray ray = ray_towards({0, 0, -5}, {0.4, -0.3, 0});
    for (Integrator integrator : {Integrator::pt, Integrator::wrt}) {
        test::SceneBuilder glossy = furnace(MaterialType::glossy, Color(0.7), 1.0);
        glossy.scene.materials[0].roughness = 0;
        EXPECT_NEAR(estimate(glossy.build(), settings_for(integrator), ray, 50).mean.x, 0.7, 1e-12);
        test::SceneBuilder translucent = furnace(MaterialType::translucent, Color(1.0), 1.0);
        translucent.scene.materials[0].roughness = 0;
        EXPECT_NEAR(estimate(translucent.build(), settings_for(integrator, LightSampling::cone, 20), ray, 2000).mean.x,
                    1.0, 1e-6);
    }
}

// Direct light from a sphere light of radiance Le and radius r at distance d from a diffuse
// point whose normal makes angle theta with the light: L = rho Le (r/d)^2 cos(theta),
// the irradiance pi Le sin^2(theta_max) cos(theta) times rho/pi.
// Each material type's smooth lobe, as next-event estimation evaluates it (eval_smooth and
// vertex.inc's smooth_lobe), is the lobe sample_material draws: at a drawn direction its
// density is the sample's and f cos / pdf its weight. A type without a smooth lobe evaluates
// to black and its samples carry no density. Over every type, so a new one is checked too.
TEST(MaterialLobes, SmoothLobeIsWhatSamplingDraws) {
    Rng rng(7, 0);
    for (size_t t = 0; t < material_type_names.names.size(); ++t) {
        Material m;
        m.type = MaterialType(t);
        m.rho = {0.2, 0.5, 0.9};
        m.roughness = 0.3;
        SCOPED_TRACE(std::string(material_type_names.names[t]));
        int smooth_samples = 0;
        for (int i = 0; i < 2000; ++i) {
            const Vec3 n = sample_uniform_sphere(rng.next(), rng.next());
            const Vec3 wi = sample_uniform_sphere(rng.next(), rng.next());
            if (std::abs(dot(wi, n)) < 1e-3) continue;
            const SurfacePoint sp{n, dot(wi, n) < 0};
            ScatterSample s;
            if (!sample_material(m, sp, wi, rng.next(), {rng.next(), rng.next()}, s)) continue;
            const Color f_cos = eval_smooth(m, sp, s.direction);
            const vertex::LobeValue<vertex::OnePath> lobe =
                vertex::eval_smooth_lobe<vertex::OnePath>(vertex::OneMaterial{m}, sp.ns(), s.direction);
            if (!has_smooth_lobe(m)) {
                EXPECT_TRUE(is_black(f_cos));
                EXPECT_FALSE(s.smooth);
                continue;
            }
            ASSERT_TRUE(s.smooth);
            ASSERT_GT(s.pdf, 0);
            ++smooth_samples;
            EXPECT_NEAR(lobe.pdf, s.pdf, 1e-12 * s.pdf);
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(f_cos[c], lobe.f_cos[c], 1e-15);
                EXPECT_NEAR(f_cos[c] / s.pdf, s.weight[c], 1e-12);
            }
        }
        if (has_smooth_lobe(m)) EXPECT_GT(smooth_samples, 1000);
    }
}

// Every light type's sample (vertex.inc's light_direct, as next-event estimation takes it)
// against the analytic irradiance on a white-ish diffuse point facing the light, and what
// light_kind says of the type against its prepared form: a light on a sphere carries that
// sphere and its shadow rays end on it; a light at a point has its shadow rays end there.
// Over every type, so a new one is checked too (its case below: a scene and its answer).
TEST(Lights, EveryTypesSampleGivesItsIrradiance) {
    const Color rho(0.5);
    const double d = 4, radius = 1, power = 2;
    for (size_t t = 0; t < light_type_names.names.size(); ++t) {
        const LightType type = LightType(t);
        SCOPED_TRACE(std::string(light_type_names.name(type)));
        test::SceneBuilder b;
        double irradiance = 0;  // at the origin, normal +y
        switch (type) {
        case LightType::point:  // I / d^2
            b.point_light({0, d, 0}, Color(power));
            irradiance = power / (d * d);
            break;
        case LightType::area:  // a sphere of radiance L wholly above the horizon: pi L (r / d)^2
            b.emitter({0, d, 0}, radius, Color(power), b.material(MaterialType::diffuse, Color(0)));
            irradiance = kPi * power * (radius / d) * (radius / d);
            break;
        }
        const RenderScene scene = b.build();
        ASSERT_EQ(scene.lights.size(), 1u);
        const RenderLight& light = scene.lights[0];
        const vertex::LightKind kind = vertex::light_kind(type);
        EXPECT_EQ(kind.on_sphere, light.sphere >= 0);
        EXPECT_EQ(scene.lights_off_spheres, kind.on_sphere ? 0u : 1u);
        Material m;
        m.type = MaterialType::diffuse;
        m.rho = rho;
        const Vec3 p{0, 0, 0}, ns{0, 1, 0};
        // Stratified light numbers; the light sample alone (no MIS), selection divided out.
        const int n = 64;
        double sum = 0, sum2 = 0;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                vertex::OneLightSample s;
                const Vec2 u{(i + 0.5) / n, (j + 0.5) / n};
                ASSERT_TRUE(vertex::light_direct<true>(scene, LightSampling::cone, light, m, p, ns, -1, false, u, s));
                const Vec3 end = p + s.wi * s.distance;
                if (kind.at_point) EXPECT_NEAR(length(end - light.position), 0, 1e-12);
                if (kind.on_sphere) {
                    EXPECT_EQ(s.to_sphere, light.sphere);
                    EXPECT_NEAR(length(end - scene.spheres[size_t(light.sphere)].centre), radius, 1e-9);
                } else {
                    EXPECT_EQ(s.to_sphere, -1);
                }
                sum += s.light.x;
                sum2 += s.light.x * s.light.x;
            }
        const double count = double(n) * n, mean = sum / count;
        const double sigma = std::sqrt(std::max(0.0, sum2 / count - mean * mean) / count);
        const double expected = rho.x / kPi * irradiance;
        EXPECT_NEAR(mean, expected, 5 * sigma + 1e-12 * expected) << "expected " << expected;
    }
}

// choose_light takes each light in proportion to its selection probability (a grid of u gives
// the shares to within one step); naive path tracing takes only the lights off the spheres,
// which come first; sphere_light names each light's sphere.
TEST(Lights, ChoiceFollowsPowerAndNaiveTakesTheLightsOffTheSpheres) {
    test::SceneBuilder b;
    const int black = b.material(MaterialType::diffuse, Color(0));
    b.emitter({0, 5, 0}, 1, Color(3), black);
    b.point_light({2, 3, 0}, Color(1));
    b.emitter({0, -5, 0}, 0.5, Color(8), black);
    b.point_light({-2, 3, 0}, Color(5, 4, 3));
    const RenderScene scene = b.build();
    ASSERT_EQ(scene.lights.size(), 4u);
    ASSERT_EQ(scene.lights_off_spheres, 2u);
    for (size_t i = 0; i < scene.lights.size(); ++i)
        EXPECT_EQ(vertex::light_kind(scene.lights[i].type).on_sphere, i >= scene.lights_off_spheres);
    EXPECT_EQ(scene.lights[0].position, Vec3(2, 3, 0));  // the file's order within each group
    for (size_t s = 0; s < scene.spheres.size(); ++s)
        if (scene.sphere_light[s] >= 0) EXPECT_EQ(scene.lights[size_t(scene.sphere_light[s])].sphere, int(s));
    const int n = 100000;
    for (bool naive : {false, true}) {
        std::vector<int> count(scene.lights.size() + 1, 0);  // the last: none
        for (int i = 0; i < n; ++i) {
            const int chosen = vertex::choose_light<vertex::OnePath>(scene, naive, (i + 0.5) / n);
            count[chosen < 0 ? scene.lights.size() : size_t(chosen)]++;
        }
        double off_share = 0;
        for (size_t i = 0; i < scene.lights.size(); ++i) {
            const bool taken = !naive || i < scene.lights_off_spheres;
            EXPECT_NEAR(count[i] / double(n), taken ? scene.lights[i].select_prob : 0.0, 2.0 / n) << naive << " " << i;
            if (i < scene.lights_off_spheres) off_share += scene.lights[i].select_prob;
        }
        EXPECT_NEAR(count.back() / double(n), naive ? 1 - off_share : 0.0, 2.0 / n);
    }
}

TEST(DirectLighting, SphereLightOnDiffuseFloor) {
    test::SceneBuilder b;
    const double rho = 0.5, le = 4.0, r = 0.5;
    b.sphere({0, -1e4, 0}, 1e4, b.material(MaterialType::diffuse, Color(rho)));  // floor y = 0
    const Vec3 light_centre{0, 3, 0};
    b.emitter(light_centre, r, Color(le), b.material(MaterialType::diffuse, Color(0)));
    const RenderScene scene = b.build();
    const Vec3 x{2, 0, 1};
    const Ray ray = ray_towards({2, 5, -4}, x);
    Hit hit;
    ASSERT_TRUE(scene.intersects(ray, hit));
    ASSERT_EQ(hit.sphere, 0);
    const Vec3 to_light = light_centre - hit.p;
    const double d = length(to_light);
    const double expected = rho * le * (r / d) * (r / d) * dot(hit.n, to_light / d);
    for (Integrator integrator : {Integrator::pt, Integrator::pt_naive, Integrator::wrt})
        for (LightSampling ls : {LightSampling::cone, LightSampling::area}) {
            const int n = integrator == Integrator::pt_naive ? 400000 : 40000;
            const Estimate e = estimate(scene, settings_for(integrator, ls), ray, n);
            EXPECT_NEAR(e.mean.x, expected, 5 * e.stderr_lum + 1e-4 * expected)
                << integrator_names.name(integrator) << " " << light_sampling_names.name(ls);
        }
}

// A point light's power is its radiant intensity: E = I cos / d^2, L = rho/pi E.
TEST(DirectLighting, PointLightIntensityConvention) {
    test::SceneBuilder b;
    const double rho = 0.8;
    b.sphere({0, -1e4, 0}, 1e4, b.material(MaterialType::diffuse, Color(rho)));
    const Vec3 light{1, 4, 2};
    b.point_light(light, Color(300));
    const RenderScene scene = b.build();
    const Ray ray = ray_towards({0, 3, -6}, {0, 0, 0});
    Hit hit;
    ASSERT_TRUE(scene.intersects(ray, hit));
    const Vec3 to_light = light - hit.p;
    const double d2 = dot(to_light, to_light);
    const double expected = rho / kPi * 300 * dot(hit.n, to_light / std::sqrt(d2)) / d2;
    for (Integrator integrator : {Integrator::wrt, Integrator::pt, Integrator::pt_naive})
        EXPECT_NEAR(estimate(scene, settings_for(integrator), ray, 1).mean.x, expected, 1e-9 * expected);
}

TEST(DirectLighting, OccluderCastsShadow) {
    test::SceneBuilder b;
    b.sphere({0, -1e4, 0}, 1e4, b.material(MaterialType::diffuse));
    b.sphere({0, 2, 0}, 0.5, b.material(MaterialType::diffuse));
    b.point_light({0, 4, 0}, Color(100));
    const RenderScene scene = b.build();
    const Ray ray = ray_towards({0, 3, -6}, {0, 0, 0});
    EXPECT_EQ(estimate(scene, settings_for(Integrator::wrt), ray, 1).mean.x, 0.0);
}

// Depth 0 shows emitters only; each extra depth adds a bounce.
TEST(Depth, CapCountsScatteringEvents) {
    const RenderScene scene = furnace(MaterialType::specular, Color(0.5), 1.0).build();
    const Ray ray = ray_towards({0, 0, -5}, {0, 0, 0});
    // Mirror in a furnace: depth 0 -> black sphere, depth >= 1 -> 0.5.
    EXPECT_EQ(estimate(scene, settings_for(Integrator::pt, LightSampling::cone, 0), ray, 1).mean.x, 0.0);
    EXPECT_EQ(estimate(scene, settings_for(Integrator::wrt, LightSampling::cone, 0), ray, 1).mean.x, 0.0);
    EXPECT_NEAR(estimate(scene, settings_for(Integrator::pt, LightSampling::cone, 1), ray, 1).mean.x, 0.5, 1e-12);
    EXPECT_NEAR(estimate(scene, settings_for(Integrator::wrt, LightSampling::cone, 1), ray, 1).mean.x, 0.5, 1e-12);
}

// The image is the same whatever the number of threads: per-pixel, per-sample RNG streams.
TEST(Progressive, ImageIndependentOfThreadCount) {
    test::SceneBuilder b = furnace(MaterialType::diffuse, Color(0.5), 1.0);
    b.sphere({0.5, 1.2, -1}, 0.4, b.material(MaterialType::dielectric, Color(0.9)));
    b.scene.renderer.width = 24;
    b.scene.renderer.height = 16;
    const RenderScene scene = b.build();
    RenderSettings settings = settings_for(Integrator::pt);
    settings.target_spp = 4;
    auto render = [&](int threads) {
        omp_set_num_threads(threads);
        RenderState state(24, 16);
        for (int i = 0; i < 4; ++i) render_pass(scene, settings, state);
        return state;
    };
    const RenderState one = render(1), two = render(2), three = render(3);
    omp_set_num_threads(omp_get_num_procs());
    for (size_t i = 0; i < one.radiance_sum().size(); ++i) {
        EXPECT_EQ(one.radiance_sum()[i], two.radiance_sum()[i]);
        EXPECT_EQ(one.radiance_sum()[i], three.radiance_sum()[i]);
    }
    EXPECT_EQ(one.rays, two.rays);
    EXPECT_EQ(one.passes, 4);
}

// A stop request ends the pass early and leaves a consistent state.
TEST(Progressive, StopFlagEndsPass) {
    const RenderScene scene = furnace(MaterialType::diffuse, Color(0.5), 1.0).build();
    RenderState state(8, 8);
    std::atomic<bool> stop{true};
    EXPECT_FALSE(render_pass(scene, settings_for(Integrator::pt), state, &stop));
    EXPECT_EQ(state.passes, 0);
    for (uint32_t c : state.sample_count()) EXPECT_EQ(c, 0u);
    stop = false;
    EXPECT_TRUE(render_pass(scene, settings_for(Integrator::pt), state, &stop));
    EXPECT_EQ(state.passes, 1);
    for (uint32_t c : state.sample_count()) EXPECT_EQ(c, 1u);
}

// The depth map records the primary hit distance, and a finite maximum for misses.
TEST(Progressive, DepthOfPrimaryHit) {
    test::SceneBuilder b;
    b.sphere({0, 0, 0}, 1, b.material(MaterialType::diffuse));
    b.scene.cameras[0].fov = 1;  // the whole image sees the sphere's near point
    b.scene.renderer.width = b.scene.renderer.height = 2;
    const RenderScene scene = b.build();
    RenderState state(2, 2);
    render_pass(scene, settings_for(Integrator::pt), state);
    for (double d : state.mean_depth()) EXPECT_NEAR(d, 9.0, 2e-2);  // 9 + (lateral offset)^2 / 2
    test::SceneBuilder empty;
    empty.sphere({0, 100, 0}, 1, empty.material(MaterialType::diffuse));
    RenderState miss(2, 2);
    render_pass(empty.build(), settings_for(Integrator::pt), miss);
    for (double d : miss.mean_depth()) EXPECT_EQ(d, kMissDepth);
}

namespace {

// A spherical area light of radius 0.5 and radiance `le` (black otherwise) at the centre of a
// clear glass ball of radius 1 and index `eta`: the light sits in glass.
test::SceneBuilder light_in_glass(double eta, double le) {
    test::SceneBuilder b;
    const int glass = b.material(MaterialType::dielectric, Color(1));
    b.scene.materials[glass].rho_r = b.scene.materials[glass].rho_t = Color(1);
    b.scene.materials[glass].eta = eta;
    b.sphere({0, 0, 0}, 1, glass);
    b.emitter({0, 0, 0}, 0.5, Color(le), b.material(MaterialType::diffuse, Color(0)));
    return b;
}

}  // namespace

// Radiance crossing into a medium of index eta scales by eta^2 (MediumScale, material.h): a
// light inside glass, seen from outside, shows its radiance over eta^2. A camera ray of
// impact parameter b (from the centre) refracts at the ball's surface into a ray passing the
// centre at b / eta (n b is conserved in a concentric scene), so it meets the light where
// b < eta r; the light is black, so the only contribution is the transmitted one:
// (1 - F(cos_i)) Le / eta^2, F the Fresnel reflectance at cos_i = sqrt(1 - b^2). Beyond
// eta r it never meets the light (every internal reflection keeps b / eta): black. Without
// the eta^2 the light was 2.25 times too bright at eta 1.5, in naive PT too.
TEST(Dielectric, LightInsideGlassShowsRadianceOverEtaSquared) {
    const double eta = 1.5, le = 4;
    const RenderScene scene = light_in_glass(eta, le).build();
    for (double b : {0.0, 0.3, 0.7, 0.8, 0.95}) {
        const Ray ray = ray_towards({b, 0, -5}, {b, 0, 0});
        const double expected =
            b < eta * 0.5 ? (1 - fresnel_dielectric(std::sqrt(1 - b * b), 1 / eta)) * le / (eta * eta) : 0.0;
        const Estimate wrt = estimate(scene, settings_for(Integrator::wrt), ray, 1);
        EXPECT_NEAR(wrt.mean.x, expected, 1e-12) << "WRT, b = " << b;
        for (Integrator integrator : {Integrator::pt, Integrator::pt_naive}) {
            // Each sample is Le / eta^2 (transmitted) or 0 (reflected): a Bernoulli mean.
            const Estimate e = estimate(scene, settings_for(integrator), ray, 20000);
            EXPECT_NEAR(e.mean.x, expected, 5 * e.stderr_lum + 1e-12)
                << integrator_names.name(integrator) << ", b = " << b;
        }
    }
    // The translucent dielectric at roughness 0 is the same glass.
    test::SceneBuilder translucent = light_in_glass(eta, le);
    translucent.scene.materials[0].type = MaterialType::translucent;
    translucent.scene.materials[0].roughness = 0;
    const Ray axis = ray_towards({0, 0, -5}, {0, 0, 0});
    const double on_axis = (1 - fresnel_dielectric(1, 1 / eta)) * le / (eta * eta);
    EXPECT_NEAR(estimate(translucent.build(), settings_for(Integrator::wrt), axis, 1).mean.x, on_axis, 1e-12);
    const Estimate e = estimate(translucent.build(), settings_for(Integrator::pt), axis, 20000);
    EXPECT_NEAR(e.mean.x, on_axis, 5 * e.stderr_lum);

    // The other way: a camera inside the glass ball (at its centre) sees the furnace's
    // radiance Le outside it as eta^2 Le. Every path leaves through the ball's wall at normal
    // incidence sooner or later (reflected ones cross the centre to the opposite side), so
    // WRT sums eta^2 Le (1 - F) F^k up to the depth: eta^2 Le (1 - F^depth).
    test::SceneBuilder inside = furnace(MaterialType::dielectric, Color(1), le);
    inside.scene.materials[0].eta = eta;
    const RenderScene camera_in_glass = inside.build();
    const Ray out = ray_towards({0, 0, 0}, {0.3, 0.2, 1});
    const double f = fresnel_dielectric(1, eta);
    EXPECT_NEAR(estimate(camera_in_glass, settings_for(Integrator::wrt, LightSampling::cone, 20), out, 1).mean.x,
                eta * eta * le * (1 - std::pow(f, 20)), 1e-9);
    for (Integrator integrator : {Integrator::pt, Integrator::pt_naive}) {
        const Estimate seen = estimate(camera_in_glass, settings_for(integrator, LightSampling::cone, 20), out, 2000);
        EXPECT_NEAR(seen.mean.x, eta * eta * le, 5 * seen.stderr_lum + 1e-9 * le) << integrator_names.name(integrator);
    }
}

// The same through the progressive renderer, whose paths run in SIMD lanes where the CPU has
// them (single precision here): a narrow view of the ball's middle, every ray within b = 0.1
// of the axis (where F changes by under 1e-4 of itself), averaged over the image.
TEST(Dielectric, LightInsideGlassInTheLanes) {
    const double eta = 1.5, le = 4;
    test::SceneBuilder b = light_in_glass(eta, le);
    b.scene.cameras[0].fov = 0.8;  // +-0.07 at distance 10
    b.scene.renderer.width = b.scene.renderer.height = 16;
    const RenderScene scene = b.build();
    const double expected = (1 - fresnel_dielectric(1, 1 / eta)) * le / (eta * eta);
    for (LaneChoice isa : {LaneChoice::best, LaneChoice::double_lanes, LaneChoice::off}) {
        RenderSettings settings = RenderSettings::from_scene(scene.renderer);
        settings.kernels = isa;
        settings.allocation = Allocation::uniform;
        RenderState state(16, 16);
        const int passes = 64;
        for (int i = 0; i < passes; ++i) render_pass(scene, settings, state);
        double sum = 0;
        for (const Color& c : state.radiance().pixels) sum += c.x;
        const double n = 16.0 * 16.0 * passes, mean = sum / (16.0 * 16.0);
        // Bernoulli samples of Le / eta^2 with probability 1 - F.
        const double p = expected / (le / (eta * eta)), stderr_mean = le / (eta * eta) * std::sqrt(p * (1 - p) / n);
        EXPECT_NEAR(mean, expected, 5 * stderr_mean) << int(isa);
    }
}
