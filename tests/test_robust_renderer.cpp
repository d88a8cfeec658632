// Numerical stability at the extremes of the lens and the renderer settings (aperture, focal
// distance, depth, samples, dimensions) and non-finite samples, which are counted, never summed.
// One test per row of the matrix in docs/robustness.md; everything is seeded; images are
// small and compared statistically or against analytic values.
#include "robustness_util.h"

namespace fs = std::filesystem;
using namespace kr;
using namespace kr::robust;

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
