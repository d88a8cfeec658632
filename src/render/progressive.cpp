#include "render/progressive.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include <omp.h>

#include "render/trace.h"

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
    px_.radiance_sum.assign(n, Color());
    px_.radiance_compensation.assign(n, Color());
    px_.depth_sum.assign(n, 0.0);
    px_.luminance_sq_sum.assign(n, 0.0);
    px_.radiance_sq_sum.assign(n, Color());
    px_.sample_count.assign(n, 0);
    px_.sample_index.assign(n, 0);
    passes = 0;
    rays = 0;
    nonfinite_samples = 0;
    px_.active.clear();
    px_.pass_samples.clear();
    px_.sample_credit.clear();
    for (auto& scratch : px_.allocation_scratch) scratch.clear();
    px_.sobol_keys.clear();
}

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

uint64_t render_memory_bytes(int width, int height, bool blurred) {
    const uint64_t eight_bit = 2 * 3 + 2 * 3, exr = 2 * 14 * sizeof(float);
    const uint64_t output = sizeof(Color) * (blurred ? 3 : 1) + sizeof(double) + std::max(eight_bit, exr);
    return uint64_t(width) * uint64_t(height) * (kRenderStateBytesPerPixel + output);
}

Image RenderState::radiance() const {
    Image img(width, height);
    for (size_t i = 0; i < img.pixels.size(); ++i)
        img.pixels[i] = px_.sample_count[i]
                            ? (px_.radiance_sum[i] + px_.radiance_compensation[i]) / double(px_.sample_count[i])
                            : Color();
    return img;
}

std::vector<double> RenderState::mean_depth() const {
    std::vector<double> d(px_.depth_sum.size(), kMissDepth);
    for (size_t i = 0; i < d.size(); ++i)
        if (px_.sample_count[i]) d[i] = px_.depth_sum[i] / double(px_.sample_count[i]);
    return d;
}

std::vector<Color> RenderState::variance_of_mean() const {
    std::vector<Color> v(px_.radiance_sum.size(), Color(kInfinity));
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

double RenderState::sample_variance(size_t i) const {
    const double n = px_.sample_count[i];
    // Below two samples there is no variance; a sum of squares that overflowed (radiance
    // above ~1e154) would give inf - inf: the variance is unknown, not zero.
    if (n < 2 || !std::isfinite(px_.luminance_sq_sum[i])) return kInfinity;
    const double mean = luminance(px_.radiance_sum[i]) / n;
    return std::max(0.0, (px_.luminance_sq_sum[i] - n * mean * mean) / (n - 1));  // unbiased
}

double RenderState::pixel_standard_error(size_t i) const {
    return std::sqrt(sample_variance(i) / px_.sample_count[i]);  // of the mean of n samples
}

double RenderState::relative_error() const {
    // Per-row sums in parallel, added in row order: the same estimate for any thread count.
    // (The viewer shows it after every pass.)
    const size_t w = size_t(width);
    std::vector<double> row_error(size_t(height), 0.0), row_signal(size_t(height), 0.0);
    std::vector<uint8_t> row_unknown(size_t(height), 0);
#pragma omp parallel for schedule(static)
    for (int y = 0; y < height; ++y)
        for (size_t i = size_t(y) * w; i < size_t(y + 1) * w; ++i) {
            const double se = pixel_standard_error(i);
            if (!std::isfinite(se)) {
                row_unknown[size_t(y)] = 1;
                break;
            }
            row_error[size_t(y)] += se * se;
            const double mean = luminance(px_.radiance_sum[i]) / px_.sample_count[i];
            row_signal[size_t(y)] += mean * mean;
        }
    double error_sq = 0, signal_sq = 0;
    for (size_t y = 0; y < size_t(height); ++y) {
        if (row_unknown[y]) return kInfinity;
        error_sq += row_error[y];
        signal_sq += row_signal[y];
    }
    if (signal_sq <= 0) return error_sq > 0 ? kInfinity : 0.0;
    return std::sqrt(error_sq / signal_sq);
}

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

double guarded_3x3(const std::vector<double>& values, const std::vector<double>& row_sums, int width, int height,
                   int y, size_t x) {
    const size_t w = size_t(width), i = size_t(y) * w + x;
    double sum = row_sums[i], cells = 1.0;
    if (y > 0) sum += row_sums[i - w], cells += 1.0;
    if (y + 1 < height) sum += row_sums[i + w], cells += 1.0;
    cells *= 1.0 + (x > 0) + (x + 1 < w);
    return std::max(values[i], sum / cells);
}

}  // namespace

size_t RenderState::update_adaptive(double target, uint32_t min_samples) {
    const size_t n = px_.sample_count.size(), w = size_t(width);
    // Rows in parallel, their sums added in order (as plan_pass).
    std::vector<double>& error_sq = px_.allocation_scratch[0];
    std::vector<double>& row_sums = px_.allocation_scratch[1];
    error_sq.resize(n);
    row_sums.resize(n);
    std::vector<double> row_signal(size_t(height), 0.0);
#pragma omp parallel for schedule(static)
    for (int y = 0; y < height; ++y) {
        for (size_t i = size_t(y) * w; i < size_t(y + 1) * w; ++i) {
            const double mean = px_.sample_count[i] ? luminance(px_.radiance_sum[i]) / px_.sample_count[i] : 0.0;
            row_signal[size_t(y)] += mean * mean;
            const double se = pixel_standard_error(i);
            error_sq[i] = se * se;
        }
        sum_three_along_row(&error_sq[size_t(y) * w], &row_sums[size_t(y) * w], w);
    }
    double signal_sq = 0;
    for (double s : row_signal) signal_sq += s;
    const double share = target * target * signal_sq / double(std::max<size_t>(n, 1));
    px_.active.resize(n);
    std::vector<size_t> row_count(size_t(height), 0);
#pragma omp parallel for schedule(static)
    for (int y = 0; y < height; ++y)
        for (size_t x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            const bool needs_more =
                px_.sample_count[i] < min_samples || !(guarded_3x3(error_sq, row_sums, width, height, y, x) <= share);
            px_.active[i] = needs_more;
            row_count[size_t(y)] += needs_more;
        }
    size_t count = 0;
    for (size_t c : row_count) count += c;
    return count;
}

void RenderState::plan_pass(const RenderSettings& settings) {
    if (settings.allocation != Allocation::adaptive || settings.estimator == Estimator::stratified ||
        passes < kAllocationWarmup) {
        px_.pass_samples.clear();
        return;
    }
    const size_t n = px_.sample_count.size(), w = size_t(width);
    // Optimal allocation: minimising sum_i var_i / n_i for a fixed sum_i n_i gives n_i in
    // proportion to the standard deviation sigma_i. The floor keeps sampling pixels whose
    // estimate may be too low, and bounds the bias of deciding from the samples themselves.
    // Every loop runs over rows in parallel; sums are taken per row and then over the rows in
    // order, so the plan is the same for any number of threads. The loops are fused:
    // at 512x512 the plan is bound by memory traffic.
    std::vector<double>& variance = px_.allocation_scratch[0];
    std::vector<double>& row_sums = px_.allocation_scratch[1];  // 3-wide sums along each row
    std::vector<double>& weight = px_.allocation_scratch[2];
    variance.resize(n);
    row_sums.resize(n);
    weight.resize(n);
#pragma omp parallel for schedule(static)
    for (int y = 0; y < height; ++y) {
        for (size_t i = size_t(y) * w; i < size_t(y + 1) * w; ++i) variance[i] = sample_variance(i);
        sum_three_along_row(&variance[size_t(y) * w], &row_sums[size_t(y) * w], w);
    }
    // Each pixel's variance guarded by its 3x3 neighbourhood (as update_adaptive), then its
    // standard deviation, summed per row.
    std::vector<double> row_weight(size_t(height), 0.0);
    std::vector<size_t> row_active(size_t(height), 0);
#pragma omp parallel for schedule(static)
    for (int y = 0; y < height; ++y)
        for (size_t x = 0; x < w; ++x) {
            const size_t i = size_t(y) * w + x;
            const bool on = px_.active.empty() || px_.active[i];
            const double guarded = guarded_3x3(variance, row_sums, width, height, y, x);
            weight[i] = on && std::isfinite(guarded) ? std::sqrt(guarded) : 0.0;
            row_weight[size_t(y)] += weight[i];
            row_active[size_t(y)] += on;
        }
    double sum = 0;
    size_t active_count = 0;
    for (int y = 0; y < height; ++y) {
        sum += row_weight[size_t(y)];
        active_count += row_active[size_t(y)];
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
    for (int y = 0; y < height; ++y)
        for (size_t i = size_t(y) * w; i < size_t(y + 1) * w; ++i) {
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
                px.depth_sum[pixel] += std::min(r.primary_distance, kMissDepth);
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

bool plan_reads_statistics(const RenderSettings& settings, const RenderState& state) {
    return settings.allocation == Allocation::adaptive && settings.estimator != Estimator::stratified &&
           state.passes >= kAllocationWarmup;
}

bool noise_check_due(const StopRule& rule, int passes) {
    return rule.noise > 0 && passes >= int(rule.min_samples) && passes % rule.adapt_every == 0;
}

bool noise_target_met(RenderState& state, const StopRule& rule) {
    // Every pixel within its share means the whole image is within the target too.
    return state.relative_error() <= rule.noise || state.update_adaptive(rule.noise, rule.min_samples) == 0;
}

ProgressiveDriver::ProgressiveDriver(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                                     const StopRule& rule, PassHooks* hooks)
    : scene_(scene), settings_(settings), state_(state), hooks_(hooks) {
    if (state.passes > 0 && noise_check_due(rule, state.passes)) {
        noise_checked_ = rule.noise;
        noise_met_ = noise_target_met(state, rule);
    }
}

bool ProgressiveDriver::pass(const StopRule& rule, const std::atomic<bool>* cancel) {
    if (noise_checked_ && *noise_checked_ != rule.noise) {
        state_.clear_adaptive();  // the mask followed another target
        noise_met_ = false;
    }
    noise_checked_ = rule.noise;
    const auto start = std::chrono::steady_clock::now();
    state_.plan_pass(settings_);
    if (hooks_) hooks_->before_pass(state_);
    if (!render_pass(scene_, settings_, state_, cancel)) return false;
    const bool noise_check = noise_check_due(rule, state_.passes);
    if (hooks_) hooks_->after_pass(state_, noise_check || plan_reads_statistics(settings_, state_));
    if (noise_check) noise_met_ = noise_target_met(state_, rule);
    seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (hooks_) time_agreed_ = hooks_->any(rule.seconds > 0 && seconds_ >= rule.seconds);
    return true;
}

std::optional<StopReason> ProgressiveDriver::stop_reason(const StopRule& rule) const {
    if (noise_met_ && rule.noise > 0 && noise_checked_ == rule.noise) return StopReason::noise;
    if (hooks_ ? time_agreed_ : rule.seconds > 0 && seconds_ >= rule.seconds) return StopReason::time;
    if (state_.passes >= rule.max_passes) return StopReason::passes;
    return std::nullopt;
}

StopReason render_until(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                        const StopRule& rule, const std::function<bool(const RenderState&)>& on_pass,
                        PassHooks* hooks) {
    ProgressiveDriver driver(scene, settings, state, rule, hooks);
    for (;;) {
        if (const auto reason = driver.stop_reason(rule)) return *reason;
        driver.pass(rule);
        if (on_pass && !on_pass(state)) return StopReason::cancelled;
    }
}

}  // namespace kr
