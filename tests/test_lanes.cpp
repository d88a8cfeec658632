// Paths in lanes (render/lanes/) against one path at a time: the same samples, so the
// same images. Each sample of a batch traced together must give what trace_sample gives it
// with the same sampler: its radiance, its first hit's distance and its ray count. Every test
// runs three times: with the kernels for any x86-64 CPU, with the x86-64-v3 double lanes and
// with the CPU's best (on a CPU with AVX2 and FMA, the single-precision lanes where the
// scene fits them; else one path, which these tests then compare with itself), so every
// build of the kernels is checked on a machine that has them all. Single-precision lanes
// agree to their rounding (lane_tolerance below).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "core/rng.h"
#include "render/precision.h"
#include "render/aov.h"
#include "render/progressive.h"
#include "render/trace.h"
#include "scene/load.h"
#include "test_util.h"

using namespace kr;

namespace kr {
void PrintTo(LaneChoice isa, std::ostream* out) { *out << lane_choice_names.name(isa); }
}  // namespace kr

namespace {

struct Agreement {
    int samples = 0, mismatches = 0;
    double radiance_sum = 0;
};

bool close(double a, double b, double tolerance = 1e-9) { return std::abs(a - b) <= tolerance * (1 + std::abs(b)); }

// How closely the lanes must agree with one path: to the rounding of their precision. In single
// precision the paths are the same (same rays, same first hit) but a path's radiance picks up
// rounding at every step: of the ~30,000 samples of the tests below, 56 differ by more than
// 1e-4, 4 (one path of scene 3 under four light strategies) by more than 1e-3, the largest
// by 0.7 %. A wrong factor or branch differs by far more, on many samples.
double lane_tolerance(const RenderScene& scene, const RenderSettings& settings) {
    const LaneKernels kernels = lane_kernels(scene, settings);
    return single_precision(kernels) ? 1e-2 : 1e-9;
}

// `batches` batches of `count` camera samples of pixels spread over the image, traced together
// and one by one.
Agreement compare(const RenderScene& scene, const RenderSettings& settings, int batches, int count) {
    Agreement a;
    const double tolerance = lane_tolerance(scene, settings);
    const int width = scene.renderer.width, height = scene.renderer.height;
    for (int batch = 0; batch < batches; ++batch) {
        std::vector<Ray> rays(static_cast<size_t>(count));
        std::vector<std::optional<Sampler>> together(static_cast<size_t>(count)), alone(static_cast<size_t>(count));
        std::vector<Sampler*> samplers(static_cast<size_t>(count));
        for (int k = 0; k < count; ++k) {
            const uint64_t pixel = (uint64_t(batch) * 7919 + uint64_t(k) * 104729) % uint64_t(width * height);
            const uint32_t index = uint32_t(batch % 5);
            together[k].emplace(settings.estimator, settings.seed, pixel, index, settings.target_spp);
            alone[k].emplace(settings.estimator, settings.seed, pixel, index, settings.target_spp);
            const Vec2 sub = together[k]->pixel();
            alone[k]->pixel();
            together[k]->skip_2d();
            alone[k]->skip_2d();
            const Vec2 film = raster_to_camera(double(pixel % width) + sub.x, double(pixel / width) + sub.y, width,
                                               height);
            const CameraRay cr = scene.camera.generate(film.x, film.y, 0, 0);
            rays[k].o = cr.origin;
            rays[k].d = cr.direction;
            samplers[k] = &*together[k];
        }
        std::vector<SampleResult> results(static_cast<size_t>(count));
        trace_samples(scene, settings, rays.data(), samplers.data(), count, results.data());
        for (int k = 0; k < count; ++k) {
            const SampleResult one = trace_sample(scene, settings, rays[k], *alone[k]);
            const SampleResult& four = results[k];
            ++a.samples;
            a.radiance_sum += four.radiance.x + four.radiance.y + four.radiance.z;
            const bool same = close(four.radiance.x, one.radiance.x, tolerance) &&
                              close(four.radiance.y, one.radiance.y, tolerance) &&
                              close(four.radiance.z, one.radiance.z, tolerance) && four.rays == one.rays &&
                              close(four.primary_distance, one.primary_distance, tolerance);
            a.mismatches += !same;
        }
    }
    return a;
}

// A camera sample's ray as camera_ray draws it, one by one: the sub-pixel position, then the
// lens's numbers (skipped for a pinhole), raster_to_camera and CameraModel::generate.
Ray camera_ray_one_by_one(const RenderScene& scene, int width, int height, int x, int y, Sampler& sampler) {
    const Vec2 sub = sampler.pixel();
    Vec2 lens;
    if (scene.camera.lens_radius > 0) lens = sampler.next_2d();
    else sampler.skip_2d();
    const Vec2 film = raster_to_camera(x + sub.x, y + sub.y, width, height);
    const CameraRay cr = scene.camera.generate(film.x, film.y, lens.x, lens.y);
    Ray ray;
    ray.o = cr.origin;
    ray.d = cr.direction;
    return ray;
}

RenderScene brief_scene(int n) {
    return prepare_scene(
        load_scene_file(test::brief_scene_file(n)).scene);
}

// The kernels a test runs with: its settings' `kernels`.
class Lanes : public ::testing::TestWithParam<LaneChoice> {
protected:
    RenderSettings settings_of(const RenderScene& scene) const {
        RenderSettings settings = RenderSettings::from_scene(scene.renderer);
        settings.kernels = GetParam();
        return settings;
    }
};

}  // namespace

INSTANTIATE_TEST_SUITE_P(Kernels, Lanes, ::testing::Values(LaneChoice::any, LaneChoice::double_lanes, LaneChoice::float8,
                                                             LaneChoice::best),
                         [](const ::testing::TestParamInfo<LaneChoice>& info) {
                             return ::testing::PrintToString(info.param);
                         });

// The names users see (`--kernels`, `--version`, the statistics' paths column) stay those of
// the targets' rows and the choices' table; the targets' precision and width follow their rows.
TEST(LaneNames, TargetsAndChoicesKeepTheirNames) {
    EXPECT_EQ(lane_kernels_names.name(LaneKernels::x86_64_v4_float), "x86-64-v4 float lanes");
    EXPECT_EQ(lane_kernels_names.name(LaneKernels::x86_64_v3_float), "x86-64-v3 float lanes");
    EXPECT_EQ(lane_kernels_names.name(LaneKernels::x86_64_v3), "x86-64-v3 lanes");
    EXPECT_EQ(lane_kernels_names.name(LaneKernels::x86_64), "x86-64 lanes");
    EXPECT_EQ(lane_kernels_names.name(LaneKernels::one_path), "one path");
    EXPECT_EQ(lane_choice_names.parse("off"), LaneChoice::off);
    EXPECT_EQ(lane_choice_names.name(LaneChoice::off), "off");
    EXPECT_EQ(lane_choice_names.parse("double"), LaneChoice::double_lanes);
    EXPECT_EQ(lane_choice_names.parse("float8"), LaneChoice::float8);
    EXPECT_TRUE(single_precision(LaneKernels::x86_64_v4_float) && single_precision(LaneKernels::x86_64_v3_float));
    EXPECT_FALSE(single_precision(LaneKernels::x86_64_v3) || single_precision(LaneKernels::x86_64) ||
                 single_precision(LaneKernels::one_path));
    EXPECT_EQ(lane_count(LaneKernels::x86_64_v4_float), 16);
    EXPECT_EQ(lane_count(LaneKernels::x86_64_v3_float), 8);
    EXPECT_EQ(lane_count(LaneKernels::x86_64_v3), 4);
    EXPECT_EQ(lane_count(LaneKernels::one_path), 1);
    // The choice `off` is one path at a time on every CPU; `any` the kernels every x86-64 runs.
    EXPECT_EQ(cpu_lane_kernels(LaneChoice::off), LaneKernels::one_path);
    EXPECT_EQ(cpu_lane_kernels(LaneChoice::any), LaneKernels::x86_64);
}

// The switch itself. `best` is the x86-64-v3 lanes where the CPU has them (in single
// precision where the scene fits them), else one path at a time, never the lanes for any CPU
// (slower than one path); which this CPU gets is printed, and asserted only where CMake saw
// AVX2 and FMA and built the v3 kernels (a CI machine may lack them). Scenes whose sizes single precision cannot keep (a wall of radius 1e6 beside a
// sphere of 0.5) keep the double lanes, and scenes that are no single BVH leaf go one path at
// a time whatever the switch says.
TEST(LaneChoiceSwitch, BestIsTheV3LanesOrOnePath) {
    const RenderScene brief = brief_scene(6);
    RenderSettings settings = RenderSettings::from_scene(brief.renderer);
    EXPECT_TRUE(float_lanes_fit(brief));
    RenderScene wide_lens = brief;  // rays from up to 1e4 away: beyond 4096 radii of 0.5
    wide_lens.camera.lens_radius = 1e4;
    EXPECT_FALSE(float_lanes_fit(wide_lens));
    settings.kernels = LaneChoice::any;
    EXPECT_EQ(lane_kernels(brief, settings), LaneKernels::x86_64);
    settings.kernels = LaneChoice::off;
    EXPECT_EQ(lane_kernels(brief, settings), LaneKernels::one_path);
    settings.kernels = LaneChoice::double_lanes;
    const LaneKernels v3 = lane_kernels(brief, settings);
    EXPECT_TRUE(v3 == LaneKernels::x86_64_v3 || v3 == LaneKernels::one_path);
    settings.kernels = LaneChoice::float8;
    const LaneKernels float8 = lane_kernels(brief, settings);
    EXPECT_EQ(float8, v3 == LaneKernels::x86_64_v3 ? LaneKernels::x86_64_v3_float : LaneKernels::one_path);
    settings.kernels = LaneChoice::best;
    const LaneKernels best = lane_kernels(brief, settings);
    // The sixteen float lanes where the CPU has AVX-512, else the eight.
    EXPECT_TRUE(best == float8 || (float8 == LaneKernels::x86_64_v3_float && best == LaneKernels::x86_64_v4_float));
    std::printf("best on this CPU: %s\n", std::string(lane_kernels_names.name(best)).c_str());
#if KEITHRAY_V4_KERNELS_EXPECTED
    // CMake built the kernels (GCC's pragmas, or the Clang sanitizer builds' whole-file
    // -march=x86-64-v4) and saw AVX-512: so every build, sanitized ones too, runs the sixteen
    // float lanes here, and the eight where asked.
    EXPECT_EQ(best, LaneKernels::x86_64_v4_float);
    EXPECT_EQ(float8, LaneKernels::x86_64_v3_float);
#elif KEITHRAY_V3_KERNELS_EXPECTED
    // CMake built the v3 kernels (GCC's pragma, or the Clang sanitizer builds' whole-file
    // -march) and saw AVX2 and FMA: so every build, sanitized ones too, runs them here.
    EXPECT_EQ(best, LaneKernels::x86_64_v3_float);
#endif

    test::SceneBuilder b;
    const int grey = b.material(MaterialType::diffuse, Color(0.7));
    b.sphere({0, -1e6 - 1, 0}, 1e6, grey);
    b.sphere({0, 0, 0}, 0.5, grey);
    b.emitter({0, 3, 0}, 0.5, Color(5), grey);
    const RenderScene huge = b.build();
    EXPECT_FALSE(float_lanes_fit(huge));
    EXPECT_EQ(lane_kernels(huge, settings), v3);  // the double lanes, where the CPU has them
    // Reaching 2001 from the origin, under 2^12 times the smallest radius (2048): single.
    b.scene.shapes[0].radius = 1000;
    b.scene.shapes[0].centre = {0, -1001, 0};
    EXPECT_TRUE(float_lanes_fit(b.build()));
    // Radiance single precision would overflow or flush to zero in a path: the double lanes.
    // A black light is fine.
    for (double radiance : {1e30, 1e-30, 0.0}) {
        b.scene.lights.back().power = Color(radiance);
        EXPECT_EQ(float_lanes_fit(b.build()), radiance == 0) << radiance;
    }
    RenderSettings wrt = settings;
    wrt.integrator = Integrator::wrt;
    EXPECT_EQ(lane_kernels(brief, wrt), LaneKernels::one_path);
}

// The brief's path-traced scenes, with every estimator and light strategy, and naive PT.
// The lanes round like one path except where fused multiply-adds land differently, which can
// only turn a path that grazes a sphere: at most one sample in 500 may differ.
TEST_P(Lanes, SameSamplesAsOneByOne) {
    for (int n : {3, 4, 5, 6, 8}) {
        const RenderScene scene = brief_scene(n);
        ASSERT_TRUE(scene.bvh.lanes_cast()) << "scene " << n;
        for (Estimator estimator : {Estimator::sobol, Estimator::uniform, Estimator::stratified})
            for (LightSampling light :
                 {LightSampling::brief, LightSampling::brief_area, LightSampling::cone, LightSampling::area})
                for (Integrator integrator : {Integrator::pt, Integrator::pt_naive}) {
                    RenderSettings settings = settings_of(scene);
                    settings.estimator = estimator;
                    settings.light_sampling = light;
                    settings.integrator = integrator;
                    settings.target_spp = 16;
                    if (integrator == Integrator::pt_naive && light != LightSampling::brief) continue;
                    // Batches of 40: lanes start new samples as paths end.
                    const Agreement a = compare(scene, settings, 10, 40);
                    const std::string where = "scene " + std::to_string(n) + ", " +
                                              std::string(estimator_names.name(estimator)) + ", " +
                                              std::string(light_sampling_names.name(light)) + ", " +
                                              std::string(integrator_names.name(integrator));
                    EXPECT_LE(a.mismatches, a.samples / 500) << where;
                    EXPECT_GT(a.radiance_sum, 0) << where;
                }
    }
}

// A scene with what the brief's lack: point lights beside area lights (so the light choice
// goes both ways), a black area light, every material, shading points inside a light, and
// batches of one to five samples (fewer than the lanes, and one more) and of a hundred.
TEST_P(Lanes, PointLightsEveryMaterialAndPartialPackets) {
    test::SceneBuilder b;
    b.scene.renderer.width = b.scene.renderer.height = 32;
    const int grey = b.material(MaterialType::diffuse, Color(0.7));
    const int mirror = b.material(MaterialType::specular, Color(0.9));
    const int glossy = b.material(MaterialType::glossy, Color(0.9));
    const int glass = b.material(MaterialType::dielectric, Color(0.9));
    const int frosted = b.material(MaterialType::translucent, Color(0.9));
    b.scene.materials[size_t(glossy)].roughness = 0.3;
    b.scene.materials[size_t(frosted)].roughness = 0.2;
    // Reflected and transmitted fractions that differ, and two indices, so that a branch
    // taken or weighted wrongly shows.
    for (int dielectric : {glass, frosted}) {
        b.scene.materials[size_t(dielectric)].rho_r = Color(0.95, 0.7, 0.5);
        b.scene.materials[size_t(dielectric)].rho_t = Color(0.5, 0.8, 0.95);
    }
    b.scene.materials[size_t(frosted)].eta = 1.33;
    b.sphere({0, -1005, 0}, 1000, grey);
    b.sphere({-3, -3, 2}, 2, mirror);
    b.sphere({3, -3, 2}, 2, glossy);
    b.sphere({0, -3.5, -1}, 1.5, glass);
    b.sphere({0, 0, 4}, 1.2, frosted);
    b.point_light({0, 4, -2}, Color(40));
    b.point_light({-4, 1, -4}, Color(10, 20, 30));
    b.emitter({4, 3, 0}, 0.8, Color(5), grey);
    b.emitter({-4, 4, 3}, 0.5, Color(2, 6, 3), grey);
    // A big dim light around everything: every shading point is inside it. And a black one,
    // which the light choice never picks.
    b.emitter({0, 0, 0}, 60, Color(0.05), b.material(MaterialType::diffuse, Color(0)));
    b.emitter({2, 5, 5}, 0.5, Color(0), grey);
    const RenderScene scene = b.build();
    ASSERT_TRUE(scene.bvh.lanes_cast());
    ASSERT_EQ(test::lights_of(scene, LightType::point).size(), 2u);
    ASSERT_EQ(test::lights_of(scene, LightType::area).size(), 4u);
    ASSERT_EQ(scene.lights.back().select_prob, 0.0);
    for (LightSampling light : {LightSampling::brief, LightSampling::cone, LightSampling::area}) {
        RenderSettings settings = settings_of(scene);
        settings.light_sampling = light;
        for (int count : {1, 2, 3, 4, 5, 100}) {
            const Agreement a = compare(scene, settings, count == 100 ? 8 : 200, count);
            EXPECT_LE(a.mismatches, a.samples / 500) << light_sampling_names.name(light) << ", " << count;
            EXPECT_GT(a.radiance_sum, 0);
        }
    }
}

// Scenes of more than 16 spheres, whose rays the lanes cast down the lane tree (accel.h) and
// whose per-sphere values they gather from wide columns: many spheres of every material (more
// materials than 16), a floor, and area lights, 20 of them in the second scene (more lights
// than 16), with point lights beside them.
RenderScene many_spheres(int n, int lights, uint64_t seed) {
    test::SceneBuilder b;
    b.scene.renderer.width = b.scene.renderer.height = 64;
    Rng rng(seed, 5);
    std::vector<int> materials;
    const MaterialType types[] = {MaterialType::diffuse, MaterialType::specular, MaterialType::glossy,
                                  MaterialType::dielectric, MaterialType::translucent};
    for (int i = 0; i < 20; ++i) {
        const int m = b.material(types[i % 5], Color(0.3 + 0.6 * rng.next(), 0.3 + 0.6 * rng.next(), 0.8));
        b.scene.materials[size_t(m)].roughness = 0.1 + 0.3 * rng.next();
        materials.push_back(m);
    }
    b.sphere({0, -1004, 0}, 1000, materials[0]);
    for (int i = 0; i < n; ++i)
        b.sphere({8 * rng.next() - 4, 6 * rng.next() - 3.5, 8 * rng.next() - 2}, 0.2 + 0.5 * rng.next(),
                 materials[size_t(i) % materials.size()]);
    for (int i = 0; i < lights; ++i)
        b.emitter({10 * rng.next() - 5, 4 + 2 * rng.next(), 8 * rng.next() - 4}, 0.3 + 0.3 * rng.next(),
                  Color(3 + 3 * rng.next()), materials[0]);
    b.point_light({0, 4, -2}, Color(20));
    return b.build();
}

TEST_P(Lanes, ManySpheresAsOneByOne) {
    // 24, 40 and 80 spheres: the sixteen lanes' wide columns looked up by one two-source
    // permute, by two, and by a gather (tables.h, kPermutedEntries).
    for (const auto& [n, lights] : {std::pair{24, 2}, std::pair{40, 2}, std::pair{80, 2}, std::pair{100, 20}}) {
        const RenderScene scene = many_spheres(n, lights, uint64_t(n));
        ASSERT_TRUE(scene.bvh.lanes_cast());
        ASSERT_FALSE(scene.bvh.one_leaf());
        ASSERT_FALSE(scene.bvh.lane_tree().nodes.empty());
        // The floor's far side is 2,004 from the origin, beyond 4,096 of the smallest radii;
        // rays reach the floor only within about 150 of it, so its sizes fit the float lanes
        // (float_sizes_fit, render/precision.h), which take the first scene (the second has
        // glass too near other surfaces: float_gaps_resolved).
        double smallest = kInfinity;
        for (const SphereGeom& s : scene.spheres) smallest = std::min(smallest, s.radius);
        EXPECT_GT(2004, kFloatSizeRatio * smallest) << n;
        EXPECT_TRUE(float_sizes_fit(scene)) << n;
        EXPECT_EQ(float_lanes_fit(scene), n != 100) << n << " " << scene.float_gaps_resolved;
        for (LightSampling light : {LightSampling::brief, LightSampling::cone, LightSampling::area})
            for (Estimator estimator : {Estimator::sobol, Estimator::uniform}) {
                RenderSettings settings = settings_of(scene);
                settings.light_sampling = light;
                settings.estimator = estimator;
                const Agreement a = compare(scene, settings, 10, 64);
                const std::string where = std::to_string(n) + " spheres, " +
                                          std::string(light_sampling_names.name(light)) + ", " +
                                          std::string(estimator_names.name(estimator));
                EXPECT_LE(a.mismatches, a.samples / 500) << where;
                EXPECT_GT(a.radiance_sum, 0) << where;
            }
    }
}

// Whole passes: the image of render_pass (which traces batches of samples in lanes) equals the image
// of the same samples traced one by one, on scenes 3 and 8 at 64x64.
TEST_P(Lanes, RenderPassImageIsOneByOnes) {
    for (int n : {3, 8}) {
        const RenderScene scene = brief_scene(n);
        RenderSettings settings = settings_of(scene);
        RenderState state(64, 64);
        for (int pass = 0; pass < 2; ++pass) render_pass(scene, settings, state);
        // The same samples, one by one, in the order render_pass draws them.
        Image alone(64, 64);
        uint64_t rays = 0;
        for (int pass = 0; pass < 2; ++pass)
            for (int y = 0; y < 64; ++y)
                for (int x = 0; x < 64; ++x) {
                    const uint64_t pixel = uint64_t(y) * 64 + uint64_t(x);
                    Sampler sampler(settings.estimator, settings.seed, pixel, uint32_t(pass), settings.target_spp);
                    const Vec2 sub = sampler.pixel();
                    sampler.skip_2d();
                    const Vec2 film = raster_to_camera(x + sub.x, y + sub.y, 64, 64);
                    const CameraRay cr = scene.camera.generate(film.x, film.y, 0, 0);
                    Ray ray;
                    ray.o = cr.origin;
                    ray.d = cr.direction;
                    const SampleResult r = trace_sample(scene, settings, ray, sampler);
                    alone.at(x, y) += r.radiance * 0.5;
                    rays += r.rays;
                }
        const Image together = state.radiance();
        const double tolerance = lane_tolerance(scene, settings);
        int differ = 0;
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                const Color a = together.at(x, y), b = alone.at(x, y);
                differ += !(close(a.x, b.x, tolerance) && close(a.y, b.y, tolerance) && close(a.z, b.z, tolerance));
            }
        EXPECT_LE(differ, 64 * 64 / 500) << "scene " << n;
        EXPECT_NEAR(double(state.rays), double(rays), double(rays) * 1e-3) << "scene " << n;
    }
}

// First hits of camera rays cast in lanes (camera_hits: the viewer's first surfaces and the
// feature buffers) against intersects one by one: the same sphere, and then the same hit to
// double's rounding (it is taken in double, by accepted_root where the BVH tests blocks of
// four), for all but rays that graze a silhouette within the lanes' rounding. On scenes 3 (through its lens too) and 8 (one BVH leaf), the many-sphere scene
// (the lane tree or clusters) and the Whitted scene 1 (lanes cast even where they trace no
// path); batches of 1 (one by one), 7 (a partial vector) and 600 (past kSampleBatch).
TEST_P(Lanes, CameraHitsAreOneByOnes) {
    std::vector<std::pair<std::string, RenderScene>> scenes;
    for (int n : {1, 3, 8}) scenes.emplace_back("scene " + std::to_string(n), brief_scene(n));
    scenes.emplace_back("scene 3, lens", brief_scene(3));
    scenes.back().second.camera.lens_radius = 0.2;
    scenes.emplace_back("40 spheres", many_spheres(40, 2, 40));
    for (const auto& [name, scene] : scenes) {
        const RenderSettings settings = settings_of(scene);
        const int width = scene.renderer.width, height = scene.renderer.height;
        int rays_cast = 0, hits = 0, differ = 0;
        for (int count : {1, 7, 600}) {
            std::vector<std::optional<Sampler>> storage(static_cast<size_t>(count));
            std::vector<Sampler*> samplers(static_cast<size_t>(count));
            std::vector<int> xs(static_cast<size_t>(count)), ys(static_cast<size_t>(count));
            for (int k = 0; k < count; ++k) {
                xs[size_t(k)] = (k * 37 + count) % width, ys[size_t(k)] = (k * 101 + 3 * count) % height;
                const uint64_t pixel = uint64_t(ys[size_t(k)]) * uint64_t(width) + uint64_t(xs[size_t(k)]);
                samplers[size_t(k)] = &storage[size_t(k)].emplace(Estimator::sobol, 4, pixel, uint32_t(k % 5), 16);
            }
            std::vector<Ray> rays(static_cast<size_t>(count));
            camera_rays(scene, settings, width, height, xs.data(), ys.data(), samplers.data(), count, rays.data());
            std::vector<Hit> together(static_cast<size_t>(count));
            camera_hits(casting_kernels(scene, settings), scene, rays.data(), count, together.data());
            for (int k = 0; k < count; ++k) {
                Hit alone;
                const bool found = scene.intersects(rays[size_t(k)], alone);
                const Hit& h = together[size_t(k)];
                ++rays_cast;
                hits += found;
                if (h.sphere != alone.sphere) {
                    ++differ;
                    continue;
                }
                if (!found) continue;
                EXPECT_TRUE(close(h.t, alone.t, 1e-12)) << name << " ray " << k;
                for (int axis = 0; axis < 3; ++axis) {
                    EXPECT_TRUE(close(h.p[axis], alone.p[axis], 1e-12)) << name << " ray " << k;
                    EXPECT_TRUE(close(h.n[axis], alone.n[axis], 1e-12)) << name << " ray " << k;
                }
            }
        }
        EXPECT_GT(hits, rays_cast / 2) << name;
        EXPECT_LE(differ, rays_cast / 500) << name;
    }
}

// The feature buffers (render/aov.h), whose Sobol camera samples the float lanes make and cast
// themselves (camera_surfaces) and whose other kernels cast their camera rays' first hits
// (camera_hits), against the same buffers traced one path at a time: per pixel the same
// albedo and a normal within the float lanes' rounding, but for pixels where a grazing ray
// meets another sphere. Scenes 3 (glass and mirrors, followed one by one; also through a
// lens) and 8, and the 40-sphere scene (clusters or the lane tree).
TEST_P(Lanes, FeatureBuffersAreOneByOnes) {
    std::vector<std::pair<std::string, RenderScene>> scenes;
    for (int n : {3, 8}) scenes.emplace_back("scene " + std::to_string(n), brief_scene(n));
    scenes.emplace_back("scene 3, lens", brief_scene(3));
    scenes.back().second.camera.lens_radius = 0.2;
    scenes.emplace_back("40 spheres", many_spheres(40, 2, 40));
    for (const auto& [name, scene] : scenes) {
        RenderSettings lanes = settings_of(scene), one = lanes;
        one.kernels = LaneChoice::off;
        const int width = scene.renderer.width, height = scene.renderer.height;
        const SurfaceLayers a = averaged_surface_layers(scene, lanes, width, height, 3);
        const SurfaceLayers b = averaged_surface_layers(scene, one, width, height, 3);
        int differ = 0, lit = 0;
        for (size_t i = 0; i < a.albedo.size(); ++i) {
            lit += length(b.normal[i]) > 0;
            bool same = true;
            for (int axis = 0; axis < 3; ++axis)
                same &= close(a.albedo[i][axis], b.albedo[i][axis], 1e-9) &&
                        std::abs(a.normal[i][axis] - b.normal[i][axis]) <= 1e-5;
            differ += !same;
        }
        EXPECT_GT(lit, int(a.albedo.size()) / 2) << name;
        EXPECT_LE(differ, int(a.albedo.size()) / 200) << name;
    }
}

// Camera rays four at a time (Sobol samplers and a pinhole; otherwise one by one) against one
// by one: the same rays, and every sampler left where the one-by-one sampler is. Seven
// samples, so the last group is partial; scene 3 also through its thin lens.
TEST_P(Lanes, CameraRaysAreOneByOnes) {
    RenderScene scene = brief_scene(3);
    const int width = scene.renderer.width, height = scene.renderer.height;
    for (double lens_radius : {0.0, 0.2})
        for (Estimator estimator : {Estimator::sobol, Estimator::uniform}) {
            scene.camera.lens_radius = lens_radius;
            constexpr int kCount = 7;
            std::vector<std::optional<Sampler>> together(kCount), alone(kCount);
            std::vector<Sampler*> samplers(kCount);
            int xs[kCount], ys[kCount];
            for (int k = 0; k < kCount; ++k) {
                xs[k] = (k * 37) % width, ys[k] = (k * 101) % height;
                const uint64_t pixel = uint64_t(ys[k]) * uint64_t(width) + uint64_t(xs[k]);
                together[size_t(k)].emplace(estimator, 4, pixel, uint32_t(k), 16);
                alone[size_t(k)].emplace(estimator, 4, pixel, uint32_t(k), 16);
                samplers[size_t(k)] = &*together[size_t(k)];
            }
            Ray rays[kCount];
            camera_rays(scene, settings_of(scene), width, height, xs, ys, samplers.data(), kCount, rays);
            for (int k = 0; k < kCount; ++k) {
                Sampler& sampler = *alone[size_t(k)];
                const Ray one = camera_ray_one_by_one(scene, width, height, xs[k], ys[k], sampler);
                const std::string where = std::string(estimator_names.name(estimator)) + " lens " +
                                          std::to_string(lens_radius) + " sample " + std::to_string(k);
                for (int axis = 0; axis < 3; ++axis) {
                    EXPECT_TRUE(close(rays[k].o[axis], one.o[axis])) << where;
                    EXPECT_TRUE(close(rays[k].d[axis], one.d[axis])) << where;
                }
                EXPECT_EQ(rays[k].tmin, 0.0);
                EXPECT_EQ(together[size_t(k)]->next_1d(), sampler.next_1d()) << where;
            }
        }
}

// Sobol camera samples given as pixel keys and indices (trace_sobol_camera_samples, what
// render_pass hands the float lanes) are those trace_camera_samples gives for the samplers
// made from them, bit for bit: with each kernel, for a batch of one (made into a sampler and
// traced as one path), within a lane group, across chunks of kSampleBatch, through a pinhole
// and a thin lens. (CameraSamplesAreOneByOnes holds the samplers' entry to one path's
// samples.)
TEST_P(Lanes, SobolSamplesAsKeysAreSamplersSamples) {
    RenderScene scene = brief_scene(3);
    const int width = scene.renderer.width, height = scene.renderer.height;
    for (double lens_radius : {0.0, 0.2})
        for (int count : {1, 2, 17, kSampleBatch + 45}) {
            scene.camera.lens_radius = lens_radius;
            const RenderSettings settings = settings_of(scene);
            const size_t n = static_cast<size_t>(count);
            std::vector<uint32_t> keys(n), indices(n), reversed(n);
            std::vector<std::optional<Sampler>> made(n);
            std::vector<Sampler*> samplers(n);
            std::vector<int> xs(n), ys(n);
            for (size_t k = 0; k < n; ++k) {
                xs[k] = int(k * 37) % width, ys[k] = int(k * 101) % height;
                keys[k] = Sampler::pixel_key(9, uint64_t(ys[k]) * uint64_t(width) + uint64_t(xs[k]));
                indices[k] = uint32_t(k % 11), reversed[k] = reverse_bits(indices[k]);
                samplers[k] = &made[k].emplace(keys[k], indices[k], reversed[k]);
            }
            std::vector<SampleResult> from_keys(n), from_samplers(n);
            trace_sobol_camera_samples(lane_kernels(scene, settings), scene, settings, width, height, xs.data(),
                                       ys.data(), keys.data(), reversed.data(), count, from_keys.data());
            trace_camera_samples(scene, settings, width, height, xs.data(), ys.data(), samplers.data(), count,
                                 from_samplers.data());
            int differ = 0;
            for (size_t k = 0; k < n; ++k) {
                const SampleResult &a = from_keys[k], &b = from_samplers[k];
                differ += !(a.radiance.x == b.radiance.x && a.radiance.y == b.radiance.y &&
                            a.radiance.z == b.radiance.z && a.primary_distance == b.primary_distance &&
                            a.rays == b.rays);
            }
            EXPECT_EQ(differ, 0) << count << " samples, lens " << lens_radius;
        }
}

// Camera samples traced from pixel positions (trace_camera_samples: with Sobol samplers and a
// pinhole, the single-precision lanes make the camera rays themselves) against camera_ray and
// trace_sample one by one: counts below, at and above a lane group and a batch, and the thin
// lens, which always takes camera_rays' rays.
TEST_P(Lanes, CameraSamplesAreOneByOnes) {
    RenderScene scene = brief_scene(3);
    const int width = scene.renderer.width, height = scene.renderer.height;
    for (double lens_radius : {0.0, 0.2})
        for (Estimator estimator : {Estimator::sobol, Estimator::uniform})
            for (int count : {1, 3, 9, 64, 130}) {
                scene.camera.lens_radius = lens_radius;
                RenderSettings settings = settings_of(scene);
                settings.estimator = estimator;
                const double tolerance = lane_tolerance(scene, settings);
                const size_t n = static_cast<size_t>(count);
                std::vector<std::optional<Sampler>> together(n), alone(n);
                std::vector<Sampler*> samplers(n);
                std::vector<int> xs(n), ys(n);
                for (int k = 0; k < count; ++k) {
                    xs[size_t(k)] = (k * 37) % width, ys[size_t(k)] = (k * 101) % height;
                    const uint64_t pixel = uint64_t(ys[size_t(k)]) * uint64_t(width) + uint64_t(xs[size_t(k)]);
                    together[size_t(k)].emplace(estimator, 4, pixel, uint32_t(k % 7), 16);
                    alone[size_t(k)].emplace(estimator, 4, pixel, uint32_t(k % 7), 16);
                    samplers[size_t(k)] = &*together[size_t(k)];
                }
                std::vector<SampleResult> results(n);
                trace_camera_samples(scene, settings, width, height, xs.data(), ys.data(), samplers.data(), count,
                                     results.data());
                int mismatches = 0;
                for (int k = 0; k < count; ++k) {
                    Sampler& sampler = *alone[size_t(k)];
                    const Ray ray = camera_ray_one_by_one(scene, width, height, xs[size_t(k)], ys[size_t(k)], sampler);
                    const SampleResult one = trace_sample(scene, settings, ray, sampler);
                    const SampleResult& r = results[size_t(k)];
                    mismatches += !(close(r.radiance.x, one.radiance.x, tolerance) &&
                                    close(r.radiance.y, one.radiance.y, tolerance) &&
                                    close(r.radiance.z, one.radiance.z, tolerance) && r.rays == one.rays &&
                                    close(r.primary_distance, one.primary_distance, tolerance));
                }
                EXPECT_LE(mismatches, count / 100) << estimator_names.name(estimator) << " lens " << lens_radius
                                                   << ", " << count << " samples";
            }
}

