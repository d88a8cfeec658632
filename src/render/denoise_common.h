// What both denoisers of render/denoise.h share: the planes they prepare from their input
// (in the image's own unit of radiance, the albedo divided out), the variance helpers and the
// last step (the albedo multiplied back, the result faded towards the raw radiance as a pixel
// converges). denoise_atrous.cpp and denoise_nlmeans.cpp hold the two filters.
#pragma once

#include <algorithm>
#include <vector>

#include "render/denoise.h"

namespace kr::denoising {

inline constexpr float kLum[3] = {0.2126f, 0.7152f, 0.0722f};  // luminance(), core/math.h
// Added to the albedo before dividing it out: a black or missing first surface (a light, the
// background) is then filtered as radiance, and no division blows up.
inline constexpr float kAlbedoFloor = 0.02f;

// exp(-x) for x >= 0 as (1 - x/16)^16: within 0.02 of it, zero beyond 16, and plain
// arithmetic the compiler vectorises (an edge stop needs its shape, not its digits).
inline float fast_exp_neg(float x) {
    float y = std::max(0.f, 1.f - x * (1.f / 16));
    y *= y;
    y *= y;
    y *= y;
    return y * y;
}

// Where a pixel's variance is unknown (one sample): the luminance's variance over its 3x3
// neighbourhood, the variance of one sample where the neighbours are alike.
void fill_unknown_variance(int w, int h, const std::vector<float>& lum, std::vector<float>& var);

// 3x3 binomial blur of a plane (borders renormalised): SVGF's prefilter of the variance
// before it scales the luminance stop.
void blur3(int w, int h, const std::vector<float>& v, std::vector<float>& out);

// Both filters' start: the caller's workspace (or `local`) with its base planes prepared for
// `input` (its size, unit, demodulated radiance, albedo, features, depth and its gradient,
// luminances and variances, the unknown ones filled). Throws std::invalid_argument where a
// feature buffer's size is not the image's.
DenoiseWorkspace& prepared_planes(const DenoiseInput& input, DenoiseWorkspace* workspace, DenoiseWorkspace& local);

// The last step of both filters: the filtered demodulated radiance (p.base.radiance) times
// the albedo, then faded towards the raw radiance as its relative standard error drops (the
// 3x3-prefiltered raw variance against the filtered luminance), so a converged pixel keeps its
// raw value. A pixel whose filtered radiance is NaN keeps its raw value exactly.
void remodulate_and_fade(const DenoiseInput& input, float fade_error, DenoiseWorkspace& p, Image& out);

}  // namespace kr::denoising
