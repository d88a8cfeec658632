// The state of a progressive render: each pixel's sums, second moments and counts
// (PixelBuffers, behind RenderState's readers), the statistics read from them (mean,
// variances, the image's estimated error), the adaptive allocation that plans the next pass
// from them (allocation.cpp), and the memory a render holds.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/image.h"
#include "render/settings.h"

namespace kr {

// An allocator whose resize() leaves the new elements uninitialised, for a buffer written
// whole before it is read: its pages are first touched where it is written (in parallel),
// not zeroed beforehand by one thread.
template <class T>
struct UninitialisedAllocator : std::allocator<T> {
    template <class U>
    struct rebind {
        using other = UninitialisedAllocator<U>;
    };
    UninitialisedAllocator() = default;
    template <class U>
    UninitialisedAllocator(const UninitialisedAllocator<U>&) noexcept {}
    template <class U>
    void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

// A RenderState's per-pixel buffers. The pass engine (render_pass, plan_pass,
// update_adaptive), checkpoints and the process exchange of PassHooks write them through
// RenderState::buffers(); everything else reads them through RenderState's readers.
struct PixelBuffers {
    std::vector<Color> radiance_sum;      // per pixel, sum of sample radiance (plainly rounded)
    // Per pixel, Neumaier's running correction of radiance_sum: radiance_sum plus it is the
    // sum to within an ulp or two after any number of samples, where the plain sum of 10^6
    // samples of 0.1 is off by 1.3e-11 relative. The mean radiance uses both; the statistics
    // (variances, plans, the noise rule) use radiance_sum alone, which processes share.
    std::vector<Color> radiance_compensation;
    std::vector<double> depth_sum;        // per pixel, sum of primary hit distances
    std::vector<double> luminance_sq_sum; // per pixel, sum of squared sample luminance
    std::vector<Color> radiance_sq_sum;   // per pixel and channel, sum of squared sample radiance
    std::vector<uint32_t> sample_count;   // per pixel, samples accumulated
    std::vector<uint32_t> sample_index;   // per pixel, samples drawn (accumulated + dropped)
    // The noise rule (update_adaptive): render_pass samples only pixels whose entry is 1
    // (empty: all of them).
    std::vector<uint8_t> active;
    // Per row, whether render_pass samples it at all (empty: every row): a process's share of
    // the rows, set around each pass by its PassHooks.
    std::vector<uint8_t> active_rows;
    // Samples per pixel in the next pass, set by plan_pass (empty: one each).
    std::vector<uint8_t> pass_samples;
    std::vector<float> sample_credit;  // adaptive allocation: fractions of a sample carried over
    std::array<std::vector<double>, 3> allocation_scratch;  // plan_pass's and update_adaptive's buffers
    // The Sobol samplers' per-pixel keys (Sampler::pixel_key) for sobol_keys_seed: the same in
    // every pass, so render_pass works them out once, row by row in its first Sobol pass
    // (empty until then).
    std::vector<uint32_t, UninitialisedAllocator<uint32_t>> sobol_keys;
    uint64_t sobol_keys_seed = 0;
    // The denoiser's split of each pixel's samples into two independent halves (empty unless
    // RenderState::track_halves): the compensated radiance sums and the counts of the samples
    // of odd-numbered passes; the other half is the rest of the pixel's sums.
    std::vector<Color> half_sum;
    std::vector<uint32_t> half_count;
};

// The rows of an image shared between `count` processes, dealt in interleaved blocks: each
// process owns height/count rows (one more for the first height mod count processes), split
// into kRowBlocks contiguous blocks of near-equal size (some empty on short images), laid out
// block 0 of process 0, of 1, ..., of count - 1, then each one's block 1, and so on. A process
// holds its own rows and their neighbours (the 3x3 guard reads them): at most 2 kRowBlocks
// rows more than its share whatever the count, and the interleaving spreads every process's
// rows over the image, for balance. Everything that maps a row to its process or its place
// there (RowShare, app/cluster's gather, scatter and exchanges) reads row_owners.
constexpr int kRowBlocks = 32;
// The process owning each row of an image `height` rows high shared by `count` processes.
std::vector<int> row_owners(int count, int height);

// This process's share of the rows (row_owners): it samples and plans its rows, and holds the
// statistics of their neighbours too. The image-wide sums (of the plan, the noise rule, the
// estimated error) are taken per row, made known to every process by combine() and added in
// row order by each: the same plan and verdicts, bit for bit, as one process that owns every
// row (no RowShare).
class RowShare {
public:
    RowShare(int index, int count) : index_(index), count_(count) {}
    virtual ~RowShare() = default;
    int index() const { return index_; }
    int count() const { return count_; }
    // `values` holds `fields` numbers per row, rows in order, this process's own rows filled
    // in: replaces every other row's with the numbers of the process that owns it.
    virtual void combine(std::vector<double>& values, int fields) const = 0;

private:
    int index_, count_;
};

// The rows `share` gives this process, in order (every row without a share), and those its
// 3x3 guard reads: its own and their neighbours.
std::vector<int> rows_owned(const RowShare* share, int height);
std::vector<int> rows_guarded(const RowShare* share, int height);
// Those of process `index` of `count`.
std::vector<int> rows_owned(int index, int count, int height);
std::vector<int> rows_guarded(int index, int count, int height);

class RenderState {
public:
    int width = 0, height = 0;
    int passes = 0;                       // completed passes
    uint64_t rays = 0;                    // every ray cast: camera, bounce and shadow rays
    uint64_t nonfinite_samples = 0;       // samples dropped for NaN/Inf radiance

    // The per-pixel buffers (PixelBuffers says what each holds).
    const std::vector<Color>& radiance_sum() const { return px_.radiance_sum; }
    const std::vector<Color>& radiance_compensation() const { return px_.radiance_compensation; }
    const std::vector<double>& depth_sum() const { return px_.depth_sum; }
    const std::vector<double>& luminance_sq_sum() const { return px_.luminance_sq_sum; }
    const std::vector<Color>& radiance_sq_sum() const { return px_.radiance_sq_sum; }
    const std::vector<uint32_t>& sample_count() const { return px_.sample_count; }
    const std::vector<uint32_t>& sample_index() const { return px_.sample_index; }
    const std::vector<uint8_t>& active() const { return px_.active; }
    const std::vector<uint8_t>& pass_samples() const { return px_.pass_samples; }
    const std::vector<float>& sample_credit() const { return px_.sample_credit; }
    const PixelBuffers& buffers() const { return px_; }
    // For the pass engine, checkpoints and PassHooks (see PixelBuffers).
    PixelBuffers& buffers() { return px_; }

    RenderState() = default;
    RenderState(int w, int h) { reset(w, h); }
    // A w x h render's state holding the image rows `held` (in order; empty: every row). A
    // process of a shared render holds its own rows and their neighbours (rows_guarded): its
    // buffers have those rows only, each pixel's sums at row_start(y) + x.
    void reset(int w, int h, std::vector<int> held = {});
    const std::vector<int>& held_rows() const { return held_; }
    bool holds_row(int y) const { return held_.empty() || slot_[size_t(y)] >= 0; }
    // Where the buffers hold pixel (0, y) of a held row.
    size_t row_start(int y) const { return size_t(held_.empty() ? y : slot_[size_t(y)]) * size_t(width); }

    // The images and the halves below read a state that holds every row.
    Image radiance() const;                  // per-pixel mean radiance (compensated sums)
    std::vector<double> mean_depth() const;  // per-pixel mean primary distance
    // Per pixel and channel, the variance of the mean radiance: the unbiased sample variance
    // over the count (infinite below two samples). What `keithray compare --statistical` tests.
    std::vector<Color> variance_of_mean() const;

    // Unbiased variance of one sample's luminance in the buffers' pixel `i` (infinite below
    // two samples).
    double sample_variance(size_t i) const {
        return luminance_sample_variance(px_.sample_count[i], px_.radiance_sum[i], px_.luminance_sq_sum[i]);
    }
    // The same from a pixel's count, radiance sum and sum of squared luminances.
    static double luminance_sample_variance(uint32_t count, const Color& sum, double luminance_sq_sum) {
        const double n = count;
        // Below two samples there is no variance; a sum of squares that overflowed (radiance
        // above ~1e154) would give inf - inf: the variance is unknown, not zero.
        // (Computed, then selected: the plan's row loops vectorise it.)
        const double mean = luminance(sum) / n;
        const double variance = std::max(0.0, (luminance_sq_sum - n * mean * mean) / (n - 1));  // unbiased
        return n < 2 || !std::isfinite(luminance_sq_sum) ? std::numeric_limits<double>::infinity() : variance;
    }
    // Standard error of pixel `i`'s mean luminance, from its sample variance (infinite below
    // two samples).
    double pixel_standard_error(size_t i) const;
    // Estimated relative RMS error of the whole image: sqrt(sum of per-pixel variances of the
    // mean) / sqrt(sum of squared mean luminances). Infinite before two samples per pixel.
    // With `share`, every process calls it after the same pass and gets the same estimate.
    double relative_error(const RowShare* share = nullptr) const;

    // Adaptive sampling towards an image relative error `target` (as relative_error()): a
    // pixel stays active while the variance of its mean exceeds an equal share of the allowed
    // total, target^2 * sum(mean^2) / pixels, or it has fewer than `min_samples` samples.
    // When no pixel is active the image meets the target. Returns the active count. With
    // `share`, the mask is set on this process's rows (from their and their neighbours'
    // statistics) and the count is the image's.
    size_t update_adaptive(double target, uint32_t min_samples = 16, const RowShare* share = nullptr);

    // Plans the next pass for `settings.allocation` (fills pass_samples). Adaptive: after
    // kAllocationWarmup passes, each active pixel's share of the pass (as many samples as
    // active pixels) is proportional to its estimated standard deviation (3x3 guarded, as
    // update_adaptive) plus a floor, which minimises the summed variance of the pixel means
    // for the budget; fractions carry over between passes. Parallel over rows, with the rows'
    // sums added in order: the plan does not depend on threads. With `share`, only this
    // process's rows are planned (their pass_samples and sample_credit), from their and their
    // neighbours' statistics and the image's sums.
    void plan_pass(const RenderSettings& settings, const RowShare* share = nullptr);

    // Samples every pixel again (no adaptive mask).
    void clear_adaptive() { px_.active.clear(); }

    // Keeps the two halves of each pixel's samples from the next pass on (PixelBuffers::half_sum).
    void track_halves();
    bool tracks_halves() const { return !px_.half_sum.empty(); }
    // Around a pass (ProgressiveDriver): the samples of a pass after an odd number of passes
    // go to the half, as the difference of the sums after and before it. A no-op unless
    // tracking, or for the other passes.
    void begin_half_pass() {
        if (passes % 2 == 1) add_sums_to_half(-1);
    }
    void end_half_pass() {
        if (passes % 2 == 0) add_sums_to_half(+1);
    }
    // The mean radiance of each half (zero where a half has no sample) and their counts.
    struct Halves {
        Image mean[2];
        std::vector<uint32_t> count[2];
    };
    Halves halves() const;

private:
    void add_sums_to_half(int sign);
    PixelBuffers px_;
    std::vector<int> held_;  // the rows held (empty: all)
    std::vector<int> slot_;  // per image row, its place among held_ (-1: not held); empty with held_
};

// The bytes per pixel a RenderState holds once every buffer is in use: the seven sums and
// counts, the adaptive mask, the pass plan and its credit, the three allocation buffers and
// the Sobol keys.
inline constexpr uint64_t kRenderStateBytesPerPixel =
    3 * sizeof(Color) + 2 * sizeof(double) + 2 * sizeof(uint32_t) + 2 * sizeof(uint8_t) + sizeof(float) +
    3 * sizeof(double) + sizeof(uint32_t);
// The bytes per pixel of the two halves of the samples (track_halves: half_sum, half_count).
inline constexpr uint64_t kHalvesBytesPerPixel = sizeof(Color) + sizeof(uint32_t);

// An upper estimate of the memory a render of width x height pixels holds at its peak: the
// RenderState, then at the end the mean radiance (and, when blurred, two more radiance images),
// the mean depth, and the larger output stage: the two 8-bit images and their encoded bytes,
// or an EXR's 14 float layers and its encoded bytes.
// A denoised render adds its halves (render_state), its feature buffers and the denoiser's
// working images (render/denoise.h: kDenoiseBytesPerPixel).
uint64_t render_memory_bytes(int width, int height, bool blurred, bool denoised = false);
// The three sums of a pixel that the 3x3 guard reads (radiance_sum, luminance_sq_sum,
// sample_count): what a process of a shared render sends its neighbours of its rows.
inline constexpr uint64_t kGuardRowBytesPerPixel = sizeof(Color) + sizeof(double) + sizeof(uint32_t);

// The memory of a process of a shared render that holds `rows` rows of `width` pixels and
// writes nothing (RenderState::reset's held rows): their state, and the buffers in which it
// sends its rows next to other processes' blocks (each at most twice: 4 kRowBlocks rows) and
// receives the rows next to its own blocks (2 kRowBlocks); with `halves`, their halves too.
inline uint64_t render_state_bytes(int width, size_t rows, bool halves = false) {
    const uint64_t per_pixel = kRenderStateBytesPerPixel + (halves ? kHalvesBytesPerPixel : 0);
    return uint64_t(width) * (uint64_t(rows) * per_pixel + 6 * kRowBlocks * kGuardRowBytesPerPixel);
}

inline constexpr int kAllocationWarmup = 8;        // passes of one sample each before adapting
inline constexpr double kAllocationFloor = 0.25;   // every pixel's share is at least this x mean
inline constexpr int kMaxPassSamples = 64;         // per pixel and pass

// Whether plan_pass reads the image's statistics for the next pass (adaptive allocation
// after its warm-up).
bool plan_reads_statistics(const RenderSettings& settings, const RenderState& state);

}  // namespace kr
