// The render state's error estimate against the true error, and the stopping rules built
// on it (--noise with adaptive sampling, --time).
#include <gtest/gtest.h>

#include <cmath>

#include "render/progressive.h"
#include "test_util.h"

using namespace kr;

namespace {

constexpr int kSize = 24;

// A diffuse ball lit by a small sphere light: noisy direct and indirect light, black
// background (zero variance) around it.
RenderScene lit_ball() {
    test::SceneBuilder b;
    b.scene.renderer.width = b.scene.renderer.height = kSize;
    b.sphere({0, 0, 0}, 2.5, b.material(MaterialType::diffuse, Color(0.7)));
    b.emitter({3, 3, -3}, 0.6, Color(20), b.material(MaterialType::diffuse, Color(0)));
    return b.build();
}

RenderSettings settings_with_seed(uint64_t seed) {
    RenderSettings s;
    s.integrator = Integrator::pt;
    s.estimator = Estimator::uniform;
    s.light_sampling = LightSampling::area;  // noisier than cone: a real test of the estimate
    s.seed = seed;
    return s;
}

// Per-pixel mean luminance of a state.
std::vector<double> luminances(const RenderState& state) {
    const Image img = state.radiance();
    std::vector<double> out;
    for (const Color& c : img.pixels) out.push_back(luminance(c));
    return out;
}

// Relative RMS error of `state` against a converged reference, as relative_error() defines it.
double true_relative_error(const RenderState& state, const std::vector<double>& reference) {
    const std::vector<double> l = luminances(state);
    double err = 0, sig = 0;
    for (size_t i = 0; i < l.size(); ++i) {
        err += (l[i] - reference[i]) * (l[i] - reference[i]);
        sig += reference[i] * reference[i];
    }
    return std::sqrt(err / sig);
}

const std::vector<double>& reference() {
    static const std::vector<double> ref = [] {
        // Cone sampling has the same expectation as area sampling and far less variance.
        const RenderScene scene = lit_ball();
        RenderSettings settings = settings_with_seed(1000);
        settings.light_sampling = LightSampling::cone;
        RenderState state(kSize, kSize);
        for (int i = 0; i < 4096; ++i) render_pass(scene, settings, state);
        return luminances(state);
    }();
    return ref;
}

}  // namespace

TEST(ErrorEstimate, MatchesTrueErrorOfAnalyticScene) {
    // The estimate is of the expected squared error; one render's actual error scatters
    // around it (widely, with the heavy tails of area sampling), so both are averaged over
    // independent renders.
    const RenderScene scene = lit_ball();
    for (int spp : {8, 64}) {
        double estimated_sq = 0, actual_sq = 0;
        constexpr int kRenders = 24;
        for (int seed = 0; seed < kRenders; ++seed) {
            RenderState state(kSize, kSize);
            for (int i = 0; i < spp; ++i) render_pass(scene, settings_with_seed(100 + seed), state);
            estimated_sq += std::pow(state.relative_error(), 2) / kRenders;
            actual_sq += std::pow(true_relative_error(state, reference()), 2) / kRenders;
        }
        const double ratio = std::sqrt(estimated_sq / actual_sq);
        RecordProperty("ratio_" + std::to_string(spp), std::to_string(ratio));
        // A wrong factor (sqrt(n), n - 1 against n at 8 spp, or the variance of one sample
        // instead of the mean's) lies well outside.
        EXPECT_GT(ratio, 0.75) << spp << " spp";
        EXPECT_LT(ratio, 1.33) << spp << " spp";
    }
}

TEST(ErrorEstimate, InfiniteBeforeTwoSamples) {
    const RenderScene scene = lit_ball();
    RenderState state(kSize, kSize);
    EXPECT_TRUE(std::isinf(state.relative_error()));
    render_pass(scene, settings_with_seed(1), state);
    EXPECT_TRUE(std::isinf(state.relative_error()));
    render_pass(scene, settings_with_seed(1), state);
    EXPECT_TRUE(std::isfinite(state.relative_error()));
}

TEST(StopRule, NoiseStopsAtThePromisedError) {
    const RenderScene scene = lit_ball();
    for (double target : {0.1, 0.03}) {
        RenderState state(kSize, kSize);
        StopRule rule;
        rule.max_passes = 1 << 16;
        rule.noise = target;
        EXPECT_EQ(render_until(scene, settings_with_seed(3), state, rule), StopReason::noise);
        EXPECT_LE(state.relative_error(), target) << state.passes;
        // The true error is within the estimate's confidence of the target.
        EXPECT_LT(true_relative_error(state, reference()), 1.25 * target) << target;
    }
}

TEST(StopRule, AdaptiveSamplingSpendsPassesOnNoisyPixels) {
    const RenderScene scene = lit_ball();
    RenderState state(kSize, kSize);
    StopRule rule;
    rule.max_passes = 1 << 16;
    rule.noise = 0.02;
    render_until(scene, settings_with_seed(5), state, rule);
    // Background pixels (no variance) stop at the minimum; lit ones go on.
    uint32_t fewest = ~0u, most = 0;
    for (uint32_t n : state.sample_count()) {
        fewest = std::min(fewest, n);
        most = std::max(most, n);
    }
    EXPECT_EQ(fewest, rule.min_samples);
    EXPECT_GT(most, 4 * rule.min_samples);
}

TEST(StopRule, PassesAndTimeRules) {
    const RenderScene scene = lit_ball();
    RenderState state(kSize, kSize);
    StopRule rule;
    rule.max_passes = 5;
    EXPECT_EQ(render_until(scene, settings_with_seed(1), state, rule), StopReason::passes);
    EXPECT_EQ(state.passes, 5);
    RenderState timed(kSize, kSize);
    rule.max_passes = 1 << 30;
    rule.seconds = 0.05;
    EXPECT_EQ(render_until(scene, settings_with_seed(1), timed, rule), StopReason::time);
    EXPECT_GE(timed.passes, 1);
    int calls = 0;
    RenderState cancelled(kSize, kSize);
    rule.seconds = 0;
    EXPECT_EQ(render_until(scene, settings_with_seed(1), cancelled, rule,
                           [&](const RenderState&) { return ++calls < 3; }),
              StopReason::cancelled);
    EXPECT_EQ(cancelled.passes, 3);
}
