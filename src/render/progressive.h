// The progressive rendering API: settings + state + render_pass(), which adds one sample to
// every pixel, and ProgressiveDriver, the one driver of passes (plan, pass, process
// exchange, stop rules) under the CLI (render_until), the viewer's render thread and MPI
// ranks.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "core/image.h"
#include "render/render_scene.h"
#include "render/settings.h"

namespace kr {

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
    // Samples per pixel in the next pass, set by plan_pass (empty: one each).
    std::vector<uint8_t> pass_samples;
    std::vector<float> sample_credit;  // adaptive allocation: fractions of a sample carried over
    std::array<std::vector<double>, 3> allocation_scratch;  // plan_pass's and update_adaptive's buffers
    // The Sobol samplers' per-pixel keys (Sampler::pixel_key) for sobol_keys_seed: the same in
    // every pass, so render_pass works them out once (empty until a Sobol pass).
    std::vector<uint32_t> sobol_keys;
    uint64_t sobol_keys_seed = 0;
};

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
    void reset(int w, int h);
    Image radiance() const;                  // per-pixel mean radiance (compensated sums)
    std::vector<double> mean_depth() const;  // per-pixel mean primary distance
    // Per pixel and channel, the variance of the mean radiance: the unbiased sample variance
    // over the count (infinite below two samples). What `keithray compare --statistical` tests.
    std::vector<Color> variance_of_mean() const;

    // Unbiased variance of one sample's luminance in pixel `i` (infinite below two samples).
    double sample_variance(size_t i) const;
    // Standard error of pixel `i`'s mean luminance, from its sample variance (infinite below
    // two samples).
    double pixel_standard_error(size_t i) const;
    // Estimated relative RMS error of the whole image: sqrt(sum of per-pixel variances of the
    // mean) / sqrt(sum of squared mean luminances). Infinite before two samples per pixel.
    double relative_error() const;

    // Adaptive sampling towards an image relative error `target` (as relative_error()): a
    // pixel stays active while the variance of its mean exceeds an equal share of the allowed
    // total, target^2 * sum(mean^2) / pixels, or it has fewer than `min_samples` samples.
    // When no pixel is active the image meets the target. Returns the active count.
    size_t update_adaptive(double target, uint32_t min_samples = 16);

    // Plans the next pass for `settings.allocation` (fills pass_samples). Adaptive: after
    // kAllocationWarmup passes, each active pixel's share of the pass (as many samples as
    // active pixels) is proportional to its estimated standard deviation (3x3 guarded, as
    // update_adaptive) plus a floor, which minimises the summed variance of the pixel means
    // for the budget; fractions carry over between passes. Parallel over rows, with the rows'
    // sums added in order: the plan does not depend on threads.
    void plan_pass(const RenderSettings& settings);

    // Samples every pixel again (no adaptive mask).
    void clear_adaptive() { px_.active.clear(); }

private:
    PixelBuffers px_;
};

// The bytes per pixel a RenderState holds once every buffer is in use: the seven sums and
// counts, the adaptive mask, the pass plan and its credit, the three allocation buffers and
// the Sobol keys.
inline constexpr uint64_t kRenderStateBytesPerPixel =
    3 * sizeof(Color) + 2 * sizeof(double) + 2 * sizeof(uint32_t) + 2 * sizeof(uint8_t) + sizeof(float) +
    3 * sizeof(double) + sizeof(uint32_t);

// An upper estimate of the memory a render of width x height pixels holds at its peak: the
// RenderState, then at the end the mean radiance (and, when blurred, two more radiance images),
// the mean depth, and the larger output stage: the two 8-bit images and their encoded bytes,
// or an EXR's 14 float layers and its encoded bytes.
uint64_t render_memory_bytes(int width, int height, bool blurred);

inline constexpr int kAllocationWarmup = 8;        // passes of one sample each before adapting
inline constexpr double kAllocationFloor = 0.25;   // every pixel's share is at least this x mean
inline constexpr int kMaxPassSamples = 64;         // per pixel and pass

// Adds one sample to every pixel of `state`, or the number state.pass_samples gives (sample
// index = the pixel's own count of samples drawn).
// Parallel over rows with OpenMP; each sample has its own RNG stream seeded by
// (seed, pixel, sample index), so the image does not depend on threads or scheduling.
// If `stop` becomes true the pass ends early and returns false; pixels it reached keep their
// sample, others do not: the state is then an unevenly sampled estimate, which
// ProgressiveDriver's users drop (the viewer stops a pass only for an edit).
bool render_pass(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                 const std::atomic<bool>* stop = nullptr);

// When a progressive render stops: after `max_passes`, after `seconds` of wall time (checked
// between passes), or when the estimated relative error reaches `noise` (adaptive sampling
// then spends passes only on pixels above their share of the error). 0 disables a rule.
struct StopRule {
    int max_passes = 1;
    double seconds = 0;
    double noise = 0;
    uint32_t min_samples = 16;  // per pixel before the noise rule trusts a variance
    int adapt_every = 4;        // passes between updates of the adaptive mask
};

enum class StopReason { passes, time, noise, cancelled };

// The noise rule of a StopRule, as every driver of passes applies it: checked after pass
// `passes` when the rule has a target, from min_samples passes on and every adapt_every
// passes (the adaptive mask is updated at the same checks).
bool noise_check_due(const StopRule& rule, int passes);
// The check itself: true when the image's estimated relative error is within the target, or
// no pixel is above its share of it; otherwise updates `state`'s adaptive mask.
bool noise_target_met(RenderState& state, const StopRule& rule);

// The driver's extension points for a render shared by several processes (app/cluster.h
// deals pixels to MPI ranks through them). Each pixel's samples are drawn by one process in
// the single-process order, so the sums are those of one process, bit for bit.
class PassHooks {
public:
    virtual ~PassHooks() = default;
    // After plan_pass, before render_pass: narrows the pass to this process's pixels.
    virtual void before_pass(RenderState& state) = 0;
    // After render_pass: undoes before_pass; when `statistics`, the next step reads the whole
    // image's statistics (plan_pass, update_adaptive, relative_error), so every process must
    // then hold every pixel's radiance_sum, luminance_sq_sum and sample_count.
    virtual void after_pass(RenderState& state, bool statistics) = 0;
    // One stop decision for all processes: whether any of them says `stop` (e.g. --time).
    virtual bool any(bool stop) = 0;
};

// Whether plan_pass reads the image's statistics for the next pass (adaptive allocation
// after its warm-up).
bool plan_reads_statistics(const RenderSettings& settings, const RenderState& state);

// The one driver of progressive passes (yocto-gl's trace_samples): each pass() plans the
// pass (plan_pass), lets `hooks` narrow it to this process's pixels, renders it
// (render_pass), shares what the next step reads, and applies the noise rule; stop_reason()
// says which rule ends the render. render_until loops over it for the CLI and MPI ranks; the
// viewer's render thread calls pass() between its previews and edits, with a cancel flag,
// under rules its user changes as it goes. The scene, settings, state and hooks must outlive
// the driver.
class ProgressiveDriver {
public:
    // A state restored from a checkpoint taken right after a noise check gets that check's
    // verdict again (a pure function of the sums), so it goes on exactly as if never stopped.
    ProgressiveDriver(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                      const StopRule& rule, PassHooks* hooks = nullptr);
    // One pass under `rule`. A changed noise target samples every pixel again until it is
    // checked. Returns false, and does nothing more, when `cancel` ended the pass early: the
    // state then holds part of a pass (render_pass) and is to be reset or dropped.
    bool pass(const StopRule& rule, const std::atomic<bool>* cancel = nullptr);
    // The rule that ends the render now, if any, in this order: the noise target met at its
    // last check (while `rule` keeps that target), the time (with hooks: the processes' common
    // decision after the last pass), the passes.
    std::optional<StopReason> stop_reason(const StopRule& rule) const;
    // Seconds spent in completed passes (the time rule's clock).
    double seconds() const { return seconds_; }

private:
    const RenderScene& scene_;
    const RenderSettings& settings_;
    RenderState& state_;
    PassHooks* hooks_;
    double seconds_ = 0;
    bool time_agreed_ = false;             // with hooks: every process's time is up
    std::optional<double> noise_checked_;  // the noise target the adaptive mask follows
    bool noise_met_ = false;               // ... and whether its last check met it
};

// Runs passes until a rule stops it: state.passes counts towards rule.max_passes, so a state
// restored from a checkpoint (render/checkpoint.h) goes on as if never stopped. `on_pass`,
// if given, is called after each pass (and its noise check) and may return false to cancel;
// `hooks` spread the passes over processes.
StopReason render_until(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                        const StopRule& rule, const std::function<bool(const RenderState&)>& on_pass = {},
                        PassHooks* hooks = nullptr);

}  // namespace kr
