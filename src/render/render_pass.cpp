#include "render/render_pass.h"

#include <algorithm>
#include <cstddef>
#include <new>
#include <type_traits>

#include "render/lanes/pixel_sums.h"
#include "render/sampler.h"
#include "render/trace.h"

namespace kr {

namespace {

PixelSums pixel_sums_of(PixelBuffers& px) {
    return {px.radiance_sum.data(), px.radiance_compensation.data(), px.depth_sum.data(),
            px.luminance_sq_sum.data(),  px.radiance_sq_sum.data(),       px.sample_count.data()};
}

// One thread's share of a pass: it fills batches of samples row by row, traces each batch
// (trace_camera_samples: SIMD lanes where they can be) and adds the results to their pixels
// in the order they were drawn, so every pixel's sums are those of tracing them one by one.
class PassThread {
public:
    PassThread(const RenderScene& scene, const RenderSettings& settings, RenderState& state, AccumulateBatch accumulate,
               LaneKernels kernels)
        : scene_(scene),
          settings_(settings),
          state_(state),
          sums_(pixel_sums_of(state.buffers())),
          accumulate_(accumulate),
          kernels_(kernels),
          sobol_lanes_(sobol_camera_lanes(kernels)) {
        PixelBuffers& px = state.buffers();
        sample_index_ = px.sample_index.data();
        sobol_keys_ = px.sobol_keys.data();
        active_ = state.plan.active.empty() ? nullptr : state.plan.active.data();
        pass_samples_ = state.plan.pass_samples.empty() ? nullptr : state.plan.pass_samples.data();
        for (int k = 0; k < kSampleBatch; ++k) {
            // A Sobol pass restarts these samplers in place (restart_sobol), or for the float
            // lanes keeps its samples' keys and indices instead; the other estimators make
            // each one anew.
            new (&slots_[k].sampler) Sampler(0, 0, 0);
            samplers_[k] = &slots_[k].sampler;
        }
    }

    // Samples row y: each pixel (of the noise rule's mask, if any) once, or as often as the
    // plan says.
    void sample_row(int y) {
        const bool sobol = settings_.estimator == Estimator::sobol;
        if (active_) sobol ? sample_row<true, true>(y) : sample_row<false, true>(y);
        else sobol ? sample_row<true, false>(y) : sample_row<false, false>(y);
    }

    uint64_t rays = 0, nonfinite = 0;

private:
    template <bool kSobol, bool kActive>
    void sample_row(int y) {
        if (pass_samples_) sample_row<kSobol, kActive, true>(y);
        else sample_row<kSobol, kActive, false>(y);
    }

    template <bool kSobol, bool kActive, bool kPlanned>
    void sample_row(int y) {
        // The row's pointers and the batch's fill in locals, so they stay in registers
        // (stores to the buffers could alias members).
        const size_t row = state_.row_start(y), image_row = size_t(y) * size_t(state_.width);
        const int width = state_.width;
        uint32_t* const index_of = sample_index_ + row;
        const uint32_t* const key_of = kSobol ? sobol_keys_ + row : nullptr;
        const uint8_t* const active = kActive ? active_ + row : nullptr;
        const uint8_t* const planned = kPlanned ? pass_samples_ + row : nullptr;
        int* const xs = xs_;
        int* const ys = ys_;
        size_t* const pixels = pixels_;
        size_t pending = 0;
        // In a pass of one sample per pixel every pixel draws the same index, so its bit
        // reversal is kept from the pixel before.
        uint32_t last_index = 0, last_reversed = 0;
        // The batch's next slot: pixel x's sample, its sampler made (or its Sobol key and
        // index set) beforehand.
        const auto fill = [&](int x) {
            xs[pending] = x;
            ys[pending] = y;
            pixels[pending] = row + size_t(x);
        };
        // Counts the slot filled last where `taken`, and traces the batch once it is full.
        const auto take = [&](bool taken) {
            pending += taken;
            if (pending == size_t(kSampleBatch)) {
                flush<kSobol>(pending);
                pending = 0;
            }
        };
        for (int x = 0; x < width; ++x) {
            if (kActive && !active[x]) continue;
            const uint32_t n = kPlanned ? planned[x] : 1;
            const uint32_t first = index_of[x];
            index_of[x] = first + n;
            if constexpr (kSobol && kPlanned) {
                // A plan's counts are an irregular mix of 0, 1 and more, which branches on
                // them mispredict: the pixel's first sample is filled in whether it has one or
                // not and counted only where it has (n > 0), its index reversed every time.
                for (uint32_t index = first; index == first || index < first + n; ++index) {
                    set_sobol(pending, key_of[x], index, reverse_bits(index));
                    fill(x);
                    take(index != first || n != 0);
                }
                continue;
            }
            for (uint32_t index = first; index != first + n; ++index) {
                if constexpr (kSobol) {
                    if (index != last_index) last_index = index, last_reversed = reverse_bits(index);
                    set_sobol(pending, key_of[x], index, last_reversed);
                } else {
                    new (&slots_[pending].sampler)
                        Sampler(settings_.estimator, settings_.seed, image_row + x, index, settings_.target_spp);
                }
                fill(x);
                take(true);
            }
        }
        if (pending > 0) flush<kSobol>(pending);
    }

    // Slot `slot`'s Sobol sample: its key and reversed index for the float lanes, else its
    // sampler.
    void set_sobol(size_t slot, uint32_t key, uint32_t index, uint32_t index_reversed) {
        if (sobol_lanes_) {
            keys_[slot] = key;
            index_reversed_[slot] = index_reversed;
        } else {
            slots_[slot].sampler.restart_sobol(key, index, index_reversed);
        }
    }

    template <bool kSobol>
    __attribute__((noinline)) void flush(size_t count_of) {
        const int count = int(count_of);
        const int width = state_.width, height = state_.height;
        if (kSobol && sobol_lanes_)
            trace_sobol_camera_samples(kernels_, scene_, settings_, width, height, xs_, ys_, keys_, index_reversed_,
                                       count, results_);
        else
            trace_camera_samples(scene_, settings_, width, height, xs_, ys_, samplers_, count, results_);
        accumulate_(sums_, pixels_, results_, count, rays, nonfinite);
    }

    const RenderScene& scene_;
    const RenderSettings& settings_;
    const RenderState& state_;
    const PixelSums sums_;
    const AccumulateBatch accumulate_;  // the CPU level's (accumulation)
    const LaneKernels kernels_;
    const bool sobol_lanes_;  // Sobol batches go to trace_sobol_camera_samples
    uint32_t* sample_index_;
    const uint32_t* sobol_keys_;
    const uint8_t* active_;
    const uint8_t* pass_samples_;
    static_assert(std::is_trivially_destructible_v<Sampler>, "slots are reused without destruction");
    union SamplerSlot {  // a Sampler made in place
        Sampler sampler;
        SamplerSlot() {}
    } slots_[kSampleBatch];
    Sampler* samplers_[kSampleBatch];
    uint32_t keys_[kSampleBatch], index_reversed_[kSampleBatch];  // Sobol samples
    int xs_[kSampleBatch], ys_[kSampleBatch];
    size_t pixels_[kSampleBatch];
    SampleResult results_[kSampleBatch];
};

}  // namespace

void accumulate_samples(PixelBuffers& buffers, const size_t* pixels, const SampleResult* results, int count,
                        AccumulationIsa isa, uint64_t& nonfinite) {
    uint64_t rays = 0;
    accumulate(pixel_sums_of(buffers), pixels, results, count, isa == AccumulationIsa::avx2 && avx2_accumulation(),
               rays, nonfinite);
}

bool accumulation_isa_available(AccumulationIsa isa) { return isa == AccumulationIsa::sse2 || avx2_accumulation(); }

bool render_pass(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                 const std::atomic<bool>* stop) {
    const int width = state.width, height = state.height;
    PixelBuffers& px = state.buffers();
    uint64_t rays = 0, nonfinite = 0;
    bool stopped = false;
    const bool sobol = settings.estimator == Estimator::sobol;
    const size_t pixels = px.sample_count.size();  // the held rows' (RenderState::reset)
    // The Sobol keys, where not yet worked out for this seed: each row's by the thread that
    // samples it, before it does.
    const bool fill_keys = sobol && (px.sobol_keys.size() != pixels || px.sobol_keys_seed != settings.seed);
    if (fill_keys) {
        px.sobol_keys.resize(pixels);
        px.sobol_keys_seed = settings.seed;
    }
    const uint8_t* const rows_active = state.active_rows.empty() ? nullptr : state.active_rows.data();
    const AccumulateBatch accumulate = accumulation(true);
    const LaneKernels kernels = lane_kernels(scene, settings);
    // The samples of a pass after an odd number of passes go to the film's half, as the
    // difference of each row's sums after and before it (the row's sums in the cache).
    const bool half_pass = state.tracks_halves() && state.passes % 2 == 1;
    const auto data = [](const std::vector<uint8_t>& v) { return v.empty() ? nullptr : v.data(); };
    const uint8_t* const active = data(state.plan.active);
    const uint8_t* const planned = data(state.plan.pass_samples);
#pragma omp parallel reduction(+ : rays, nonfinite) reduction(|| : stopped)
    {
        PassThread thread(scene, settings, state, accumulate, kernels);
        // Rows handed out one at a time: rows through glass cost far more than rows of wall.
#pragma omp for schedule(dynamic, 1)
        for (int y = 0; y < height; ++y) {
            if (!state.holds_row(y)) continue;
            if (fill_keys)  // every held row's, sampled or not
                Sampler::pixel_keys(settings.seed, uint64_t(y) * uint64_t(width), size_t(width),
                                    px.sobol_keys.data() + state.row_start(y));
            if (rows_active && !rows_active[y]) continue;
            if (stop && stop->load(std::memory_order_relaxed)) {
                stopped = true;  // each thread's own copy, or-ed together at the end (no data race)
                continue;
            }
            if (half_pass) state.add_row_to_half(-1, state.row_start(y), active, planned);
            thread.sample_row(y);
            if (half_pass) state.add_row_to_half(+1, state.row_start(y), active, planned);
        }
        rays += thread.rays;
        nonfinite += thread.nonfinite;
    }
    state.rays += rays;
    state.nonfinite_samples += nonfinite;
    if (stopped) return false;
    ++state.passes;
    return true;
}

}  // namespace kr
