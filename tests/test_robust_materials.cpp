// Numerical stability at the extremes of materials and lights: eta 1 and below 1, roughness
// 0 and near 1, rho 0 and 1 furnaces, zero and huge power, point lights on surfaces.
// One test per row of the matrix in docs/robustness.md; everything is seeded; images are
// small and compared statistically or against analytic values.
#include "robustness_util.h"

namespace fs = std::filesystem;
using namespace kr;
using namespace kr::robust;

// =======================================================================================
// Materials

// eta = 1 and rhoR = rhoT = 1: the glass ball is invisible. WRT (point light, the ball away
// from the shadow rays) gives the same image to rounding; PT with an area light, with the
// ball between light and floor, the same image within noise (the light then arrives through
// the ball by BSDF sampling alone).
TEST(RobustMaterials, EtaOneDielectricIsInvisible) {
    auto scene = [](bool with_glass, bool area, double eta = 1.0) {
        test::SceneBuilder b;
        b.scene.cameras[0].position = {0, 2, -6};
        b.scene.cameras[0].target = {0, 0.5, 0};
        b.sphere({0, -1000, 0}, 1000, b.material(MaterialType::diffuse, Color(0.6)));
        b.sphere({-1.2, 0.5, 1}, 0.5, b.material(MaterialType::diffuse, Color(0.8, 0.3, 0.2)));
        if (area)
            b.emitter({0, 4, 0}, 0.8, Color(6), b.material(MaterialType::diffuse, Color(0)));
        else
            b.point_light({-20, 3, -1}, Color(1500));  // low, from the side: shadows fall out of view
        if (with_glass) {
            const int glass = b.material(MaterialType::dielectric, Color(1));
            b.scene.materials[glass].rho_r = b.scene.materials[glass].rho_t = Color(1);
            b.scene.materials[glass].eta = eta;
            b.sphere(area ? Vec3(0.3, 1.5, 0) : Vec3(0.6, 2.0, -1), 0.8, glass);
        }
        return b.build();
    };
    {
        const RenderSettings s = settings_for(Integrator::wrt, kMaxDepth, 4);
        const RenderState with = render(scene(true, false), s, 24, 24, 4);
        const RenderState without = render(scene(false, false), s, 24, 24, 4);
        EXPECT_LT(relative_l1(with.radiance(), without.radiance()), 1e-9);
        // The ball is in view (its depth shows), and at eta = 1.5 it shows in the image too.
        int in_view = 0;
        for (size_t i = 0; i < with.depth_sum().size(); ++i) in_view += with.depth_sum()[i] != without.depth_sum()[i];
        EXPECT_GT(in_view, 20);
        const RenderState glass = render(scene(true, false, 1.5), s, 24, 24, 4);
        EXPECT_GT(relative_l1(glass.radiance(), without.radiance()), 1e-2);
    }
    {
        // Independent estimates (seeds 11 and 99) with and without the ball.
        RenderSettings s = settings_for(Integrator::pt, kMaxDepth, 256);
        const RenderState with = render(scene(true, true), s, 12, 12, 256);
        s.seed = 99;
        const RenderState without = render(scene(false, true), s, 12, 12, 256);
        // Light through the ball is found only by BSDF sampling, so a few pixels are
        // heavy-tailed and per-pixel z-scores mislead. Instead: the mean luminance over the
        // pixels where the ball is (its depth shows), whose standard error pools them all.
        std::vector<size_t> ball;
        for (size_t i = 0; i < with.depth_sum().size(); ++i)
            if (with.depth_sum()[i] != without.depth_sum()[i]) ball.push_back(i);
        ASSERT_GT(ball.size(), 10u);
        auto ball_mean = [&](const RenderState& state, double& standard_error) {
            double sum = 0, variance = 0;
            for (size_t i : ball) {
                sum += luminance(state.radiance_sum()[i]) / state.sample_count()[i];
                variance += std::pow(state.pixel_standard_error(i), 2);
            }
            standard_error = std::sqrt(variance) / double(ball.size());
            return sum / double(ball.size());
        };
        double se_with = 0, se_without = 0;
        const double difference = ball_mean(with, se_with) - ball_mean(without, se_without);
        EXPECT_LT(std::abs(difference), 4 * std::hypot(se_with, se_without));
        double sum_with = 0, sum_without = 0;
        for (size_t i = 0; i < with.radiance_sum().size(); ++i) {
            sum_with += luminance(with.radiance_sum()[i]);
            sum_without += luminance(without.radiance_sum()[i]);
        }
        EXPECT_NEAR(sum_with / sum_without, 1.0, 0.03);
    }
}

// eta < 1 (a bubble: less dense inside): total internal reflection happens on the way in.
// Clear (rho = 1) it still conserves energy in the furnace, to the depth cap.
TEST(RobustMaterials, EtaBelowOne) {
    for (double eta : {0.5, 0.75, 0.99}) {
        test::SceneBuilder b = furnace(MaterialType::dielectric, Color(1.0), 1.0);
        b.scene.materials[0].eta = eta;
        const RenderScene scene = b.build();
        for (const Vec3 target : {Vec3(0, 0, 0), Vec3(0.7, 0, 0), Vec3(0.999, 0, 0)}) {
            const Ray ray = ray_towards({0, 0, -5}, target);
            const double wrt = estimate(scene, settings_for(Integrator::wrt, kMaxDepth), ray, 1).mean.x;
            EXPECT_NEAR(wrt, 1.0, 1e-6) << "eta " << eta;
            const Estimate pt = estimate(scene, settings_for(Integrator::pt, kMaxDepth), ray, 2000);
            EXPECT_EQ(pt.nonfinite, 0);
            EXPECT_NEAR(pt.mean.x, 1.0, 1e-6) << "eta " << eta;
        }
    }
}

// Roughness 0 is the mirror and clear glass exactly: the same image, sample for sample (the
// path tracer draws the same random dimensions at every vertex). Furnace values for single
// rays are Furnace.ZeroRoughnessEqualsDeltaMaterials in test_render.cpp.
TEST(RobustMaterials, ZeroRoughnessImageEqualsMirror) {
    auto scene = [](MaterialType type, MaterialType glass_type) {
        test::SceneBuilder b = still_life(1);
        b.scene.materials[2].type = type;  // the mirror ball
        b.scene.materials[2].roughness = 0;
        b.scene.materials[3].type = glass_type;  // the glass ball
        b.scene.materials[3].roughness = 0;
        return b.build();
    };
    const RenderSettings s = settings_for(Integrator::pt, 8, 4);
    const Image delta = render(scene(MaterialType::specular, MaterialType::dielectric), s, 24, 24, 4).radiance();
    const Image rough0 = render(scene(MaterialType::glossy, MaterialType::translucent), s, 24, 24, 4).radiance();
    EXPECT_LT(relative_l1(delta, rough0), 1e-12);
}

// Roughness just below 1: finite, never above rho Le in the furnace, and exactly rho Le at
// normal incidence (a perturbation of length < 1 cannot turn the normal below the surface).
TEST(RobustMaterials, RoughnessCloseToOne) {
    for (double beta : {0.9, 0.999, 0.999999}) {
        test::SceneBuilder g = furnace(MaterialType::glossy, Color(0.7), 1.0);
        g.scene.materials[0].roughness = beta;
        const RenderScene glossy = g.build();
        for (Integrator integrator : {Integrator::pt, Integrator::wrt}) {
            const Estimate normal = estimate(glossy, settings_for(integrator), ray_towards({0, 0, -5}, {0, 0, 0}), 500);
            EXPECT_EQ(normal.nonfinite, 0);
            EXPECT_NEAR(normal.mean.x, 0.7, 1e-12) << beta;
            const Estimate oblique =
                estimate(glossy, settings_for(integrator), ray_towards({0, 0, -5}, {0.9, 0.2, 0}), 500);
            EXPECT_EQ(oblique.nonfinite, 0);
            EXPECT_GT(oblique.mean.x, 0.0);
            EXPECT_LE(oblique.mean.x, 0.7 + 1e-12);
        }
        test::SceneBuilder t = furnace(MaterialType::translucent, Color(1.0), 1.0);
        t.scene.materials[0].roughness = beta;
        const RenderScene translucent = t.build();
        for (Integrator integrator : {Integrator::pt, Integrator::wrt}) {
            const Estimate e =
                estimate(translucent, settings_for(integrator, kMaxDepth), ray_towards({0, 0, -5}, {0.3, 0.2, 0}), 300);
            EXPECT_EQ(e.nonfinite, 0);
            EXPECT_GT(e.mean.x, 0.0);
            EXPECT_LE(e.mean.x, 1.0 + 1e-9);
        }
    }
}

// rho = 0 absorbs everything; rho = 1 in a closed white furnace at depth 20 stays finite and
// matches the analytic sums exactly (Russian roulette never fires: q = max(throughput) = 1):
// - a point light of intensity I at the centre of a white sphere of radius R: each of the 20
//   scattering events adds the direct radiance I / (pi R^2);
// - the camera inside a white emitting sphere of radiance Le: Le at each of the 21 vertices.
TEST(RobustMaterials, RhoZeroAndOneFurnaces) {
    for (MaterialType type : {MaterialType::diffuse, MaterialType::specular, MaterialType::glossy}) {
        test::SceneBuilder b = furnace(type, Color(0), 3.0);
        b.scene.materials[0].roughness = 0.3;
        const RenderScene scene = b.build();
        for (Integrator integrator : {Integrator::pt, Integrator::wrt})
            EXPECT_EQ(estimate(scene, settings_for(integrator), ray_towards({0, 0, -5}, {0.2, 0.1, 0}), 50).mean.x, 0.0);
    }
    const double R = 2, I = 5;
    {
        test::SceneBuilder b;
        b.sphere({0, 0, 0}, R, b.material(MaterialType::diffuse, Color(1)));
        b.point_light({0, 0, 0}, Color(I));
        b.scene.cameras[0].position = {0.3, 0.2, -0.5};
        b.scene.cameras[0].target = {0, 0, 1};
        const RenderScene scene = b.build();
        const RenderSettings settings = settings_for(Integrator::pt, kMaxDepth, 4);
        const RenderState state = render(scene, settings, 6, 6, 4);
        ASSERT_TRUE(all_finite(state));
        const double expected = kMaxDepth * I / (kPi * R * R);
        for (const Color& c : state.radiance().pixels)
            EXPECT_NEAR(c.x, expected, test::analytic_tolerance(scene, settings) * expected);
    }
    {
        test::SceneBuilder b;
        b.emitter({0, 0, 0}, R, Color(0.5), b.material(MaterialType::diffuse, Color(1)));
        b.scene.cameras[0].position = {0.3, 0.2, -0.5};
        b.scene.cameras[0].target = {0, 0, 1};
        const RenderScene scene = b.build();
        for (LightSampling ls : {LightSampling::brief, LightSampling::cone, LightSampling::area}) {
            const RenderState state = render(scene, settings_for(Integrator::pt, kMaxDepth, 4, ls), 6, 6, 4);
            ASSERT_TRUE(all_finite(state));
            for (const Color& c : state.radiance().pixels) EXPECT_NEAR(c.x, (kMaxDepth + 1) * 0.5, 1e-9);
        }
        // Whitted has no diffuse interreflection: the emitter seen from inside shows Le.
        const RenderState wrt = render(scene, settings_for(Integrator::wrt, kMaxDepth, 1), 6, 6, 1);
        for (const Color& c : wrt.radiance().pixels) EXPECT_NEAR(c.x, 0.5, 1e-12);
    }
}
// =======================================================================================
// Lights

// Power 0: black, never NaN (light selection falls back to equal shares). Power 1e30: the
// sigmoid saturates at 255. Power 1.7e308: selection probabilities stay defined (the
// light's share is computed without overflow) and the tone map shows white, not black.
TEST(RobustLights, ZeroAndHugePower) {
    for (double power : {0.0, 1e30, 1.7e308}) {
        for (bool area : {false, true}) {
            test::SceneBuilder b;
            b.sphere({0, 0, 0}, 1, b.material(MaterialType::diffuse, Color(0.5)));
            if (area)
                b.emitter({0, 3, -2}, 0.5, Color(power), b.material(MaterialType::diffuse, Color(0)));
            else
                b.point_light({0, 3, -2}, Color(power));
            b.scene.cameras[0].fov = 5;  // the ball fills the image
            const RenderScene scene = b.build();
            ASSERT_EQ(scene.lights.size(), 1u);
            EXPECT_NEAR(scene.lights[0].select_prob, 1.0, 1e-15);
            for (Integrator integrator : {Integrator::wrt, Integrator::pt}) {
                const RenderState state = render(scene, settings_for(integrator, 4, 2), 6, 6, 2);
                const Rgb8Image img = tonemap(state.radiance(), ToneMap::sigmoid);
                const std::string what = std::string(integrator_names.name(integrator)) + (area ? " area " : " point ") +
                                         std::to_string(power);
                // The top of the ball faces the light.
                const uint8_t top = img.bytes[(0 * 6 + 3) * 3];
                if (power == 0) {
                    for (uint8_t v : img.bytes) EXPECT_EQ(v, 0) << what;
                    EXPECT_EQ(state.nonfinite_samples, 0u) << what;
                } else {
                    EXPECT_EQ(top, 255) << what;
                }
                if (power == 1e30) EXPECT_EQ(state.nonfinite_samples, 0u) << what;
            }
        }
    }
    // Several lights of very different powers, one of them 0: probabilities sum to 1.
    test::SceneBuilder b;
    b.sphere({0, 0, 0}, 1, b.material(MaterialType::diffuse));
    b.point_light({0, 3, 0}, Color(0));
    b.point_light({0, 3, 1}, Color(1e-300));
    b.point_light({0, 3, 2}, Color(1.7e308));
    b.emitter({0, 5, 0}, 1e150, Color(1e300), b.material(MaterialType::diffuse, Color(0)));
    const RenderScene scene = b.build();
    double total = 0;
    for (const RenderLight& l : scene.lights) {
        EXPECT_TRUE(std::isfinite(l.select_prob));
        total += l.select_prob;
    }
    EXPECT_NEAR(total, 1.0, 1e-12);
    EXPECT_EQ(test::lights_of(scene, LightType::point)[0].select_prob, 0.0);
    EXPECT_GT(test::lights_of(scene, LightType::area)[0].select_prob, 0.99);
    // The tone maps on infinite and NaN radiance: white and black.
    Image img(3, 1);
    img.pixels = {Color(kInfinity), Color(std::nan("")), Color(1)};
    const Rgb8Image sig = tonemap(img, ToneMap::sigmoid), lin = tonemap(img, ToneMap::linear);
    EXPECT_EQ(sig.bytes[0], 255);
    EXPECT_EQ(sig.bytes[3], 0);
    EXPECT_EQ(sig.bytes[6], 128);
    EXPECT_EQ(lin.bytes[0], 255);
    EXPECT_EQ(lin.bytes[3], 0);
    EXPECT_EQ(lin.bytes[6], 255);
}

// A point light on a surface lights the open half-space above it like any point light, with
// no speckle from the shadow ray ending exactly on the surface; one inside a closed sphere
// lights nothing outside it.
TEST(RobustLights, PointLightOnOrInsideASurface) {
    for (double scale : {1e-3, 1.0, 1e3}) {
        test::SceneBuilder b;
        b.scene.cameras[0].position = Vec3(0, 3, -6) * scale;
        b.scene.cameras[0].target = Vec3(0, 1, 0) * scale;
        const int white = b.material(MaterialType::diffuse, Color(0.5));
        b.sphere(Vec3(0, -100, 0) * scale, 100 * scale, white);  // floor: its top at y = 0
        b.sphere(Vec3(0, 1.5, 0) * scale, 0.5 * scale, white);   // a ball above the light
        b.point_light(Vec3(0, 0, 0), Color(10) * (scale * scale));  // on the floor's top point
        const RenderScene scene = b.build();
        // A direct check: the ball's lowest point faces the light from 1 away.
        const Ray down = ray_towards(Vec3(0, 1.5, 0) * scale + Vec3(0, 0, -5) * scale, Vec3(0, 1.0, 0) * scale);
        Hit hit;
        ASSERT_TRUE(scene.intersects(down, hit));
        const Vec3 to_light = Vec3(0, 0, 0) - hit.p;
        const double d2 = dot(to_light, to_light);
        const double expected = 0.5 / kPi * 10 * scale * scale * dot(hit.n, to_light / std::sqrt(d2)) / d2;
        ASSERT_GT(expected, 0);
        EXPECT_NEAR(estimate(scene, settings_for(Integrator::wrt), down, 1).mean.x, expected, 1e-9 * expected)
            << "scale " << scale;
        // Image: every pixel of the ball's lower half is lit the same with every jitter.
        const RenderState state = render(scene, settings_for(Integrator::wrt, 2, 1), 16, 16, 1);
        ASSERT_TRUE(all_finite(state));
        EXPECT_EQ(state.nonfinite_samples, 0u);
        // Many small shadow rays towards the light from points on the ball's underside.
        int lit = 0, total = 0;
        Rng rng(4, 4);
        for (int i = 0; i < 2000; ++i) {
            const double phi = 2 * kPi * rng.next(), ct = -0.2 - 0.8 * rng.next(), st = std::sqrt(1 - ct * ct);
            Ray r = ray_towards(Vec3(0, 1.5, 0) * scale + Vec3(st * std::cos(phi), ct, st * std::sin(phi)) * (2 * scale),
                                Vec3(0, 1.5, 0) * scale);
            Hit h;
            if (!scene.intersects(r, h) || h.sphere != 1) continue;
            Ray shadow;
            shadow.o = h.p;
            shadow.d = normalize(Vec3(0, 0, 0) - h.p);
            shadow.tmax = length(Vec3(0, 0, 0) - h.p);
            shadow.from_sphere = 1;
            ++total;
            lit += !scene.is_occluded(shadow);
        }
        EXPECT_EQ(lit, total) << "shadow rays ending on the floor under the light, scale " << scale;
    }
    // Inside a closed sphere: the floor outside and the sphere's outside stay black.
    test::SceneBuilder b;
    b.scene.cameras[0].position = {0, 3, -6};
    b.scene.cameras[0].target = {0, 1, 0};
    b.sphere({0, -100, 0}, 100, b.material(MaterialType::diffuse, Color(0.5)));
    b.sphere({0, 1, 0}, 1, b.material(MaterialType::diffuse, Color(0.5)));
    b.point_light({0, 1, 0}, Color(100));
    for (Integrator integrator : {Integrator::wrt, Integrator::pt}) {
        const RenderState state = render(b.build(), settings_for(integrator, 6, 4), 12, 12, 4);
        ASSERT_TRUE(all_finite(state));
        for (const Color& c : state.radiance_sum()) EXPECT_EQ(c.x, 0.0) << integrator_names.name(integrator);
    }
}

// The camera inside an area light: RobustMaterials.RhoZeroAndOneFurnaces renders a camera
// inside a white emitter; here the emitter is black inside a lit room, seen from within.
TEST(RobustLights, CameraInsideAnAreaLight) {
    test::SceneBuilder b;
    b.scene.cameras[0].position = {0, 0, 0};
    b.scene.cameras[0].target = {0, 0, 1};
    b.emitter({0, 0, 0}, 1, Color(3), b.material(MaterialType::diffuse, Color(0.5)));
    b.sphere({0, 0, 0}, 10, b.material(MaterialType::diffuse, Color(0.5)));  // a room around it
    const RenderScene scene = b.build();
    for (Integrator integrator : {Integrator::wrt, Integrator::pt})
        for (LightSampling ls : {LightSampling::brief, LightSampling::cone, LightSampling::area}) {
            const RenderState state = render(scene, settings_for(integrator, 6, 16, ls), 6, 6, 16);
            ASSERT_TRUE(all_finite(state));
            EXPECT_EQ(state.nonfinite_samples, 0u);
            // Le from the inside of the emitter, plus its own diffuse interreflection in PT:
            // Le (1 + rho + ...), the room outside never reached (the emitter is opaque).
            const double expected = integrator == Integrator::wrt ? 3.0 : 3.0 * (1 - std::pow(0.5, 7)) / 0.5;
            double mean = 0;
            for (const Color& c : state.radiance().pixels) mean += c.x / 36;
            EXPECT_NEAR(mean, expected, 0.05 * expected)
                << integrator_names.name(integrator) << " " << light_sampling_names.name(ls);
        }
}
