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

// off: the raw estimate; on: the edge-avoiding a-trous filter (denoise_atrous).
enum class Denoise { off, on };
inline constexpr EnumNames<Denoise, 2> denoise_names{{"off", "on"}};

// What a denoiser reads, all width x height, row-major.
struct DenoiseInput {
    const Image* radiance = nullptr;  // the mean radiance
    std::span<const float> variance;  // 3 per pixel: the variance of the mean (infinite: unknown)
    std::span<const float> albedo;    // 3 per pixel: first-surface albedo, averaged
    std::span<const float> normal;    // 3 per pixel: first-surface normal, averaged (shorter at silhouettes)
    std::span<const double> depth;    // the mean primary hit distance
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
    std::vector<float> c[3], c2[3];  // demodulated radiance (and the next pass's)
    std::vector<float> var, var2;    // variance of its luminance (of the mean)
    std::vector<float> demod[3];     // albedo + floor
    std::vector<float> f[4];         // unit feature: normal and coverage by nothing
    std::vector<float> z, zgrad;     // depth and its local gradient (per pixel step)
    std::vector<float> raw_var;      // variance of the raw radiance's luminance
    std::vector<float> lum, lum_raw, inv_l, inv_z, var_blur;  // per-pass scratch
};
Image denoise_atrous(const DenoiseInput& input, const AtrousParams& params = {}, DenoiseWorkspace* workspace = nullptr);

// Working memory of the filter and its feature buffers, per pixel (render_memory_bytes).
inline constexpr uint64_t kDenoiseBytesPerPixel = 40 * sizeof(float) + sizeof(Color);

}  // namespace kr
