#include "render/render_pass.h"

#include <algorithm>
#include <new>
#include <type_traits>

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

}  // namespace

bool render_pass(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                 const std::atomic<bool>* stop) {
    const int width = state.width, height = state.height;
    PixelBuffers& px = state.buffers();
    uint64_t rays = 0, nonfinite = 0;
    bool stopped = false;
    const bool sobol = settings.estimator == Estimator::sobol;
    const size_t pixels = px.sample_count.size();  // the held rows' (RenderState::reset)
    if (sobol && (px.sobol_keys.size() != pixels || px.sobol_keys_seed != settings.seed)) {
        px.sobol_keys.resize(pixels);
        px.sobol_keys_seed = settings.seed;
        // Each key from the pixel's place in the image.
#pragma omp parallel for schedule(static)
        for (int y = 0; y < height; ++y) {
            if (!state.holds_row(y)) continue;
            const size_t start = state.row_start(y), first = size_t(y) * size_t(width);
            for (size_t x = 0; x < size_t(width); ++x)
                px.sobol_keys[start + x] = Sampler::pixel_key(settings.seed, uint64_t(first + x));
        }
    }
    const PixelSums pixel_sums{px.radiance_sum.data(), px.radiance_compensation.data(), px.depth_sum.data(),
                               px.luminance_sq_sum.data(), px.radiance_sq_sum.data(), px.sample_count.data()};
    const uint8_t* const pixel_active = px.active.empty() ? nullptr : px.active.data();
    const uint8_t* const rows_active = px.active_rows.empty() ? nullptr : px.active_rows.data();
    const uint8_t* const pixel_pass_samples = px.pass_samples.empty() ? nullptr : px.pass_samples.data();
#pragma omp parallel reduction(+ : rays, nonfinite) reduction(|| : stopped)
    {
        // The pass's constants as each thread's own copies, so that they stay in registers.
        const PixelSums sums = pixel_sums;
        const uint8_t* const active = pixel_active;
        const uint8_t* const pass_samples = pixel_pass_samples;
        uint32_t* const sample_index = px.sample_index.data();
        const uint32_t* const sobol_keys = px.sobol_keys.data();
        const int w = width, h = height;
        // Samples go to trace_samples kSampleBatch at a time (path tracing traces their paths
        // in SIMD lanes) and are accumulated in the order they were drawn, so every pixel's
        // sums are those of tracing them one by one. The batch's arrays are each thread's,
        // for all its rows.
        static_assert(std::is_trivially_destructible_v<Sampler>, "slots are reused without destruction");
        union SamplerSlot {  // a Sampler made in place for each sample
            Sampler sampler;
            SamplerSlot() {}
        } slots[kSampleBatch];
        Sampler* batch_samplers[kSampleBatch];
        for (int k = 0; k < kSampleBatch; ++k) batch_samplers[k] = &slots[k].sampler;
        int batch_x[kSampleBatch], batch_y[kSampleBatch];
        size_t batch_pixels[kSampleBatch];
        SampleResult results[kSampleBatch];
        // Rows handed out one at a time: rows through glass cost far more than rows of wall.
#pragma omp for schedule(dynamic, 1)
        for (int y = 0; y < h; ++y) {
            if ((rows_active && !rows_active[y]) || !state.holds_row(y)) continue;
            if (stop && stop->load(std::memory_order_relaxed)) {
                stopped = true;  // each thread's own copy, or-ed together at the end (no data race)
                continue;
            }
            int pending = 0;
            auto flush = [&] {
                trace_camera_samples(scene, settings, w, h, batch_x, batch_y, batch_samplers, pending, results);
                for (int k = 0; k < pending; ++k) {
                    rays += results[k].rays;
                    nonfinite += !sums.add(batch_pixels[k], results[k]);
                }
                pending = 0;
            };
            // One sample into the batch. In a pass of one sample per pixel every pixel has the
            // same sample index, so its bit reversal is kept from the pixel before.
            uint32_t last_index = 0, last_reversed = 0;
            // `pixel`: the pixel's place in the buffers; `image_pixel`: in the image.
            const auto draw = [&](int x, size_t pixel, size_t image_pixel) {
                const uint32_t index = sample_index[pixel]++;
                if (sobol) {
                    if (index != last_index) last_index = index, last_reversed = reverse_bits(index);
                    new (&slots[pending].sampler) Sampler(sobol_keys[pixel], index, last_reversed);
                } else {
                    new (&slots[pending].sampler)
                        Sampler(settings.estimator, settings.seed, image_pixel, index, settings.target_spp);
                }
                batch_x[pending] = x;
                batch_y[pending] = y;
                batch_pixels[pending] = pixel;
                if (++pending == kSampleBatch) flush();
            };
            const size_t row = state.row_start(y), image_row = static_cast<size_t>(y) * w;
            for (int x = 0; x < w; ++x) {
                const size_t pixel = row + x;
                if (active && !active[pixel]) continue;
                if (!pass_samples) {
                    draw(x, pixel, image_row + x);
                    continue;
                }
                for (int k = 0; k < pass_samples[pixel]; ++k) draw(x, pixel, image_row + x);
            }
            if (pending > 0) flush();
        }
    }
    state.rays += rays;
    state.nonfinite_samples += nonfinite;
    if (stopped) return false;
    ++state.passes;
    return true;
}

}  // namespace kr
