#include "render/render_pass.h"

#include <algorithm>
#include <cstddef>
#include <new>
#include <type_traits>

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#define KR_ACCUMULATE_AVX2 1
#endif

#include "render/sampler.h"
#include "render/trace.h"

namespace kr {

namespace {

// Two doubles in one SSE2 register (GCC vector extension): a Color's x and y travel together,
// z alone. Each lane does the same IEEE operations as the scalar code, so the sums are the
// same bits.
typedef double Pair __attribute__((vector_size(16)));
inline Pair load_pair(const double* p) {
    Pair v;
    __builtin_memcpy(&v, p, sizeof v);
    return v;
}
inline void store_pair(double* p, Pair v) { __builtin_memcpy(p, &v, sizeof v); }

// Compensated summation (Neumaier's, with Knuth's TwoSum for the rounding error of each
// addition: exact whichever term is larger, and without a branch), given t = sum + x.
// `sum` stays the plain running sum; `compensation` gathers what its roundings lost.
template <class T>
inline T two_sum_error(T sum, T x, T t) {
    const T x_part = t - sum;
    return (sum - (t - x_part)) + (x - x_part);
}

// The per-pixel sums one sample adds to (PixelBuffers' columns, their data pointers taken
// once per pass).
struct PixelSums {
    Color* radiance;
    Color* compensation;
    double* depth;
    double* luminance_sq;
    Color* radiance_sq;
    uint32_t* count;

    // Adds sample `r` to pixel `i`, unless it is not finite (NaN or Inf) or would overflow
    // the pixel's sum: the sums stay finite, so a sum plus a sample is finite only where the
    // sample is too, and one test of the new sums covers both. Returns whether it was added.
    bool add(size_t i, const SampleResult& r) const {
        double* sum = &radiance[i].x;
        const Pair sum_xy = load_pair(sum), x_xy = load_pair(&r.radiance.x);
        const double sum_z = sum[2], x_z = r.radiance.z;
        const Pair t_xy = sum_xy + x_xy;
        const double t_z = sum_z + x_z;
        // Finite: t - t is 0, not NaN, in every channel.
        const Pair zero_xy = t_xy - t_xy;
        if (!((zero_xy[0] + zero_xy[1]) + (t_z - t_z) == 0)) return false;
        store_pair(sum, t_xy);
        sum[2] = t_z;
        double* lost = &compensation[i].x;
        store_pair(lost, load_pair(lost) + two_sum_error(sum_xy, x_xy, t_xy));
        lost[2] += two_sum_error(sum_z, x_z, t_z);
        depth[i] += r.primary_distance;  // kMissDepth for a miss; a farther hit stays farther
        const double lum = luminance(r.radiance);
        luminance_sq[i] += lum * lum;
        double* sq = &radiance_sq[i].x;
        store_pair(sq, load_pair(sq) + x_xy * x_xy);
        sq[2] += x_z * x_z;
        count[i] += 1;
        return true;
    }
};

// A batch's samples added to their pixels in the order they were drawn (PixelSums::add each).
void accumulate_sse2(const PixelSums& pixel_sums, const size_t* pixels, const SampleResult* results, int count,
                     uint64_t& rays, uint64_t& nonfinite) {
    const PixelSums sums = pixel_sums;  // in registers, not reloaded after each store
    uint64_t batch_rays = 0, dropped = 0;
    for (int k = 0; k < count; ++k) {
        batch_rays += results[k].rays;
        dropped += !sums.add(pixels[k], results[k]);
    }
    rays += batch_rays;
    nonfinite += dropped;
}

#ifdef KR_ACCUMULATE_AVX2
// The same with a colour's three channels in one AVX register: the same IEEE operations per
// channel as PixelSums::add, so the same sums bit for bit, in about two thirds of its
// instructions. (No FMA in this target, so no product is fused into a sum.)
__attribute__((target("avx2"))) inline void store_xyz(double* p, __m256d v) {
    _mm_storeu_pd(p, _mm256_castpd256_pd128(v));
    _mm_store_sd(p + 2, _mm256_extractf128_pd(v, 1));
}

// A pixel's sums, held in registers, stored. (A function of this target, not a lambda: a
// lambda is compiled without AVX2, and would take the vectors through memory.)
__attribute__((target("avx2"), always_inline)) inline void store_sums(const PixelSums& sums, size_t i, __m256d sum,
                                                                     __m256d lost, __m256d sq, double depth,
                                                                     double luminance_sq, uint32_t count) {
    store_xyz(&sums.radiance[i].x, sum);
    store_xyz(&sums.compensation[i].x, lost);
    store_xyz(&sums.radiance_sq[i].x, sq);
    sums.depth[i] = depth;
    sums.luminance_sq[i] = luminance_sq;
    sums.count[i] = count;
}

__attribute__((target("avx2"))) void accumulate_avx2(const PixelSums& pixel_sums, const size_t* pixels,
                                                     const SampleResult* results, int count, uint64_t& rays,
                                                     uint64_t& nonfinite) {
    static_assert(offsetof(SampleResult, primary_distance) == 3 * sizeof(double), "one load reads a result's colour");
    if (count <= 0) return;
    const PixelSums sums = pixel_sums;
    const __m256i xyz = _mm256_setr_epi64x(-1, -1, -1, 0);  // the lanes of a Color read from a pixel's sums
    const __m256d zero = _mm256_setzero_pd();
    uint64_t batch_rays = 0, dropped = 0;
    // A planned pass gives a pixel its samples one after another: its sums stay in registers
    // until a sample of another pixel comes, instead of being reloaded from the stores just
    // made (a load that spans two stores waits for them to reach the cache).
    size_t held = pixels[0];
    __m256d sum = _mm256_maskload_pd(&sums.radiance[held].x, xyz);
    __m256d lost = _mm256_maskload_pd(&sums.compensation[held].x, xyz);
    __m256d sq = _mm256_maskload_pd(&sums.radiance_sq[held].x, xyz);
    double depth = sums.depth[held], luminance_sq = sums.luminance_sq[held];
    uint32_t samples = sums.count[held];
    for (int k = 0; k < count; ++k) {
        const SampleResult& r = results[k];
        const size_t i = pixels[k];
        batch_rays += r.rays;
        if (i != held) {
            store_sums(sums, held, sum, lost, sq, depth, luminance_sq, samples);
            held = i;
            sum = _mm256_maskload_pd(&sums.radiance[i].x, xyz);
            lost = _mm256_maskload_pd(&sums.compensation[i].x, xyz);
            sq = _mm256_maskload_pd(&sums.radiance_sq[i].x, xyz);
            depth = sums.depth[i];
            luminance_sq = sums.luminance_sq[i];
            samples = sums.count[i];
        }
        // The sample's colour, its fourth lane (the depth) cleared, and the new sums.
        const __m256d x = _mm256_blend_pd(_mm256_loadu_pd(&r.radiance.x), zero, 0b1000);
        const __m256d t = sum + x;
        // Finite (the sample, and the sum not overflowed): t - t is 0 in every lane.
        if (_mm256_movemask_pd(_mm256_cmp_pd(t - t, zero, _CMP_EQ_OQ)) != 0b1111) {
            ++dropped;
            continue;
        }
        // two_sum_error(sum, x, t) written out: Clang passes no AVX vector to a function
        // compiled without AVX.
        const __m256d x_part = t - sum;
        lost = lost + ((sum - (t - x_part)) + (x - x_part));
        sum = t;
        depth += r.primary_distance;
        const double lum = luminance(r.radiance);
        luminance_sq += lum * lum;
        sq = sq + x * x;
        samples += 1;
    }
    store_sums(sums, held, sum, lost, sq, depth, luminance_sq, samples);
    rays += batch_rays;
    nonfinite += dropped;
}
#endif

bool avx2_accumulation() {
#ifdef KR_ACCUMULATE_AVX2
    static const bool has = __builtin_cpu_supports("avx2");
    return has;
#else
    return false;
#endif
}

void accumulate(const PixelSums& sums, const size_t* pixels, const SampleResult* results, int count,
                bool avx2, uint64_t& rays, uint64_t& nonfinite) {
#ifdef KR_ACCUMULATE_AVX2
    if (avx2) return accumulate_avx2(sums, pixels, results, count, rays, nonfinite);
#endif
    (void)avx2;
    accumulate_sse2(sums, pixels, results, count, rays, nonfinite);
}

PixelSums pixel_sums_of(PixelBuffers& px) {
    return {px.radiance_sum.data(), px.radiance_compensation.data(), px.depth_sum.data(),
            px.luminance_sq_sum.data(),  px.radiance_sq_sum.data(),       px.sample_count.data()};
}

// One thread's share of a pass: it fills batches of samples row by row, traces each batch
// (trace_camera_samples: SIMD lanes where they can be) and adds the results to their pixels
// in the order they were drawn, so every pixel's sums are those of tracing them one by one.
class PassThread {
public:
    PassThread(const RenderScene& scene, const RenderSettings& settings, RenderState& state, bool avx2,
               PacketKernels kernels)
        : scene_(scene),
          settings_(settings),
          state_(state),
          sums_(pixel_sums_of(state.buffers())),
          avx2_(avx2),
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
        accumulate(sums_, pixels_, results_, count, avx2_, rays, nonfinite);
    }

    const RenderScene& scene_;
    const RenderSettings& settings_;
    const RenderState& state_;
    const PixelSums sums_;
    const bool avx2_;
    const PacketKernels kernels_;
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
    const bool avx2 = avx2_accumulation();
    const PacketKernels kernels = packet_kernels(scene, settings);
#pragma omp parallel reduction(+ : rays, nonfinite) reduction(|| : stopped)
    {
        PassThread thread(scene, settings, state, avx2, kernels);
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
            thread.sample_row(y);
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
