// The denoiser (render/denoise.h) on synthetic images with known answers, its feature
// buffers and halves, and on path-traced scenes against a high-spp reference.
#include <gtest/gtest.h>

#include <omp.h>

#include <atomic>
#include <cmath>
#include <random>

#include "core/image_hdr.h"
#include "render/aov.h"
#include "render/denoise.h"
#include "render/outputs.h"
#include "render/options.h"
#include "render/progressive.h"
#include "render/render_pass.h"
#include "render/render_scene.h"
#include "scene/load.h"
#include "test_util.h"
#include "viewer/status.h"

namespace kr {
namespace {

// A synthetic render: per pixel, the true radiance `truth`, its features, and Gaussian noise
// of standard deviation `sigma` (given to the filter as the variance of the mean).
struct Synthetic {
    int w, h;
    Image truth, noisy;
    std::vector<Color> variance;  // of the mean, per channel
    std::vector<float> albedo, normal;
    std::vector<double> depth;

    Synthetic(int w_, int h_) : w(w_), h(h_), truth(w_, h_), noisy(w_, h_) {
        const size_t n = size_t(w) * size_t(h);
        variance.assign(n, Color());
        albedo.assign(3 * n, 1.f);
        normal.assign(3 * n, 0.f);
        for (size_t i = 0; i < n; ++i) normal[3 * i + 2] = -1;
        depth.assign(n, 10.0);
    }
    size_t at(int x, int y) const { return size_t(y) * size_t(w) + size_t(x); }
    void set(int x, int y, double radiance, double albedo_value, Vec3 n, double z) {
        const size_t i = at(x, y);
        truth.pixels[i] = Color(radiance);
        for (int k = 0; k < 3; ++k) albedo[3 * i + size_t(k)] = float(albedo_value);
        normal[3 * i] = float(n.x);
        normal[3 * i + 1] = float(n.y);
        normal[3 * i + 2] = float(n.z);
        depth[i] = z;
    }
    void add_noise(double sigma, uint32_t seed = 1) {
        std::mt19937 rng(seed);
        std::normal_distribution<double> g(0, sigma);
        for (size_t i = 0; i < truth.pixels.size(); ++i) {
            noisy.pixels[i] = truth.pixels[i] + Color(g(rng), g(rng), g(rng));
            variance[i] = Color(float(sigma * sigma));
        }
    }
    // Noise of standard deviation sigma on the mean as the average of two independent halves
    // (each of sigma sqrt 2, `count` samples each): the final filter's input.
    void add_noise_halves(double sigma, uint32_t count = 4, uint32_t seed = 1) {
        std::mt19937 rng(seed);
        std::normal_distribution<double> g(0, sigma * std::sqrt(2.0));
        const size_t n = truth.pixels.size();
        for (int h = 0; h < 2; ++h) {
            half[h] = Image(w, this->h);
            half_count[h].assign(n, count);
            for (size_t i = 0; i < n; ++i) half[h].pixels[i] = truth.pixels[i] + Color(g(rng), g(rng), g(rng));
        }
        for (size_t i = 0; i < n; ++i) {
            noisy.pixels[i] = (half[0].pixels[i] + half[1].pixels[i]) * 0.5;
            variance[i] = Color(float(sigma * sigma));
        }
    }
    Image half[2];
    std::vector<uint32_t> half_count[2];

    DenoiseInput input() const {
        DenoiseInput in;
        in.radiance = &noisy;
        in.variance = variance;
        in.albedo = albedo;
        in.normal = normal;
        in.depth = depth;
        for (int h = 0; h < 2; ++h)
            if (!half_count[h].empty()) {
                in.half[h] = &half[h];
                in.half_count[h] = half_count[h];
            }
        return in;
    }
    Image denoise(const AtrousParams& params = {}) const { return denoise_atrous(input(), params); }
    Image denoise_final(const NlmParams& params = {}) const { return denoise_nlmeans(input(), params); }
};

// Mean of the green channel over a column's interior rows.
double column_mean(const Image& img, int x, int margin) {
    double s = 0;
    for (int y = margin; y < img.height - margin; ++y) s += img.at(x, y).y;
    return s / (img.height - 2 * margin);
}

// Both filters, with and without their fade: noiseless halves of a constant (with a variance
// given) come back as the constant.
TEST(Denoise, ConstantStaysConstant) {
    Synthetic s(64, 48);
    for (int y = 0; y < s.h; ++y)
        for (int x = 0; x < s.w; ++x) s.set(x, y, 0.37, 0.5, {0, 0, -1}, 7);
    s.add_noise_halves(0.1);  // the variance of the mean: 0.01
    for (int h = 0; h < 2; ++h) s.half[h] = s.truth;
    s.noisy = s.truth;
    auto expect_constant = [](const Image& out) {
        for (const Color& c : out.pixels)
            for (int k = 0; k < 3; ++k) ASSERT_NEAR(c[k], 0.37, 1e-5);
    };
    AtrousParams no_fade;
    no_fade.fade_error = 0;
    for (const AtrousParams& params : {AtrousParams{}, no_fade}) expect_constant(s.denoise(params));
    NlmParams final_no_fade;
    final_no_fade.fade_error = 0;
    for (const NlmParams& params : {NlmParams{}, final_no_fade}) expect_constant(s.denoise_final(params));
}

// A filtered noisy constant of 1 (i.i.d. noise of `sigma`): its mean stays 1 beyond `margin`
// pixels from the border, and its variance there over sigma^2 is returned.
double noise_factor(const Image& out, int margin, double sigma) {
    double sum = 0, sq = 0;
    int n = 0;
    for (int y = margin; y < out.height - margin; ++y)
        for (int x = margin; x < out.width - margin; ++x) {
            const double v = out.at(x, y).y;
            sum += v;
            sq += v * v;
            ++n;
        }
    const double mean = sum / n;
    EXPECT_NEAR(mean, 1.0, 0.005);
    return (sq / n - mean * mean) / (sigma * sigma);
}

// With every edge stop at one (flat features, no luminance stop, no fade) the filter is the
// linear a-trous cascade of [1/4 1/2 1/4]^2 kernels at steps 1, 2, 4, 8, 16: i.i.d. noise's
// variance drops to the sum of the squared weights of their convolution.
TEST(Denoise, NoiseOnAConstantDropsByTheCascadesFactor) {
    Synthetic s(400, 400);
    for (int y = 0; y < s.h; ++y)
        for (int x = 0; x < s.w; ++x) s.set(x, y, 1.0, 1.0, {0, 0, -1}, 10);
    s.add_noise(0.1);
    AtrousParams linear;
    linear.sigma_luminance = 0;
    linear.fade_error = 0;
    // The 1-D cascade's weights (the 2-D kernel is their outer product).
    std::vector<double> kernel{1.0};
    for (int it = 0; it < linear.iterations; ++it) {
        const int step = 1 << it;
        std::vector<double> next(kernel.size() + 2 * size_t(step), 0.0);
        for (size_t i = 0; i < kernel.size(); ++i) {
            next[i] += 0.25 * kernel[i];
            next[i + size_t(step)] += 0.5 * kernel[i];
            next[i + 2 * size_t(step)] += 0.25 * kernel[i];
        }
        kernel = next;
    }
    double sum_sq = 0;
    for (double k : kernel) sum_sq += k * k;
    const double expected_factor = sum_sq * sum_sq;  // 2-D: the product of the axes' sums
    const int margin = 32;                           // beyond the cascade's reach of 31 pixels
    for (const bool with_luminance_stop : {false, true}) {
        AtrousParams params = linear;
        if (with_luminance_stop) params.sigma_luminance = AtrousParams{}.sigma_luminance;
        const double factor = noise_factor(s.denoise(params), margin, 0.1);
        if (!with_luminance_stop) {
            // One realisation of correlated output: about 10 % spread.
            EXPECT_GT(factor, 0.7 * expected_factor) << expected_factor;
            EXPECT_LT(factor, 1.3 * expected_factor) << expected_factor;
        } else {
            // The luminance stop keeps part of the noise, but at least 1/20 of the variance goes.
            EXPECT_LT(factor, 0.05) << "linear cascade: " << expected_factor;
        }
    }
}

// A vertical edge at x = w/2 between two sides, noise of 0.3 on both: the columns next to the
// edge keep their side's value. `side(left)` sets a pixel of one side.
// `final`: the final filter, on two halves of noise.
template <class Side>
void expect_edge_kept(Side side, double left_value, double right_value, double tolerance, bool final = false) {
    Synthetic s(96, 64);
    for (int y = 0; y < s.h; ++y)
        for (int x = 0; x < s.w; ++x) side(s, x, y, x < s.w / 2);
    if (final) s.add_noise_halves(0.3);
    else s.add_noise(0.3);
    const Image out = final ? s.denoise_final() : s.denoise();
    const int margin = 4;
    // Noise went down away from the edge (the filter did something) ...
    double raw_err = 0, err = 0;
    for (int y = margin; y < s.h - margin; ++y) {
        raw_err += std::pow(s.noisy.at(10, y).y - left_value, 2);
        err += std::pow(out.at(10, y).y - left_value, 2);
    }
    EXPECT_LT(err, 0.2 * raw_err);
    // ... and nothing leaked across it: the columns beside it keep their side's mean.
    EXPECT_NEAR(column_mean(out, s.w / 2 - 1, margin), left_value, tolerance);
    EXPECT_NEAR(column_mean(out, s.w / 2, margin), right_value, tolerance);
    EXPECT_NEAR(column_mean(out, s.w / 2 - 3, margin), left_value, tolerance);
    EXPECT_NEAR(column_mean(out, s.w / 2 + 2, margin), right_value, tolerance);
}

// Each edge for both filters: the interactive one, then the final one.
TEST(Denoise, AlbedoEdgeIsKept) {
    // The same light on albedo 0.2 and 0.8: the radiance is the albedo.
    for (const bool final : {false, true})
        expect_edge_kept(
            [](Synthetic& s, int x, int y, bool left) { s.set(x, y, left ? 0.2 : 0.8, left ? 0.2 : 0.8, {0, 0, -1}, 10); },
            0.2, 0.8, 0.03, final);
}

TEST(Denoise, NormalEdgeIsKept) {
    // A crease: the same albedo and depth, faces at right angles lit 0.2 and 0.8.
    for (const bool final : {false, true})
        expect_edge_kept(
            [](Synthetic& s, int x, int y, bool left) {
                s.set(x, y, left ? 0.2 : 0.8, 0.5, left ? Vec3{-0.7071, 0, -0.7071} : Vec3{0.7071, 0, -0.7071}, 10);
            },
            0.2, 0.8, 0.03, final);
}

TEST(Denoise, DepthEdgeIsKept) {
    // A silhouette: the same albedo and normal, a near surface lit 0.2 before a far one lit 0.8.
    for (const bool final : {false, true})
        expect_edge_kept(
            [](Synthetic& s, int x, int y, bool left) { s.set(x, y, left ? 0.2 : 0.8, 0.5, {0, 0, -1}, left ? 5 : 50); },
            0.2, 0.8, 0.03, final);
}

// A filter whose image is the same bits at 1, 2 and 3 threads, on images with edges in every
// feature, among them images narrower than the a-trous filter's widest step and the final
// filter's window, with and without a workspace reused from a larger image; and the noise
// drops. `filter(input, workspace)` runs it; `halves`: the noise as two halves (the final
// filter's input), else one mean with pixels of unknown variance.
template <class Filter>
void expect_same_bits_at_any_thread_count(Filter filter, bool halves) {
    const int threads = omp_get_max_threads();
    for (const auto [w, h] : {std::pair{61, 45}, std::pair{20, 7}, std::pair{1, 3}}) {
        Synthetic s(w, h);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const bool left = x < w / 2, top = y < h / 3;
                s.set(x, y, left ? 0.2 : 0.8, top ? 0.3 : 0.6, left ? Vec3{-0.7071, 0, -0.7071} : Vec3{0, 0, -1},
                      top ? 5 + 0.1 * x : 50);
            }
        Synthetic big(70, 50);
        if (halves) {
            s.add_noise_halves(0.2);
            big.add_noise_halves(0.1);
        } else {
            s.add_noise(0.2);
            for (size_t i = 0; i < s.truth.pixels.size(); i += 13)
                s.variance[i] = Color(INFINITY);  // one sample there
            big.add_noise(0.1);
        }
        DenoiseWorkspace reused;
        (void)filter(big.input(), &reused);
        std::vector<Image> out;
        for (const int n : {1, 2, 3}) {
            omp_set_num_threads(n);
            out.push_back(filter(s.input(), nullptr));
            out.push_back(filter(s.input(), &reused));
        }
        omp_set_num_threads(threads);
        for (const Image& img : out)
            for (size_t i = 0; i < img.pixels.size(); ++i)
                for (int k = 0; k < 3; ++k) {
                    ASSERT_TRUE(std::isfinite(img.pixels[i][k])) << w << "x" << h << " pixel " << i;
                    ASSERT_EQ(img.pixels[i][k], out[0].pixels[i][k]) << w << "x" << h << " pixel " << i;
                }
        if (w * h < 100) continue;
        // The filter did something: the noise dropped.
        double raw = 0, filtered = 0;
        for (size_t i = 0; i < s.truth.pixels.size(); ++i) {
            raw += std::pow(s.noisy.pixels[i].y - s.truth.pixels[i].y, 2);
            filtered += std::pow(out[0].pixels[i].y - s.truth.pixels[i].y, 2);
        }
        EXPECT_LT(filtered, raw) << w << "x" << h;
    }
}

// The interactive filter splits its rows between threads and each row into spans by which
// taps fall outside the image.
TEST(Denoise, AtrousDoesNotDependOnTheThreadCount) {
    expect_same_bits_at_any_thread_count(
        [](const DenoiseInput& in, DenoiseWorkspace* ws) { return denoise_atrous(in, {}, ws); }, false);
}

// The final filter's sweep over the window's offsets splits rows between threads, for each
// candidate's sums.
TEST(Denoise, FinalFilterDoesNotDependOnTheThreadCount) {
    expect_same_bits_at_any_thread_count(
        [](const DenoiseInput& in, DenoiseWorkspace* ws) { return denoise_nlmeans(in, {}, ws); }, true);
}

// With every weight at one (distances scaled away, flat features, no fade) the final filter
// is the mean over its (2 radius + 1)^2 window: i.i.d. noise's variance drops by that count.
TEST(Denoise, FinalFilterNoiseOnAConstantDropsByTheWindowsCount) {
    Synthetic s(200, 200);
    for (int y = 0; y < s.h; ++y)
        for (int x = 0; x < s.w; ++x) s.set(x, y, 1.0, 1.0, {0, 0, -1}, 10);
    s.add_noise_halves(0.1);
    NlmParams flat;
    for (NlmCandidate& c : flat.candidates) c.k = 1e4f;
    flat.fade_error = 0;
    const double window = double((2 * flat.radius + 1) * (2 * flat.radius + 1));
    for (const bool default_weights : {false, true}) {
        NlmParams params = flat;
        if (default_weights)
            for (int c = 0; c < kMaxNlmCandidates; ++c) params.candidates[c].k = NlmParams{}.candidates[c].k;
        const double factor = noise_factor(s.denoise_final(params), flat.radius, 0.1);
        if (!default_weights) {
            // About 180^2 / 289 independent windows: a spread of about 5 %.
            EXPECT_GT(factor, 0.8 / window);
            EXPECT_LT(factor, 1.2 / window);
        } else {
            // The patch distances keep part of the weights, but at least 1/20 of the variance goes.
            EXPECT_LT(factor, 0.05) << "plain window mean: " << 1 / window;
        }
    }
}

// Normals that turn from one pixel to the next (small spheres, a bumpy surface) under the
// same light: the candidate that crosses normals (the third, its normal stop at 32) takes
// the noise the two that stop at normals (128) leave; a crease at right angles
// (NormalEdgeIsKept) is still kept, its weight exp(-32) under that stop too.
TEST(Denoise, FinalFilterSmoothsShadingAcrossTurningNormals) {
    Synthetic s(96, 96);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> tilt(-0.8, 0.8);  // up to 40 degrees each way
    for (int y = 0; y < s.h; ++y)
        for (int x = 0; x < s.w; ++x) {
            const double a = tilt(rng), b = tilt(rng);
            s.set(x, y, 1.0, 0.5, normalize(Vec3{std::sin(a), std::sin(b), -1}), 10);
        }
    s.add_noise_halves(0.1);
    NlmParams normal_stops;  // the first two candidates only
    normal_stops.candidate_count = 2;
    const double with_stops = noise_factor(s.denoise_final(normal_stops), 6, 0.1);
    const double all = noise_factor(s.denoise_final(), 6, 0.1);
    // Measured: 0.126 of the raw variance left with the stops alone, 0.043 with all three.
    EXPECT_LT(all, 0.06);
    EXPECT_LT(all, 0.5 * with_stops);
}

// A firefly (one huge sample) lands in one half only and is clamped away; a highlight is in
// both halves and is kept.
TEST(Denoise, FinalFilterRemovesAFireflyAndKeepsAHighlight) {
    Synthetic s(64, 48);
    for (int y = 0; y < s.h; ++y)
        for (int x = 0; x < s.w; ++x) s.set(x, y, (x >= 40 && x < 42 && y >= 20 && y < 22) ? 5.0 : 0.5, 0.5, {0, 0, -1}, 10);
    s.add_noise_halves(0.05);
    const size_t fly = s.at(20, 20);
    s.half[0].pixels[fly] = Color(100.0);
    s.noisy.pixels[fly] = (s.half[0].pixels[fly] + s.half[1].pixels[fly]) * 0.5;
    s.variance[fly] = Color(50.f * 50.f / 8);  // as its samples would say
    const Image out = s.denoise_final();
    for (int y = 18; y <= 22; ++y)
        for (int x = 18; x <= 22; ++x) EXPECT_NEAR(out.at(x, y).y, 0.5, 0.1) << x << "," << y;
    for (int y = 20; y < 22; ++y)
        for (int x = 40; x < 42; ++x) EXPECT_NEAR(out.at(x, y).y, 5.0, 0.25) << x << "," << y;
    EXPECT_NEAR(out.at(43, 20).y, 0.5, 0.1);  // and it did not spread
}

// A dark surface beside thin noisy highlights on the same surface (same albedo, normal and
// depth: a glossy ball's dark side beside its highlights): the dark pixels' samples are all
// nearly dark, so the final filter must not light them with the highlights' noise.
TEST(Denoise, FinalFilterKeepsDarkPixelsBesideNoisyHighlightsDark) {
    Synthetic s(64, 48);
    auto bright = [](int x) { return x % 8 == 0; };  // a 1-pixel highlight every 8 columns
    for (int y = 0; y < s.h; ++y)
        for (int x = 0; x < s.w; ++x) s.set(x, y, bright(x) ? 2.0 : 0.01, 0.5, {0, 0, -1}, 10);
    // Halves of 8 samples: the highlights' relative error is 1, the dark pixels' 1 %.
    std::mt19937 rng(3);
    std::normal_distribution<double> g(0, 1);
    const size_t n = s.truth.pixels.size();
    for (int h = 0; h < 2; ++h) {
        s.half[h] = Image(s.w, s.h);
        s.half_count[h].assign(n, 8);
    }
    for (size_t i = 0; i < n; ++i) {
        const double mean = s.truth.pixels[i].y, sigma_half = bright(int(i % size_t(s.w))) ? 2.0 : 1e-4;
        for (int h = 0; h < 2; ++h) s.half[h].pixels[i] = Color(std::max(0.0, mean + sigma_half * g(rng)));
        s.noisy.pixels[i] = (s.half[0].pixels[i] + s.half[1].pixels[i]) * 0.5;
        s.variance[i] = Color(float(sigma_half * sigma_half / 2));
    }
    const Image out = s.denoise_final();
    // The dark columns' error, relative as relMSE weighs it ((x - 0.01)^2 / (0.01^2 + 0.01)),
    // stays far below what light from the highlights would add (their share of an average
    // over the window, about 0.25, gives 6); the raw dark pixels' own error is about 1e-6.
    double err = 0;
    int count = 0;
    for (int y = 0; y < s.h; ++y)
        for (int x = 0; x < s.w; ++x)
            if (!bright(x)) {
                err += std::pow(out.at(x, y).y - 0.01, 2) / (0.01 * 0.01 + 0.01);
                ++count;
            }
    EXPECT_LT(err / count, 0.01) << "raw: about 1e-6";
}

TEST(Denoise, ConvergedImageIsLeftAsItIs) {
    // A relative standard error far below the fade's: each filter's output is its input.
    Synthetic s(48, 48);
    for (int y = 0; y < s.h; ++y)
        for (int x = 0; x < s.w; ++x) s.set(x, y, 0.1 + 0.8 * ((x / 3 + y / 5) % 2), 0.5, {0, 0, -1}, 10);
    s.add_noise_halves(1e-5);
    for (const bool final : {false, true}) {
        const Image out = final ? s.denoise_final() : s.denoise();
        for (size_t i = 0; i < out.pixels.size(); ++i) ASSERT_NEAR(out.pixels[i].y, s.noisy.pixels[i].y, 2e-5) << final;
    }
}

// A Whitted render's anti-aliasing error falls about as 1/spp, and both filters only soften
// its edges past the first passes (docs/denoising.md): the display's filter smooths its first
// pass and leaves it raw from kWhittedRawSpp on; the final filter always leaves it raw.
TEST(Denoise, WhittedRenderIsRawPastItsFirstPasses) {
    const Scene scene = test::brief_scene(1, 32);
    ASSERT_EQ(scene.renderer.type, RendererType::wrt);
    const RenderScene rs = prepare_scene(scene);
    const RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    auto changed_pixels = [&](int passes, bool interactive) {
        RenderState state(32, 32);
        StopRule rule;
        rule.max_passes = passes;
        render_until(rs, settings, state, rule);
        DevelopOptions options;
        options.denoise = Denoise::on;
        options.interactive = interactive;
        options.sampling = settings;
        const Developed d = develop(rs, render_estimates(state, kLayerRadiance | develop_reads(options)), options, kLayerRadiance);
        int changed = 0;
        for (size_t i = 0; i < d.radiance.pixels.size(); ++i) changed += d.radiance.pixels[i] != d.raw.pixels[i];
        return changed;
    };
    EXPECT_GT(changed_pixels(1, true), 0);                              // the first pass is smoothed
    EXPECT_EQ(changed_pixels(int(kWhittedRawSpp), true), 0);            // then raw, bit for bit
    EXPECT_EQ(changed_pixels(1, false), 0);                             // the final filter: raw
}

TEST(Denoise, FeatureBuffersAverageTheCameraSamples) {
    // Scene 3 at 24x24: the averaged albedo lies between the centre ray's on edge pixels, and
    // equals it on flat ones; normals are unit inside surfaces, shorter nowhere else than at
    // silhouettes against nothing.
    const Scene scene = test::brief_scene(3, 24);
    const RenderScene rs = prepare_scene(scene);
    const RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    const SurfaceLayers centre = first_surface_layers(rs, 24, 24);
    const SurfaceLayers one = averaged_surface_layers(rs, settings, 24, 24, 1);
    const SurfaceLayers many = averaged_surface_layers(rs, settings, 24, 24, 16);
    int differ = 0, same = 0;
    for (size_t i = 0; i < centre.albedo.size(); ++i) {
        EXPECT_LE(length(many.normal[i]), 1 + 1e-9);
        if (length(many.albedo[i] - centre.albedo[i]) > 1e-6) ++differ;
        else ++same;
        // One sample is one camera ray's first surface: a unit normal or nothing.
        const double l = length(one.normal[i]);
        EXPECT_TRUE(std::abs(l - 1) < 1e-9 || l == 0) << l;
    }
    EXPECT_GT(differ, 10);  // edges are anti-aliased
    EXPECT_GT(same, 200);   // flat areas are not changed
}

TEST(Denoise, HalvesSplitTheSamplesIntoTwoIndependentSets) {
    const Scene scene = test::brief_scene(3, 16);
    const RenderScene rs = prepare_scene(scene);
    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    settings.allocation = Allocation::uniform;
    RenderState state(16, 16);
    state.track_halves();
    StopRule rule;
    rule.max_passes = 7;
    render_until(rs, settings, state, rule);
    const RenderState::Halves halves = state.halves();
    const Image mean = state.radiance();
    for (size_t i = 0; i < mean.pixels.size(); ++i) {
        ASSERT_EQ(halves.count[0][i], 4u);  // passes 1, 3, 5, 7
        ASSERT_EQ(halves.count[1][i], 3u);  // passes 2, 4, 6
        const Color joined = (halves.mean[0].pixels[i] * 4.0 + halves.mean[1].pixels[i] * 3.0) / 7.0;
        ASSERT_LT(length(joined - mean.pixels[i]), 1e-9 * (1 + length(mean.pixels[i])));
    }
    // The halves differ (independent samples), where the image is noisy.
    double diff = 0;
    for (size_t i = 0; i < mean.pixels.size(); ++i) diff += length(halves.mean[0].pixels[i] - halves.mean[1].pixels[i]);
    EXPECT_GT(diff, 0);
}

// render_pass keeps the halves: the second half's sum is, bit for bit, that of the sums'
// differences across passes 2, 4 and 6 (each pixel's sums before and after its pass), and a
// pass stopped before its first row changes no half.
TEST(Denoise, HalvesAreThePassesDifferencesOfTheSums) {
    const Scene scene = test::brief_scene(3, 16);
    const RenderScene rs = prepare_scene(scene);
    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    RenderState state(16, 16);
    state.track_halves();
    const size_t n = 16 * 16;
    std::vector<Color> second(n, Color());
    std::atomic<bool> stop{true};
    for (int pass = 0; pass < 7; ++pass) {
        std::vector<Color> before(n);
        for (size_t i = 0; i < n; ++i) before[i] = state.radiance_sum()[i] + state.radiance_compensation()[i];
        const RenderState::Halves kept = state.halves();
        EXPECT_FALSE(render_pass(rs, settings, state, &stop));
        const RenderState::Halves after_stop = state.halves();
        for (int h = 0; h < 2; ++h) {
            EXPECT_EQ(kept.count[h], after_stop.count[h]);
            EXPECT_EQ(kept.mean[h].pixels, after_stop.mean[h].pixels);
        }
        ASSERT_TRUE(render_pass(rs, settings, state));
        if (pass % 2 == 1)
            for (size_t i = 0; i < n; ++i)
                second[i] += -1.0 * before[i], second[i] += state.radiance_sum()[i] + state.radiance_compensation()[i];
    }
    const RenderState::Halves halves = state.halves();
    for (size_t i = 0; i < n; ++i) {
        ASSERT_EQ(halves.count[1][i], 3u);
        EXPECT_EQ(halves.mean[1].pixels[i], second[i] / 3.0) << i;
    }
}

// Path-traced: scene `n` at `size` px and `spp` (the halves tracked, as render --denoise
// does), developed raw and denoised by each filter (0: the interactive a-trous, 1: the final
// one), against a high-spp reference of the same settings (another seed), as relMSE of the
// luminance, over all pixels and over the reference's edges.
struct PathTraced {
    double raw_mse = 0, raw_edge_mse = 0;
    double mse[2] = {0, 0}, edge_mse[2] = {0, 0};
};

PathTraced path_traced(Scene scene, int size, int spp, int reference_spp) {
    scene.renderer.width = scene.renderer.height = size;
    const RenderScene rs = prepare_scene(scene);
    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    auto render = [&](int passes, uint64_t seed) {
        RenderSettings s = settings;
        s.seed = seed;
        s.allocation = Allocation::uniform;
        RenderState state(size, size);
        state.track_halves();
        StopRule rule;
        rule.max_passes = passes;
        render_until(rs, s, state, rule);
        return state;
    };
    const Image reference = render(reference_spp, 99).radiance();
    const RenderState state = render(spp, 1);
    const RenderEstimates estimates = render_estimates(state, kAllLayers | kLayerHalves);
    EXPECT_EQ(estimates.halves.count[1].size(), size_t(size) * size_t(size));
    PathTraced out;
    for (int f = 0; f < 2; ++f) {
        DevelopOptions options;
        options.denoise = Denoise::on;
        options.interactive = f == 0;
        options.sampling = settings;
        options.sampling.seed = 1;
        const Developed developed = develop(rs, estimates, options, kLayerRadiance);
        // Edge pixels: where the reference's luminance changes by more than 20 % to a neighbour.
        for (int y = 1; y < size - 1; ++y)
            for (int x = 1; x < size - 1; ++x) {
                const double ref = luminance(reference.at(x, y));
                const double raw = luminance(developed.raw.at(x, y)) - ref, den = luminance(developed.radiance.at(x, y)) - ref;
                // relMSE: the squared error over the reference's square (plus 0.01), so that the
                // light's pixels do not decide it.
                const double scale = 1 / (ref * ref + 0.01);
                if (f == 0) out.raw_mse += raw * raw * scale;
                out.mse[f] += den * den * scale;
                bool edge = false;
                for (const auto [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}})
                    edge |= std::abs(luminance(reference.at(x + dx, y + dy)) - ref) > 0.2 * std::max(ref, 1e-3);
                if (edge) {
                    if (f == 0) out.raw_edge_mse += raw * raw * scale;
                    out.edge_mse[f] += den * den * scale;
                }
            }
    }
    return out;
}

// Both filters: less than half the raw error, and less on the reference's edges.
void expect_closer_than_raw(const PathTraced& r) {
    for (int f = 0; f < 2; ++f) {
        EXPECT_LT(r.mse[f], 0.5 * r.raw_mse) << (f ? "final " : "a-trous ") << r.raw_mse << " " << r.mse[f];
        EXPECT_LT(r.edge_mse[f], r.raw_edge_mse) << (f ? "final " : "a-trous ") << r.raw_edge_mse << " " << r.edge_mse[f];
    }
}

TEST(Denoise, PathTracedSceneIsCloserToTheReferenceThanRaw) {
    // The reference's own error (512 spp) is 1/128 of the raw 4 spp's: it does not decide.
    expect_closer_than_raw(path_traced(load_scene_file(test::brief_scene_file(3)).scene, 48, 4, 512));
}

TEST(Denoise, DepthOfFieldKeepsTheFocusBoundary) {
    // Scene 3 through its lens camera (aperture 1, focus at 14): blurred spheres over the
    // focused wall. Edge pixels include the blurred silhouettes.
    Scene scene = load_scene_file(test::brief_scene_file(3)).scene;
    for (size_t c = 0; c < scene.cameras.size(); ++c)
        if (scene.cameras[c].type == CameraType::lens) scene.camera = int(c);
    ASSERT_EQ(scene.cameras[size_t(scene.camera)].type, CameraType::lens);
    expect_closer_than_raw(path_traced(scene, 48, 4, 512));
}

TEST(Denoise, FlagTakesANameOrStandsAlone) {
    auto read = [](std::vector<std::string> words) {
        std::vector<char*> argv{const_cast<char*>("keithray"), const_cast<char*>("render")};
        for (std::string& w : words) argv.push_back(w.data());
        RenderOptions options;
        std::vector<std::string> rest;
        for (ArgCursor args(int(argv.size()), argv.data()); args.next();)
            if (!read_shared_flag(args, options)) rest.push_back(args.arg());
        return std::pair{options.denoise, rest};
    };
    EXPECT_EQ(read({"--denoise", "scene.json"}), (std::pair{std::optional{Denoise::on}, std::vector<std::string>{"scene.json"}}));
    EXPECT_EQ(read({"--denoise"}).first, Denoise::on);
    EXPECT_EQ(read({"--denoise", "off"}).first, Denoise::off);
    EXPECT_EQ(read({"--denoise", "on", "a.json"}).second, std::vector<std::string>{"a.json"});
    EXPECT_FALSE(read({"a.json"}).first.has_value());
}

TEST(Denoise, ExrKeepsTheRawRadianceAndTheFeatureBuffers) {
    const Scene scene = test::brief_scene(3, 16);
    const RenderScene rs = prepare_scene(scene);
    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    RenderState state(16, 16);
    StopRule rule;
    rule.max_passes = 2;
    render_until(rs, settings, state, rule);
    DevelopOptions options;
    options.denoise = Denoise::on;
    options.sampling = settings;
    const Developed d = develop(rs, render_estimates(state, kAllLayers), options, kAllLayers);
    const HdrImage read = decode_exr(encode_exr(hdr_from_developed(d)), "test.exr");
    ASSERT_EQ(read.raw.size(), 3u * 256);
    ASSERT_EQ(read.albedo.size(), 3u * 256);
    const Image raw = state.radiance();
    for (size_t i = 0; i < 256; ++i) {
        EXPECT_FLOAT_EQ(read.raw[3 * i + 1], float(raw.pixels[i].y));
        EXPECT_FLOAT_EQ(read.rgb[3 * i + 1], float(d.radiance.pixels[i].y));
    }
    // Without the denoiser nothing changes: no raw layer.
    const Developed plain = develop(rs, render_estimates(state, kAllLayers), DevelopOptions{}, kAllLayers);
    EXPECT_TRUE(hdr_from_developed(plain).raw.empty());
}

// `render --denoise` and the viewer's Save write through output_files, which reads the
// halves of the samples with the rest (develop_reads): their final filter's image is the one
// with the halves, not the one a caller that read the other layers alone would get.
TEST(Denoise, RenderOutputsFilterWithTheHalves) {
    const Scene scene = test::brief_scene(3, 32);
    const RenderScene rs = prepare_scene(scene);
    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    RenderState state(32, 32);
    state.track_halves();
    StopRule rule;
    rule.max_passes = 8;
    render_until(rs, settings, state, rule);
    OutputRequest request;
    request.path = "out.pfm";
    request.develop.denoise = Denoise::on;
    request.develop.sampling = settings;
    const std::vector<FileOutput> files = output_files(rs, state, request);
    const auto written = [&](unsigned layers) {
        return encode_outputs(request.path, develop(rs, render_estimates(state, layers), request.develop, kAllLayers),
                              request.display);
    };
    const std::vector<FileOutput> with_halves = written(kAllLayers | kLayerHalves), without = written(kAllLayers);
    ASSERT_FALSE(files.empty());
    ASSERT_EQ(with_halves.size(), files.size());
    EXPECT_EQ(files[0].bytes, with_halves[0].bytes);
    EXPECT_NE(files[0].bytes, without[0].bytes);  // the halves change the image
}

// A filter whose result depended on the unit of power would be wrong: both filters work in a
// unit of the image's own scale (docs/denoising.md), so scene 3 rendered with its lights at
// 1e-30, 1e-20 and 1e30 times their power develops into that factor times the image at
// power 1, to float rounding, and the filter changes as many pixels at every power. (Before,
// at 1e-30 the variance, then floats, was zero and nothing was filtered; at 1e30 infinite.)
// The paths are traced in double lanes with a uniform allocation, so that the renders
// themselves are proportional.
TEST(Denoise, BothFiltersAreProportionalToTheLightsPower) {
    const Scene base = test::brief_scene(3, 32);
    struct Result {
        Image denoised, raw;
    };
    auto develop_at = [&](double power, bool interactive) {
        Scene scene = base;
        for (Light& light : scene.lights) light.power = light.power * power;
        const RenderScene rs = prepare_scene(scene);
        RenderSettings settings = RenderSettings::from_scene(scene.renderer);
        settings.kernels = LaneChoice::double_lanes;
        settings.allocation = Allocation::uniform;
        RenderState state(32, 32);
        state.track_halves();
        StopRule rule;
        rule.max_passes = 6;
        render_until(rs, settings, state, rule);
        DevelopOptions options;
        options.denoise = Denoise::on;
        options.interactive = interactive;
        options.sampling = settings;
        Developed d = develop(rs, render_estimates(state, kLayerRadiance | develop_reads(options)), options, kLayerRadiance);
        return Result{std::move(d.radiance), std::move(d.raw)};
    };
    for (const bool interactive : {false, true}) {
        const Result unit = develop_at(1, interactive);
        int changed_at_one = 0;
        for (size_t i = 0; i < unit.raw.pixels.size(); ++i) changed_at_one += unit.denoised.pixels[i] != unit.raw.pixels[i];
        EXPECT_GT(changed_at_one, 400) << interactive;  // of 1024: the filter does filter
        for (const double power : {1e-30, 1e-20, 1e30}) {
            const Result scaled = develop_at(power, interactive);
            int changed = 0;
            double worst = 0;
            for (size_t i = 0; i < unit.raw.pixels.size(); ++i) {
                changed += scaled.denoised.pixels[i] != scaled.raw.pixels[i];
                for (int k = 0; k < 3; ++k) {
                    const double expected = unit.denoised.pixels[i][k] * power, got = scaled.denoised.pixels[i][k];
                    worst = std::max(worst, std::fabs(got - expected) / (std::fabs(expected) + 1e-300));
                }
            }
            EXPECT_EQ(changed, changed_at_one) << interactive << " at power " << power;
            EXPECT_LT(worst, 1e-5) << interactive << " at power " << power;  // float planes' rounding
        }
    }
}

TEST(Denoise, ViewerShowsRawDenoisedOrSplit) {
    viewer::Snapshot frame;
    frame.radiance = Image(4, 2);
    frame.denoised = Image(4, 2);
    for (Color& c : frame.denoised.pixels) c = Color(1.0);
    using viewer::DenoiseView;
    EXPECT_EQ(viewer::shown_radiance(frame, DenoiseView::off).at(3, 1).x, 0.0);
    EXPECT_EQ(viewer::shown_radiance(frame, DenoiseView::on).at(0, 0).x, 1.0);
    const Image split = viewer::shown_radiance(frame, DenoiseView::split);
    EXPECT_EQ(split.at(1, 1).x, 0.0);
    EXPECT_EQ(split.at(2, 1).x, 1.0);
    EXPECT_EQ(viewer::shown_word(frame, DenoiseView::split), "split");
    // The display uploads the frame's own image where the shown one is it whole.
    EXPECT_EQ(viewer::shown_image_in_place(frame, DenoiseView::off), &frame.radiance);
    EXPECT_EQ(viewer::shown_image_in_place(frame, DenoiseView::on, 4, 2), &frame.denoised);
    EXPECT_EQ(viewer::shown_image_in_place(frame, DenoiseView::split), nullptr);
    frame.scale = 2;  // a preview of an 8x4 image: upscaled
    EXPECT_EQ(viewer::shown_image_in_place(frame, DenoiseView::on, 8, 4), nullptr);
    frame.scale = 1;
    frame.denoised = Image();  // a frame the worker did not denoise shows raw
    EXPECT_EQ(viewer::shown_word(frame, DenoiseView::on), "raw");
    EXPECT_EQ(viewer::shown_image_in_place(frame, DenoiseView::on), &frame.radiance);
}

// bench/denoise_scenes.py, the scenes the denoiser's goals are measured on
// (scripts/bench_denoise.sh): the same seed writes the same bytes, every scene loads without
// a warning and prepares for rendering, and they have what the generator promises (5 to 200
// spheres besides the floor, walls and lamps; 1 to 3 lights).
class GeneratedScenes : public test::ScratchDirTest {};

TEST_F(GeneratedScenes, AreDeterministicByTheirSeedAndLoad) {
    const std::filesystem::path script =
        std::filesystem::path(KEITHRAY_RES_DIR).parent_path() / "bench" / "denoise_scenes.py";
    for (const char* out : {"a", "b"}) {
        const test::CommandResult run = test::run_command(
            "python3 '" + script.string() + "' '" + (dir / out).string() + "' --tune 2 --eval 3 --size 32", dir);
        ASSERT_EQ(run.status, 0) << run.err;
    }
    std::vector<std::string> texts;
    for (const char* name : {"tune_00", "tune_01", "eval_00", "eval_01", "eval_02"}) {
        const std::filesystem::path a = dir / "a" / (std::string(name) + ".json"), b = dir / "b" / (std::string(name) + ".json");
        const std::string text = read_scene_text(a);
        EXPECT_EQ(text, read_scene_text(b)) << name;
        texts.push_back(text);
        const LoadedScene loaded = load_scene_file(a);
        EXPECT_TRUE(loaded.warnings.empty()) << name << ": " << (loaded.warnings.empty() ? "" : loaded.warnings[0]);
        const Scene& scene = loaded.scene;
        int spheres = 0;
        for (const Primitive& prim : scene.primitives) {
            const std::string& id = scene.shapes[size_t(prim.shape)].id;
            spheres += prim.type == PrimitiveType::geometric && id != "floor" && id != "back" && id != "left" &&
                       id != "right";
        }
        EXPECT_GE(spheres, 5) << name;
        EXPECT_LE(spheres, 200) << name;
        EXPECT_GE(scene.active_lights.size(), 1u) << name;
        EXPECT_LE(scene.active_lights.size(), 3u) << name;
        EXPECT_EQ(scene.renderer.width, 32) << name;
        EXPECT_NO_THROW((void)prepare_scene(scene)) << name;
    }
    // Each seed its own scene.
    for (size_t i = 0; i < texts.size(); ++i)
        for (size_t j = i + 1; j < texts.size(); ++j) EXPECT_NE(texts[i], texts[j]) << i << " " << j;
}

}  // namespace
}  // namespace kr
