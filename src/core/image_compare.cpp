#include "core/image_compare.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "core/text.h"

namespace kr {

namespace {

constexpr double kRelMseEpsilon = 0.01;

ImageErrors errors_of(size_t pixels, auto value_pair) {
    ImageErrors out;
    out.pixel_error.resize(pixels);
    double sum_sq = 0, sum_rel = 0;
    for (size_t i = 0; i < pixels; ++i) {
        double pixel_sq = 0;
        for (int k = 0; k < 3; ++k) {
            const auto [t, r] = value_pair(3 * i + size_t(k));
            const double d = t - r;
            pixel_sq += d * d;
            sum_rel += d * d / (r * r + kRelMseEpsilon);
        }
        sum_sq += pixel_sq;
        out.pixel_error[i] = float(std::sqrt(pixel_sq / 3));
    }
    const double count = double(std::max<size_t>(3 * pixels, 1));
    out.rmse = std::sqrt(sum_sq / count);
    out.relmse = sum_rel / count;
    return out;
}

}  // namespace

ImageErrors radiance_errors(const HdrImage& test, const HdrImage& reference) {
    if (test.width != reference.width || test.height != reference.height || test.rgb.size() != reference.rgb.size())
        throw std::invalid_argument("images differ in size");
    return errors_of(test.pixel_count(), [&](size_t j) {
        return std::pair<double, double>(test.rgb[j], reference.rgb[j]);
    });
}

ImageErrors rgb8_errors(const Rgb8Image& test, const Rgb8Image& reference) {
    if (test.width != reference.width || test.height != reference.height || test.bytes.size() != reference.bytes.size())
        throw std::invalid_argument("images differ in size");
    return errors_of(test.bytes.size() / 3, [&](size_t j) {
        return std::pair<double, double>(test.bytes[j] / 255.0, reference.bytes[j] / 255.0);
    });
}

double normal_upper_quantile(double p) {
    if (!(p > 0)) return std::numeric_limits<double>::infinity();
    if (p >= 0.5) return 0;
    // Bisection on the tail 0.5 erfc(z / sqrt 2), decreasing in z; 200 halvings reach double's resolution.
    double lo = 0, hi = 40;
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

const std::vector<float>& tested_radiance(const HdrImage& image) {
    return image.raw.size() == image.rgb.size() ? image.raw : image.rgb;
}

StatisticalResult statistical_compare(const HdrImage& test, const std::string& test_name, const HdrImage& reference,
                                      const std::string& reference_name, const StatisticalSettings& settings) {
    if (test.width != reference.width || test.height != reference.height)
        throw std::invalid_argument(test_name + " is " + std::to_string(test.width) + "x" + std::to_string(test.height) +
                                    " but " + reference_name + " is " + std::to_string(reference.width) + "x" +
                                    std::to_string(reference.height));
    const size_t n = test.pixel_count();
    const std::pair<const HdrImage*, const std::string*> inputs[] = {{&test, &test_name}, {&reference, &reference_name}};
    for (const auto& [image, name] : inputs)
        if (image->variance.size() != 3 * n)
            throw std::runtime_error(show_user_text(*name) + ": --statistical needs the variance layer (variance.R/G/B) of an EXR "
                                             "render; this image has none");
    for (const auto& [image, name] : inputs)
        for (size_t i = 0; i < 3 * n; ++i)
            if (!std::isfinite(image->variance[i]) || image->variance[i] < 0)
                throw std::runtime_error(show_user_text(*name) + ": pixel (" + std::to_string(i / 3 % size_t(image->width)) + ", " +
                                         std::to_string(i / 3 / size_t(image->width)) +
                                         ") has no variance estimate (fewer than 2 samples, or squares beyond a double's range); "
                                         "--statistical needs at least 2 per pixel");
    // The means tested: a denoised render's raw ones (raw.R/G/B), which its variance layer
    // describes; its R, G, B are biased by the filter.
    const std::vector<float>& test_rgb = tested_radiance(test);
    const std::vector<float>& reference_rgb = tested_radiance(reference);
    // Degrees of freedom of a pixel's variance: its sample count less one (a file without the
    // samples layer is taken as large-sample).
    auto dof = [](const HdrImage& image, size_t i) {
        return image.samples.empty() ? 1e9 : std::max(1.0, double(image.samples[i]) - 1);
    };
    // Float storage rounds equal means of noiseless pixels apart by about 2^-24 of their value:
    // a variance floor of that size keeps such pixels from reading as a change.
    auto rounding_floor = [](double a, double b) {
        const double scale = 1e-6 * std::max(std::abs(a), std::abs(b));
        return scale * scale;
    };

    // Each pixel's variance of the mean, its sample variance raised to the mean of its 3x3
    // neighbourhood's where that is larger, over its count. Adaptive sampling gives a pixel
    // whose early samples happened to vary little fewer samples, so its own estimate stays low
    // (docs/accuracy.md, "The statistical comparison"); its neighbours' estimates correct
    // that. Needs the samples layer.
    auto guarded_variance = [&](const HdrImage& image) {
        std::vector<double> out(image.variance.begin(), image.variance.end());
        if (image.samples.size() != n) return out;
        const int w = image.width, h = image.height;
        std::vector<double> sample_var(3 * n);
        for (size_t i = 0; i < n; ++i)
            for (size_t k = 0; k < 3; ++k) sample_var[3 * i + k] = double(image.variance[3 * i + k]) * image.samples[i];
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (size_t k = 0; k < 3; ++k) {
                    double sum = 0;
                    int cells = 0;
                    for (int ny = std::max(0, y - 1); ny <= std::min(h - 1, y + 1); ++ny)
                        for (int nx = std::max(0, x - 1); nx <= std::min(w - 1, x + 1); ++nx, ++cells)
                            sum += sample_var[3 * (size_t(ny) * size_t(w) + size_t(nx)) + k];
                    const size_t i = size_t(y) * size_t(w) + size_t(x);
                    out[3 * i + k] = std::max(out[3 * i + k], sum / cells / std::max<double>(image.samples[i], 1));
                }
        return out;
    };
    const std::vector<double> test_var = guarded_variance(test), reference_var = guarded_variance(reference);

    StatisticalResult out;
    const int block = std::max(1, settings.block);
    // Per base block and channel: the sums of the differences, of the variances, and
    // Welch-Satterthwaite's denominator (each variance squared over its degrees of freedom).
    struct BlockSums {
        double diff = 0, var = 0, var_by_dof = 0;
    };
    int bx = (test.width + block - 1) / block, by = (test.height + block - 1) / block;
    std::vector<BlockSums> level(size_t(bx) * size_t(by) * 3);
    for (int y = 0; y < test.height; ++y)
        for (int x = 0; x < test.width; ++x) {
            const size_t i = size_t(y) * size_t(test.width) + size_t(x);
            for (int k = 0; k < 3; ++k) {
                const size_t j = 3 * i + size_t(k);
                const double va = test_var[j], vb = reference_var[j];
                BlockSums& b = level[(size_t(y / block) * size_t(bx) + size_t(x / block)) * 3 + size_t(k)];
                b.diff += double(test_rgb[j]) - double(reference_rgb[j]);
                b.var += va + vb + rounding_floor(test_rgb[j], reference_rgb[j]);
                b.var_by_dof += va * va / dof(test, i) + vb * vb / dof(reference, i);
            }
        }
    // The z of one block's mean difference.
    auto block_z = [](const BlockSums& b) {
        if (!(b.var > 0)) return b.diff != 0 ? std::numeric_limits<double>::infinity() : 0.0;  // noiseless, differing
        const double t = b.diff / std::sqrt(b.var);
        const double nu = b.var_by_dof > 0 ? b.var * b.var / b.var_by_dof : 1e9;
        // A t value with nu degrees of freedom as a normal z (conservative for small nu).
        return t * (1 - 1 / (4 * nu)) / std::sqrt(1 + t * t / (2 * nu));
    };
    // The chi-square over the base blocks: sum of z^2 against its Wilson-Hilferty limit.
    const double m = double(level.size());
    for (const BlockSums& b : level) out.chi_square += block_z(b) * block_z(b);
    const double wh = 2.0 / (9.0 * m);
    out.chi_square_limit = m * std::pow(1 - wh + normal_upper_quantile(settings.alpha / 2) * std::sqrt(wh), 3.0);
    // Blocks of every size from `block` doubling up to the whole image (a change spread over
    // a region shows in the block that covers it), each tested; the z limit is Bonferroni's
    // over all of them, two-sided, at alpha/2.
    std::vector<std::vector<BlockSums>> levels;
    std::vector<std::pair<int, int>> level_shape;
    for (;;) {
        levels.push_back(level);
        level_shape.emplace_back(bx, by);
        out.tests += level.size();
        if (bx == 1 && by == 1) break;
        const int cx = (bx + 1) / 2, cy = (by + 1) / 2;
        std::vector<BlockSums> coarse(size_t(cx) * size_t(cy) * 3);
        for (int y = 0; y < by; ++y)
            for (int x = 0; x < bx; ++x)
                for (size_t k = 0; k < 3; ++k) {
                    const BlockSums& f = level[(size_t(y) * size_t(bx) + size_t(x)) * 3 + k];
                    BlockSums& c = coarse[(size_t(y / 2) * size_t(cx) + size_t(x / 2)) * 3 + k];
                    c.diff += f.diff, c.var += f.var, c.var_by_dof += f.var_by_dof;
                }
        level = std::move(coarse);
        bx = cx, by = cy;
    }
    out.z_limit = normal_upper_quantile(settings.alpha / 2 / 2 / double(out.tests));
    for (size_t l = 0; l < levels.size(); ++l) {
        const int size = block << l, width_blocks = level_shape[l].first;
        for (size_t b = 0; b < levels[l].size(); ++b) {
            const double z = block_z(levels[l][b]);
            if (std::abs(z) > out.max_abs_z) {
                out.max_abs_z = std::abs(z);
                out.worst_x = int(b / 3 % size_t(width_blocks)) * size;
                out.worst_y = int(b / 3 / size_t(width_blocks)) * size;
                out.worst_size = size;
                out.worst_channel = int(b % 3);
            }
        }
    }
    // A pixel without noise in either image (black background, an emitter seen directly) is
    // exact: its values differing beyond float rounding is a change whatever the blocks say.
    for (size_t j = 0; j < 3 * n; ++j)
        if (test.variance[j] == 0 && reference.variance[j] == 0) {
            const double d = double(test_rgb[j]) - double(reference_rgb[j]);
            if (d * d > rounding_floor(test_rgb[j], reference_rgb[j])) {
                out.max_abs_z = std::numeric_limits<double>::infinity();
                out.worst_x = int(j / 3 % size_t(test.width));
                out.worst_y = int(j / 3 / size_t(test.width));
                out.worst_size = 1;
                out.worst_channel = int(j % 3);
                break;
            }
        }
    out.agree = out.max_abs_z <= out.z_limit && out.chi_square <= out.chi_square_limit;

    out.pixel_z.resize(n);
    for (size_t i = 0; i < n; ++i) {
        double worst = 0;
        for (size_t j = 3 * i; j < 3 * i + 3; ++j) {
            const double d = double(test_rgb[j]) - double(reference_rgb[j]);
            const double v = test_var[j] + reference_var[j] + rounding_floor(test_rgb[j], reference_rgb[j]);
            worst = std::max(worst, v > 0 ? std::abs(d) / std::sqrt(v) : (d != 0 ? 1e30 : 0.0));
        }
        out.pixel_z[i] = float(std::min(worst, 1e30));
    }
    return out;
}

namespace {

// Viridis, sampled at nine even steps from 0 to 1 (sRGB bytes); linear in between.
constexpr std::array<std::array<uint8_t, 3>, 9> kViridis{{{68, 1, 84},
                                                          {71, 44, 122},
                                                          {59, 81, 139},
                                                          {44, 113, 142},
                                                          {33, 144, 141},
                                                          {39, 173, 129},
                                                          {92, 200, 99},
                                                          {170, 220, 50},
                                                          {253, 231, 37}}};

}  // namespace

std::array<uint8_t, 3> viridis(double v) {
    v = std::clamp(std::isnan(v) ? 1.0 : v, 0.0, 1.0) * (kViridis.size() - 1);
    const size_t i = std::min(size_t(v), kViridis.size() - 2);
    const double f = v - double(i);
    std::array<uint8_t, 3> out{};
    for (size_t k = 0; k < 3; ++k)
        out[k] = uint8_t(std::lround(kViridis[i][k] * (1 - f) + kViridis[i + 1][k] * f));
    return out;
}

Rgb8Image false_colour_picture(const std::vector<float>& values, int width, int height, double scale) {
    if (width <= 0 || height <= 0 || values.size() != size_t(width) * size_t(height))
        throw std::invalid_argument("false_colour: values do not match the image size");
    Rgb8Image img{width, height, std::vector<uint8_t>(values.size() * 3)};
    const double inv = scale > 0 ? 1 / scale : 0;
    for (size_t i = 0; i < values.size(); ++i) {
        const std::array<uint8_t, 3> c = viridis(values[i] * inv);
        std::copy(c.begin(), c.end(), img.bytes.begin() + std::ptrdiff_t(3 * i));
    }
    return img;
}

Rgb8Image false_colour(const std::vector<float>& error, int width, int height, double scale) {
    const Rgb8Image picture = false_colour_picture(error, width, height, scale);
    // The picture, then under it a gap, the bar and a row of labels, on black.
    // Labels in stb_easy_font at 1.4 pixels a unit: its digits' 7 units fit the 10-pixel row.
    constexpr int kGap = 4, kBar = 12, kLabel = 10, kMargin = 8;
    constexpr double kLabelScale = 1.4;
    Rgb8Image img;
    img.width = std::max(width, 160);
    img.height = height + kGap + kBar + kGap + kLabel + kGap;
    img.bytes.assign(size_t(img.width) * size_t(img.height) * 3, 0);
    auto put = [&](int x, int y, const std::array<uint8_t, 3>& c) {
        uint8_t* p = &img.bytes[3 * (size_t(y) * size_t(img.width) + size_t(x))];
        p[0] = c[0], p[1] = c[1], p[2] = c[2];
    };
    for (int y = 0; y < height; ++y)
        std::copy_n(picture.bytes.begin() + std::ptrdiff_t(3 * size_t(y) * size_t(width)), 3 * width,
                    img.bytes.begin() + std::ptrdiff_t(3 * size_t(y) * size_t(img.width)));
    const int bar_top = height + kGap, bar_left = kMargin, bar_right = img.width - kMargin;
    for (int x = bar_left; x < bar_right; ++x) {
        const auto c = viridis(double(x - bar_left) / double(std::max(1, bar_right - 1 - bar_left)));
        for (int y = bar_top; y < bar_top + kBar; ++y) put(x, y, c);
    }
    char label[32];
    std::snprintf(label, sizeof label, "%.3g", scale);
    const int label_top = bar_top + kBar + kGap;
    constexpr std::array<uint8_t, 3> kWhite{255, 255, 255};
    draw_text(img, bar_left, label_top, "0", kWhite, kLabelScale);
    draw_text(img, bar_right - text_width(label, kLabelScale), label_top, label, kWhite, kLabelScale);
    return img;
}

}  // namespace kr
