// The BVH with four-wide sphere blocks against the plain linear scan: same hits at every
// scale and size, for every kind of ray the integrators cast (shadow segments ending short
// of, on and past a surface included), and the same images.
#include <gtest/gtest.h>

#include <cmath>

#include "core/image.h"
#include "core/sampling.h"
#include "render/progressive.h"
#include "render/trace.h"
#include "scene/load.h"
#include "test_util.h"

using namespace kr;

namespace {

// n random spheres with radii spread over two decades, in a cube of side `scale`, inside a
// wall sphere of radius 50 * scale when `walls` is set.
RenderScene random_spheres(int n, double scale, uint64_t seed, bool walls) {
    test::SceneBuilder b;
    const int m = b.material(MaterialType::diffuse);
    Rng rng(seed, 3);
    for (int i = 0; i < n; ++i) {
        const Vec3 c{scale * (rng.next() - 0.5), scale * (rng.next() - 0.5), scale * (rng.next() - 0.5)};
        const double r = scale * 0.2 / std::cbrt(double(n)) * std::pow(10.0, -rng.next());
        b.sphere(c, r, m);
    }
    if (walls) b.sphere({0, 0, 0}, 50 * scale, m);
    return b.build();
}

Vec3 random_direction(Rng& rng) { return sample_uniform_sphere(rng.next(), rng.next()); }

struct Agreement {
    int rays = 0, hits = 0, mismatches = 0;
};

// Casts camera-like, surface-leaving and shadow rays; compares BVH and linear answers.
Agreement compare(const RenderScene& scene, double scale, uint64_t seed, int count) {
    Agreement a;
    Rng rng(seed, 9);
    for (int i = 0; i < count; ++i) {
        // A camera far outside the spheres, aimed at one of them (Embree's float ray starts
        // nearer: accel_embree.cpp), its aim off by up to twice the radius.
        {
            const SphereGeom& target = scene.spheres[size_t(rng.next() * double(scene.spheres.size()))];
            Ray far;
            far.o = random_direction(rng) * (1e3 * scale);
            far.d = normalize(target.centre + random_direction(rng) * (2 * target.radius * rng.next()) - far.o);
            Hit lin, fast;
            const bool hit_lin = scene.intersects_linear(far, lin), hit_fast = scene.intersects(far, fast);
            ++a.rays;
            if (hit_lin != hit_fast || (hit_lin && lin.sphere != fast.sphere)) ++a.mismatches;
        }
        Ray ray;
        ray.o = Vec3{rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5} * (2 * scale);
        ray.d = random_direction(rng);
        Hit lin, fast;
        const bool hit_lin = scene.intersects_linear(ray, lin);
        const bool hit_fast = scene.intersects(ray, fast);
        ++a.rays;
        if (hit_lin != hit_fast || (hit_lin && (lin.sphere != fast.sphere || std::abs(lin.t - fast.t) > 1e-12 * (lin.t + scale)))) {
            ++a.mismatches;
            continue;
        }
        if (scene.is_occluded_linear(ray) != scene.is_occluded(ray)) ++a.mismatches;
        if (!hit_lin) continue;
        ++a.hits;
        // From the hit: a bounce out of or into the sphere, and a shadow ray to a random point.
        Ray bounce;
        bounce.o = lin.p;
        bounce.d = random_direction(rng);
        bounce.from_sphere = lin.sphere;
        bounce.into_from_sphere = dot(bounce.d, lin.n) < 0;
        Hit b_lin, b_fast;
        const bool bh_lin = scene.intersects_linear(bounce, b_lin), bh_fast = scene.intersects(bounce, b_fast);
        ++a.rays;
        if (bh_lin != bh_fast || (bh_lin && b_lin.sphere != b_fast.sphere)) ++a.mismatches;
        if (bh_lin) {
            Ray shadow = bounce;
            shadow.tmax = b_lin.t;
            shadow.to_sphere = b_lin.sphere;
            ++a.rays;
            if (scene.is_occluded_linear(shadow) != scene.is_occluded(shadow)) ++a.mismatches;
            // Segments ending at a random point, and a hair before and after the next
            // surface, with no target sphere: the any-hit query culls spheres that start
            // beyond a segment's end before taking a square root.
            for (double end : {rng.next(), 1 - 1e-9, 1 + 1e-9}) {
                Ray partial = bounce;
                partial.tmax = end * b_lin.t;
                ++a.rays;
                if (scene.is_occluded_linear(partial) != scene.is_occluded(partial)) ++a.mismatches;
            }
        }
    }
    return a;
}

// The BVHs this build has: ours, and Embree's where CMake found it.
std::vector<AccelBackend> backends() {
    if (embree_available()) return {AccelBackend::own, AccelBackend::embree};
    return {AccelBackend::own};
}

RenderScene with_backend(RenderScene scene, AccelBackend backend) {
    scene.accel_backend = backend;
    scene.build_accel();
    return scene;
}

}  // namespace

TEST(Accel, AgreesWithLinearScanAtAllScalesAndSizes) {
    for (AccelBackend backend : backends())
        for (int n : {1, 3, 4, 5, 8, 17, 200, 3000})
            for (double scale : {1e-4, 1.0, 1e4})
                for (bool walls : {false, true}) {
                    const RenderScene scene = with_backend(random_spheres(n, scale, 11 + n, walls), backend);
                    ASSERT_EQ(scene.bvh.backend(), backend);
                    const Agreement a = compare(scene, scale, 5 + n, 3000);
                    const std::string where = std::string(accel_backend_names.name(backend)) + ", " +
                                              std::to_string(n) + " spheres at scale " + std::to_string(scale) +
                                              (walls ? " in a wall" : "");
                    EXPECT_GT(a.hits, 0) << where;
                    if (walls) EXPECT_GE(a.hits, 3000 - a.mismatches) << where;  // inside the wall every ray hits
                    // Rounding may differ in the last bit (FMA in the AVX2 path) on a grazing ray.
                    EXPECT_LE(a.mismatches, a.rays / 2000) << where;
                }
}

// Embree's float traversal must never cull a sphere the double test hits: the rays of the
// test above, and exactly the same answers as the plain path (both run accepted_root).
TEST(Accel, EmbreeGivesExactlyThePlainPathsHits) {
    if (!embree_available()) GTEST_SKIP() << "built without Embree";
    for (double scale : {1e-4, 1.0, 1e4}) {
        const RenderScene scene = with_backend(random_spheres(500, scale, 21, true), AccelBackend::embree);
        EXPECT_EQ(compare(scene, scale, 8, 3000).mismatches, 0) << "scale " << scale;
    }
    // The hardest rays for a float traversal: from far away, grazing a sphere where it
    // touches its box (a millionth of the radius inside the extreme point of an axis), so
    // that the rounding of the float ray alone moves many out of the box.
    for (double scale : {1e-4, 1.0, 1e4}) {
        const RenderScene scene = with_backend(random_spheres(200, scale, 23, false), AccelBackend::embree);
        Rng rng(31, 2);
        int rays = 0, mismatches = 0, hits = 0;
        for (size_t i = 0; i < scene.spheres.size(); ++i)
            for (int axis = 0; axis < 3; ++axis)
                for (double side : {-1.0, 1.0}) {
                    const SphereGeom& s = scene.spheres[i];
                    Vec3 e;
                    (axis == 0 ? e.x : axis == 1 ? e.y : e.z) = side;
                    const Vec3 grazed = s.centre + e * (s.radius * (1 - 1e-6));
                    // A direction across the axis, tilted by up to a millionth, from a
                    // million times the scene's size away: a naive float slab test misses
                    // the box for about 40 % of these rays.
                    Vec3 d = random_direction(rng);
                    d = normalize(d - dot(d, e) * e + e * (2e-6 * rng.next() - 1e-6));
                    Ray ray;
                    ray.o = grazed - d * (1e6 * scale * (1 + rng.next()));
                    ray.d = d;
                    Hit lin, fast;
                    const bool hit_lin = scene.intersects_linear(ray, lin), hit_fast = scene.intersects(ray, fast);
                    ++rays;
                    hits += hit_lin;
                    mismatches += hit_lin != hit_fast || (hit_lin && (lin.sphere != fast.sphere || lin.t != fast.t));
                }
        EXPECT_EQ(hits, rays) << "scale " << scale;  // each ray at least grazes its sphere
        EXPECT_EQ(mismatches, 0) << "of " << rays << " grazing rays at scale " << scale;
    }
}

TEST(Accel, AutomaticChoiceBySphereCount) {
    EXPECT_EQ(random_spheres(16, 1.0, 5, true).bvh.backend(), AccelBackend::own);  // 17 with the wall
    EXPECT_EQ(random_spheres(31, 1.0, 5, true).bvh.backend(), AccelBackend::own);
    EXPECT_EQ(random_spheres(32, 1.0, 5, true).bvh.backend(),
              embree_available() ? AccelBackend::embree : AccelBackend::own);
    // The brief's scenes are small: always our own one-leaf blocks.
    for (int n = 1; n <= 8; ++n) {
        const RenderScene scene = prepare_scene(
            load_scene_file(test::brief_scene_file(n)).scene);
        EXPECT_EQ(scene.bvh.backend(), AccelBackend::own) << "scene " << n;
    }
    // Spheres beyond single precision's range: our tree, which works in double throughout.
    const RenderScene huge = random_spheres(40, 1e37, 5, false);
    EXPECT_EQ(huge.bvh.backend(), AccelBackend::own);
    EXPECT_EQ(compare(huge, 1e37, 3, 300).mismatches, 0);
    if (!embree_available()) {
        RenderScene scene = random_spheres(40, 1.0, 5, false);
        scene.accel_backend = AccelBackend::embree;
        EXPECT_THROW(scene.build_accel(), std::runtime_error);
    }
}

TEST(Accel, LargeSceneBuildsShallowTree) {
    const RenderScene scene = with_backend(random_spheres(100000, 1.0, 3, true), AccelBackend::own);
    EXPECT_LE(scene.bvh.depth(), 60);
    EXPECT_GE(scene.bvh.depth(), 10);  // it did split
    EXPECT_EQ(scene.bvh.block_count() * 4 >= scene.spheres.size(), true);
    const Agreement a = compare(scene, 1.0, 77, 300);
    EXPECT_LE(a.mismatches, a.rays / 2000);
}

// Rays along the axes, their other components +0 or -0 (a slab's reciprocal +inf or -inf:
// the tree takes its near plane by that sign), from inside and outside the spheres' cube and
// from exactly on a box's plane: the tree's hits are the linear scan's.
TEST(Accel, AxisRaysWithSignedZerosThroughTheTree) {
    for (AccelBackend backend : backends()) {
        const RenderScene scene = with_backend(random_spheres(300, 1.0, 21, false), backend);
        Rng rng(4, 2);
        int rays = 0, hits = 0, mismatches = 0;
        for (int i = 0; i < 400; ++i) {
            const SphereGeom& s = scene.spheres[size_t(rng.next() * double(scene.spheres.size()))];
            for (int axis = 0; axis < 3; ++axis)
                for (double sign : {1.0, -1.0})
                    for (double zero : {0.0, -0.0}) {
                        Ray ray;
                        double o[3] = {s.centre.x, s.centre.y, s.centre.z}, d[3] = {zero, zero, zero};
                        // Through the sphere, or on its box's plane (lo or hi) and clear of it.
                        const int other = (axis + 1) % 3, third = (axis + 2) % 3;
                        o[other] += (i % 3 == 0) ? s.radius * (rng.next() - 0.5) : (i % 3 == 1 ? -s.radius : s.radius);
                        if (i % 3 != 0) o[third] += 0.5 * s.radius;
                        o[axis] -= sign * (i % 2 ? 3.0 : 0.0);
                        d[axis] = sign;
                        ray.o = {o[0], o[1], o[2]};
                        ray.d = {d[0], d[1], d[2]};
                        Hit lin, fast;
                        const bool hit_lin = scene.intersects_linear(ray, lin), hit_fast = scene.intersects(ray, fast);
                        ++rays;
                        hits += hit_lin;
                        if (hit_lin != hit_fast || (hit_lin && (lin.sphere != fast.sphere || std::abs(lin.t - fast.t) > 1e-12 * (lin.t + 1))) ||
                            scene.is_occluded_linear(ray) != scene.is_occluded(ray))
                            ++mismatches;
                    }
        }
        EXPECT_GT(hits, rays / 4) << accel_backend_names.name(backend);
        EXPECT_EQ(mismatches, 0) << accel_backend_names.name(backend);
    }
}

// Up to 16 spheres are one leaf of four blocks, tested without box tests: for the brief's
// rooms of wall spheres, whose huge boxes every ray enters, a tree cost 40% more instructions.
TEST(Accel, SmallScenesAreOneLeaf) {
    const RenderScene sixteen = random_spheres(15, 1.0, 5, true);
    EXPECT_EQ(sixteen.bvh.node_count(), 1u);
    EXPECT_EQ(sixteen.bvh.block_count(), 4u);
    const RenderScene seventeen = with_backend(random_spheres(16, 1.0, 5, true), AccelBackend::own);
    EXPECT_GT(seventeen.bvh.node_count(), 1u);
    const RenderScene room =
        prepare_scene(load_scene_file(std::string(KEITHRAY_RES_DIR) + "/scenes/assignment_06.json").scene);
    EXPECT_EQ(room.spheres.size(), 10u);
    EXPECT_EQ(room.bvh.node_count(), 1u);
}

// The float lanes' scan of up to kLaneScanMaxSpheres (LaneTree::clusters): every sphere once,
// the wall (a box spanning the scene) first and alone, the others in clusters of up to eight
// whose padded boxes hold them.
TEST(Accel, LaneClustersHoldEverySphereOnce) {
    const RenderScene scene = with_backend(random_spheres(60, 1.0, 7, true), AccelBackend::own);
    const LaneTree& tree = scene.bvh.lane_tree();
    ASSERT_FALSE(tree.clusters.empty());
    ASSERT_EQ(tree.scan_f.size(), scene.spheres.size());
    std::vector<int> seen(scene.spheres.size(), 0);
    for (const LaneSphere<float>& s : tree.scan_f) ++seen[size_t(s.id)];
    for (size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], 1) << "sphere " << i;
    const LaneCluster& first = tree.clusters.front();
    EXPECT_EQ(first.count, 1);
    EXPECT_FALSE(first.boxed);
    EXPECT_EQ(tree.scan_f[first.first].id, 60);  // the wall
    uint32_t next = 0;
    size_t boxed = 0;
    for (const LaneCluster& c : tree.clusters) {
        EXPECT_EQ(c.first, next);  // in order, without gaps
        next += c.count;
        EXPECT_GE(c.count, 1);
        EXPECT_LE(c.count, 8);
        EXPECT_EQ(c.boxed, c.count > 1);
        if (!c.boxed) continue;
        ++boxed;
        for (uint32_t k = c.first; k < c.first + c.count; ++k) {
            const SphereGeom& s = scene.spheres[size_t(tree.scan_f[k].id)];
            const double centre[3] = {s.centre.x, s.centre.y, s.centre.z};
            for (int a = 0; a < 3; ++a) {
                EXPECT_LT(double(c.lo[a]), centre[a] - s.radius);
                EXPECT_GT(double(c.hi[a]), centre[a] + s.radius);
            }
        }
    }
    EXPECT_EQ(next, scene.spheres.size());
    EXPECT_GE(boxed, 60u / 8);
    // Every lane tree of own's is scanned, on every kind of CPU (lane_tree_limits().own
    // spheres, the wall one of them); above it there is none: one path at a time down our tree.
    const size_t own = lane_tree_limits().own;
    for (const CpuModel cpu : {CpuModel{false, 6}, CpuModel{true, 25}, CpuModel{true, 26}, CpuModel{}}) {
        const LaneTreeLimits limits = lane_tree_limits(cpu);
        EXPECT_LE(limits.beside_embree, limits.own);
        EXPECT_LE(limits.own, kLaneScanMaxSpheres);
    }
    const RenderScene most = with_backend(random_spheres(int(own) - 1, 1.0, 7, true), AccelBackend::own);
    EXPECT_FALSE(most.bvh.lane_tree().nodes.empty());
    EXPECT_EQ(most.bvh.lane_tree().scan_f.size(), most.spheres.size());
    const RenderScene many = with_backend(random_spheres(int(own) + 8, 1.0, 7, true), AccelBackend::own);
    EXPECT_TRUE(many.bvh.lane_tree().nodes.empty());
    EXPECT_TRUE(many.bvh.lane_tree().clusters.empty());
    EXPECT_FALSE(many.bvh.lanes_cast());
    // Beside Embree's tree (automatic), up to this CPU's other limit.
    if (embree_available()) {
        const size_t beside = lane_tree_limits().beside_embree;
        const RenderScene within =
            with_backend(random_spheres(int(beside) - 1, 1.0, 7, true), AccelBackend::automatic);
        EXPECT_TRUE(within.bvh.lanes_cast());
        EXPECT_EQ(within.bvh.lane_tree().scan_f.size(), within.spheres.size());
        const RenderScene beyond =
            with_backend(random_spheres(int(beside) + 8, 1.0, 7, true), AccelBackend::automatic);
        EXPECT_FALSE(beyond.bvh.lanes_cast());
    }
}

TEST(Accel, CoincidentCentresStillSplit) {
    test::SceneBuilder b;
    const int m = b.material(MaterialType::diffuse);
    for (int i = 0; i < 100; ++i) b.sphere({0, 0, 0}, 1.0 + i, m);  // nested shells, one centre
    for (AccelBackend backend : backends()) {
        const RenderScene scene = with_backend(b.build(), backend);
        Ray ray;
        ray.o = {0, 0, -1000};
        ray.d = {0, 0, 1};
        Hit hit;
        ASSERT_TRUE(scene.intersects(ray, hit));
        EXPECT_EQ(scene.spheres[hit.sphere].radius, 100.0);
        ray.o = {0, 0, 0};
        ASSERT_TRUE(scene.intersects(ray, hit));
        EXPECT_DOUBLE_EQ(hit.t, 1.0);
    }
}

// Embree's BVH changes no image: 300 spheres under a lamp, path traced with Embree and with
// the plain path (the same double-precision test decides both), same seeds, bit for bit.
TEST(Accel, EmbreeImageIsThePlainPaths) {
    if (!embree_available()) GTEST_SKIP() << "built without Embree";
    test::SceneBuilder b;
    const int m = b.material(MaterialType::diffuse), glass = b.material(MaterialType::dielectric);
    b.scene.materials[glass].rho_r = b.scene.materials[glass].rho_t = Color(0.9);
    Rng rng(4, 1);
    for (int i = 0; i < 300; ++i)
        b.sphere({8 * rng.next() - 4, 8 * rng.next() - 4, 8 * rng.next() - 4}, 0.2 + 0.3 * rng.next(),
                 i % 4 ? m : glass);
    b.sphere({0, -1005, 0}, 1000, m);
    b.emitter({3, 12, -6}, 3, Color(5), m);
    const RenderScene embree = with_backend(b.build(), AccelBackend::embree);
    RenderScene plain = b.build();
    plain.linear_scan = true;
    RenderSettings settings = RenderSettings::from_scene(plain.renderer);
    settings.target_spp = 2;
    RenderState a(64, 64), c(64, 64);
    for (int i = 0; i < 2; ++i) {
        render_pass(plain, settings, a);
        render_pass(embree, settings, c);
    }
    EXPECT_EQ(a.rays, c.rays);
    const Image ia = a.radiance(), ic = c.radiance();
    size_t differ = 0;
    double total = 0;
    for (size_t i = 0; i < ia.pixels.size(); ++i) {
        differ += !(ia.pixels[i].x == ic.pixels[i].x && ia.pixels[i].y == ic.pixels[i].y &&
                    ia.pixels[i].z == ic.pixels[i].z);
        total += luminance(ia.pixels[i]);
    }
    EXPECT_EQ(differ, 0u);
    EXPECT_GT(total, 0.0);  // not a black image
}

// The fast path changes no image beyond rounding: the same scene rendered with the BVH and
// with the linear scan, same seeds.
TEST(Accel, ImagesMatchLinearScan) {
    for (int n : {3, 8}) {
        RenderScene scene =
            prepare_scene(load_scene_file(test::brief_scene_file(n)).scene);
        RenderSettings settings = RenderSettings::from_scene(scene.renderer);
        settings.target_spp = 2;
        RenderState fast(128, 128), plain(128, 128);
        for (int i = 0; i < 2; ++i) render_pass(scene, settings, fast);
        scene.linear_scan = true;
        for (int i = 0; i < 2; ++i) render_pass(scene, settings, plain);
        const Rgb8Image a = tonemap(fast.radiance(), ToneMap::sigmoid), b = tonemap(plain.radiance(), ToneMap::sigmoid);
        size_t differ = 0;
        for (size_t i = 0; i < a.bytes.size(); ++i) differ += a.bytes[i] != b.bytes[i];
        EXPECT_LE(differ, a.bytes.size() / 1000) << "scene " << n;
    }
}

namespace {

// A room of five wall spheres, `balls` diffuse balls and a spherical lamp, every length times
// `scale` (an area light's radiance does not depend on scale, so the image should not).
test::SceneBuilder scaled_room(double scale, int balls) {
    test::SceneBuilder b;
    const int grey = b.material(MaterialType::diffuse, Color(0.7)),
              red = b.material(MaterialType::diffuse, Color(0.8, 0.2, 0.2)),
              black = b.material(MaterialType::diffuse, Color(0));
    for (const Vec3 c : {Vec3{-505, 0, 0}, Vec3{505, 0, 0}, Vec3{0, 0, 505}, Vec3{0, 505, 0}, Vec3{0, -505, 0}})
        b.sphere(c * scale, 500 * scale, grey);
    for (int k = 0; k < balls; ++k)
        b.sphere(Vec3{-4 + 1.6 * (k % 6), -4 + 1.2 * (k / 6), 1 + 0.1 * k} * scale, 0.4 * scale, red);
    b.emitter(Vec3{0, 4, 0} * scale, 0.8 * scale, Color(20), black);
    b.scene.cameras[0].position = Vec3{0, 0, -14} * scale;
    b.scene.cameras[0].focal_distance = 5 * scale;
    b.scene.renderer.width = b.scene.renderer.height = 24;
    return b;
}

Image render_image(const RenderScene& scene, int spp, Integrator integrator = Integrator::pt,
                   LaneChoice kernels = LaneChoice::best) {
    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    settings.integrator = integrator;
    settings.kernels = kernels;
    settings.target_spp = spp;
    RenderState state(scene.renderer.width, scene.renderer.height);
    for (int i = 0; i < spp; ++i) render_pass(scene, settings, state);
    return state.radiance();
}

bool same_image(const Image& a, const Image& b) {
    for (size_t i = 0; i < a.pixels.size(); ++i)
        if (!(a.pixels[i].x == b.pixels[i].x && a.pixels[i].y == b.pixels[i].y && a.pixels[i].z == b.pixels[i].z))
            return false;
    return true;
}

// The largest difference of a pixel's channel between two images, relative to the largest
// channel of the first.
double largest_relative_difference(const Image& a, const Image& b) {
    double largest = 0, scale = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i) {
        scale = std::max(scale, max_component(a.pixels[i]));
        for (int k = 0; k < 3; ++k) largest = std::max(largest, std::abs(a.pixels[i][k] - b.pixels[i][k]));
    }
    return scale > 0 ? largest / scale : (largest > 0 ? kInfinity : 0.0);
}

double total_luminance(const Image& image) {
    double total = 0;
    for (const Color& c : image.pixels) total += luminance(c);
    return total;
}

}  // namespace

// Scenes of more than 32 spheres at the extremes of scale: Embree's single-precision traversal
// takes only the scenes it can trace exactly (embree_fits); the others go to our double BVH
// (at 1e18 Embree asserted on its rays, at 1e20 and 1e-40 it saw nothing: a black image).
// At every scale the default BVH gives the plain path's image (Embree's bit for bit, ours to
// its rounding), and that is the scale-1 image: the rules of Ray are scale-free.
TEST(Accel, ExtremeScalesGiveThePlainPathsImage) {
    const RenderScene unit_scene = scaled_room(1, 34).build();
    // One path at a time: the BVHs against the plain path (the lanes' own tree and their
    // rounding: ExtremeScalesInTheLanes below).
    const LaneChoice one = LaneChoice::off;
    const Image unit = render_image(unit_scene, 2, Integrator::pt, one),
                unit_wrt = render_image(unit_scene, 1, Integrator::wrt);
    ASSERT_GT(total_luminance(unit), 0.0);
    ASSERT_GT(total_luminance(unit_wrt), 0.0);
    Ray centre;
    centre.o = unit_scene.camera.position;
    centre.d = normalize(Vec3{0, 0, 0} - centre.o);
    Sampler unit_sampler(Rng::for_sample(1, 0, 0));
    const double unit_depth =
        trace_sample(unit_scene, RenderSettings::from_scene(unit_scene.renderer), centre, unit_sampler).primary_distance;
    ASSERT_GT(unit_depth, 0.0);
    for (double scale : {1e-100, 1e-40, 1e-30, 1e-20, 1e-6, 1.0, 1e6, 1e17, 1e18, 1e20, 1e30, 1e100}) {
        const RenderScene automatic = scaled_room(scale, 34).build();
        RenderScene plain = automatic;
        plain.linear_scan = true;
        const Image a = render_image(automatic, 2, Integrator::pt, one), p = render_image(plain, 2, Integrator::pt, one);
        char where[64];
        std::snprintf(where, sizeof where, "scale %g (%s)", scale,
                      std::string(accel_backend_names.name(automatic.bvh.backend())).c_str());
        EXPECT_EQ(automatic.bvh.backend() == AccelBackend::embree, embree_available() && embree_fits(automatic.spheres))
            << where;
        EXPECT_EQ(embree_fits(automatic.spheres), scale >= 1e-6 && scale <= 1e6) << where;
        if (automatic.bvh.backend() == AccelBackend::embree) EXPECT_TRUE(same_image(a, p)) << where;
        EXPECT_LE(largest_relative_difference(a, p), 1e-9) << where;
        EXPECT_LE(largest_relative_difference(a, unit), 1e-9) << where;
        // WRT too, and the depth of the first hits (primary_distance) scales with the scene.
        EXPECT_LE(largest_relative_difference(render_image(automatic, 1, Integrator::wrt), unit_wrt), 1e-9) << where;
        Ray centre;
        centre.o = automatic.camera.position;
        centre.d = normalize(Vec3{0, 0, 0} - centre.o);
        Sampler sampler(Rng::for_sample(1, 0, 0));
        const double depth = trace_sample(automatic, RenderSettings::from_scene(automatic.renderer), centre, sampler)
                                 .primary_distance;
        EXPECT_NEAR(depth / scale, unit_depth, 1e-9 * unit_depth) << where;
    }
}

// The same where paths run in SIMD lanes, at a few spheres (one leaf) and at 34 (the lanes'
// tree, where its boxes fit single precision): the single-precision lanes only where every
// length keeps its square a normal float (float_lanes_fit), the double ones at every scale;
// their images are the one-path image to the lanes' rounding.
TEST(Accel, ExtremeScalesInTheLanes) {
    for (int spheres : {4, 34}) {
        const Image unit = render_image(scaled_room(1, spheres).build(), 2, Integrator::pt, LaneChoice::off);
        for (double scale : {1e-100, 1e-40, 1e-20, 1e-13, 1e-6, 1.0, 1e6, 1e13, 1e20, 1e30, 1e100}) {
            const RenderScene scene = scaled_room(scale, spheres).build();
            char where[48];
            std::snprintf(where, sizeof where, "%d spheres, scale %g", spheres, scale);
            if (spheres > 16) EXPECT_EQ(scene.bvh.lanes_cast(), scale <= 1e20) << where;  // the tree's boxes in floats
            EXPECT_EQ(float_lanes_fit(scene), scale >= 1e-6 && scale <= 1e6) << where;
            const Image one_path = render_image(scene, 2, Integrator::pt, LaneChoice::off);
            const Image lanes = render_image(scene, 2);
            EXPECT_LE(largest_relative_difference(one_path, unit), 1e-9) << where;
            // Single precision moves a rare sample by more (a path's decision near a boundary):
            // a thousandth of the brightest pixel, against the whole of it for a wrong image.
            EXPECT_LE(largest_relative_difference(lanes, one_path), float_lanes_fit(scene) ? 1e-3 : 1e-9) << where;
        }
    }
}
