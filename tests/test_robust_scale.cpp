// Numerical stability at the extremes of scale and of the camera: scenes from 1e-4 to 1e4,
// huge and tiny spheres, grazing rays, a camera on or inside a surface, degenerate views.
// One test per row of the matrix in docs/robustness.md; everything is seeded; images are
// small and compared statistically or against analytic values.
#include "robustness_util.h"

namespace fs = std::filesystem;
using namespace kr;
using namespace kr::robust;

// =======================================================================================
// Scale

// The same scene at scales 1e-4 ... 1e4 (lengths x s, point intensity x s^2) gives the same
// image: the renderer has no absolute epsilon anywhere. In double precision (one path, the
// double lanes) only rounding differs; the float lanes, which take this scene (its floor is
// reached only near the camera: float_sizes_fit), round hit distances to about 2^-24 of the
// distances a test meets, relative too.
TEST(RobustScale, SceneScaledFrom1em4To1e4GivesTheSameImage) {
    for (Integrator integrator : {Integrator::wrt, Integrator::pt})
        for (LaneChoice kernels : {LaneChoice::double_lanes, LaneChoice::best}) {
            if (integrator == Integrator::wrt && kernels != LaneChoice::best) continue;  // one path
            RenderSettings settings = settings_for(integrator, 8, 4);
            settings.kernels = kernels;
            const RenderScene unit = still_life(1).build();
            const LaneKernels ran = lane_kernels(unit, settings);
            const bool single = single_precision(ran);
            const std::string where = std::string(integrator_names.name(integrator)) + ", " +
                                      std::string(lane_kernels_names.name(ran));
            const RenderState reference = render(unit, settings, 24, 24, 4);
            const Image ref = reference.radiance();
            for (double s : {1e-4, 1e-2, 1e2, 1e4}) {
                const RenderState state = render(still_life(s).build(), settings, 24, 24, 4);
                ASSERT_TRUE(all_finite(state));
                EXPECT_EQ(state.nonfinite_samples, 0u);
                const Image img = state.radiance();
                // Same random numbers, same paths: only rounding differs (measured: 1e-14 in
                // double precision).
                EXPECT_LT(relative_l1(ref, img), single ? 1e-4 : 1e-9) << where << ", scale " << s;
                EXPECT_GT(psnr(tonemap(ref, ToneMap::sigmoid), tonemap(img, ToneMap::sigmoid)), single ? 60.0 : 98.9)
                    << where << ", scale " << s;
                // Depth scales with the scene.
                const std::vector<double> d0 = reference.mean_depth(), d1 = state.mean_depth();
                for (size_t i = 0; i < d0.size(); i += 37)
                    if (d0[i] < 100 && d1[i] / s < 100)  // all hits
                        EXPECT_NEAR(d1[i] / s, d0[i], (single ? 1e-4 : 1e-6) * d0[i]) << where << ", scale " << s;
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
