#include "render/film.h"

#include <algorithm>
#include <cmath>

#include "render/lanes/levels.h"
#include "render/trace.h"

namespace kr {

void Film::reset(int w, int h, std::vector<int> held) {
    width = w;
    height = h;
    held_ = std::move(held);
    slot_.clear();
    if (!held_.empty()) {
        slot_.assign(size_t(h), -1);
        for (size_t k = 0; k < held_.size(); ++k) slot_[size_t(held_[k])] = int(k);
    }
    const size_t n = static_cast<size_t>(w) * (held_.empty() ? static_cast<size_t>(h) : held_.size());
    px_.radiance_sum.assign(n, Color());
    px_.radiance_compensation.assign(n, Color());
    px_.depth_sum.assign(n, 0.0);
    px_.luminance_sq_sum.assign(n, 0.0);
    px_.radiance_sq_sum.assign(n, Color());
    px_.sample_count.assign(n, 0);
    px_.sample_index.assign(n, 0);
    px_.sobol_keys.clear();
    if (tracks_halves()) track_halves();
}

void Film::track_halves() {
    const size_t n = px_.sample_count.size();
    px_.half_sum.assign(n, Color());
    px_.half_count.assign(n, 0);
}

namespace {

// add_row_to_half's loop over the pixels of the row's [begin, end) that its masks pick,
// specialised on which masks there are.
template <bool kActive, bool kPlanned>
void add_pixels_to_half(PixelBuffers& px, double sign, size_t begin, size_t end, const uint8_t* active,
                        const uint8_t* planned) {
    Color* const half = px.half_sum.data();
    uint32_t* const half_count = px.half_count.data();
    const Color* const sum = px.radiance_sum.data();
    const Color* const compensation = px.radiance_compensation.data();
    const uint32_t* const count = px.sample_count.data();
    const uint32_t count_sign = uint32_t(int32_t(sign));
    for (size_t i = begin; i < end; ++i) {
        if ((kActive && !active[i]) || (kPlanned && !planned[i])) continue;
        half[i] += sign * (sum[i] + compensation[i]);
        half_count[i] += count_sign * count[i];  // modulo 2^32, exact
    }
}

// A row of every pixel: the channels of its sums as one run of doubles (three a pixel) and
// its counts, so that each loop is vectorised whole. Subtracting is adding the negated sum,
// so the halves' bits are add_pixels_to_half's.
KR_LOOP_CLONES
void add_channels_to_half(double* half, const double* sum, const double* compensation, size_t channels, int sign) {
    if (sign > 0)
        for (size_t i = 0; i < channels; ++i) half[i] += sum[i] + compensation[i];
    else
        for (size_t i = 0; i < channels; ++i) half[i] -= sum[i] + compensation[i];
}

KR_LOOP_CLONES
void add_counts_to_half(uint32_t* half_count, const uint32_t* count, size_t pixels, int sign) {
    if (sign > 0)
        for (size_t i = 0; i < pixels; ++i) half_count[i] += count[i];  // modulo 2^32, exact
    else
        for (size_t i = 0; i < pixels; ++i) half_count[i] -= count[i];
}

}  // namespace

void Film::add_row_to_half(int sign, size_t start, const uint8_t* active, const uint8_t* planned) {
    // Only the pixels the pass samples, whose sums are the only ones it changes: a region's or
    // an adaptive pass costs what its pixels cost, and the others' halves stay as they are,
    // bit for bit.
    const size_t end = start + size_t(width);
    if (!active && !planned) {
        static_assert(sizeof(Color) == 3 * sizeof(double), "a row's colours are one run of doubles");
        add_channels_to_half(&px_.half_sum[start].x, &px_.radiance_sum[start].x, &px_.radiance_compensation[start].x,
                             3 * size_t(width), sign);
        add_counts_to_half(px_.half_count.data() + start, px_.sample_count.data() + start, size_t(width), sign);
        return;
    }
    if (active) {
        if (planned) add_pixels_to_half<true, true>(px_, sign, start, end, active, planned);
        else add_pixels_to_half<true, false>(px_, sign, start, end, active, planned);
    } else {
        add_pixels_to_half<false, true>(px_, sign, start, end, active, planned);
    }
}

Film::Halves Film::halves() const {
    Halves out;
    for (int h = 0; h < 2; ++h) {
        out.mean[h] = Image(width, height);
        out.count[h].assign(px_.sample_count.size(), 0);
    }
    if (!tracks_halves()) return out;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < px_.sample_count.size(); ++i) {
        const uint32_t odd = std::min(px_.half_count[i], px_.sample_count[i]), even = px_.sample_count[i] - odd;
        const Color total = px_.radiance_sum[i] + px_.radiance_compensation[i];
        out.count[0][i] = even;
        out.count[1][i] = odd;
        if (odd) out.mean[1].pixels[i] = px_.half_sum[i] / double(odd);
        if (even) out.mean[0].pixels[i] = (total - px_.half_sum[i]) / double(even);
    }
    return out;
}

Image Film::radiance() const {
    Image img(width, height);
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < img.pixels.size(); ++i)
        img.pixels[i] = px_.sample_count[i]
                            ? (px_.radiance_sum[i] + px_.radiance_compensation[i]) / double(px_.sample_count[i])
                            : Color();
    return img;
}

std::vector<double> Film::mean_depth() const {
    std::vector<double> d(px_.depth_sum.size(), kMissDepth);
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < d.size(); ++i)
        if (px_.sample_count[i]) d[i] = px_.depth_sum[i] / double(px_.sample_count[i]);
    return d;
}

std::vector<Color> Film::variance_of_mean() const {
    std::vector<Color> v(px_.radiance_sum.size(), Color(kInfinity));
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < v.size(); ++i) {
        const double n = px_.sample_count[i];
        if (n < 2 || !is_finite(px_.radiance_sq_sum[i])) continue;  // unknown, as sample_variance
        // The unbiased sample variance of each channel, then over n for the mean's.
        auto channel = [&](double sum, double sq_sum) {
            const double mean = sum / n;
            return std::max(0.0, (sq_sum - n * mean * mean) / (n - 1)) / n;
        };
        v[i] = {channel(px_.radiance_sum[i].x, px_.radiance_sq_sum[i].x), channel(px_.radiance_sum[i].y, px_.radiance_sq_sum[i].y),
                channel(px_.radiance_sum[i].z, px_.radiance_sq_sum[i].z)};
    }
    return v;
}

double Film::pixel_standard_error(size_t i) const {
    return std::sqrt(sample_variance(i) / px_.sample_count[i]);  // of the mean of n samples
}

double Film::relative_error(const RowShare* share) const {
    // Per-row sums in parallel, added in row order: the same estimate for any thread or
    // process count. (The viewer shows it after every pass.) Per row: the error, the signal,
    // and whether a pixel's error is unknown.
    const size_t w = size_t(width);
    const std::vector<int> own = rows_owned(share, height);
    std::vector<double> rows(3 * size_t(height), 0.0);
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < own.size(); ++k) {
        const size_t y = size_t(own[k]), start = row_start(own[k]);
        double error = 0, signal = 0;
        for (size_t i = start; i < start + w; ++i) {
            const double se = pixel_standard_error(i);
            if (!std::isfinite(se)) {
                rows[3 * y + 2] = 1;
                break;
            }
            error += se * se;
            const double mean = luminance(px_.radiance_sum[i]) / px_.sample_count[i];
            signal += mean * mean;
        }
        rows[3 * y] = error;
        rows[3 * y + 1] = signal;
    }
    if (share) share->combine(rows, 3);
    double error_sq = 0, signal_sq = 0;
    for (size_t y = 0; y < size_t(height); ++y) {
        if (rows[3 * y + 2] != 0) return kInfinity;
        error_sq += rows[3 * y];
        signal_sq += rows[3 * y + 1];
    }
    if (signal_sq <= 0) return error_sq > 0 ? kInfinity : 0.0;
    return std::sqrt(error_sq / signal_sq);
}

}  // namespace kr
