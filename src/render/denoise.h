// Denoisers of a render's mean radiance, guided by its feature buffers (the first-surface
// albedo and normal averaged over each pixel's camera samples, render/aov.h; the mean depth)
// and its per-pixel variance. A denoised image is biased: `compare --statistical` tests raw
// images. The develop step of render/outputs.h runs them, so `render --denoise`, the viewer's
// display and its Save give the same image.
#pragma once

#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include "core/denoise_mode.h"
#include "core/enum_names.h"
#include "core/image.h"

namespace kr {

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
    // The final filter's two independent halves of each pixel's samples (Film::halves):
    // their means and counts. Absent (null), or a pixel with an empty half: that pixel's
    // distances are taken on the mean itself.
    const Image* half[2] = {nullptr, nullptr};
    std::span<const uint32_t> half_count[2];
};

// One of the final filter's candidates: a non-local means filter of the halves, its own
// patch distance scale and normal stop (the other stops are shared).
struct NlmCandidate {
    float k;             // patch distance scale, in standard deviations of the difference
    float sigma_normal;  // normal stop: exp(-sigma (1 - n.n')); 0: none
};
inline constexpr int kMaxNlmCandidates = 3;

// The interactive filter's parameters (docs/denoising.md says how they were chosen).
struct AtrousParams {
    int iterations = 5;            // 3x3 B-spline taps at steps 1, 2, 4, ...: reach 2^iterations - 1 pixels
    float sigma_luminance = 4;     // luminance stop in local standard deviations (0: no luminance stop)
    float sigma_normal = 128;      // normal stop: exp(-sigma (1 - n.n'))
    float sigma_depth = 1;         // depth stop in units of the local depth gradient times the step
    float fade_error = 0.01f;      // relative standard error at which the result is half raw (0: never fade)
};

// The filters' working planes, one per channel and feature so that a tap's loop along a row
// reads each contiguously: every member of the three structs below is one float plane of
// w x h (plane_count counts them).
// What both filters prepare from their input (denoise_common.cpp), in the filter's unit of
// radiance (DenoiseWorkspace::unit).
struct DenoiseBasePlanes {
    std::vector<float> radiance[3];     // the demodulated radiance (the a-trous pass's input)
    std::vector<float> albedo[3];       // the albedo plus a floor, which demodulation divides out
    std::vector<float> feature[4];      // unit feature vector: the normal and coverage by nothing
    std::vector<float> variance;        // the variance of the demodulated luminance (of the mean)
    std::vector<float> raw_variance;    // the variance of the raw radiance's luminance
    std::vector<float> depth, depth_gradient;  // the depth and its local gradient (per pixel step)
    std::vector<float> luminance, raw_luminance;  // of the demodulated radiance, of the raw one
    std::vector<float> scratch;         // a plane each step borrows (a prefiltered variance)
};
// The a-trous filter's own: the next pass's demodulated radiance, variance and luminance.
struct DenoiseAtrousPlanes {
    std::vector<float> radiance[3], variance, luminance;
};
// The final filter's own, per half of the samples (g) or per candidate (c).
struct DenoiseNlmPlanes {
    std::vector<float> half_radiance[2][3];  // [g][channel]: the demodulated radiance, a guide
    std::vector<float> half_variance[2][3];  // [g][channel]: its mean's variance, 3x3-prefiltered
    std::vector<float> distance[2];          // [g]: the patch distances of one offset, summed along rows
    std::vector<float> sums[kMaxNlmCandidates][2][4];  // [c][g]: the filtered sums of the three channels and of the weights
    std::vector<float> own_variance[2];      // [g]: the pixel's own variance, summed over the channels
    std::vector<float> candidate[kMaxNlmCandidates][4];  // [c]: the filtered image, then its relative gain (box mean)
    std::vector<float> own_gain[kMaxNlmCandidates];      // [c]: the pixel's own estimate of that gain
};
// The float planes per pixel of one of the structs above.
template <class Planes>
constexpr uint64_t plane_count() {
    static_assert(sizeof(Planes) % sizeof(std::vector<float>) == 0, "a plane struct holds float planes only");
    return sizeof(Planes) / sizeof(std::vector<float>);
}

// A caller that denoises often (the viewer's render thread) keeps one between calls: fresh
// memory's page faults cost about as much as the filter.
struct DenoiseWorkspace {
    int w = 0, h = 0;
    // The unit of radiance the planes hold (a robust scale of the image, so that the result
    // is proportional to the light's power) and the factor from the input's variance to the
    // planes' (one over the unit's square).
    double unit = 1, var_scale = 1;
    DenoiseBasePlanes base;
    DenoiseAtrousPlanes atrous;
    DenoiseNlmPlanes nlm;
    std::vector<uint8_t> clamped;  // the final filter's, per pixel: a half was clamped (a firefly)

    // What a workspace holds per pixel once both filters have run in it.
    static constexpr uint64_t kBytesPerPixel =
        sizeof(float) * (plane_count<DenoiseBasePlanes>() + plane_count<DenoiseAtrousPlanes>() +
                         plane_count<DenoiseNlmPlanes>()) +
        sizeof(uint8_t);
};

// The edge-avoiding a-trous wavelet filter (Dammertz et al. 2010, with SVGF's variance-scaled
// luminance stop, Schied et al. 2017): the albedo divided out, `iterations` passes of a 3x3
// B-spline with holes weighted by edge stops on normal, depth and luminance (scaled by the
// filtered standard deviation, propagated through the passes), the albedo multiplied back,
// then blended towards the raw radiance as a pixel's relative standard error drops, so a
// converged image is left as it is. Parallel over rows (OpenMP); the inner loops run along
// rows over planes of floats, which the compiler vectorises (denoise_atrous.cpp). Once
// `cancel` is set (by another thread) it stops before its next pass and returns an empty image.
Image denoise_atrous(const DenoiseInput& input, const AtrousParams& params = {}, DenoiseWorkspace* workspace = nullptr,
                     const std::atomic<bool>* cancel = nullptr);

// The final filter's parameters (docs/denoising.md says how they were chosen).
struct NlmParams {
    int radius = 5;             // search window: (2 radius + 1)^2 pixels
    int patch = 1;              // patch: (2 patch + 1)^2 pixels
    // The filters the selection chooses from per pixel besides the raw mean, all made in one
    // sweep over the window's offsets: a strong and a weak one that stop at normals, and a
    // stronger one that crosses them (the shading of small spheres, whose normals turn from
    // one pixel to the next).
    NlmCandidate candidates[kMaxNlmCandidates] = {{0.45f, 128}, {0.25f, 128}, {0.6f, 32}};
    int candidate_count = kMaxNlmCandidates;  // the first this many are made (1 to kMaxNlmCandidates)
    int select_radius = 3;      // the estimated relative errors are averaged over (2 r + 1)^2 pixels
    float own_error_stop = 300;  // a filtered value this many of the pixel's own standard errors off is refused
    float sigma_albedo = 0.1f;  // albedo stop: exp(-|a - a'|^2 / sigma^2)
    float sigma_depth = 1;      // depth stop in units of the local depth gradient times the offset
    float fade_error = 0.01f;   // as AtrousParams::fade_error
};

// The final-quality filter: joint non-local means (Buades et al. 2005) with the patch
// distance of Rousselle, Knaus and Zwicker 2012 (squared differences less their expected
// noise, over the variance of the difference) taken on the albedo-demodulated radiance,
// times edge stops on normal, albedo and depth. Each half of the samples is filtered with
// weights from the other half, so each filtered half is linear in its own samples and Stein's
// unbiased risk estimate gives its error; per pixel, of the candidates and the raw mean, the
// one of least risk relative to the pixel's squared luminance (averaged over a small box) is
// kept, with the pixel's own samples overruling the box where they are decisive
// (docs/denoising.md). The halves are averaged, the albedo multiplied back, and the result
// faded towards the raw radiance as a pixel converges, as denoise_atrous does. Parallel over
// rows (OpenMP); the result does not depend on the thread count (denoise_nlmeans.cpp).
Image denoise_nlmeans(const DenoiseInput& input, const NlmParams& params = {}, DenoiseWorkspace* workspace = nullptr);

// Working memory of the filters, per pixel (render_memory_bytes): the workspace, the feature
// buffers (albedo and normal), the estimates' variance in double while the filter runs (3
// floats more than its layer), the final filter's halves (two Images and their counts) and
// the denoised Image.
inline constexpr uint64_t kDenoiseBytesPerPixel = DenoiseWorkspace::kBytesPerPixel + 2 * 3 * sizeof(float) +
                                                  3 * sizeof(float) + 2 * (sizeof(Color) + sizeof(uint32_t)) +
                                                  sizeof(Color);

}  // namespace kr
