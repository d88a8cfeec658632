// Comparing a test image with a reference: error figures, a statistical test of two Monte
// Carlo renders against each other, and a false-colour picture of the error.
#pragma once

#include <string>
#include <vector>

#include "core/image.h"
#include "core/image_hdr.h"

namespace kr {

// Error of `test` against `reference` over every pixel and channel: root mean square, and
// relative MSE, the mean of (t - r)^2 / (r^2 + 0.01) (the 0.01 keeps dark pixels from
// dominating). Per pixel, `pixel_error` holds the RMS over the channels.
struct ImageErrors {
    double rmse = 0, relmse = 0;
    std::vector<float> pixel_error;
};
// On the radiance of two HDR images of one size (throws std::invalid_argument otherwise).
ImageErrors radiance_errors(const HdrImage& test, const HdrImage& reference);
// On 8-bit values scaled to [0, 1].
ImageErrors rgb8_errors(const Rgb8Image& test, const Rgb8Image& reference);

// The hypothesis that two renders are unbiased estimates of one image, from each pixel's mean
// and variance of the mean (each pixel's sample variance raised to its 3x3 neighbourhood's mean
// where that is larger, where the samples layer gives the counts). Per block and channel, the difference of the two block means over
// its standard error (Welch: the two images' variances add, and Welch-Satterthwaite's degrees
// of freedom turn the t value into an equivalent normal z), for blocks of `block` pixels a
// side, then twice that, and so on up to the whole image. The images disagree when the largest
// |z| passes the Bonferroni limit for alpha/2 over all those tests (a local change, or one
// over a region at the block size that covers it), or the sum of z^2 over the smallest blocks
// passes the chi-square limit at alpha/2 (a change spread thinly over the image): alpha in all
// is the false-alarm rate.
struct StatisticalSettings {
    double alpha = 1e-4;
    int block = 8;
};
struct StatisticalResult {
    bool agree = true;
    size_t tests = 0;  // blocks of every size x 3 channels
    double max_abs_z = 0, z_limit = 0;
    int worst_x = 0, worst_y = 0, worst_size = 0, worst_channel = 0;  // the worst block: top-left pixel, side
    double chi_square = 0, chi_square_limit = 0;
    std::vector<float> pixel_z;  // per pixel, the largest |z| of its own difference over the channels
};
// The means the test compares: a denoised render's raw radiance (its raw.R/G/B layer, the
// mean its variance layer belongs to) where the image holds one, else its R, G, B.
const std::vector<float>& tested_radiance(const HdrImage& image);
// Throws std::runtime_error naming the file when a variance layer is missing or a pixel has
// no variance estimate (fewer than two samples), std::invalid_argument when sizes differ.
StatisticalResult statistical_compare(const HdrImage& test, const std::string& test_name, const HdrImage& reference,
                                      const std::string& reference_name, const StatisticalSettings& settings);

// The upper quantile of the standard normal distribution: z with P(Z > z) = p.
double normal_upper_quantile(double p);

// Viridis at v in [0, 1] (clamped; NaN is the top colour), dark to bright.
std::array<uint8_t, 3> viridis(double v);
// Per pixel, viridis of value / scale: the picture alone, width x height.
Rgb8Image false_colour_picture(const std::vector<float>& values, int width, int height, double scale);

// A false-colour picture of a per-pixel error (viridis from 0 to `scale`, brighter is larger,
// values above saturate), with a colour bar under it labelled 0 and `scale`.
Rgb8Image false_colour(const std::vector<float>& error, int width, int height, double scale);

}  // namespace kr
