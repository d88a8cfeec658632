// The render thread: runs progressive passes of the core renderer and publishes
// immutable Snapshots for the UI thread. It owns its accumulation buffer outright; the UI
// only ever sees finished Snapshots, handed over under a mutex, and never touches GL here.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "core/image.h"
#include "render/aov.h"
#include "render/denoise.h"
#include "render/progressive.h"

namespace kr::viewer {

// What to render: a prepared scene (shared, never modified once built), the settings, and
// the rule that ends the refinement (RenderWorker::set_stop_rule changes it for the running
// estimate).
struct RenderJob {
    uint64_t generation = 0;  // the model's edit counter: frames carry it back
    std::shared_ptr<const RenderScene> scene;
    RenderSettings settings;
    StopRule stop;
    // The scene `scene` was prepared from: what the other ranks prepare (SharedPasses; only
    // needed with them).
    std::shared_ptr<const Scene> source;
    // When the edit was made (RenderWorker::submit stamps a job that has none): frames count
    // their wall time from it.
    std::chrono::steady_clock::time_point edited{};
};

// A render region: the image pixels that full passes refine (core/image.h).
using kr::PixelBox;

// Narrows each full pass to a region's pixels (AND the noise rule's mask), through the
// driver's pass hooks, before the pass is planned: the plan gives the region's pixels as many
// samples as they are (a pass costs what its pixels cost) and render_pass skips the pixels
// whose active entry is 0, so the others keep their samples and their image. No region: the
// pass is untouched.
class RegionHooks : public PassHooks {
public:
    std::optional<PixelBox> region;
    void before_plan(RenderState& state) override;
    // The pass's rows narrowed to the region's (AND the rows a process's share sets before it):
    // render_pass and the halves skip the others' rows whole.
    void before_pass(RenderState& state) override;
    void after_pass(RenderState& state, bool statistics) override;
    bool any(bool stop) override { return stop; }

private:
    std::vector<uint8_t> saved_;       // the noise rule's mask while the region's is in place
    std::vector<uint8_t> saved_rows_;  // the pass's rows before the region's
    bool applied_ = false, rows_applied_ = false;
};

// A region's hooks over a process's share of the rows (SharedPasses::hooks): a pass samples
// the region's pixels of this process's rows; the share decides the stops and the row sums.
class RegionOverShare final : public PassHooks {
public:
    RegionOverShare(RegionHooks& region, PassHooks& share) : region_(region), share_(share) {}
    void before_plan(RenderState& state) override {
        share_.before_plan(state);
        region_.before_plan(state);
    }
    void before_pass(RenderState& state) override {
        share_.before_pass(state);
        region_.before_pass(state);
    }
    void after_pass(RenderState& state, bool statistics) override {
        region_.after_pass(state, statistics);
        share_.after_pass(state, statistics);
    }
    bool any(bool stop) override { return share_.any(stop); }
    const RowShare* rows() const override { return share_.rows(); }

private:
    RegionHooks& region_;
    PassHooks& share_;
};

// The other processes of an MPI job that share the full passes (`mpirun -np N keithray view`;
// app/view_ranks.h implements it, so the viewer holds no MPI). Each pixel's samples are drawn
// by one process in the single-process order (app/cluster.h), so the image at N passes is the
// single-process viewer's, bit for bit. Only the render thread calls it, in this order: a job,
// then for each full pass begin_pass, the driver's pass with hooks(), end_pass.
class SharedPasses {
public:
    virtual ~SharedPasses() = default;
    // Every other rank prepares `scene` (the viewer's, sent as saved) with `settings` and
    // resets its state to its rows of the scene's image, tracking the two halves of
    // the samples when `halves`. Returns without waiting for them.
    virtual void start_job(const Scene& scene, const RenderSettings& settings, bool halves) = 0;
    // Every other rank starts its share of the next full pass under `rule`, narrowed to
    // `region`. Returns "" or, where a rank could not take the job (its memory), why; every
    // rank has then dropped the job, and this one must drop it too (no pass).
    virtual std::string begin_pass(const StopRule& rule, const std::optional<PixelBox>& region) = 0;
    // This rank's share of each pass (the driver's hooks, under the region's).
    virtual PassHooks& hooks() = 0;
    // After the driver's pass: every rank's rows into `state` (which holds every row), and
    // the job's rays and dropped samples so far.
    virtual void end_pass(RenderState& state, uint64_t& rays, uint64_t& nonfinite) = 0;
    // Any thread: "" while the job is whole, else why it is not (a rank died); the calling
    // render thread then waits for ever, and the process is to end.
    virtual std::string lost() const = 0;
};

// The first-surface albedo and normal of a frame's pixels (3 floats per pixel each): the
// denoiser's feature buffers (render/outputs.h feature_buffers), which the albedo and normal
// views show. One per edit at full resolution, shared by its frames.
struct FeatureBuffers {
    int width = 0, height = 0;
    std::vector<float> albedo, normal;
};

// One published snapshot of the estimate.
struct Snapshot {
    uint64_t generation = 0;
    uint64_t serial = 0;     // increases with every frame published
    int scale = 1;           // > 1: a preview rendered at 1/scale resolution, shown upscaled
    Image radiance;          // per-pixel mean radiance
    Image denoised;          // the radiance developed with the denoiser (render/outputs.h); empty when off
    int spp = 0;             // full-resolution passes accumulated (0 for a preview)
    int max_passes = 1;      // the stop rule's pass limit (kUnlimitedPasses: none)
    double seconds = 0;      // wall time from the edit to this frame (pauses excluded)
    double full_seconds = 0; // the engine's time in full-resolution passes (the time rule's clock)
    uint64_t rays = 0;       // rays of the full-resolution passes
    double relative_error = 0;  // RenderState::relative_error() of the accumulation
    // Full-resolution frames only (viewer/inspect.h): per pixel, the samples accumulated
    // and the standard error of the mean luminance (infinite below two samples).
    std::vector<uint32_t> sample_count;
    std::vector<float> standard_error;
    // And what Save develops with the radiance and the counts (render/outputs.h): the mean
    // depth and, per pixel, the variance of the mean radiance (in double, as render_estimates gives it).
    std::vector<double> depth;
    std::vector<Color> variance;
    // While a feature view is on (RenderWorker::set_features), previews included, at the
    // frame's resolution: the albedo and normal, and per pixel the mean primary hit distance
    // where every sample hit (infinite where one missed; viewer/inspect.h hit_depths).
    std::shared_ptr<const FeatureBuffers> features;
    std::vector<float> hit_depth;
    RenderState::Halves halves;  // the two halves of the samples (the final denoiser's guides)
    // Whether the frame carries the halves (a full frame of a finished or paused render, or
    // while RenderWorker::set_halves asks for them).
    bool has_halves() const { return halves.count[0].size() == radiance.pixels.size(); }
    uint64_t nonfinite_samples = 0;
    // Pixels whose display image took an earlier view's picture (viewer/reproject.h): after a
    // camera move, until the job nears its target.
    size_t carried_pixels = 0;
    bool finished = false;   // a stop rule ended the refinement
    std::optional<StopReason> stopped_by;  // which, once finished
    // Not empty: the job could not be rendered (its state does not fit in memory); the frame
    // has no image and the worker waits for the next job.
    std::string error;
};

// When the render thread develops a full-resolution frame of its estimate (the radiance, the
// display's denoised image, the pixel statistics) between passes. The first full pass of an
// edit, the last one (a stop rule met) and the pass before a pause always make one; between
// them a frame is due once `since_last` seconds have passed since the previous one, where the
// interval grows with the image's age (seconds since the edit: the image changes fast at
// first, slowly later) up to `max_interval`, and is never so short that the frames (`cost`:
// the render thread's time to make one plus the window's to draw it) take more than
// `cost_share` of the time. Frames nobody could see in time are not made. Frames come only at
// balanced sample counts (frame_spp), so one is also due a little early, once half the
// interval has passed, where waiting `next_wait` seconds for the next balanced count would
// end further past the interval than now is short of it.
struct FrameSchedule {
    double age_fraction = 0.5;   // interval: half the image's age (frames at ages 1, 1.5, 2.25, ...)
    double min_interval = 1.0 / 60;
    double max_interval = 1.0;
    double cost_share = 0.25;
    // The seconds the carried picture of an earlier view (reproject.h: the new view's first
    // surfaces traced, the picture reprojected) may add before a camera move's first full
    // frame, predicted from its measured cost per pixel (prior_first): a
    // dearer one (a large image; docs/viewer.md, "The render pipeline, measured") is made once
    // that frame is on screen, and the frame after it carries the picture.
    double prior_budget = 0.1;
    bool due(double age, double since_last, double cost, double next_wait = 0) const;
    // Whether the carried picture of `pixels` pixels is made before the first full frame: its
    // cost per pixel as measured last (`prior_seconds_per_pixel`; 0: never), else twice a
    // pass's (`pass_seconds_per_pixel`), within prior_budget.
    bool prior_first(double prior_seconds_per_pixel, double pass_seconds_per_pixel, double pixels) const;
};

// The display's feature buffers of one image (albedo and normal, render/outputs.h): refined a
// few camera samples at a time (render/aov.h add_surface_samples), so that the first frame of
// an edit costs one sample a pixel, and within a render region only while there is one; at
// kFeatureSamples they are feature_buffers', bit for bit.
struct DisplayFeatures {
    int width = 0, height = 0;
    SurfaceLayers sums;
    std::vector<uint8_t> counts;  // camera samples per pixel in the sums
    int samples = 0;              // the samples a pixel the display asked for last
    int whole = 0;                // ... that every pixel has
    std::vector<float> albedo, normal;  // of the sums

    void reset(int w, int h);
    // Refined to `total` camera samples a pixel (at most kFeatureSamples): the pixels of `box`
    // only, where given (a render region's: the others are not refined). False where `cancel`
    // was set before it was done (an edit replaced the view): the buffers are then left
    // unfinished, for the job that is dropped.
    bool refine_to(const RenderJob& job, int total, const std::optional<PixelBox>& box = std::nullopt,
                   const std::atomic<bool>* cancel = nullptr);
    // Before their first camera sample: the buffers of a preview of the same view (`preview`,
    // of a smaller image), each pixel taking those of the preview pixel it lies in. No sample
    // is counted: the next refine_to(1) traces every pixel's first one and replaces them.
    void take_preview(const DisplayFeatures& preview);
};
// A preview fine enough to guide the denoiser of a full frame: at least half the resolution.
bool guides_full_frame(const DisplayFeatures& preview, int width, int height);
// The display's feature buffers for the job's next full frame, as the render thread makes them:
// the first full frame of an edit, without a region, takes those of the job's last preview
// (`preview`, null where it had none) where guides_full_frame (their camera samples are paid
// for already: at 1920x1080 one sample a pixel costs about a pass), and the next frame traces
// both of its own samples (kDisplayFeatureSamples); otherwise each frame refines them by a
// sample (next_display_feature_samples), within the region where there is one. So every frame
// after an edit's first has kDisplayFeatureSamples, however many frames came before it.
// False where `cancel` stopped them (refine_to).
bool display_features_for_frame(DisplayFeatures& features, const RenderJob& job, const DisplayFeatures* preview,
                                const std::optional<PixelBox>& region, const std::atomic<bool>* cancel = nullptr);
// The camera samples a pixel of the display's feature buffers at the next frame: the first full
// frame of an edit traces one (or takes its preview's, and the next frame traces both:
// display_features_for_frame), the next one more (at 1920x1080 a sample costs about as much as
// a pass; kFeatureSamples, which Save and the feature views use, would hold up the first frames).
inline constexpr int kDisplayFeatureSamples = 2;
int next_display_feature_samples(const DisplayFeatures& features);
// A preview's feature buffers: one camera sample a preview pixel. Its image is coarse anyway,
// and the 1/2 preview's, which guide the first full frame, make it no worse than a second
// sample did (FirstFrames; docs/viewer.md), which at 1920x1080 cost more than the preview's pass.
inline constexpr int kPreviewFeatureSamples = 1;

// The frames the render thread publishes, as it makes them (the tests make the same):
// a preview of `job` at 1/scale resolution (one pass of its own), with the display's denoised
// radiance and the feature layers where asked (the display's feature buffers, of the
// preview's resolution, moved to `kept` where given: display_features_for_frame takes them);
// with a render `region`, only the preview pixels over it (preview_box) are sampled, their
// features made and denoised (the others black, as in the region's full frames);
void make_preview_frame(const RenderJob& job, int scale, bool denoise, bool features, DenoiseWorkspace& workspace,
                        Snapshot& frame, DisplayFeatures* kept = nullptr,
                        const std::optional<PixelBox>& region = std::nullopt);
// The pixels of a 1/scale preview of a width x height image that cover some of `region`.
std::optional<PixelBox> preview_box(const std::optional<PixelBox>& region, int width, int height, int scale);
// and a full-resolution frame of `state`: the radiance, the denoised radiance guided by
// `features` (null: not denoised) and the pixel statistics. With a render `region`, only the
// region's pixels are denoised where denoised_box says so, over the job's `previous` full
// frame's picture (or the raw one, black, where no other pixel has a sample). False, the
// frame left unfinished, where `cancel` was set (an edit replaced the view) before it was done:
// its steps check between them, and the filter between its passes. With `with_halves`, the
// frame carries the two halves of the samples too (Snapshot::halves: Save's final filter).
bool make_full_frame(const RenderJob& job, const RenderState& state, DisplayFeatures* features,
                     DenoiseWorkspace& workspace, Snapshot& frame, const Snapshot* previous = nullptr,
                     const std::optional<PixelBox>& region = std::nullopt,
                     const std::atomic<bool>* cancel = nullptr, bool with_halves = false);
// The pixels a full frame denoises alone: the render region clipped to the image, where the
// job's previous full frame (of `generation`) has a denoised picture to keep outside it, or
// where no pixel outside it has a sample yet (`samples`: per pixel; the raw radiance, black,
// is then the picture there); none (the whole image) otherwise, or where the region is most
// of the image.
std::optional<PixelBox> denoised_box(const std::optional<PixelBox>& region, int width, int height,
                                     const Snapshot* previous, uint64_t generation, const std::vector<uint32_t>& samples);

// The sample counts at which the render thread makes a full-resolution frame by its schedule
// (a stop rule met or a pause makes one at any count): from `first` on (after previews:
// first_frame_spp), and only where the samples are balanced: powers of two up to 8, then
// multiples of 8 (a Sobol or stratified estimate between them is less even: a Whitted render
// lost about 1 dB from 8 spp to 9).
bool frame_spp(int spp, int first = 1);
// The first full frame after previews: fewer samples, denoised, can look worse than the last
// preview. Through a pinhole 2 spp are already better; through a lens (its blur is noisy) 4
// (FirstFrames over every bundled scene: the lens scene's 2 spp frame is 0.3 dB below its
// preview at 96 px).
int first_frame_spp(const RenderScene& scene);
// The next count after `spp` that frame_spp allows from `first` on.
int next_frame_spp(int spp, int first);

// Preview resolutions for the first passes after an edit: 1/first_scale, then halving up
// to full resolution. first_scale is the smallest power of two (up to 16) whose pass is
// predicted to take under `budget_seconds`, from the measured cost of a pixel sample;
// 8 when nothing has been measured yet. Steps are skipped once a full pass is cheap.
std::vector<int> preview_scales(int width, int height, double seconds_per_pixel, double budget_seconds);

class RenderWorker {
public:
    // `on_publish` runs on the render thread after each snapshot (the window passes
    // glfwPostEmptyEvent, thread-safe, to wake its event wait): it must not touch GL.
    // With `ranks`, full passes are shared with the other processes of an MPI job (previews stay
    // here); a full pass under way then runs to its end before an edit's job starts.
    explicit RenderWorker(std::function<void()> on_publish = {}, SharedPasses* ranks = nullptr);
    ~RenderWorker();  // stops the pass in flight and joins
    RenderWorker(const RenderWorker&) = delete;
    RenderWorker& operator=(const RenderWorker&) = delete;

    // Restarts at once: stops the running pass (at its next row) and renders `job` from
    // scratch, low-resolution previews first.
    void submit(RenderJob job);
    // Neither resets the estimate. Pausing takes effect at the end of the running pass,
    // so the accumulated passes stay whole (and the image deterministic), and not before the
    // job has a full-resolution frame: a pause during the previews (or an edit while paused)
    // skips the previews left and stops after the first full pass's frame.
    void set_paused(bool paused);
    // A new stop rule for the running estimate: it keeps its samples and refines on to the
    // new pass limit (kUnlimitedPasses: none), for the rule's seconds of full-resolution
    // rendering, or until its estimated relative error is below the rule's noise (passes
    // going only to pixels above their share of it); or it stops (finished) if the new rule
    // is already met.
    void set_stop_rule(const StopRule& rule);
    // A render region for the running estimate and the next ones (none: the whole image):
    // only its pixels refine from the next full pass on; the others keep their samples.
    void set_region(std::optional<PixelBox> region);
    // Whether frames carry the denoised radiance (Snapshot::denoised), from the next frame on.
    void set_denoise(bool on) { denoise_.store(on); }
    // The window's time to draw a new frame (seconds; the frame schedule counts it).
    void set_display_cost(double seconds) { display_cost_.store(seconds); }
    void set_schedule(const FrameSchedule& schedule);
    // Whether frames carry the feature layers (Snapshot::features, hit_depth): from the next
    // frame on, and a finished or paused render's newest frame is published again with them.
    void set_features(bool on);
    // Whether every frame carries the two halves of the samples (Snapshot::halves), which Save
    // develops a denoised image with: from the next frame on, and a finished or paused
    // render's newest frame is published again with them. Without it only a finished or
    // paused render's frames carry them: they cost a frame about a sixth of its time.
    void set_halves(bool on);

    // The newest frame (null before the first).
    std::shared_ptr<const Snapshot> latest() const;
    // Blocks until a frame newer than `serial` is published or `timeout` passes.
    std::shared_ptr<const Snapshot> wait_newer(uint64_t serial, std::chrono::milliseconds timeout) const;

private:
    void run();
    void publish(std::shared_ptr<Snapshot> frame);
    void publish_error(uint64_t generation, std::string error);  // a frame with only the error

    std::function<void()> on_publish_;
    SharedPasses* ranks_;
    mutable std::mutex mutex_;
    mutable std::condition_variable changed_;   // wakes the render thread
    mutable std::condition_variable published_; // wakes waiters on frames
    std::optional<RenderJob> pending_;
    bool paused_ = false, quit_ = false;
    StopRule rule_;  // the job's, until set_stop_rule
    std::optional<PixelBox> region_;  // set_region's, read before each pass
    std::shared_ptr<const Snapshot> latest_;
    uint64_t serial_ = 0;
    std::atomic<bool> stop_{false};
    std::atomic<bool> denoise_{true};
    std::atomic<bool> features_{false};
    std::atomic<bool> halves_{false};
    std::atomic<double> display_cost_{0};
    FrameSchedule schedule_;  // under the mutex
    // The wall time of the job so far less its pauses (under the mutex): the job's start (its
    // edit), the pauses' total and when the current pause began.
    std::chrono::steady_clock::time_point job_start_{}, pause_start_{};
    double paused_seconds_ = 0;
    std::thread thread_;  // last: starts after every member above exists
};

}  // namespace kr::viewer
