// Adaptive allocation: the plan of the next pass (samples per pixel by estimated noise) and
// the noise rule's mask of pixels still above their share of the error.
#include <algorithm>
#include <cmath>

#include "render/render_state.h"

namespace kr {

namespace {

// The 3x3 guard on per-pixel values (variances): each value replaced by the larger of itself
// and the mean over its 3x3 neighbourhood (the cells inside the image). A few samples can
// miss a rare bright path and show almost no variance; variance varies smoothly over the
// image, so the neighbours guard against that. Separable, in two loops over rows: first
// each row's 3-wide sums, then the guarded value from three rows of those sums.
void sum_three_along_row(const double* values, double* sums, size_t width) {
    for (size_t x = 0; x < width; ++x)
        sums[x] = (x > 0 ? values[x - 1] : 0.0) + values[x] + (x + 1 < width ? values[x + 1] : 0.0);
}

// At pixel x of row y, whose row starts at `start` in the buffers (and the rows above and
// below at their own starts, where they are in the image).
double guarded_3x3(const RenderState& state, const std::vector<double>& values, const std::vector<double>& row_sums,
                   int y, size_t start, size_t x) {
    const size_t i = start + x;
    double sum = row_sums[i], cells = 1.0;
    if (y > 0) sum += row_sums[state.row_start(y - 1) + x], cells += 1.0;
    if (y + 1 < state.height) sum += row_sums[state.row_start(y + 1) + x], cells += 1.0;
    cells *= 1.0 + (x > 0) + (x + 1 < size_t(state.width));
    return std::max(values[i], sum / cells);
}

}  // namespace

size_t RenderState::update_adaptive(double target, uint32_t min_samples, const RowShare* share) {
    const size_t n = px_.sample_count.size(), w = size_t(width);
    const std::vector<int> own = rows_owned(share, height), guarded = rows_guarded(share, height);
    // Rows in parallel, their sums added in order (as plan_pass).
    std::vector<double>& error_sq = px_.allocation_scratch[0];
    std::vector<double>& row_sums = px_.allocation_scratch[1];
    error_sq.resize(n);
    row_sums.resize(n);
    std::vector<double> row_signal(size_t(height), 0.0);
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < guarded.size(); ++k) {
        const int y = guarded[k];
        const size_t start = row_start(y);
        for (size_t i = start; i < start + w; ++i) {
            const double mean = px_.sample_count[i] ? luminance(px_.radiance_sum[i]) / px_.sample_count[i] : 0.0;
            row_signal[size_t(y)] += mean * mean;
            const double se = pixel_standard_error(i);
            error_sq[i] = se * se;
        }
        sum_three_along_row(&error_sq[start], &row_sums[start], w);
    }
    if (share) share->combine(row_signal, 1);
    double signal_sq = 0;
    for (double s : row_signal) signal_sq += s;
    const double allowed = target * target * signal_sq / double(std::max<size_t>(size_t(width) * size_t(height), 1));
    px_.active.resize(n);
    std::vector<double> row_count(size_t(height), 0.0);
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < own.size(); ++k) {
        const int y = own[k];
        const size_t start = row_start(y);
        size_t count = 0;
        for (size_t x = 0; x < w; ++x) {
            const size_t i = start + x;
            const bool needs_more =
                px_.sample_count[i] < min_samples || !(guarded_3x3(*this, error_sq, row_sums, y, start, x) <= allowed);
            px_.active[i] = needs_more;
            count += needs_more;
        }
        row_count[size_t(y)] = double(count);
    }
    if (share) share->combine(row_count, 1);
    size_t count = 0;
    for (double c : row_count) count += size_t(c);
    return count;
}

void RenderState::plan_pass(const RenderSettings& settings, const RowShare* share) {
    if (settings.allocation != Allocation::adaptive || settings.estimator == Estimator::stratified ||
        passes < kAllocationWarmup) {
        px_.pass_samples.clear();
        return;
    }
    const size_t n = px_.sample_count.size(), w = size_t(width);
    const std::vector<int> own = rows_owned(share, height), guarded = rows_guarded(share, height);
    // Optimal allocation: minimising sum_i var_i / n_i for a fixed sum_i n_i gives n_i in
    // proportion to the standard deviation sigma_i. The floor keeps sampling pixels whose
    // estimate may be too low, and bounds the bias of deciding from the samples themselves.
    // Every loop runs over rows in parallel; sums are taken per row and then over the rows in
    // order, so the plan is the same for any number of threads or processes. The loops are
    // fused: at 512x512 the plan is bound by memory traffic.
    std::vector<double>& variance = px_.allocation_scratch[0];
    std::vector<double>& row_sums = px_.allocation_scratch[1];  // 3-wide sums along each row
    std::vector<double>& weight = px_.allocation_scratch[2];
    variance.resize(n);
    row_sums.resize(n);
    weight.resize(n);
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < guarded.size(); ++k) {
        const size_t start = row_start(guarded[k]);
        for (size_t i = start; i < start + w; ++i) variance[i] = sample_variance(i);
        sum_three_along_row(&variance[start], &row_sums[start], w);
    }
    // Each pixel's variance guarded by its 3x3 neighbourhood (as update_adaptive), then its
    // standard deviation; per row, the sum of the weights and the active pixels.
    std::vector<double> row_weight_active(2 * size_t(height), 0.0);
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < own.size(); ++k) {
        const int y = own[k];
        const size_t start = row_start(y);
        double row_weight = 0;
        size_t row_active = 0;
        for (size_t x = 0; x < w; ++x) {
            const size_t i = start + x;
            const bool on = px_.active.empty() || px_.active[i];
            const double guarded_variance = guarded_3x3(*this, variance, row_sums, y, start, x);
            weight[i] = on && std::isfinite(guarded_variance) ? std::sqrt(guarded_variance) : 0.0;
            row_weight += weight[i];
            row_active += on;
        }
        row_weight_active[2 * size_t(y)] = row_weight;
        row_weight_active[2 * size_t(y) + 1] = double(row_active);
    }
    if (share) share->combine(row_weight_active, 2);
    double sum = 0;
    size_t active_count = 0;
    for (size_t y = 0; y < size_t(height); ++y) {
        sum += row_weight_active[2 * y];
        active_count += size_t(row_weight_active[2 * y + 1]);
    }
    const double floor = active_count ? kAllocationFloor * sum / double(active_count) : 0.0;
    const double total = sum * (1 + kAllocationFloor);  // of weight + floor over active pixels
    if (!(total > 0) || !std::isfinite(total)) {
        px_.pass_samples.clear();  // no variance anywhere (or all unknown): one sample each
        return;
    }
    px_.sample_credit.resize(n, 0.0f);
    px_.pass_samples.resize(n);
    const double quota_scale = double(active_count) / total;
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < own.size(); ++k) {
        const size_t start = row_start(own[k]);
        for (size_t i = start; i < start + w; ++i) {
            if (!(px_.active.empty() || px_.active[i])) {
                px_.pass_samples[i] = 0;
                continue;
            }
            // Quotas sum to the active pixel count: the pass costs what a uniform one does.
            const double quota = (weight[i] + floor) * quota_scale;
            const double credit = std::min<double>(px_.sample_credit[i] + quota, 4 * kMaxPassSamples);
            const int take = std::min(int(credit), kMaxPassSamples);
            px_.pass_samples[i] = static_cast<uint8_t>(take);
            px_.sample_credit[i] = static_cast<float>(credit - take);
        }
    }
}

bool plan_reads_statistics(const RenderSettings& settings, const RenderState& state) {
    return settings.allocation == Allocation::adaptive && settings.estimator != Estimator::stratified &&
           state.passes >= kAllocationWarmup;
}

}  // namespace kr
