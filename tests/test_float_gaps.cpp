// Surfaces closer than float rounding (render/precision.h): the single-precision lanes take a
// scene only where their rounding resolves its gaps. Hostile scenes are generated on both
// sides of every threshold (the hit tolerance between surfaces, the shadow end tolerance
// around lights, the share of a sphere's area allowed near another): every kernel must then
// render one path's image (a statistical test against one path at another seed), with no
// NaN sample, and the brief's scenes keep the float lanes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "core/image_compare.h"
#include "core/rng.h"
#include "render/outputs.h"
#include "render/precision.h"
#include "render/progressive.h"
#include "render/trace.h"
#include "scene/load.h"
#include "test_util.h"

using namespace kr;

namespace {

constexpr double kEps = std::numeric_limits<float>::epsilon();
double l1(const Vec3& v) { return std::abs(v.x) + std::abs(v.y) + std::abs(v.z); }

// The fraction by sampling: uniform points on A, those within `tolerance` of B's surface.
double sampled_fraction(const SphereGeom& a, const SphereGeom& b, double tolerance, int n, Rng& rng) {
    int near = 0;
    for (int k = 0; k < n; ++k) {
        const double z = 1 - 2 * rng.next(), phi = 2 * kPi * rng.next();
        const double s = std::sqrt(std::max(0.0, 1 - z * z));
        const Vec3 p = a.centre + Vec3(s * std::cos(phi), s * std::sin(phi), z) * a.radius;
        near += std::abs(length(p - b.centre) - b.radius) <= tolerance;
    }
    return double(near) / n;
}

TEST(FloatGaps, NearSurfaceFractionIsTheSampledOne) {
    Rng rng(7, 1);
    const SphereGeom unit{{0, 0, 0}, 1};
    // Concentric shells: all or nothing.
    EXPECT_EQ(near_surface_fraction(unit, {{0, 0, 0}, 1 + 1e-6}, 1e-5), 1.0);
    EXPECT_EQ(near_surface_fraction(unit, {{0, 0, 0}, 1 + 1e-4}, 1e-5), 0.0);
    EXPECT_EQ(near_surface_fraction(unit, {{5, 0, 0}, 1}, 1e-3), 0.0);  // far apart
    // Touching outside, nested and off centre, crossing, a tiny sphere beside a large one:
    // the exact fraction within 5 binomial standard errors of 200,000 sampled points.
    const std::vector<std::pair<SphereGeom, double>> cases = {
        {{{2.001, 0, 0}, 1}, 0.05},     {{{0.3, 0.2, 0}, 1.5}, 0.2}, {{{1.2, 0, 0.5}, 1}, 0.02},
        {{{0, 30, 0}, 29.0}, 0.2},      {{{0.05, 0, 0}, 1.04}, 0.03}};
    for (const auto& [b, tolerance] : cases) {
        const double exact = near_surface_fraction(unit, b, tolerance);
        const double sampled = sampled_fraction(unit, b, tolerance, 200000, rng);
        const double se = std::sqrt(std::max(exact * (1 - exact), 1e-6) / 200000);
        EXPECT_NEAR(sampled, exact, 5 * se) << b.centre.x << " " << b.radius;
        EXPECT_GT(exact, 0.001);
        // and from B's side
        const double exact_b = near_surface_fraction(b, unit, tolerance);
        EXPECT_NEAR(sampled_fraction(b, unit, tolerance, 200000, rng), exact_b,
                    5 * std::sqrt(std::max(exact_b * (1 - exact_b), 1e-6) / 200000));
    }
}

TEST(FloatGaps, BriefAndExampleScenesKeepTheFloatLanes) {
    std::vector<std::filesystem::path> files;
    for (int n = 1; n <= 8; ++n) files.push_back(test::brief_scene_file(n));
    for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(KEITHRAY_RES_DIR) / "scenes/examples"))
        if (entry.path().extension() == ".json") files.push_back(entry.path());
    for (const auto& file : files) {
        const RenderScene scene = prepare_scene(load_scene_file(file).scene);
        EXPECT_TRUE(scene.float_gaps_resolved) << file.filename();
    }
    for (int n = 1; n <= 8; ++n) EXPECT_TRUE(float_lanes_fit(prepare_scene(load_scene_file(files[size_t(n - 1)]).scene))) << n;
}

// Spheres whose grid cells no integer counts (a ball 1e30 away beside unit ones) are paired
// with every other: a shell there is still found, and spheres far apart still pass.
TEST(FloatGaps, FarSpheresAreStillPaired) {
    for (double far : {1e20, 1e30, -1e300}) {
        test::SceneBuilder b;
        const int grey = b.material(MaterialType::diffuse, Color(0.8));
        b.sphere({0, 0, 0}, 1, grey);
        b.sphere({0, 2, 0}, 0.5, grey);
        b.sphere({far, 0, 0}, 1, grey);
        RenderScene scene = b.build();
        EXPECT_TRUE(float_resolves_gaps(scene)) << far;
        scene.spheres.push_back({{far, 0, 0}, 1 + 1e-9 * std::abs(far)});  // a shell around it
        EXPECT_FALSE(float_resolves_gaps(scene)) << far;
    }
}

// The hostile configurations, in a closed room lit by a lamp, around a unit sphere at c.
enum class Hostile { point_inside_ball, point_outside_ball, lamp_in_shell, lamp_in_glass, glass_in_glass, ball_in_glass };
const char* name(Hostile h) {
    static const char* names[] = {"point light inside a ball", "point light outside a ball", "lamp in an opaque shell",
                                  "lamp in a glass shell", "glass ball in a glass shell", "diffuse ball in a glass shell"};
    return names[int(h)];
}
const Vec3 kCentre{0.3, -2.0, 0.2};

test::SceneBuilder room() {
    test::SceneBuilder b;
    b.scene.cameras[0].position = {0, 0, -15};
    b.scene.renderer.width = b.scene.renderer.height = 24;
    const int grey = b.material(MaterialType::diffuse, Color(0.8));
    // Walls of radius 50 (the shadow end tolerance grows with the scene's extent: with the
    // brief's walls of 500 a touching lamp's near share could not fall below the limit).
    for (const Vec3 wall : {Vec3(-55, 0, 0), Vec3(55, 0, 0), Vec3(0, 0, 55), Vec3(0, 55, 0), Vec3(0, -55, 0)})
        b.sphere(wall, 50, grey);
    b.emitter({0, 3, 0}, 0.8, Color(10), b.material(MaterialType::diffuse, Color(1)));
    return b;
}

// `hostile` at `gap` (the sphere's or the light's distance from the shell or surface), the
// shell's centre moved by `offset` along x.
RenderScene hostile_scene(Hostile hostile, double gap, double offset = 0) {
    test::SceneBuilder b = room();
    const int grey = b.material(MaterialType::diffuse, Color(0.8));
    const int glass = b.material(MaterialType::dielectric, Color(1));
    b.scene.materials[size_t(glass)].rho_r = b.scene.materials[size_t(glass)].rho_t = Color(1);
    const Vec3 shell_centre = kCentre + Vec3(offset, 0, 0);
    switch (hostile) {
    case Hostile::point_inside_ball:
        b.sphere(kCentre, 1, grey);
        b.point_light(kCentre + Vec3(1 - gap, 0, 0), Color(50));
        break;
    case Hostile::point_outside_ball:
        b.sphere(kCentre, 1, grey);
        b.point_light(kCentre + Vec3(1 + gap, 0, 0), Color(50));
        break;
    case Hostile::lamp_in_shell:
    case Hostile::lamp_in_glass:
        b.emitter(kCentre, 1, Color(20), b.material(MaterialType::diffuse, Color(1)));
        b.sphere(shell_centre, 1 + gap + offset, hostile == Hostile::lamp_in_shell ? grey : glass);
        break;
    case Hostile::glass_in_glass:
    case Hostile::ball_in_glass:
        b.sphere(kCentre, 1, hostile == Hostile::glass_in_glass ? glass : b.material(MaterialType::diffuse, Color(0.9, 0.2, 0.1)));
        b.sphere(shell_centre, 1 + gap + offset, glass);
        break;
    }
    return b.build();
}

// The largest 1-norm a ray meets in the room (the walls' far sides), as precision.cpp bounds it.
double room_extent() { return 55 + std::sqrt(3.0) * 50; }
// The gap at which each configuration's tolerance lies: the shadow end tolerance where a
// light is concerned, else the hit tolerance of the two unit-sized spheres.
double threshold(Hostile hostile) {
    switch (hostile) {
    case Hostile::point_inside_ball:
    case Hostile::point_outside_ball:
    case Hostile::lamp_in_shell:
    case Hostile::lamp_in_glass: return kFloatShadowEndUlps * kEps * (3 * room_extent() + l1(kCentre));
    default: return kFloatHitUlps * kEps * 2 * (l1(kCentre) + 1);
    }
}
const std::vector<Hostile> kAllHostile = {Hostile::point_inside_ball, Hostile::point_outside_ball,
                                          Hostile::lamp_in_shell,     Hostile::lamp_in_glass,
                                          Hostile::glass_in_glass,    Hostile::ball_in_glass};

// The shell's offset at which the inner sphere's share near the touching shell is `fraction`.
double offset_for_fraction(Hostile hostile, double fraction) {
    double lo = 1e-9, hi = 2;  // the share falls as the offset grows
    for (int k = 0; k < 100; ++k) {
        const double mid = std::sqrt(lo * hi);
        const SphereGeom inner{kCentre, 1}, shell{kCentre + Vec3(mid, 0, 0), 1 + mid};
        const double tolerance = hostile == Hostile::lamp_in_shell || hostile == Hostile::lamp_in_glass
                                     ? kFloatShadowEndUlps * kEps * (3 * room_extent() + l1(shell.centre))
                                     : kFloatHitUlps * kEps * (l1(inner.centre) + 1 + l1(shell.centre) + shell.radius);
        (near_surface_fraction(inner, shell, tolerance) > fraction ? lo : hi) = mid;
    }
    EXPECT_LT(hi, 2) << "no offset within the room gives the share " << fraction;
    return hi;
}

TEST(FloatGaps, TheFloatLanesTakeHostileScenesOnlyBeyondEachThreshold) {
    for (Hostile hostile : kAllHostile) {
        const double t = threshold(hostile);
        EXPECT_TRUE(float_lanes_fit(hostile_scene(hostile, 2 * t))) << name(hostile) << " at twice " << t;
        EXPECT_FALSE(float_lanes_fit(hostile_scene(hostile, t / 2))) << name(hostile) << " at half " << t;
        EXPECT_FALSE(float_lanes_fit(hostile_scene(hostile, 1e-5 * t))) << name(hostile);
    }
    // A point light on a surface, as double precision sees it, is on it for both.
    EXPECT_TRUE(float_lanes_fit(hostile_scene(Hostile::point_inside_ball, 0)));
    // Shells touching their inner sphere: near it on a share of its area below the limit,
    // or above it.
    for (Hostile hostile : {Hostile::lamp_in_glass, Hostile::glass_in_glass}) {
        EXPECT_TRUE(float_lanes_fit(hostile_scene(hostile, 0, offset_for_fraction(hostile, kFloatNearFraction / 2))))
            << name(hostile);
        EXPECT_FALSE(float_lanes_fit(hostile_scene(hostile, 0, offset_for_fraction(hostile, kFloatNearFraction * 2))))
            << name(hostile);
    }
}

// The viewer prepares a scene again after each edit, keeping the gap check where the spheres
// and lights stayed: each edit's answer is a fresh preparation's.
TEST(FloatGaps, AnEditsPreparedSceneChecksTheGapsAsAFreshOne) {
    test::SceneBuilder b = room();
    const int grey = b.material(MaterialType::diffuse, Color(0.8));
    b.sphere(kCentre, 1, grey);
    b.point_light(kCentre + Vec3(2, 0, 0), Color(50));
    const RenderScene before = b.build();
    ASSERT_TRUE(before.float_gaps_resolved);
    Light& light = b.scene.lights.back();
    const auto check = [&](const char* edit) {
        const RenderScene edited = prepare_scene(b.scene, nullptr, &before);
        EXPECT_EQ(edited.float_gaps_resolved, b.build().float_gaps_resolved) << edit;
        return edited.float_gaps_resolved;
    };
    b.scene.cameras[0].position = {1, 0, -14};
    EXPECT_TRUE(check("camera moved"));
    light.position = kCentre + Vec3(1 - threshold(Hostile::point_inside_ball) / 2, 0, 0);
    EXPECT_FALSE(check("point light moved just inside the ball"));
    light.power = Color(0);
    EXPECT_TRUE(check("that light made black"));
}

// A render's radiance with its variance layer, and its count of non-finite samples.
HdrImage render(const RenderScene& scene, LaneChoice kernels, uint64_t seed, int passes, uint64_t& nonfinite) {
    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    settings.kernels = kernels;
    settings.seed = seed;
    settings.allocation = Allocation::uniform;
    RenderState state(scene.renderer.width, scene.renderer.height);
    StopRule rule;
    rule.max_passes = passes;
    render_until(scene, settings, state, rule);
    nonfinite = state.nonfinite_samples;
    DevelopOptions options;
    options.sampling = settings;
    const unsigned layers = kLayerRadiance | kLayerVariance | kLayerSamples;
    return hdr_from_developed(develop(scene, render_estimates(state, layers), options, layers));
}

TEST(FloatGaps, EveryKernelRendersHostileScenesAsOnePath) {
    std::vector<std::pair<RenderScene, std::string>> scenes;
    for (Hostile hostile : kAllHostile) {
        const double t = threshold(hostile);
        for (double gap : {2 * t, t / 2, 1e-5 * t}) {
            char what[96];
            std::snprintf(what, sizeof what, "%s at gap %.3g", name(hostile), gap);
            scenes.emplace_back(hostile_scene(hostile, gap), what);
        }
    }
    for (Hostile hostile : {Hostile::lamp_in_glass, Hostile::glass_in_glass})
        scenes.emplace_back(hostile_scene(hostile, 0, offset_for_fraction(hostile, kFloatNearFraction / 2)),
                            std::string(name(hostile)) + " touching, near on half the allowed share");
    const int passes = 48;
    for (const auto& [scene, what] : scenes) {
        uint64_t nonfinite = 0;
        const HdrImage one_path = render(scene, LaneChoice::off, 1, passes, nonfinite);
        EXPECT_EQ(nonfinite, 0u) << what;
        for (LaneChoice kernels : {LaneChoice::best, LaneChoice::float8, LaneChoice::double_lanes, LaneChoice::any}) {
            const HdrImage lanes = render(scene, kernels, 2, passes, nonfinite);
            EXPECT_EQ(nonfinite, 0u) << what << ", " << lane_choice_names.name(kernels);
            const StatisticalResult r = statistical_compare(lanes, "lanes", one_path, "one path", {});
            EXPECT_TRUE(r.agree) << what << ", " << lane_choice_names.name(kernels) << ": max |z| " << r.max_abs_z
                                 << " (limit " << r.z_limit << "), chi2 " << r.chi_square << " (limit "
                                 << r.chi_square_limit << ")";
        }
    }
}

// The size rule sphere by sphere (float_sizes_fit): a floor of radius 1000, its far side
// 2,001.5 from the origin, beside balls of radius 0.4, so the scene spans 5,000 smallest radii
// (the global rule's limit is 4,096); but from a camera 1.5 above the floor rays reach it
// only within about 110 of the origin. The float lanes take it, and render one path's image
// (at another seed). A glass floor (rays cross it to its far side), a camera inside the
// floor, or one 1,000 above it (its tangent to the floor 1,734 long) keep the double lanes.
RenderScene far_floor_scene(MaterialType floor_type, const Vec3& camera) {
    test::SceneBuilder b;
    b.scene.renderer.width = b.scene.renderer.height = 16;
    b.scene.cameras[0].position = camera;
    const int grey = b.material(MaterialType::diffuse, Color(0.7));
    b.sphere({0, -1001.5, 0}, 1000, b.material(floor_type, Color(0.7)));
    for (int i = 0; i < 6; ++i) b.sphere({-2.5 + i, -1.0 + 0.3 * i, 0.5 * (i % 2)}, 0.4, grey);
    b.emitter({0, 3, 0}, 0.5, Color(5), grey);
    return b.build();
}

TEST(FloatGaps, SizesAreJudgedWhereRaysReach) {
    const RenderScene scene = far_floor_scene(MaterialType::diffuse, {0, 0, -10});
    double largest = 0, smallest = kInfinity;
    for (const SphereGeom& s : scene.spheres) {
        largest = std::max(largest, length(s.centre) + s.radius);
        smallest = std::min(smallest, s.radius);
    }
    EXPECT_GT(largest, kFloatSizeRatio * smallest);  // beyond the global rule
    EXPECT_TRUE(float_reach_fits(scene));
    EXPECT_TRUE(float_lanes_fit(scene));
    EXPECT_FALSE(float_lanes_fit(far_floor_scene(MaterialType::dielectric, {0, 0, -10})));
    EXPECT_FALSE(float_lanes_fit(far_floor_scene(MaterialType::diffuse, {0, -10, -10})));
    EXPECT_FALSE(float_lanes_fit(far_floor_scene(MaterialType::diffuse, {0, 1000, -10})));

    const int passes = 48;
    uint64_t nonfinite = 0;
    const HdrImage one_path = render(scene, LaneChoice::off, 1, passes, nonfinite);
    EXPECT_EQ(nonfinite, 0u);
    for (LaneChoice kernels : {LaneChoice::best, LaneChoice::float8}) {
        const HdrImage lanes = render(scene, kernels, 2, passes, nonfinite);
        EXPECT_EQ(nonfinite, 0u) << lane_choice_names.name(kernels);
        const StatisticalResult r = statistical_compare(lanes, "lanes", one_path, "one path", {});
        EXPECT_TRUE(r.agree) << lane_choice_names.name(kernels) << ": max |z| " << r.max_abs_z << " (limit "
                             << r.z_limit << "), chi2 " << r.chi_square << " (limit " << r.chi_square_limit << ")";
    }
}

}  // namespace
