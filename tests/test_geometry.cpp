// Ray casting: intersects / is_occluded, at scales from 1e-4 to 1e6, from on and off surfaces.
#include <gtest/gtest.h>

#include <cmath>

#include "core/rng.h"
#include "core/sampling.h"
#include "render/render_scene.h"
#include "test_util.h"

using namespace kr;

namespace {

RenderScene single_sphere(Vec3 centre, double radius) {
    test::SceneBuilder b;
    b.sphere(centre, radius, b.material(MaterialType::diffuse));
    return b.build();
}

Vec3 random_direction(Rng& rng) { return sample_uniform_sphere(rng.next(), rng.next()); }

}  // namespace

TEST(Geometry, SphereRootsMatchAnalyticDistances) {
    const SphereGeom s{{0, 0, 5}, 2};
    double t0, t1;
    ASSERT_TRUE(sphere_roots(s, {0, 0, 0}, {0, 0, 1}, t0, t1));
    EXPECT_DOUBLE_EQ(t0, 3);
    EXPECT_DOUBLE_EQ(t1, 7);
    EXPECT_FALSE(sphere_roots(s, {0, 0, 0}, {0, 1, 0}, t0, t1));
    // Tangent line: one double root at the touching point.
    ASSERT_TRUE(sphere_roots(s, {2, 0, 0}, {0, 0, 1}, t0, t1));
    EXPECT_NEAR(t0, 5, 1e-6);
    EXPECT_NEAR(t1, 5, 1e-6);
}

TEST(Geometry, ClosestHitWithinSegment) {
    test::SceneBuilder b;
    const int m = b.material(MaterialType::diffuse);
    b.sphere({0, 0, 10}, 1, m);
    b.sphere({0, 0, 5}, 1, m);
    const RenderScene scene = b.build();
    Ray ray;
    ray.d = {0, 0, 1};
    Hit hit;
    ASSERT_TRUE(scene.intersects(ray, hit));
    EXPECT_EQ(hit.sphere, 1);
    EXPECT_DOUBLE_EQ(hit.t, 4);
    EXPECT_NEAR(length(hit.n - Vec3(0, 0, -1)), 0, 1e-12);
    // [tmin, tmax] bounds the segment: the near sphere is skipped when tmin is past it.
    ray.tmin = 6.5;
    ASSERT_TRUE(scene.intersects(ray, hit));
    EXPECT_EQ(hit.sphere, 0);
    EXPECT_DOUBLE_EQ(hit.t, 9);
    ray.tmin = 0;
    ray.tmax = 3.9;
    EXPECT_FALSE(scene.intersects(ray, hit));
    EXPECT_FALSE(scene.is_occluded(ray));
    ray.tmax = 4.1;
    EXPECT_TRUE(scene.is_occluded(ray));
}

TEST(Geometry, OriginInsideSphereHitsFarSide) {
    const RenderScene scene = single_sphere({0, 0, 0}, 500);
    Ray ray;
    ray.o = {3, -2, 1};
    ray.d = normalize(Vec3(1, 2, 3));
    Hit hit;
    ASSERT_TRUE(scene.intersects(ray, hit));
    EXPECT_NEAR(length(hit.p), 500, 1e-9);
    EXPECT_GT(hit.t, 400);
}

// Rays leaving a surface, at every scale, never hit the sphere they leave (no acne), and
// rays entering it hit its far side at the chord length (no leaks).
TEST(Geometry, ReintersectionAtRandomScales) {
    Rng rng(7, 1);
    int checked = 0;
    for (double scale : {1e-4, 1e-2, 1.0, 1e2, 1e4, 1e6}) {
        for (int trial = 0; trial < 200; ++trial) {
            const Vec3 centre = scale * Vec3(rng.next() * 10 - 5, rng.next() * 10 - 5, rng.next() * 10 - 5);
            const double radius = scale * (0.01 + rng.next());
            const RenderScene scene = single_sphere(centre, radius);
            // A camera ray from outside towards a random point of the sphere.
            Ray primary;
            const Vec3 target = centre + radius * 0.999 * random_direction(rng);
            primary.o = centre + (radius * 3) * random_direction(rng);
            primary.d = normalize(target - primary.o);
            Hit hit;
            ASSERT_TRUE(scene.intersects(primary, hit)) << "scale " << scale;
            EXPECT_NEAR(length(hit.p - centre), radius, radius * 1e-12);

            // Leaving: a random direction in the outward hemisphere.
            Vec3 out = random_direction(rng);
            if (dot(out, hit.n) < 0) out = -out;
            Ray leave{hit.p, out, 0, kInfinity, hit.sphere, false, -1};
            Hit again;
            EXPECT_FALSE(scene.intersects(leave, again)) << "acne at scale " << scale;

            // Entering: must meet the far side at the chord length 2 r cos.
            Ray enter{hit.p, -out, 0, kInfinity, hit.sphere, true, -1};
            ASSERT_TRUE(scene.intersects(enter, again)) << "leak at scale " << scale;
            const double chord = 2 * radius * dot(out, hit.n);
            EXPECT_NEAR(again.t, chord, radius * 1e-9 + chord * 1e-9);
            ++checked;
        }
    }
    EXPECT_EQ(checked, 1200);
}

// The reference scenes' walls: spheres of radius 500 whose near side is 5 units from the
// room's centre. Every ray from inside the room must hit a wall at a distance consistent
// with the plane it approximates.
TEST(Geometry, LargeWallsSeenFromInsideTheRoom) {
    test::SceneBuilder b;
    const int m = b.material(MaterialType::diffuse);
    for (Vec3 c : {Vec3(-505, 0, 0), Vec3(505, 0, 0), Vec3(0, 505, 0), Vec3(0, -505, 0), Vec3(0, 0, 505), Vec3(0, 0, -505)})
        b.sphere(c, 500, m);
    const RenderScene scene = b.build();
    Rng rng(3, 3);
    for (int i = 0; i < 10000; ++i) {
        Ray ray;
        ray.o = {rng.next() * 8 - 4, rng.next() * 8 - 4, rng.next() * 8 - 4};
        ray.d = random_direction(rng);
        Hit hit;
        ASSERT_TRUE(scene.intersects(ray, hit));
        // The hit lies on its sphere and within the box of half-size 5 (plus the sag of the
        // radius-500 cap, under 0.1 at these angles).
        EXPECT_NEAR(length(hit.p - scene.spheres[hit.sphere].centre), 500, 1e-9);
        EXPECT_LE(max_abs_component(hit.p), 5.1);
        // Re-cast from the hit point back into the room: no acne on the wall itself.
        Vec3 out = random_direction(rng);
        if (dot(out, hit.n) < 0) out = -out;
        Ray bounce{hit.p, out, 0, kInfinity, hit.sphere, false, -1};
        Hit next;
        ASSERT_TRUE(scene.intersects(bounce, next));
        EXPECT_NE(next.sphere, hit.sphere);
        EXPECT_GT(next.t, 0);
    }
}

TEST(Geometry, TinySphereIsHitAndOccludes) {
    const RenderScene scene = single_sphere({0, 0, 1}, 1e-4);
    Ray ray;
    ray.d = {0, 0, 1};
    Hit hit;
    ASSERT_TRUE(scene.intersects(ray, hit));
    EXPECT_NEAR(hit.t, 1 - 1e-4, 1e-15);
    Ray miss;
    miss.d = normalize(Vec3(2e-4, 0, 1));
    EXPECT_FALSE(scene.is_occluded(miss));
}

TEST(Geometry, ShadowRayIgnoresTheLightItEndsOn) {
    test::SceneBuilder b;
    const int m = b.material(MaterialType::diffuse);
    b.sphere({0, 0, 0}, 1, m);
    const RenderScene scene = b.build();
    Ray shadow;
    shadow.o = {0, 0, -5};
    shadow.d = {0, 0, 1};
    shadow.tmax = 4;  // ends on the sphere's near side
    shadow.to_sphere = 0;
    EXPECT_FALSE(scene.is_occluded(shadow));
    shadow.to_sphere = -1;
    shadow.tmax = 4.000001;
    EXPECT_TRUE(scene.is_occluded(shadow));
}

TEST(Geometry, GrazingRaysAreStable) {
    const RenderScene scene = single_sphere({0, 0, 0}, 1);
    // Lines at distance 1 - eps from the centre hit; at 1 + eps they miss.
    for (double eps : {1e-3, 1e-6, 1e-9}) {
        Ray inside_ray, outside_ray;
        inside_ray.o = {1 - eps, 0, -10};
        inside_ray.d = {0, 0, 1};
        outside_ray.o = {1 + eps, 0, -10};
        outside_ray.d = {0, 0, 1};
        Hit hit;
        EXPECT_TRUE(scene.intersects(inside_ray, hit)) << eps;
        EXPECT_TRUE(std::isfinite(hit.t));
        EXPECT_NEAR(length(hit.p), 1, 1e-12);
        EXPECT_FALSE(scene.intersects(outside_ray, hit)) << eps;
    }
}
