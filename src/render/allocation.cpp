// The planner (allocation.h): the plan of the next pass (samples per pixel by estimated noise)
// and the noise rule's mask of pixels still above their share of the error.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/vectorise.h"
#include "render/allocation.h"
#include "render/lanes/levels.h"
#include "render/render_state.h"

namespace kr {

namespace {

// The plan's per-pixel loops are compiled for AVX-512 and AVX2 too (KR_LOOP_CLONES) and
// vectorised, with the same bits as the scalar ones.

// The 3x3 guard on per-pixel values (variances): each value replaced by the larger of itself
// and the mean over its 3x3 neighbourhood (the cells inside the image). A few samples can
// miss a rare bright path and show almost no variance; variance varies smoothly over the
// image, so the neighbours guard against that. Separable, in two loops over rows: first
// each row's 3-wide sums, then the guarded value from three rows of those sums.
KR_LOOP_CLONES
void sum_three_along_row(const double* values, double* sums, size_t width) {
    if (width == 1) {
        sums[0] = (0.0 + values[0]) + 0.0;
        return;
    }
    // The ends apart, so the loop between has no test (the same sums, the same order).
    sums[0] = (0.0 + values[0]) + values[1];
    for (size_t x = 1; x + 1 < width; ++x) sums[x] = (values[x - 1] + values[x]) + values[x + 1];
    sums[width - 1] = (values[width - 2] + values[width - 1]) + 0.0;
}

// The 3x3 guard's cells: how many values each mean is over, 3 rows (or 2 at an edge) times 3
// columns (2 at an edge), exact small integers; `above` and `below` the 3-wide sums of the
// rows around (nullptr outside the image).
struct GuardCells {
    double inner, edge;
};
GuardCells guard_cells(const double* above, const double* below, size_t width) {
    double rows = 1.0;
    if (above) rows += 1.0;
    if (below) rows += 1.0;
    return {rows * 3.0, rows * (width > 1 ? 2.0 : 1.0)};
}
// Pixel x's guarded value: the larger of its own and the mean over its 3x3 neighbourhood.
inline double guarded_value(const double* values, const double* sums, const double* above, const double* below,
                            size_t x, double cells) {
    double sum = sums[x];
    if (above) sum += above[x];
    if (below) sum += below[x];
    return std::max(values[x], sum / cells);
}

// The guarded values of one row: `values` and `sums` (its 3-wide sums) at the row's start,
// `above` and `below` as for guard_cells; calls guarded(x, value) in order of x.
template <class F>
void guard_row(const double* values, const double* sums, const double* above, const double* below, size_t width,
               F&& guarded) {
    const GuardCells cells = guard_cells(above, below, width);
    guarded(0, guarded_value(values, sums, above, below, 0, cells.edge));
    for (size_t x = 1; x + 1 < width; ++x) guarded(x, guarded_value(values, sums, above, below, x, cells.inner));
    if (width > 1) guarded(width - 1, guarded_value(values, sums, above, below, width - 1, cells.edge));
}

// RenderState::luminance_sample_variance of a row's pixels.
KR_LOOP_CLONES
void sample_variance_row(const uint32_t* __restrict count, const Color* __restrict radiance,
                         const double* __restrict luminance_sq, double* __restrict variance, size_t width) {
KR_INDEPENDENT_ITERATIONS
    for (size_t x = 0; x < width; ++x)
        variance[x] = RenderState::luminance_sample_variance(count[x], radiance[x], luminance_sq[x]);
}

// A row's sampling weights: the standard deviation of each active pixel's guarded variance
// (guard_row's value: the larger of its own and its 3x3 mean), 0 where inactive or unknown.
KR_LOOP_CLONES
void weight_row(const double* __restrict values, const double* __restrict sums, const double* __restrict above,
                const double* __restrict below, const uint8_t* __restrict on, double* __restrict weight, size_t width) {
    const GuardCells cells = guard_cells(above, below, width);
    const auto weight_of = [&](size_t x, double guarded) {
        return (!on || on[x]) && std::isfinite(guarded) ? std::sqrt(guarded) : 0.0;
    };
    const auto at = [&](size_t x, double cells_of) {
        return weight_of(x, guarded_value(values, sums, above, below, x, cells_of));
    };
    weight[0] = at(0, cells.edge);
    // The inner pixels of a row with both neighbours apart (the same sums, in the same
    // order), so that loop vectorises without a test per pixel.
    if (above && below) {
KR_INDEPENDENT_ITERATIONS
        for (size_t x = 1; x + 1 < width; ++x)
            weight[x] = weight_of(x, std::max(values[x], ((sums[x] + above[x]) + below[x]) / cells.inner));
    } else {
        for (size_t x = 1; x + 1 < width; ++x) weight[x] = at(x, cells.inner);
    }
    if (width > 1) weight[width - 1] = at(width - 1, cells.edge);
}

// A row's samples in the next pass: each active pixel's quota (its weight plus the floor,
// scaled) added to its credit, the whole samples taken, the rest kept.
KR_LOOP_CLONES
void take_row(const double* __restrict weight, const uint8_t* __restrict on, double floor, double quota_scale,
              float* __restrict credit, uint8_t* __restrict take, size_t width) {
KR_INDEPENDENT_ITERATIONS
    for (size_t x = 0; x < width; ++x) {
        const double quota = (weight[x] + floor) * quota_scale;
        const double sum = std::min<double>(credit[x] + quota, 4 * kMaxPassSamples);
        const int whole = std::min(int(sum), kMaxPassSamples);
        const bool active = !on || on[x];
        take[x] = active ? static_cast<uint8_t>(whole) : uint8_t(0);
        credit[x] = active ? static_cast<float>(sum - whole) : credit[x];
    }
}

}  // namespace

void SamplePlan::clear() {
    active.clear();
    pass_samples.clear();
    sample_credit.clear();
    for (auto& buffer : scratch) buffer.clear();
}

size_t update_adaptive(RenderState& state, double target, uint32_t min_samples, const RowShare* share) {
    const PixelBuffers& px = state.buffers();
    SamplePlan& plan = state.plan;
    const int width = state.width, height = state.height;
    const size_t n = px.sample_count.size(), w = size_t(width);
    const std::vector<int> own = rows_owned(share, height), guarded = rows_guarded(share, height);
    // Rows in parallel, their sums added in order (as plan_pass).
    std::vector<double>& error_sq = plan.scratch[0];
    std::vector<double>& row_sums = plan.scratch[1];
    error_sq.resize(n);
    row_sums.resize(n);
    std::vector<double> row_signal(size_t(height), 0.0);
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < guarded.size(); ++k) {
        const int y = guarded[k];
        const size_t start = state.row_start(y);
        for (size_t i = start; i < start + w; ++i) {
            const double mean = px.sample_count[i] ? luminance(px.radiance_sum[i]) / px.sample_count[i] : 0.0;
            row_signal[size_t(y)] += mean * mean;
            const double se = state.pixel_standard_error(i);
            error_sq[i] = se * se;
        }
        sum_three_along_row(&error_sq[start], &row_sums[start], w);
    }
    if (share) share->combine(row_signal, 1);
    double signal_sq = 0;
    for (double s : row_signal) signal_sq += s;
    const double allowed = target * target * signal_sq / double(std::max<size_t>(size_t(width) * size_t(height), 1));
    plan.active.resize(n);
    std::vector<double> row_count(size_t(height), 0.0);
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < own.size(); ++k) {
        const int y = own[k];
        const size_t start = state.row_start(y);
        const double* const above = y > 0 ? row_sums.data() + state.row_start(y - 1) : nullptr;
        const double* const below = y + 1 < height ? row_sums.data() + state.row_start(y + 1) : nullptr;
        const uint32_t* const samples = px.sample_count.data() + start;
        uint8_t* const active = plan.active.data() + start;
        size_t count = 0;
        guard_row(error_sq.data() + start, row_sums.data() + start, above, below, w, [&](size_t x, double guarded) {
            const bool needs_more = samples[x] < min_samples || !(guarded <= allowed);
            active[x] = needs_more;
            count += needs_more;
        });
        row_count[size_t(y)] = double(count);
    }
    if (share) share->combine(row_count, 1);
    size_t count = 0;
    for (double c : row_count) count += size_t(c);
    return count;
}

bool plan_reads_statistics(const RenderSettings& settings, const RenderState& state) {
    return settings.allocation == Allocation::adaptive && settings.estimator != Estimator::stratified &&
           state.passes >= kAllocationWarmup;
}

void plan_pass(RenderState& state, const RenderSettings& settings, const RowShare* share) {
    SamplePlan& plan = state.plan;
    if (!plan_reads_statistics(settings, state)) {
        plan.pass_samples.clear();
        return;
    }
    const PixelBuffers& px = state.buffers();
    const int width = state.width, height = state.height;
    const size_t n = px.sample_count.size(), w = size_t(width);
    std::vector<int> own = rows_owned(share, height), guarded = rows_guarded(share, height);
    // Rows with no pixel on (the noise rule's mask, a render region's) take no samples, and
    // their zero weights would add nothing to the sums below: only the others are planned
    // (and their neighbours read), so a region's pass plans what its pixels need.
    std::vector<int> idle_rows;
    if (!plan.active.empty()) {
        std::vector<uint8_t> row_on(size_t(height), 0);
        for (const int y : own) {
            const uint8_t* const row = plan.active.data() + state.row_start(y);
            row_on[size_t(y)] = std::any_of(row, row + w, [](uint8_t on) { return on != 0; });
        }
        const auto on = [&](int y) { return y >= 0 && y < height && row_on[size_t(y)]; };
        std::vector<int> kept;
        for (const int y : own) (on(y) ? kept : idle_rows).push_back(y);
        own.swap(kept);
        guarded.erase(std::remove_if(guarded.begin(), guarded.end(), [&](int y) { return !(on(y - 1) || on(y) || on(y + 1)); }),
                      guarded.end());
    }
    // Optimal allocation: minimising sum_i var_i / n_i for a fixed sum_i n_i gives n_i in
    // proportion to the standard deviation sigma_i. The floor keeps sampling pixels whose
    // estimate may be too low, and bounds the bias of deciding from the samples themselves.
    // Every loop runs over rows in parallel; sums are taken per row and then over the rows in
    // order, so the plan is the same for any number of threads or processes. The loops are
    // fused: at 512x512 the plan is bound by memory traffic.
    std::vector<double>& variance = plan.scratch[0];
    std::vector<double>& row_sums = plan.scratch[1];  // 3-wide sums along each row
    std::vector<double>& weight = plan.scratch[2];
    variance.resize(n);
    row_sums.resize(n);
    weight.resize(n);
    // The buffers' data as locals: the plan's byte stores may alias any member.
    const uint32_t* const count = px.sample_count.data();
    const Color* const radiance = px.radiance_sum.data();
    const double* const luminance_sq = px.luminance_sq_sum.data();
    const uint8_t* const active = plan.active.empty() ? nullptr : plan.active.data();
    double* const variance_of = variance.data();
    double* const row_sums_of = row_sums.data();
    double* const weight_of = weight.data();
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < guarded.size(); ++k) {
        const size_t start = state.row_start(guarded[k]);
        sample_variance_row(count + start, radiance + start, luminance_sq + start, variance_of + start, w);
        sum_three_along_row(variance_of + start, row_sums_of + start, w);
    }
    // Each pixel's variance guarded by its 3x3 neighbourhood (as update_adaptive), then its
    // standard deviation; per row, the sum of the weights and the active pixels.
    std::vector<double> row_weight_active(2 * size_t(height), 0.0);
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < own.size(); ++k) {
        const int y = own[k];
        const size_t start = state.row_start(y);
        const double* const above = y > 0 ? row_sums_of + state.row_start(y - 1) : nullptr;
        const double* const below = y + 1 < height ? row_sums_of + state.row_start(y + 1) : nullptr;
        const uint8_t* const row_on = active ? active + start : nullptr;
        weight_row(variance_of + start, row_sums_of + start, above, below, row_on, weight_of + start, w);
        // The row's sum in order of x, as every process and thread count adds it.
        double row_weight = 0;
        for (size_t x = 0; x < w; ++x) row_weight += weight_of[start + x];
        size_t row_active = w;
        if (row_on) row_active = size_t(std::count_if(row_on, row_on + w, [](uint8_t on) { return on != 0; }));
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
        plan.pass_samples.clear();  // no variance anywhere (or all unknown): one sample each
        return;
    }
    plan.sample_credit.resize(n, 0.0f);
    plan.pass_samples.resize(n);
    float* const credit_of = plan.sample_credit.data();
    uint8_t* const take_of = plan.pass_samples.data();
    for (const int y : idle_rows) std::fill_n(take_of + state.row_start(y), w, uint8_t(0));
    const double quota_scale = double(active_count) / total;
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < own.size(); ++k) {
        // Quotas sum to the active pixel count: the pass costs what a uniform one does.
        const size_t start = state.row_start(own[k]);
        take_row(weight_of + start, active ? active + start : nullptr, floor, quota_scale, credit_of + start,
                 take_of + start, w);
    }
}

}  // namespace kr
