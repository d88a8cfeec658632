#include "render/render_pass.h"

#include <algorithm>
#include <optional>

#include "render/sampler.h"
#include "render/trace.h"

namespace kr {

namespace {

// Compensated summation (Neumaier's, with Knuth's TwoSum for the rounding error of each
// addition: exact whichever term is larger, and without a branch). `sum` stays the plain
// running sum; `compensation` gathers what its roundings lost.
inline void add_compensated(double& sum, double& compensation, double x) {
    const double t = sum + x;
    const double x_part = t - sum;
    compensation += (sum - (t - x_part)) + (x - x_part);
    sum = t;
}

}  // namespace

bool render_pass(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                 const std::atomic<bool>* stop) {
    const int width = state.width, height = state.height;
    PixelBuffers& px = state.buffers();
    uint64_t rays = 0, nonfinite = 0;
    bool stopped = false;
    const bool sobol = settings.estimator == Estimator::sobol;
    const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
    if (sobol && (px.sobol_keys.size() != pixels || px.sobol_keys_seed != settings.seed)) {
        px.sobol_keys.resize(pixels);
        px.sobol_keys_seed = settings.seed;
        const long n = long(pixels);
#pragma omp parallel for schedule(static)
        for (long i = 0; i < n; ++i) px.sobol_keys[size_t(i)] = Sampler::pixel_key(settings.seed, uint64_t(i));
    }
    // Rows handed out one at a time: rows through glass cost far more than rows of wall.
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : rays, nonfinite) reduction(|| : stopped)
    for (int y = 0; y < height; ++y) {
        if (stop && stop->load(std::memory_order_relaxed)) {
            stopped = true;  // each thread's own copy, or-ed together at the end (no data race)
            continue;
        }
        // Samples go to trace_samples kSampleBatch at a time (path tracing traces their paths
        // in SIMD lanes) and are accumulated in the order they were drawn, so every pixel's
        // sums are those of tracing them one by one.
        std::optional<Sampler> samplers[kSampleBatch];
        Sampler* batch_samplers[kSampleBatch];
        int batch_x[kSampleBatch], batch_y[kSampleBatch];
        size_t batch_pixels[kSampleBatch];
        SampleResult results[kSampleBatch];
        int pending = 0;
        auto flush = [&] {
            trace_camera_samples(scene, settings, width, height, batch_x, batch_y, batch_samplers, pending, results);
            for (int k = 0; k < pending; ++k) {
                const SampleResult& r = results[k];
                const size_t pixel = batch_pixels[k];
                rays += r.rays;
                // A NaN or Inf sample is dropped and counted, never accumulated; so is one that
                // would overflow the pixel's sum. The sums stay finite, so a sum plus a sample
                // is finite only where the sample is too: one test covers both.
                if (!is_finite(px.radiance_sum[pixel] + r.radiance)) {
                    ++nonfinite;
                    continue;
                }
                Color& sum = px.radiance_sum[pixel];
                Color& lost = px.radiance_compensation[pixel];
                add_compensated(sum.x, lost.x, r.radiance.x);
                add_compensated(sum.y, lost.y, r.radiance.y);
                add_compensated(sum.z, lost.z, r.radiance.z);
                px.depth_sum[pixel] += r.primary_distance;  // kMissDepth for a miss; a farther hit stays farther
                const double lum = luminance(r.radiance);
                px.luminance_sq_sum[pixel] += lum * lum;
                px.radiance_sq_sum[pixel] += r.radiance * r.radiance;
                px.sample_count[pixel] += 1;
            }
            pending = 0;
        };
        for (int x = 0; x < width; ++x) {
            const size_t pixel = static_cast<size_t>(y) * width + x;
            if (!px.active.empty() && !px.active[pixel]) continue;
            const int samples = px.pass_samples.empty() ? 1 : px.pass_samples[pixel];
            for (int k = 0; k < samples; ++k) {
                const uint32_t index = px.sample_index[pixel]++;
                batch_samplers[pending] =
                    sobol ? &samplers[pending].emplace(px.sobol_keys[pixel], index)
                          : &samplers[pending].emplace(settings.estimator, settings.seed, pixel, index, settings.target_spp);
                batch_x[pending] = x;
                batch_y[pending] = y;
                batch_pixels[pending] = pixel;
                if (++pending == kSampleBatch) flush();
            }
        }
        if (pending > 0) flush();
    }
    state.rays += rays;
    state.nonfinite_samples += nonfinite;
    if (stopped) return false;
    ++state.passes;
    return true;
}

}  // namespace kr
