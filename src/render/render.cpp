#include "render/render.h"

#include <chrono>
#include <cmath>

#include <omp.h>

namespace kr {

RenderSettings RenderSettings::from_scene(const RendererSettings& renderer) {
    RenderSettings s;
    s.integrator = renderer.type == RendererType::wrt ? Integrator::wrt : Integrator::pt;
    s.max_depth = std::clamp(renderer.depth, 0, kMaxDepth);
    s.target_spp = std::max(1, renderer.samples);
    return s;
}

void RenderState::reset(int w, int h) {
    width = w;
    height = h;
    const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h);
    radiance_sum.assign(n, Color());
    depth_sum.assign(n, 0.0);
    luminance_sq_sum.assign(n, 0.0);
    sample_count.assign(n, 0);
    sample_index.assign(n, 0);
    passes = 0;
    rays = 0;
    nonfinite_samples = 0;
    active.clear();
}

Image RenderState::radiance() const {
    Image img(width, height);
    for (size_t i = 0; i < img.pixels.size(); ++i)
        img.pixels[i] = sample_count[i] ? radiance_sum[i] / double(sample_count[i]) : Color();
    return img;
}

std::vector<double> RenderState::mean_depth() const {
    std::vector<double> d(depth_sum.size(), kMissDepth);
    for (size_t i = 0; i < d.size(); ++i)
        if (sample_count[i]) d[i] = depth_sum[i] / double(sample_count[i]);
    return d;
}

double RenderState::pixel_standard_error(size_t i) const {
    const double n = sample_count[i];
    // Below two samples there is no variance; a sum of squares that overflowed (radiance
    // above ~1e154) would give inf - inf: the error is unknown, not zero.
    if (n < 2 || !std::isfinite(luminance_sq_sum[i])) return kInfinity;
    const double mean = luminance(radiance_sum[i]) / n;
    // Unbiased sample variance of one sample, then of the mean of n.
    const double variance = std::max(0.0, (luminance_sq_sum[i] - n * mean * mean) / (n - 1));
    return std::sqrt(variance / n);
}

double RenderState::relative_error() const {
    double error_sq = 0, signal_sq = 0;
    for (size_t i = 0; i < sample_count.size(); ++i) {
        const double se = pixel_standard_error(i);
        if (!std::isfinite(se)) return kInfinity;
        error_sq += se * se;
        const double mean = luminance(radiance_sum[i]) / sample_count[i];
        signal_sq += mean * mean;
    }
    if (signal_sq <= 0) return error_sq > 0 ? kInfinity : 0.0;
    return std::sqrt(error_sq / signal_sq);
}

size_t RenderState::update_adaptive(double target, uint32_t min_samples) {
    const size_t n = sample_count.size();
    double signal_sq = 0;
    std::vector<double> error_sq(n);
    for (size_t i = 0; i < n; ++i) {
        const double mean = sample_count[i] ? luminance(radiance_sum[i]) / sample_count[i] : 0.0;
        signal_sq += mean * mean;
        const double se = pixel_standard_error(i);
        error_sq[i] = se * se;
    }
    const double share = target * target * signal_sq / double(std::max<size_t>(n, 1));
    active.assign(n, 0);
    size_t count = 0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            // A few samples can miss a rare bright path and show almost no variance; the
            // mean over the 3x3 neighbourhood (variance varies smoothly) guards against that.
            double sum = 0;
            int cells = 0;
            for (int yy = std::max(0, y - 1); yy <= std::min(height - 1, y + 1); ++yy)
                for (int xx = std::max(0, x - 1); xx <= std::min(width - 1, x + 1); ++xx) {
                    sum += error_sq[size_t(yy) * width + xx];
                    ++cells;
                }
            const size_t i = size_t(y) * width + x;
            const double local = std::max(error_sq[i], sum / cells);
            const bool needs_more = sample_count[i] < min_samples || !(local <= share);
            active[i] = needs_more;
            count += needs_more;
        }
    return count;
}

bool render_pass(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                 const std::atomic<bool>* stop) {
    const int width = state.width, height = state.height;
    uint64_t rays = 0, nonfinite = 0;
    bool stopped = false;
    // Rows handed out one at a time: rows through glass cost far more than rows of wall.
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : rays, nonfinite) reduction(|| : stopped)
    for (int y = 0; y < height; ++y) {
        if (stop && stop->load(std::memory_order_relaxed)) {
            stopped = true;  // each thread's own copy, or-ed together at the end (no data race)
            continue;
        }
        for (int x = 0; x < width; ++x) {
            const size_t pixel = static_cast<size_t>(y) * width + x;
            if (!state.active.empty() && !state.active[pixel]) continue;
            const uint32_t index = state.sample_index[pixel]++;
            Sampler sampler(settings.estimator, settings.seed, pixel, index, settings.target_spp);
            const Vec2 sub = sampler.pixel();
            Vec2 lens;
            if (scene.camera.lens_radius > 0) lens = sampler.next_2d();
            else sampler.skip_2d();  // a pinhole's image stays the same as a tiny lens's
            const Vec2 film = raster_to_camera(x + sub.x, y + sub.y, width, height);
            const CameraRay cr = scene.camera.generate(film.x, film.y, lens.x, lens.y);
            Ray ray;
            ray.o = cr.origin;
            ray.d = cr.direction;
            const SampleResult r = trace_sample(scene, settings, ray, sampler);
            rays += r.rays;
            // A NaN or Inf sample is dropped and counted, never accumulated; so is one that
            // would overflow the pixel's sum.
            if (!is_finite(r.radiance) || !is_finite(state.radiance_sum[pixel] + r.radiance)) {
                ++nonfinite;
                continue;
            }
            state.radiance_sum[pixel] += r.radiance;
            state.depth_sum[pixel] += std::min(r.primary_distance, kMissDepth);
            const double lum = luminance(r.radiance);
            state.luminance_sq_sum[pixel] += lum * lum;
            state.sample_count[pixel] += 1;
        }
    }
    state.rays += rays;
    state.nonfinite_samples += nonfinite;
    if (stopped) return false;
    ++state.passes;
    return true;
}

StopReason render_until(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                        const StopRule& rule, const std::function<bool(const RenderState&)>& on_pass) {
    const auto start = std::chrono::steady_clock::now();
    for (int pass = 0; pass < rule.max_passes; ++pass) {
        render_pass(scene, settings, state);
        if (on_pass && !on_pass(state)) return StopReason::cancelled;
        if (rule.noise > 0 && pass + 1 >= int(rule.min_samples) && (pass + 1) % rule.adapt_every == 0) {
            if (state.relative_error() <= rule.noise) return StopReason::noise;
            // Every pixel within its share means the whole image is within the target too.
            if (state.update_adaptive(rule.noise, rule.min_samples) == 0) return StopReason::noise;
        }
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (rule.seconds > 0 && elapsed >= rule.seconds) return StopReason::time;
    }
    return StopReason::passes;
}

}  // namespace kr
