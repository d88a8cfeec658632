// Denoisers of a render's mean radiance, guided by its feature buffers (the first-surface
// albedo and normal averaged over each pixel's camera samples, render/aov.h; the mean depth)
// and its per-pixel variance. A denoised image is biased: `compare --statistical` tests raw
// images. The develop step of render/outputs.h runs them, so `render --denoise`, the viewer's
// display and its Save give the same image.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/enum_names.h"
#include "core/image.h"

namespace kr {

// off: the raw estimate; on: denoised (render and the viewer's Save: the final filter,
// denoise_nlmeans; the viewer's live display: the interactive one, denoise_atrous).
enum class Denoise { off, on };
inline constexpr EnumNames<Denoise, 2> denoise_names{{"off", "on"}};

// What a denoiser reads, all width x height, row-major.
struct DenoiseInput {
    const Image* radiance = nullptr;  // the mean radiance
    // Per pixel and channel the variance of the mean (infinite: unknown), in double: a render
    // at a light power of 1e30 has variances of about 1e60, at 1e-30 about 1e-60, infinite or
    // zero as floats; the filters take it over their unit's square (DenoiseWorkspace::unit).
    std::span<const Color> variance;
    std::span<const float> albedo;    // 3 per pixel: first-surface albedo, averaged
    std::span<const float> normal;    // 3 per pixel: first-surface normal, averaged (shorter at silhouettes)
    std::span<const double> depth;    // the mean primary hit distance
    // The final filter's two independent halves of each pixel's samples (RenderState::halves):
    // their means and counts. Absent (null), or a pixel with an empty half: that pixel's
    // distances are taken on the mean itself.
    const Image* half[2] = {nullptr, nullptr};
    std::span<const uint32_t> half_count[2];
};

// The interactive filter's parameters (docs/denoising.md says how they were chosen).
struct AtrousParams {
    int iterations = 5;            // 3x3 B-spline taps at steps 1, 2, 4, ...: reach 2^iterations - 1 pixels
    float sigma_luminance = 4;     // luminance stop in local standard deviations (0: no luminance stop)
    float sigma_normal = 128;      // normal stop: exp(-sigma (1 - n.n'))
    float sigma_depth = 1;         // depth stop in units of the local depth gradient times the step
    float fade_error = 0.01f;      // relative standard error at which the result is half raw (0: never fade)
};

// The edge-avoiding a-trous wavelet filter (Dammertz et al. 2010, with SVGF's variance-scaled
// luminance stop, Schied et al. 2017): the albedo divided out, `iterations` passes of a 3x3
// B-spline with holes weighted by edge stops on normal, depth and luminance (scaled by the
// filtered standard deviation, propagated through the passes), the albedo multiplied back,
// then blended towards the raw radiance as a pixel's relative standard error drops, so a
// converged image is left as it is. Parallel over rows (OpenMP); the inner loops run along
// rows over planes of floats, which the compiler vectorises.
// The filter's working planes, one per channel and feature so that a tap's loop along a row
// reads each contiguously. A caller that denoises often (the viewer's render thread) keeps
// one between calls: fresh memory's page faults cost about as much as the filter.
struct DenoiseWorkspace {
    int w = 0, h = 0;
    // The unit of radiance the planes hold (a robust scale of the image, so that the result
    // is proportional to the light's power) and the factor from the input's variance to the
    // planes' (one over the unit's square).
    double unit = 1, var_scale = 1;
    std::vector<float> c[3], c2[3];  // demodulated radiance (and the next pass's)
    std::vector<float> var, var2;    // variance of its luminance (of the mean)
    std::vector<float> demod[3];     // albedo + floor
    std::vector<float> f[4];         // unit feature: normal and coverage by nothing
    std::vector<float> z, zgrad;     // depth and its local gradient (per pixel step)
    std::vector<float> raw_var;      // variance of the raw radiance's luminance
    std::vector<float> lum, lum2, lum_raw, var_blur;  // luminance of c (of c2), of the raw radiance; scratch
    // The final filter's: per half, the demodulated radiance and its variance, the patch
    // distances of one offset (summed along rows), the filtered sums and weights; per half the
    // pixel's own variance (not prefiltered, summed over the channels); per candidate the
    // pixel's own estimate of what filtering gains.
    std::vector<float> u[2][3], v[2][3], hbox[2], acc[2][4], cand[3][4], own_var[2], own_gain[2];
    std::vector<uint8_t> clamped;  // per pixel: a half was clamped (a firefly)
};
Image denoise_atrous(const DenoiseInput& input, const AtrousParams& params = {}, DenoiseWorkspace* workspace = nullptr);

// The final filter's parameters (docs/denoising.md says how they were chosen).
struct NlmParams {
    int radius = 5;             // search window: (2 radius + 1)^2 pixels
    int patch = 1;              // patch: (2 patch + 1)^2 pixels
    float k = 0.45f;            // patch distance scale, in standard deviations of the difference
    float k_weak = 0.25f;       // the second candidate's (per pixel the one of least estimated error)
    int select_radius = 3;      // the estimated relative errors are averaged over (2 r + 1)^2 pixels
    float own_error_stop = 300;  // a filtered value this many of the pixel's own standard errors off is refused
    float sigma_normal = 128;   // normal stop: exp(-sigma (1 - n.n'))
    float sigma_albedo = 0.1f;  // albedo stop: exp(-|a - a'|^2 / sigma^2)
    float sigma_depth = 1;      // depth stop in units of the local depth gradient times the offset
    float fade_error = 0.01f;   // as AtrousParams::fade_error
};

// The final-quality filter: joint non-local means (Buades et al. 2005) with the patch
// distance of Rousselle, Knaus and Zwicker 2012 (squared differences less their expected
// noise, over the variance of the difference) taken on the albedo-demodulated radiance,
// times edge stops on normal, albedo and depth. Each half of the samples is filtered with
// weights from the other half, so each filtered half is linear in its own samples and Stein's
// unbiased risk estimate gives its error; per pixel, of the two strengths (k, k_weak) and
// the raw mean, the one of least risk relative to the pixel's squared luminance (averaged
// over a small box) is kept, with the pixel's own samples overruling the box where they are
// decisive (docs/denoising.md). The halves are
// averaged, the albedo multiplied back, and the result faded towards the raw radiance as a
// pixel converges, as denoise_atrous does. Parallel over rows (OpenMP); the result does not
// depend on the thread count.
Image denoise_nlmeans(const DenoiseInput& input, const NlmParams& params = {}, DenoiseWorkspace* workspace = nullptr);

// Working memory of the filter and its feature buffers, per pixel (render_memory_bytes).
// The final filter's planes (DenoiseWorkspace::u ...) and its halves (two Images and counts).
// The estimates' variance is in double while the filter runs (3 floats more than its layer).
inline constexpr uint64_t kDenoiseBytesPerPixel =
    (39 + 38 + 3) * sizeof(float) + 1 + 3 * sizeof(Color) + 2 * sizeof(uint32_t);

}  // namespace kr
