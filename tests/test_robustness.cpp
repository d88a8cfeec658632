// Issue 6: numerical stability at the extremes and hostile input. One test per row of the
// matrix in docs/robustness.md; rows already covered elsewhere are named there instead.
// Everything is seeded; images are small and compared statistically or against analytic
// values, so the file runs in seconds on two cores.
#include <gtest/gtest.h>

#include <algorithm>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/image_io.h"
#include "render/camera.h"
#include "render/progressive.h"
#include "render/trace.h"
#include "scene/load.h"
#include "test_util.h"

namespace fs = std::filesystem;
using namespace kr;

namespace {

// ---------------------------------------------------------------------------------------
// Helpers

RenderState render(const RenderScene& scene, const RenderSettings& settings, int width, int height, int passes) {
    RenderState state(width, height);
    for (int i = 0; i < passes; ++i) render_pass(scene, settings, state);
    return state;
}

RenderSettings settings_for(Integrator integrator, int depth = 6, int spp = 1,
                            LightSampling ls = LightSampling::cone) {
    RenderSettings s;
    s.integrator = integrator;
    s.max_depth = depth;
    s.target_spp = spp;
    s.light_sampling = ls;
    s.seed = 11;
    return s;
}

bool all_finite(const RenderState& state) {
    for (const Color& c : state.radiance_sum())
        if (!is_finite(c)) return false;
    for (double d : state.depth_sum())
        if (!std::isfinite(d)) return false;
    return true;
}

// Mean radiance of n independent samples along one ray.
struct Estimate {
    Color mean;
    double stderr_lum = 0;
    int nonfinite = 0;
};
Estimate estimate(const RenderScene& scene, const RenderSettings& settings, const Ray& ray, int n) {
    Estimate e;
    double sum_l = 0, sum_l2 = 0;
    int used = 0;
    for (int i = 0; i < n; ++i) {
        Sampler sampler(Rng::for_sample(settings.seed, 0, uint64_t(i)));
        const SampleResult r = trace_sample(scene, settings, ray, sampler);
        if (!is_finite(r.radiance)) {
            ++e.nonfinite;
            continue;
        }
        e.mean += r.radiance;
        const double l = luminance(r.radiance);
        sum_l += l;
        sum_l2 += l * l;
        ++used;
    }
    e.mean = e.mean / double(std::max(used, 1));
    const double mean_l = sum_l / std::max(used, 1);
    e.stderr_lum = std::sqrt(std::max(0.0, sum_l2 / std::max(used, 1) - mean_l * mean_l) / std::max(used, 1));
    return e;
}

Ray ray_towards(Vec3 from, Vec3 to) {
    Ray r;
    r.o = from;
    r.d = normalize(to - from);
    return r;
}

// Relative difference of two radiance images: sum |a - b| / sum (|a| + |b|), per channel.
double relative_l1(const Image& a, const Image& b) {
    double diff = 0, total = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            diff += std::abs(a.pixels[i][k] - b.pixels[i][k]);
            total += std::abs(a.pixels[i][k]) + std::abs(b.pixels[i][k]);
        }
    return total > 0 ? diff / total : 0.0;
}

// Per-pixel z-scores of the luminance difference of two independent estimates of one
// image; returns the mean of z^2 (about 1 for unbiased estimates of the same image).
// Per pixel, the squared difference of two independent estimates of the same image over
// their combined variance of the mean (z^2; 1 on average for independent random samples).
std::vector<double> pixel_z2(const RenderState& a, const RenderState& b) {
    const Image ia = a.radiance(), ib = b.radiance();
    std::vector<double> z2;
    for (size_t i = 0; i < ia.pixels.size(); ++i) {
        const double se2 = std::pow(a.pixel_standard_error(i), 2) + std::pow(b.pixel_standard_error(i), 2);
        const double d = luminance(ia.pixels[i]) - luminance(ib.pixels[i]);
        // Both pixels noise-free (e.g. a miss): they must agree exactly.
        z2.push_back(se2 > 0 ? d * d / se2 : (d == 0 ? 1.0 : 1e9));
    }
    return z2;
}

double mean_z2(const RenderState& a, const RenderState& b) {
    const std::vector<double> z2 = pixel_z2(a, b);
    double sum = 0;
    for (double z : z2) sum += z;
    return sum / double(z2.size());
}

size_t state_bytes(const RenderState& s) {
    return s.radiance_sum().capacity() * sizeof(Color) + s.radiance_compensation().capacity() * sizeof(Color) +
           s.radiance_sq_sum().capacity() * sizeof(Color) + s.depth_sum().capacity() * sizeof(double) +
           s.luminance_sq_sum().capacity() * sizeof(double) + s.sample_count().capacity() * sizeof(uint32_t) +
           s.sample_index().capacity() * sizeof(uint32_t) + s.active().capacity();
}

// A small still life: floor, diffuse, mirror and glass balls, a point light and (for the
// path tracer) a spherical area light; every length multiplied by `s`, the point light's
// intensity by s^2 (irradiance I cos / d^2) and area radiance unchanged.
test::SceneBuilder still_life(double s) {
    test::SceneBuilder b;
    b.scene.cameras[0].position = Vec3(0, 1.5, -7) * s;
    b.scene.cameras[0].target = Vec3(0, 0.6, 0) * s;
    b.sphere(Vec3(0, -1000, 0) * s, 1000 * s, b.material(MaterialType::diffuse, Color(0.7, 0.7, 0.6)));
    b.sphere(Vec3(-1.3, 0.6, 0) * s, 0.6 * s, b.material(MaterialType::diffuse, Color(0.8, 0.2, 0.2)));
    b.sphere(Vec3(0.2, 0.5, 0.8) * s, 0.5 * s, b.material(MaterialType::specular, Color(0.9)));
    const int glass = b.material(MaterialType::dielectric);
    b.scene.materials[glass].rho_r = b.scene.materials[glass].rho_t = Color(0.95);
    b.sphere(Vec3(1.2, 0.45, -0.6) * s, 0.45 * s, glass);
    b.sphere(Vec3(0.6, 0.12, -1.8) * s, 0.12 * s, b.material(MaterialType::diffuse, Color(0.2, 0.3, 0.9)));
    b.point_light(Vec3(2, 4, -3) * s, Color(40) * (s * s));
    b.emitter(Vec3(-2, 3.5, 1) * s, 0.5 * s, Color(12), b.material(MaterialType::diffuse, Color(0)));
    return b;
}

// A closed room of six wall spheres of radius R whose inner sides are 5 from the origin,
// a diffuse ball and a spherical light.
test::SceneBuilder room(double R) {
    test::SceneBuilder b;
    b.scene.cameras[0].position = {0, 0, -4.5};
    b.scene.cameras[0].target = {0, -0.5, 0};
    b.scene.cameras[0].fov = 80;
    const int white = b.material(MaterialType::diffuse, Color(0.75));
    const int red = b.material(MaterialType::diffuse, Color(0.75, 0.2, 0.2));
    const double c = R + 5;
    b.sphere({-c, 0, 0}, R, red);
    b.sphere({c, 0, 0}, R, white);
    b.sphere({0, c, 0}, R, white);
    b.sphere({0, -c, 0}, R, white);
    b.sphere({0, 0, c}, R, white);
    b.sphere({0, 0, -c}, R, white);
    b.sphere({1, -3.5, 1}, 1.5, b.material(MaterialType::specular, Color(0.9)));
    b.sphere({-1.5, -4, -0.5}, 1, white);
    b.emitter({0, 4, 0}, 0.6, Color(15), b.material(MaterialType::diffuse, Color(0)));
    return b;
}

using test::furnace;

// A scratch folder per test.
class TempDir : public test::ScratchDirTest {};

// A valid scene file; `renderer` and `extra` let tests change one thing.
std::string scene_json(const std::string& output = "out.ppm", const std::string& dims = "[16, 12]",
                       const std::string& light = R"({"id": "lamp", "type": "point", "position": [0, 3, -3], "power": [50, 50, 50]})",
                       const std::string& material = R"({"id": "white", "type": "diffuse", "rho": [0.8, 0.8, 0.8]})") {
    return R"({
  "cameras": [{"id": "cam", "type": "pinhole", "fov": 45, "aspect": 1.333, "position": [0, 0, -5], "target": [0, 0, 0]}],
  "materials": [)" + material + R"(],
  "shapes": [{"id": "ball", "type": "sphere", "centre": [0, 0, 0], "radius": 1}],
  "lights": [)" + light + R"(],
  "scene": {
    "camera": "cam", "lights": ["lamp"],
    "primitives": [{"id": "ball", "type": "geometric", "shape": "ball", "material": "white"}],
    "renderer": {"type": "WRT", "dimensions": )" + dims + R"(, "samples": 2, "depth": 4, "output": ")" + output + R"("}
  }
})";
}

// The SceneError message of loading `text`, or "" if it loads.
std::string load_error(const std::string& text) {
    try {
        parse_scene(text, "hostile.json");
    } catch (const SceneError& e) {
        return e.what();
    }
    return "";
}

}  // namespace

// =======================================================================================
// Scale

// The same scene at scales 1e-4 ... 1e4 (lengths x s, point intensity x s^2) gives the same
// image: the renderer has no absolute epsilon anywhere.
TEST(RobustScale, SceneScaledFrom1em4To1e4GivesTheSameImage) {
    for (Integrator integrator : {Integrator::wrt, Integrator::pt}) {
        const RenderSettings settings = settings_for(integrator, 8, 4);
        const RenderState reference = render(still_life(1).build(), settings, 24, 24, 4);
        const Image ref = reference.radiance();
        for (double s : {1e-4, 1e-2, 1e2, 1e4}) {
            const RenderState state = render(still_life(s).build(), settings, 24, 24, 4);
            ASSERT_TRUE(all_finite(state));
            EXPECT_EQ(state.nonfinite_samples, 0u);
            const Image img = state.radiance();
            // Same random numbers, same paths: only rounding differs (measured: 1e-14).
            EXPECT_LT(relative_l1(ref, img), 1e-9) << integrator_names.name(integrator) << " scale " << s;
            EXPECT_EQ(psnr(tonemap(ref, ToneMap::sigmoid), tonemap(img, ToneMap::sigmoid)), 99.0)
                << integrator_names.name(integrator) << " scale " << s;
            // Depth scales with the scene.
            const std::vector<double> d0 = reference.mean_depth(), d1 = state.mean_depth();
            for (size_t i = 0; i < d0.size(); i += 37)
                if (d0[i] < 100 && d1[i] / s < 100) EXPECT_NEAR(d1[i] / s, d0[i], 1e-6 * d0[i]);  // all hits
        }
    }
}

// Rooms whose walls are spheres of radius 1e4, 1e5 and 1e6 seen from inside: no leaks (every
// primary ray hits a wall), no acne, and the same image up to the walls' tiny curvature.
TEST(RobustScale, HugeWallSpheresSeenFromInside) {
    const RenderSettings settings = settings_for(Integrator::pt, 6, 4);
    const RenderState base = render(room(1e4).build(), settings, 20, 20, 4);
    for (double R : {1e5, 1e6}) {
        const RenderState state = render(room(R).build(), settings, 20, 20, 4);
        ASSERT_TRUE(all_finite(state));
        EXPECT_EQ(state.nonfinite_samples, 0u);
        for (double d : state.mean_depth()) EXPECT_LT(d, 20.0) << "a primary ray left the room, R = " << R;
        EXPECT_LT(relative_l1(base.radiance(), state.radiance()), 1e-2) << "R = " << R;
        EXPECT_GT(psnr(tonemap(base.radiance(), ToneMap::sigmoid), tonemap(state.radiance(), ToneMap::sigmoid)), 35.0);
    }
}

// A radius-1e-4 sphere, at the origin or up to 1e12 away, is hit where it is: the BVH and the plain
// scan agree to rounding, and a diffuse ball that small in a furnace still shows rho Le.
TEST(RobustScale, TinySpheresAnywhere) {
    for (double far : {0.0, 1e3, 1e6, 1e12}) {
        test::SceneBuilder b;
        const int m = b.material(MaterialType::diffuse);
        const Vec3 c{far, far, 1};
        b.sphere(c, 1e-4, m);
        b.sphere({far + 1, far, 1}, 1e-4, m);  // a neighbour, so the BVH has work to do
        const RenderScene scene = b.build();
        Ray ray;
        ray.o = {far, far, 0};
        ray.d = {0, 0, 1};
        Hit fast, lin;
        ASSERT_TRUE(scene.intersects(ray, fast)) << far;
        ASSERT_TRUE(scene.intersects_linear(ray, lin)) << far;
        EXPECT_EQ(fast.sphere, 0);
        // The ray starts beside the sphere, so the root is exact to rounding at unit scale.
        EXPECT_NEAR(fast.t, 1 - 1e-4, 1e-15) << far;
        EXPECT_NEAR(fast.t, lin.t, 1e-15) << "BVH and linear scan disagree at " << far;
        // Just beside the sphere: a miss for both.
        Ray beside = ray;
        beside.o.x = far + 1.5e-4;
        EXPECT_FALSE(scene.is_occluded(beside)) << far;
        EXPECT_FALSE(scene.is_occluded_linear(beside)) << far;
    }
    // rho Le in a furnace, at radius 1e-4 (the emitter around it has radius 2e-3).
    test::SceneBuilder b;
    const int m = b.material(MaterialType::diffuse, Color(0.5));
    b.sphere({0, 0, 0}, 1e-4, m);
    b.emitter({0, 0, 0}, 2e-3, Color(2), b.material(MaterialType::diffuse, Color(0)));
    const RenderScene scene = b.build();
    for (Integrator integrator : {Integrator::pt, Integrator::wrt}) {
        const Estimate e = estimate(scene, settings_for(integrator), ray_towards({0, 0, -1e-3}, {2e-5, 3e-5, 0}), 4000);
        EXPECT_EQ(e.nonfinite, 0);
        EXPECT_NEAR(e.mean.x, 1.0, 5 * e.stderr_lum + 1e-3) << integrator_names.name(integrator);
    }
}

// Grazing camera rays: a diffuse ball in a furnace shows rho Le right up to its silhouette,
// and a clear glass ball stays finite and never above Le.
TEST(RobustScale, GrazingRays) {
    const RenderScene diffuse = furnace(MaterialType::diffuse, Color(0.5), 2.0).build();
    const RenderScene glass = furnace(MaterialType::dielectric, Color(1.0), 1.0).build();
    for (double eps : {1e-3, 1e-6, 1e-9, 1e-12}) {
        Ray ray;
        ray.o = {1 - eps, 0, -5};
        ray.d = {0, 0, 1};
        Hit hit;
        ASSERT_TRUE(diffuse.intersects(ray, hit)) << eps;
        const Estimate d = estimate(diffuse, settings_for(Integrator::pt), ray, 2000);
        EXPECT_EQ(d.nonfinite, 0);
        EXPECT_NEAR(d.mean.x, 1.0, 5 * d.stderr_lum + 1e-3) << eps;
        for (Integrator integrator : {Integrator::pt, Integrator::wrt}) {
            const Estimate g = estimate(glass, settings_for(integrator, kMaxDepth), ray, 500);
            EXPECT_EQ(g.nonfinite, 0);
            EXPECT_GE(g.mean.x, 0.5) << eps;
            EXPECT_LE(g.mean.x, 1.0 + 1e-9) << eps;
        }
    }
}

// A camera exactly on a sphere's surface: looking in, it sees the far side at the chord
// length; looking out, it never sees the sphere it stands on. Either way, every pixel agrees.
TEST(RobustScale, CameraOnASurface) {
    for (double scale : {1e-3, 1.0, 1e3}) {
        test::SceneBuilder b;
        b.sphere({0, 0, 0}, scale, b.material(MaterialType::diffuse, Color(0.5)));
        b.sphere({0, 0, -10 * scale}, scale, b.material(MaterialType::diffuse, Color(0.5)));
        b.point_light({0, 0, -3 * scale}, Color(scale * scale));
        // On the surface, looking in through the centre (fov 1 degree: all near the axis).
        b.scene.cameras[0].position = {0, 0, -scale};
        b.scene.cameras[0].target = {0, 0, 0};
        b.scene.cameras[0].fov = 1;
        RenderState in = render(b.build(), settings_for(Integrator::wrt), 8, 8, 1);
        ASSERT_TRUE(all_finite(in));
        for (double d : in.mean_depth()) EXPECT_NEAR(d, 2 * scale, 1e-2 * scale) << scale;
        // Looking out towards the other ball: the first hit is 8 scale away.
        b.scene.cameras[0].target = {0, 0, -5 * scale};
        RenderState out = render(b.build(), settings_for(Integrator::wrt), 8, 8, 1);
        ASSERT_TRUE(all_finite(out));
        for (double d : out.mean_depth()) EXPECT_NEAR(d, 8 * scale, 1e-2 * scale) << scale;
    }
}

// A camera inside a closed diffuse sphere with a point light at its centre: the wall shows
// rho I / (pi R^2) direct (WRT) and, with interreflection, that over (1 - rho) (PT, up to
// the depth cap).
TEST(RobustScale, CameraInsideASphere) {
    const double R = 3, I = 9, rho = 0.5;
    test::SceneBuilder b;
    b.sphere({0, 0, 0}, R, b.material(MaterialType::diffuse, Color(rho)));
    b.point_light({0, 0, 0}, Color(I));
    b.scene.cameras[0].position = {0.5, 0.3, -1};
    b.scene.cameras[0].target = {0, 0, 1};
    const RenderScene scene = b.build();
    const double direct = rho * I / (kPi * R * R);
    const RenderState wrt = render(scene, settings_for(Integrator::wrt), 8, 8, 1);
    for (const Color& c : wrt.radiance().pixels) EXPECT_NEAR(c.x, direct, 1e-12);
    const RenderState pt = render(scene, settings_for(Integrator::pt, kMaxDepth, 64), 8, 8, 64);
    const double expected = direct * (1 - std::pow(rho, kMaxDepth)) / (1 - rho);
    double mean = 0;
    for (const Color& c : pt.radiance().pixels) mean += c.x / 64;
    EXPECT_NEAR(mean, expected, 0.02 * expected);
    EXPECT_EQ(pt.nonfinite_samples, 0u);
}

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
// Lens

test::SceneBuilder lens_scene(double alpha, double focal) {
    test::SceneBuilder b = still_life(1);
    b.scene.cameras[0].type = CameraType::lens;
    b.scene.cameras[0].alpha = alpha;
    b.scene.cameras[0].focal_distance = focal;
    return b;
}

// Aperture 0 is the pinhole, sample for sample.
TEST(RobustLens, ApertureZeroEqualsPinhole) {
    const RenderSettings s = settings_for(Integrator::pt, 6, 4);
    const RenderState pinhole = render(still_life(1).build(), s, 20, 20, 4);
    for (double focal : {1e-9, 7.0, 1e9}) {
        const RenderState lens = render(lens_scene(0, focal).build(), s, 20, 20, 4);
        EXPECT_EQ(relative_l1(pinhole.radiance(), lens.radiance()), 0.0) << focal;
    }
}

// Very large apertures: finite; a camera in a uniform furnace still sees exactly Le, and
// rays from lens points far outside the scene still converge on the plane in focus. (At
// alpha = 1e100 a lens point's ray cannot resolve a scene 1e100 times smaller than its
// distance in double precision: the image is black, but still finite.)
TEST(RobustLens, HugeAperture) {
    for (double alpha : {10.0, 1e3, 1e6, 1e100}) {
        test::SceneBuilder f = furnace(MaterialType::specular, Color(1.0), 2.0);
        f.scene.cameras[0].type = CameraType::lens;
        f.scene.cameras[0].alpha = alpha;
        f.scene.cameras[0].focal_distance = 10;  // the ball's centre
        const RenderState state = render(f.build(), settings_for(Integrator::wrt, 6, 4), 8, 8, 4);
        ASSERT_TRUE(all_finite(state)) << alpha;
        EXPECT_EQ(state.nonfinite_samples, 0u);
        // Every ray meets the emitter (Le = 2) directly or through the white mirror ball.
        if (alpha <= 1e6)
            for (const Color& c : state.radiance().pixels) EXPECT_NEAR(c.x, 2.0, 1e-12) << alpha;
        const RenderState still = render(lens_scene(alpha, 7).build(), settings_for(Integrator::pt, 6, 2), 12, 12, 2);
        ASSERT_TRUE(all_finite(still)) << alpha;
        EXPECT_EQ(still.nonfinite_samples, 0u);
    }
}

// Focal distances from 1e-300 to the largest double: finite rays, no dropped samples, and a
// plane in focus far away with a small aperture is the pinhole image.
TEST(RobustLens, TinyAndHugeFocalDistance) {
    const RenderSettings s = settings_for(Integrator::pt, 6, 4);
    for (double focal : {1e-300, 1e-9, 1e9, 1e300, 1.7e308}) {
        for (double alpha : {1e-20, 0.1}) {
            const CameraModel cam = CameraModel::from(lens_scene(alpha, focal).scene.cameras[0]);
            for (double fx : {0.0, 0.5, 0.999})
                for (double u : {0.0, 0.5, 0.999}) {
                    const CameraRay r = cam.generate(fx, 1 - fx, u, 0.5);
                    EXPECT_TRUE(is_finite(r.origin) && is_finite(r.direction)) << focal << " " << alpha;
                    EXPECT_NEAR(length(r.direction), 1.0, 1e-12) << focal << " " << alpha;
                }
        }
        const RenderState state = render(lens_scene(0.05, focal).build(), s, 16, 16, 4);
        ASSERT_TRUE(all_finite(state)) << focal;
        EXPECT_EQ(state.nonfinite_samples, 0u) << focal;
    }
    const RenderState pinhole = render(still_life(1).build(), s, 16, 16, 4);
    for (double focal : {1e9, 1e300, 1.7e308}) {
        const RenderState far = render(lens_scene(1e-6, focal).build(), s, 16, 16, 4);
        EXPECT_GT(psnr(tonemap(pinhole.radiance(), ToneMap::sigmoid), tonemap(far.radiance(), ToneMap::sigmoid)), 40.0)
            << focal;
    }
}

// =======================================================================================
// Renderer

// In a closed white sphere around a point light, depth d adds exactly d times the direct
// radiance (depth 0: emitters only). A file asking for more than 20 is clamped to 20 with a
// warning, and RenderSettings::from_scene clamps as well.
TEST(RobustRenderer, DepthZeroOneTwentyAndAbove) {
    test::SceneBuilder b;
    b.sphere({0, 0, 0}, 2, b.material(MaterialType::diffuse, Color(1)));
    b.point_light({0, 0, 0}, Color(4));
    b.scene.cameras[0].position = {0.3, 0.2, -0.5};
    b.scene.cameras[0].target = {0, 0, 1};
    const RenderScene scene = b.build();
    const double direct = 4 / (kPi * 4);
    for (int depth : {0, 1, 2, 20}) {
        const RenderSettings settings = settings_for(Integrator::pt, depth, 1);
        const RenderState s = render(scene, settings, 4, 4, 1);
        const double tolerance = test::analytic_tolerance(scene, settings) * std::max(1.0, depth * direct);
        for (const Color& c : s.radiance().pixels) EXPECT_NEAR(c.x, depth * direct, tolerance) << depth;
    }
    // From the scene file: 25 becomes 20 (with a warning), and so does the default settings.
    const LoadedScene loaded = parse_scene(test::edit_once(scene_json(), "\"depth\": 4", "\"depth\": 25"), "deep.json");
    ASSERT_EQ(loaded.warnings.size(), 1u);
    EXPECT_NE(loaded.warnings[0].find("clamped to 20"), std::string::npos);
    EXPECT_EQ(loaded.scene.renderer.depth, kMaxDepth);
    RendererSettings r;
    r.depth = 1000;
    EXPECT_EQ(RenderSettings::from_scene(r).max_depth, kMaxDepth);
}

// One sample per pixel, and non-square counts with the stratified estimator: every pass adds
// exactly one sample to every pixel, and the image is an unbiased estimate of the same
// picture as the uniform estimator's (pixel by pixel, within noise).
TEST(RobustRenderer, SamplesOneAndNonSquareStratified) {
    const RenderScene scene = still_life(1).build();
    for (int spp : {1, 2, 3, 8, 50}) {
        RenderSettings s = settings_for(Integrator::wrt, 6, spp);
        s.estimator = Estimator::stratified;
        const RenderState state = render(scene, s, 10, 10, spp);
        ASSERT_TRUE(all_finite(state));
        for (uint32_t c : state.sample_count()) EXPECT_EQ(c, uint32_t(spp));
        EXPECT_EQ(state.passes, spp);
    }
    // 50 (7x7 strata plus one uniform) against 200 uniform samples.
    RenderSettings strat = settings_for(Integrator::wrt, 6, 50);
    strat.estimator = Estimator::stratified;
    RenderSettings uni = settings_for(Integrator::wrt, 6, 200);
    uni.estimator = Estimator::uniform;
    uni.seed = 5;
    const RenderState a = render(scene, strat, 10, 10, 50), b = render(scene, uni, 10, 10, 200);
    EXPECT_LT(mean_z2(a, b), 2.0);
    EXPECT_NEAR(luminance(a.radiance().pixels[55]) + 1, luminance(b.radiance().pixels[55]) + 1, 0.2);
}

// 1x1, 1x4096 and 4096x2160 images: correct sizes, finite, and the memory of the render
// state (96 bytes per pixel) printed for docs/robustness.md.
TEST(RobustRenderer, ExtremeDimensions) {
    // A white mirror ball in a furnace of radiance 2: every pixel shows exactly 2.
    const RenderScene scene = furnace(MaterialType::specular, Color(1.0), 2.0).build();
    const RenderSettings s = settings_for(Integrator::wrt, 2, 1);
    {
        const RenderState one = render(scene, s, 1, 1, 4);
        ASSERT_EQ(one.radiance_sum().size(), 1u);
        EXPECT_EQ(one.sample_count()[0], 4u);
        EXPECT_NEAR(one.radiance().pixels[0].x, 2.0, 1e-12);
    }
    {
        const RenderState tall = render(scene, s, 1, 4096, 1);
        ASSERT_TRUE(all_finite(tall));
        EXPECT_EQ(tall.radiance_sum().size(), 4096u);
        for (uint32_t c : tall.sample_count()) EXPECT_EQ(c, 1u);
        for (const Color& c : tall.radiance().pixels) EXPECT_NEAR(c.x, 2.0, 1e-12);
        const Rgb8Image img = tonemap(tall.radiance(), ToneMap::sigmoid);
        EXPECT_EQ(img.width, 1);
        EXPECT_EQ(img.height, 4096);
        std::printf("[ memory   ] RenderState 1x4096: %zu bytes\n", state_bytes(tall));
    }
    {
        const auto start = std::chrono::steady_clock::now();
        const RenderState big = render(scene, s, 4096, 2160, 1);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        ASSERT_EQ(big.radiance_sum().size(), size_t(4096) * 2160);
        EXPECT_EQ(big.nonfinite_samples, 0u);
        size_t unsampled = 0;
        for (uint32_t c : big.sample_count()) unsampled += c != 1;
        EXPECT_EQ(unsampled, 0u);
        const Image radiance = big.radiance();
        const Rgb8Image img = tonemap(radiance, ToneMap::sigmoid);
        EXPECT_EQ(img.bytes.size(), size_t(4096) * 2160 * 3);
        const size_t bytes = state_bytes(big);
        EXPECT_EQ(bytes, size_t(4096) * 2160 * 96);
        std::printf("[ memory   ] RenderState 4096x2160: %zu bytes (%.1f MiB); radiance image %.1f MiB; "
                    "8-bit image %.1f MiB; 1 spp pass %.2f s\n",
                    bytes, bytes / 1048576.0, radiance.pixels.capacity() * sizeof(Color) / 1048576.0,
                    img.bytes.capacity() / 1048576.0, seconds);
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
            for (const PointLight& l : scene.point_lights) EXPECT_NEAR(l.select_prob, 1.0, 1e-15);
            for (const AreaLight& l : scene.area_lights) EXPECT_NEAR(l.select_prob, 1.0, 1e-15);
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
    for (const PointLight& l : scene.point_lights) {
        EXPECT_TRUE(std::isfinite(l.select_prob));
        total += l.select_prob;
    }
    for (const AreaLight& l : scene.area_lights) {
        EXPECT_TRUE(std::isfinite(l.select_prob));
        total += l.select_prob;
    }
    EXPECT_NEAR(total, 1.0, 1e-12);
    EXPECT_EQ(scene.point_lights[0].select_prob, 0.0);
    EXPECT_GT(scene.area_lights[0].select_prob, 0.99);
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

// =======================================================================================
// Camera

// Position equal to target: a clear loader error (LoadErrors.PositionEqualsTarget covers the
// file); built in code, prepare_scene gives the same kind of error; so do positions too far
// apart for their difference to be a finite vector.
TEST(RobustCamera, PositionEqualsTargetAndDegenerateViews) {
    test::SceneBuilder b;
    b.sphere({0, 0, 0}, 1, b.material(MaterialType::diffuse));
    b.scene.cameras[0].position = b.scene.cameras[0].target = {1, 2, 3};
    EXPECT_THROW(b.build(), SceneError);
    try {
        b.build();
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("position equals target"), std::string::npos) << e.what();
    }
    // Distinct, but so close that the difference's length underflows: a sound camera or a
    // clear error, never NaN rays.
    b.scene.cameras[0].target = {1, 2, 3 + 1e-15};
    {
        const RenderScene scene = b.build();
        EXPECT_TRUE(is_finite(scene.camera.forward));
        EXPECT_NEAR(length(scene.camera.forward), 1.0, 1e-12);
    }
    b.scene.cameras[0].position = {0, 0, 0};
    b.scene.cameras[0].target = {0, 0, 1e-310};  // subnormal: the squared length underflows
    {
        const RenderScene scene = b.build();
        EXPECT_NEAR(scene.camera.forward.z, 1.0, 1e-12);
    }
    // Far apart: the difference of the two points overflows or its square does.
    for (double big : {1e200, 1e308}) {
        b.scene.cameras[0].position = {0, 0, -big};
        b.scene.cameras[0].target = {0, 0, big};
        try {
            const RenderScene scene = b.build();
            EXPECT_NEAR(scene.camera.forward.z, 1.0, 1e-12) << big;
        } catch (const SceneError& e) {
            // Acceptable only with a message that says what is wrong.
            EXPECT_EQ(std::string(e.what()).find("equals target"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("finite"), std::string::npos) << e.what();
        }
    }
}

// Looking straight up or down: an orthonormal, left-handed basis (right = up x forward),
// continuous with the nearly vertical views around it, and a finite image.
TEST(RobustCamera, LookingStraightUpOrDown) {
    for (double sign : {1.0, -1.0}) {
        for (double tilt : {0.0, 1e-300, 1e-12, 1e-6}) {
            Camera c;
            c.position = {0, 0, 0};
            c.target = {0, 5 * sign, tilt};
            const CameraModel m = CameraModel::from(c);
            ASSERT_TRUE(is_finite(m.right) && is_finite(m.up) && is_finite(m.forward));
            EXPECT_NEAR(length(m.right), 1, 1e-12);
            EXPECT_NEAR(length(m.up), 1, 1e-12);
            EXPECT_NEAR(dot(m.right, m.forward), 0, 1e-12);
            EXPECT_NEAR(dot(m.up, m.forward), 0, 1e-12);
            EXPECT_NEAR(dot(m.right, m.up), 0, 1e-12);
            // Left-handed: up x forward points right.
            EXPECT_GT(dot(cross(m.up, m.forward), m.right), 0.999);
            // Continuity: the vertical view's basis is the limit of the tilted ones.
            Camera tilted = c;
            tilted.target.z = 1e-3;
            const CameraModel t = CameraModel::from(tilted);
            EXPECT_GT(dot(t.right, m.right), 0.99) << sign << " " << tilt;
            EXPECT_GT(dot(t.up, m.up), 0.99) << sign << " " << tilt;
        }
        test::SceneBuilder b = still_life(1);
        b.scene.cameras[0].position = {0, sign > 0 ? 0.5 : 6.0, 0};
        b.scene.cameras[0].target = {0, sign > 0 ? 6.0 : 0.5, 0};
        const RenderState state = render(b.build(), settings_for(Integrator::pt, 4, 2), 8, 8, 2);
        ASSERT_TRUE(all_finite(state));
        EXPECT_EQ(state.nonfinite_samples, 0u);
    }
}

// =======================================================================================
// JSON

TEST(RobustJson, NanAndInfinityLiteralsAreRefused) {
    const std::string base = scene_json();
    for (const char* literal : {"NaN", "nan", "Infinity", "-Infinity", "inf", "1e999", "-1e400"}) {
        std::string text = base;
        text = test::edit_once(text, "\"radius\": 1", std::string("\"radius\": ") + literal);
        const std::string error = load_error(text);
        EXPECT_NE(error, "") << literal;
        EXPECT_NE(error.find("hostile.json"), std::string::npos) << error;
        const bool names_it = error.find("malformed JSON at line 4") != std::string::npos ||
                              error.find("not a finite number") != std::string::npos;
        EXPECT_TRUE(names_it) << literal << ": " << error;
    }
}

TEST(RobustJson, StringsForNumbers) {
    const std::string base = scene_json();
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"\"radius\": 1", "\"radius\": \"1\""},
        {"[16, 12]", "[\"16\", 12]"},
        {"\"samples\": 2", "\"samples\": \"2\""},
        {"\"depth\": 4", "\"depth\": \"4\""},
        {"\"fov\": 45", "\"fov\": \"45deg\""},
        {"\"power\": [50, 50, 50]", "\"power\": [\"50\", 50, 50]"},
    };
    for (const auto& [from, to] : cases) {
        std::string text = base;
        text = test::edit_once(text, from, to);
        const std::string error = load_error(text);
        EXPECT_NE(error.find("got string"), std::string::npos) << to << ": " << error;
    }
}

// Huge arrays: a million-element vector or primitive list is refused with its size (how long
// that takes is no test's business: RobustJson.HundredThousandPrimitives prints load times).
TEST(RobustJson, HugeArrays) {
    std::string numbers = "[0";
    for (int i = 1; i < 1000000; ++i) numbers += ",0";
    numbers += "]";
    std::string text = scene_json();
    text = test::edit_once(text, "\"centre\": [0, 0, 0]", "\"centre\": " + numbers);
    std::string error = load_error(text);
    EXPECT_NE(error.find("/shapes/0/centre: expected an array of 3 finite numbers, got an array of 1000000 elements"),
              std::string::npos)
        << error.substr(0, 200);
    text = scene_json();
    text = test::edit_once(text, "\"lights\": [\"lamp\"]", "\"lights\": " + numbers);
    error = load_error(text);
    EXPECT_NE(error.find("/scene/lights/0: expected a light id (a string), got number 0"), std::string::npos) << error;
}

// Deep nesting: 10^5 (and 10^6) nested arrays or objects are refused before parsing, with a
// clear error and no stack overflow (nlohmann's DOM is recursive).
TEST(RobustJson, DeepNesting) {
    for (size_t depth : {size_t(100000), size_t(1000000)}) {
        const std::string arrays = std::string(depth, '[') + std::string(depth, ']');
        std::string error = load_error(arrays);
        EXPECT_NE(error.find("nesting deeper than 64 levels at line 1, column 65"), std::string::npos) << error;
        std::string objects;
        for (size_t i = 0; i < depth; ++i) objects += "{\"a\":";
        objects += "0" + std::string(depth, '}');
        error = load_error(objects);
        EXPECT_NE(error.find("nesting deeper than 64 levels"), std::string::npos) << error;
        // Inside a valid scene, unbalanced and never closed.
        std::string text = scene_json();
        text = test::edit_once(text, "\"radius\": 1", "\"radius\": " + std::string(depth, '['));
        error = load_error(text);
        EXPECT_NE(error.find("nesting deeper than 64 levels at line 4"), std::string::npos) << error;
    }
}

// Ids: duplicates within a category are errors, across categories legal; dangling ids are
// errors naming the valid ones (more in test_load.cpp: DuplicateIdInACategory,
// DanglingMaterialId, DanglingCameraLightAndShapeIds).
TEST(RobustJson, DuplicateAndDanglingIds) {
    std::string text = scene_json();
    text = test::edit_once(text, "\"shapes\": [", "\"shapes\": [{\"id\": \"ball\", \"type\": \"sphere\", \"centre\": [1, 0, 0], \"radius\": 1}, ");
    EXPECT_NE(load_error(text).find("/shapes/1/id: duplicate shape id \"ball\""), std::string::npos) << load_error(text);
    text = scene_json();
    text = test::edit_once(text, "\"cameras\": [", "\"cameras\": [{\"id\": \"cam\", \"type\": \"pinhole\", \"fov\": 45, \"aspect\": 1, \"position\": [0, 0, -5], "
                 "\"target\": [0, 0, 0]}, ");
    EXPECT_NE(load_error(text).find("duplicate camera id \"cam\""), std::string::npos) << load_error(text);
    // One id in every category (and repeated primitive ids): legal.
    text = scene_json("out.ppm", "[16, 12]",
                      R"({"id": "ball", "type": "point", "position": [0, 3, -3], "power": [50, 50, 50]})",
                      R"({"id": "ball", "type": "diffuse", "rho": [0.8, 0.8, 0.8]})");
    text = test::edit_once(text, "\"lights\": [\"lamp\"]", "\"lights\": [\"ball\"]");
    text = test::edit_once(text, "\"material\": \"white\"", "\"material\": \"ball\"");
    EXPECT_EQ(load_error(text), "");
    // Dangling: the light the scene lists, and an area light's shape.
    text = scene_json();
    text = test::edit_once(text, "\"lights\": [\"lamp\"]", "\"lights\": [\"sun\"]");
    EXPECT_NE(load_error(text).find("/scene/lights/0: no light with id \"sun\"; expected one of \"lamp\""),
              std::string::npos)
        << load_error(text);
}

// Empty scenes: no primitives and no lights load, render black and finite; an empty file or
// object is a clear error.
TEST(RobustJson, EmptyScene) {
    const std::string empty = R"({
  "cameras": [{"id": "cam", "type": "pinhole", "fov": 45, "aspect": 1, "position": [0, 0, -5], "target": [0, 0, 0]}],
  "scene": {"camera": "cam", "lights": [], "primitives": [],
            "renderer": {"type": "PT", "dimensions": [8, 8], "samples": 1, "depth": 6, "output": "out.ppm"}}
})";
    const LoadedScene loaded = parse_scene(empty, "empty.json");
    const RenderScene scene = prepare_scene(loaded.scene);
    for (Integrator integrator : {Integrator::wrt, Integrator::pt, Integrator::pt_naive}) {
        const RenderState state = render(scene, settings_for(integrator), 8, 8, 2);
        for (const Color& c : state.radiance_sum()) EXPECT_EQ(c, Color());
        for (double d : state.mean_depth()) EXPECT_EQ(d, kMissDepth);
    }
    EXPECT_NE(load_error("").find("malformed JSON"), std::string::npos);
    EXPECT_NE(load_error("{}").find("missing key \"scene\""), std::string::npos);
    EXPECT_NE(load_error("{\"scene\": {}}").find("missing key"), std::string::npos);
    EXPECT_NE(load_error("null").find("expected a JSON object at the top level"), std::string::npos);
}

// 100,000 primitives: the file loads, is prepared and renders a small image in seconds; the
// time is printed for docs/robustness.md. Every primitive is emissive with its own active
// light, the worst case for the loader's and prepare_scene's cross-checks.
TEST(RobustJson, HundredThousandPrimitives) {
    constexpr int kCount = 100000;
    std::string text = R"({"cameras": [{"id": "cam", "type": "pinhole", "fov": 60, "aspect": 1, "position": [0, 0, -80], "target": [0, 0, 0]}],
"materials": [{"id": "m", "type": "diffuse", "rho": [0.7, 0.7, 0.7]}, {"id": "e", "type": "diffuse", "rho": [0, 0, 0]}],
"shapes": [)";
    std::string lights = "\"lights\": [", light_ids = "\"lights\": [", prims = "\"primitives\": [";
    Rng rng(1, 2);
    for (int i = 0; i < kCount; ++i) {
        const std::string id = std::to_string(i);
        char buf[160];
        std::snprintf(buf, sizeof buf, R"({"id": "s%d", "type": "sphere", "centre": [%.4f, %.4f, %.4f], "radius": %.4f})",
                      i, 60 * rng.next() - 30, 60 * rng.next() - 30, 60 * rng.next() - 30, 0.05 + 0.2 * rng.next());
        text += std::string(i ? "," : "") + buf;
        const bool emissive = i % 2 == 0;
        if (emissive) {
            lights += std::string(i ? "," : "") + R"({"id": "l)" + id + R"(", "type": "area", "shape": "s)" + id +
                      R"(", "power": [1, 1, 1]})";
            light_ids += std::string(i ? "," : "") + "\"l" + id + "\"";
            prims += std::string(i ? "," : "") + R"({"id": "p)" + id + R"(", "type": "emissive", "shape": "s)" + id +
                     R"(", "material": "e", "light": "l)" + id + "\"}";
        } else {
            prims += R"(,{"id": "p)" + id + R"(", "type": "geometric", "shape": "s)" + id + R"(", "material": "m"})";
        }
    }
    text += "],\n" + lights + "],\n\"scene\": {\"camera\": \"cam\", " + light_ids + "], " + prims +
            "],\n\"renderer\": {\"type\": \"PT\", \"dimensions\": [32, 32], \"samples\": 1, \"depth\": 4, "
            "\"output\": \"out.ppm\"}}}";
    const auto t0 = std::chrono::steady_clock::now();
    const LoadedScene loaded = parse_scene(text, "many.json");
    const auto t1 = std::chrono::steady_clock::now();
    const RenderScene scene = prepare_scene(loaded.scene);
    const auto t2 = std::chrono::steady_clock::now();
    const RenderState state = render(scene, settings_for(Integrator::pt, 4, 1), 32, 32, 1);
    const auto t3 = std::chrono::steady_clock::now();
    auto sec = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
    EXPECT_EQ(loaded.scene.primitives.size(), size_t(kCount));
    EXPECT_EQ(scene.spheres.size(), size_t(kCount));
    EXPECT_EQ(scene.area_lights.size(), size_t(kCount / 2));
    ASSERT_TRUE(all_finite(state));
    EXPECT_EQ(state.nonfinite_samples, 0u);
    double lit = 0;
    for (const Color& c : state.radiance_sum()) lit += c.x;
    EXPECT_GT(lit, 0);
    std::printf("[ timing   ] 100k primitives (50k area lights), %.1f MB of JSON: parse+load %.2f s, "
                "prepare %.2f s, 32x32 PT 1 spp render %.2f s\n",
                text.size() / 1e6, sec(t0, t1), sec(t1, t2), sec(t2, t3));
    // Generous bounds: the quadratic cross-checks this guards against took minutes.
    EXPECT_LT(sec(t0, t1), 30.0);
    EXPECT_LT(sec(t1, t2), 10.0);
}

// =======================================================================================
// Non-finite samples

// A hostile but accepted scene: a point light of intensity 1.7e308 (finite) 0.05 from a
// wall makes some radiance samples overflow to infinity (and, after a black bounce, NaN).
// They are counted, never accumulated: every pixel's samples drawn = accumulated + dropped.
TEST(RobustNonFinite, SamplesAreCountedAndNeverAccumulated) {
    test::SceneBuilder b;
    b.scene.cameras[0].fov = 30;
    b.sphere({0, 0, 0}, 1, b.material(MaterialType::diffuse, Color(0.5)));
    b.sphere({1.3, 0, -1}, 0.3, b.material(MaterialType::diffuse, Color(0)));  // black: 0 * inf = NaN
    b.point_light({0, 0, -1.05}, Color(1.7e308));
    const RenderScene scene = b.build();
    for (Integrator integrator : {Integrator::wrt, Integrator::pt}) {
        const RenderState state = render(scene, settings_for(integrator, 6, 4), 16, 16, 4);
        EXPECT_GT(state.nonfinite_samples, 0u) << integrator_names.name(integrator);
        ASSERT_TRUE(all_finite(state));
        for (double v : state.luminance_sq_sum()) EXPECT_FALSE(std::isnan(v));
        uint64_t dropped = 0;
        for (size_t i = 0; i < state.sample_count().size(); ++i) {
            EXPECT_LE(state.sample_count()[i], state.sample_index()[i]);
            dropped += state.sample_index()[i] - state.sample_count()[i];
        }
        EXPECT_EQ(dropped, state.nonfinite_samples);
        // The corner pixels see the lit wall far from the light: finite, kept.
        EXPECT_EQ(state.sample_count()[0], 4u);
    }
}

// Radiance whose square overflows (a light of radiance 1e200 is accepted): the per-pixel
// variance behind --noise and adaptive sampling must not collapse to 0 (inf - inf = NaN,
// then max(0, NaN) = 0), or the noise stop rule would end a noisy render at once.
TEST(RobustNonFinite, NoiseEstimateWithHugeRadiance) {
    test::SceneBuilder b;
    b.sphere({0, 0, 0}, 1, b.material(MaterialType::diffuse, Color(0.5)));
    b.emitter({0, 3, -2}, 0.5, Color(1e200), b.material(MaterialType::diffuse, Color(0)));
    b.scene.cameras[0].fov = 5;  // the ball fills the image
    const RenderState state = render(b.build(), settings_for(Integrator::pt, 4, 16, LightSampling::area), 4, 4, 16);
    ASSERT_TRUE(all_finite(state));
    EXPECT_EQ(state.nonfinite_samples, 0u);
    const double error = state.relative_error();
    EXPECT_GT(error, 0.0);
}

// =======================================================================================
// Output files

// The CLI reports dropped non-finite samples.
TEST_F(TempDir, CliReportsNonFiniteSamples) {
    const fs::path scene = write("hot.json", scene_json("hot.ppm", "[16, 12]",
                                                        R"({"id": "lamp", "type": "point", "position": [0, 0, -1.02], "power": [1.7e308, 1.7e308, 1.7e308]})"));
    const test::CommandResult r = cli("render '" + scene.string() + "' -q");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("non-finite samples were dropped"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::exists(dir / "hot.ppm"));
}

// write_ppm replaces the file by a rename: a reader holding the old file keeps reading the
// old bytes whole, and a failed write leaves the target and no temporary behind.
TEST_F(TempDir, OutputIsWrittenAtomically) {
    const fs::path out = dir / "img.ppm";
    Rgb8Image small{2, 1, {1, 2, 3, 4, 5, 6}};
    write_ppm(out, small);
    std::ifstream reader(out, std::ios::binary);
    ASSERT_TRUE(reader);
    Rgb8Image big{64, 64, std::vector<uint8_t>(64 * 64 * 3, 200)};
    write_ppm(out, big);
    std::string old((std::istreambuf_iterator<char>(reader)), std::istreambuf_iterator<char>());
    EXPECT_EQ(old, std::string("P6\n2 1\n255\n\x01\x02\x03\x04\x05\x06"));
    EXPECT_EQ(read_ppm(out).width, 64);
    // Writing onto a directory fails cleanly.
    fs::create_directories(dir / "taken");
    std::ofstream(dir / "taken" / "keep") << "x";
    EXPECT_THROW(write_ppm(dir / "taken", big), std::runtime_error);
    EXPECT_TRUE(fs::exists(dir / "taken" / "keep"));
    for (const auto& e : fs::directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

// No render ever writes over an input scene file: -o naming it, the file's own "output"
// naming it (or its depth map landing on it), or, with several scenes, one scene's output
// naming another input. Each is refused with a clear error before anything is written.
TEST_F(TempDir, SceneFileIsNeverOverwritten) {
    // "output" naming the scene file itself.
    const fs::path self = write("self.ppm", scene_json("self.ppm"));
    const std::string self_text = test::read_file(self);
    test::CommandResult r = cli("render '" + self.string() + "' -q");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("overwrite the scene file"), std::string::npos) << r.err;
    EXPECT_EQ(test::read_file(self), self_text);
    // Its depth map would land on the scene file: out-depth.json.
    const fs::path depth = write("out-depth.json", scene_json("out.json"));
    const std::string depth_text = test::read_file(depth);
    r = cli("render '" + depth.string() + "' -q");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("overwrite"), std::string::npos) << r.err;
    EXPECT_EQ(test::read_file(depth), depth_text);
    EXPECT_FALSE(fs::exists(dir / "out.json"));
    // -o through another path to the same file (a symbolic link).
    fs::create_symlink(self, dir / "link.ppm");
    const fs::path good = write("good.json", scene_json("good.ppm"));
    const std::string good_text = test::read_file(good);
    r = cli("render '" + good.string() + "' -q -o '" + (dir / "sub" / ".." / "good.json").string() + "'");
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(test::read_file(good), good_text);
    // Several scenes: the first one's output is the second scene file.
    const fs::path first = write("first.json", scene_json("second.json"));
    const fs::path second = write("second.json", scene_json("second.ppm"));
    const std::string second_text = test::read_file(second);
    r = cli("render '" + first.string() + "' '" + second.string() + "' -q");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("overwrite"), std::string::npos) << r.err;
    EXPECT_EQ(test::read_file(second), second_text);
    EXPECT_TRUE(fs::exists(dir / "second.ppm"));  // the second scene itself still renders
    for (const auto& e : fs::directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

// Dimensions the loader accepts but memory cannot hold: a clear error naming the size, exit
// status 1, nothing written (run under a 1 GiB address-space limit).
TEST_F(TempDir, DimensionsTooLargeForMemory) {
#ifdef KR_TEST_SANITIZED
    GTEST_SKIP() << "sanitizers reserve terabytes of address space: ulimit -v cannot be used";
#endif
    const fs::path scene = write("huge.json", scene_json("huge.ppm", "[32768, 32768]"));
    const test::CommandResult r = test::run_command(
        "ulimit -v 1048576; '" + std::string(KEITHRAY_EXE) + "' render '" + scene.string() + "' -q --threads 1", dir);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("32768x32768"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("memory"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "huge.ppm"));
}

// =======================================================================================
// Coincident spheres

namespace {

// A ball on a floor under a point light, the ball's primitive repeated `copies` times under
// further shape ids at exactly the same centre and radius (a copy-paste), the last copy with
// material `copy_material`.
std::string copied_ball_json(int copies, const std::string& copy_material = "white") {
    std::string shapes = R"({"id": "floor", "type": "sphere", "centre": [0, -1001, 0], "radius": 1000},
        {"id": "ball", "type": "sphere", "centre": [0, 0, 0], "radius": 1})";
    std::string prims = R"({"id": "floor", "type": "geometric", "shape": "floor", "material": "white"},
        {"id": "ball", "type": "geometric", "shape": "ball", "material": "white"})";
    for (int k = 1; k <= copies; ++k) {
        const std::string id = "ball copy " + std::to_string(k);
        shapes += R"(, {"id": ")" + id + R"(", "type": "sphere", "centre": [0, 0, 0], "radius": 1})";
        prims += R"(, {"id": ")" + id + R"(", "type": "geometric", "shape": ")" + id + R"(", "material": ")" +
                 (k == copies ? copy_material : "white") + R"("})";
    }
    return R"({"cameras": [{"id": "cam", "type": "pinhole", "fov": 40, "aspect": 1, "position": [0, 1, -6], "target": [0, 0, 0]}],
      "materials": [{"id": "white", "type": "diffuse", "rho": [0.8, 0.8, 0.8]},
                    {"id": "red", "type": "diffuse", "rho": [0.8, 0.1, 0.1]}],
      "shapes": [)" + shapes + R"(],
      "lights": [{"id": "lamp", "type": "point", "position": [2, 4, -3], "power": [40, 40, 40]}],
      "scene": {"camera": "cam", "lights": ["lamp"], "primitives": [)" + prims + R"(],
                "renderer": {"type": "PT", "dimensions": [32, 32], "samples": 4, "depth": 3, "output": "out.ppm"}}})";
}

size_t occurrences(const std::string& text, const std::string& what) {
    size_t count = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++count;
    return count;
}

}  // namespace

// The same sphere under two shape ids rendered both surfaces, which shadowed each other at
// random (speckle, 26 to 32 dB against the one-sphere image). The second is left out with one
// warning naming both primitives: the image is the one-sphere image byte for byte.
TEST_F(TempDir, CoincidentSpheresRenderAsOne) {
    const fs::path one = write("one.json", copied_ball_json(0)), two = write("two.json", copied_ball_json(1));
    test::CommandResult r = cli("render '" + one.string() + "' --seed 3 -o '" + (dir / "one.ppm").string() + "' -q");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err, "");
    r = cli("render '" + two.string() + "' --seed 3 -o '" + (dir / "two.ppm").string() + "' -q");
    ASSERT_EQ(r.status, 0) << r.err;
    ASSERT_TRUE(fs::exists(dir / "one.ppm"));
    EXPECT_EQ(test::read_file(dir / "one.ppm"), test::read_file(dir / "two.ppm"));
    EXPECT_EQ(occurrences(r.err, "\n"), 1u) << r.err;  // one line
    EXPECT_EQ(occurrences(r.err, "warning: "), 1u) << r.err;
    EXPECT_NE(r.err.find("/scene/primitives/2: primitive \"ball copy 1\" (shape \"ball copy 1\") is the same sphere as "
                         "primitive \"ball\" (shape \"ball\"); rendered once, as the first"),
              std::string::npos)
        << r.err;

    // Three copies, the last of another material: one warning each, the last saying its
    // material is left out; the image is still the first ball's.
    const Scene three = load_scene_file(write("three.json", copied_ball_json(3, "red"))).scene;
    std::vector<std::string> warnings;
    const RenderScene prepared = prepare_scene(three, &warnings);
    EXPECT_EQ(prepared.spheres.size(), 2u);
    EXPECT_EQ(prepared.materials.size(), 1u);
    ASSERT_EQ(warnings.size(), 3u);
    EXPECT_NE(warnings[2].find("; its material \"red\" is left out"), std::string::npos) << warnings[2];
    EXPECT_EQ(warnings[0].find("left out"), std::string::npos) << warnings[0];
    // Spheres that only nearly coincide (a radius one ulp larger) stay two spheres.
    test::SceneBuilder b;
    const int m = b.material(MaterialType::diffuse);
    b.sphere({0, 0, 0}, 1, m);
    b.sphere({0, 0, 0}, std::nextafter(1.0, 2.0), m);
    warnings.clear();
    EXPECT_EQ(prepare_scene(b.scene, &warnings).spheres.size(), 2u);
    EXPECT_TRUE(warnings.empty());
}
