// The film of a progressive render: each pixel's sums, second moments and counts
// (PixelBuffers, behind Film's readers), the statistics read from them (mean, variances, the
// image's estimated error), and the denoiser's two halves of each pixel's samples. A
// RenderState (render_state.h) holds one, with the plan of the next pass (allocation.h) and the
// rows a pass samples (row_share.h).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/image.h"
#include "render/row_share.h"

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

// A Film's per-pixel buffers. The pass engine (render_pass), checkpoints and the process
// exchange of PassHooks write them through Film::buffers(); everything else reads them through
// Film's readers.
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
    // The Sobol samplers' per-pixel keys (Sampler::pixel_key) for sobol_keys_seed: the same in
    // every pass, so render_pass works them out once, row by row in its first Sobol pass
    // (empty until then).
    std::vector<uint32_t, UninitialisedAllocator<uint32_t>> sobol_keys;
    uint64_t sobol_keys_seed = 0;
    // The denoiser's split of each pixel's samples into two independent halves (empty unless
    // Film::track_halves): the compensated radiance sums and the counts of the samples of
    // odd-numbered passes; the other half is the rest of the pixel's sums.
    std::vector<Color> half_sum;
    std::vector<uint32_t> half_count;
};

class Film {
public:
    int width = 0, height = 0;

    // The per-pixel buffers (PixelBuffers says what each holds).
    const std::vector<Color>& radiance_sum() const { return px_.radiance_sum; }
    const std::vector<Color>& radiance_compensation() const { return px_.radiance_compensation; }
    const std::vector<double>& depth_sum() const { return px_.depth_sum; }
    const std::vector<double>& luminance_sq_sum() const { return px_.luminance_sq_sum; }
    const std::vector<Color>& radiance_sq_sum() const { return px_.radiance_sq_sum; }
    const std::vector<uint32_t>& sample_count() const { return px_.sample_count; }
    const std::vector<uint32_t>& sample_index() const { return px_.sample_index; }
    const PixelBuffers& buffers() const { return px_; }
    // For the pass engine, checkpoints and PassHooks (see PixelBuffers).
    PixelBuffers& buffers() { return px_; }

    Film() = default;
    Film(int w, int h) { reset(w, h); }
    // A w x h film holding the image rows `held` (in order; empty: every row). A process of a
    // shared render holds its own rows and their neighbours (rows_guarded): its buffers have
    // those rows only, each pixel's sums at row_start(y) + x. Keeps tracking the halves if it did.
    void reset(int w, int h, std::vector<int> held = {});
    const std::vector<int>& held_rows() const { return held_; }
    bool holds_row(int y) const { return held_.empty() || slot_[size_t(y)] >= 0; }
    // Where the buffers hold pixel (0, y) of a held row.
    size_t row_start(int y) const { return size_t(held_.empty() ? y : slot_[size_t(y)]) * size_t(width); }

    // The images and the halves below read a film that holds every row.
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

    // Keeps the two halves of each pixel's samples from the next pass on (PixelBuffers::half_sum).
    void track_halves();
    bool tracks_halves() const { return !px_.half_sum.empty(); }
    // Adds `sign` x the sums of the pixels a pass samples in the row starting at buffer pixel
    // `start` (row_start) to the half: those `active` marks and those `planned` gives a
    // sample (nullptr: all; both indexed as the buffers). render_pass calls it around each row
    // of a pass after an odd number of passes, where the film tracks the halves.
    void add_row_to_half(int sign, size_t start, const uint8_t* active, const uint8_t* planned);
    // The mean radiance of each half (zero where a half has no sample) and their counts.
    struct Halves {
        Image mean[2];
        std::vector<uint32_t> count[2];
    };
    Halves halves() const;

private:
    PixelBuffers px_;
    std::vector<int> held_;  // the rows held (empty: all)
    std::vector<int> slot_;  // per image row, its place among held_ (-1: not held); empty with held_
};

// The bytes per pixel a Film holds once every buffer is in use, halves apart: the seven sums
// and counts and the Sobol keys.
inline constexpr uint64_t kFilmBytesPerPixel =
    3 * sizeof(Color) + 2 * sizeof(double) + 2 * sizeof(uint32_t) + sizeof(uint32_t);
// The bytes per pixel of the two halves of the samples (track_halves: half_sum, half_count).
inline constexpr uint64_t kHalvesBytesPerPixel = sizeof(Color) + sizeof(uint32_t);

}  // namespace kr
