#include "viewer/render_worker.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <omp.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include "core/memory.h"
#include "render/outputs.h"
#include "viewer/inspect.h"

namespace kr::viewer {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// A preview pass: the same renderer on a smaller image of the same view.
int scaled(int size, int scale) { return std::max(1, (size + scale - 1) / scale); }

}  // namespace

std::vector<int> preview_scales(int width, int height, double seconds_per_pixel, double budget_seconds) {
    const double pixels = double(width) * double(height);
    auto cost = [&](int scale) { return pixels / (double(scale) * scale) * seconds_per_pixel; };
    int first = 8;
    if (seconds_per_pixel > 0) {
        first = 16;
        while (first > 1 && cost(first / 2) <= budget_seconds) first /= 2;
    }
    std::vector<int> scales;
    // Each step costs a quarter of the next; stop refining once a full pass is quick anyway.
    for (int s = first; s > 1; s /= 2) {
        scales.push_back(s);
        if (seconds_per_pixel > 0 && cost(1) < 4 * budget_seconds) break;
    }
    return scales;
}

RenderWorker::RenderWorker(std::function<void()> on_publish, SharedPasses* ranks)
    : on_publish_(std::move(on_publish)), ranks_(ranks), thread_([this] { run(); }) {}

RenderWorker::~RenderWorker() {
    {
        std::lock_guard lock(mutex_);
        quit_ = true;
        stop_.store(true);
    }
    changed_.notify_all();
    thread_.join();
}

void RenderWorker::submit(RenderJob job) {
    {
        std::lock_guard lock(mutex_);
        rule_ = job.stop;
        rule_.max_passes = std::max(1, rule_.max_passes);
        pending_ = std::move(job);
        stop_.store(true);  // the pass in flight ends at its next row
    }
    changed_.notify_all();
}

void RenderWorker::set_paused(bool paused) {
    {
        std::lock_guard lock(mutex_);
        paused_ = paused;
    }
    changed_.notify_all();
}

void RegionHooks::before_pass(RenderState& state) {
    applied_ = false;
    if (!region) return;
    const int w = state.width, h = state.height;
    std::vector<uint8_t>& active = state.buffers().active;
    saved_.swap(active);  // empty: every pixel, else the noise rule's mask
    active.assign(state.sample_count().size(), 0);
    // A process of a shared render holds some rows only (RenderState::row_start).
    for (int y = std::max(0, region->y0); y < std::min(h, region->y1); ++y) {
        if (!state.holds_row(y)) continue;
        for (int x = std::max(0, region->x0); x < std::min(w, region->x1); ++x) {
            const size_t i = state.row_start(y) + size_t(x);
            active[i] = saved_.empty() ? 1 : saved_[i];
        }
    }
    applied_ = true;
}

void RegionHooks::after_pass(RenderState& state, bool) {
    if (applied_) state.buffers().active.swap(saved_);
    saved_.clear();
    applied_ = false;
}

void RenderWorker::set_region(std::optional<PixelBox> region) {
    {
        std::lock_guard lock(mutex_);
        region_ = region;
    }
    changed_.notify_all();
}

void RenderWorker::set_features(bool on) {
    {
        std::lock_guard lock(mutex_);
        features_.store(on);
    }
    changed_.notify_all();
}

void RenderWorker::set_stop_rule(const StopRule& rule) {
    {
        std::lock_guard lock(mutex_);
        rule_ = rule;
        rule_.max_passes = std::max(1, rule_.max_passes);
    }
    changed_.notify_all();
}

std::shared_ptr<const Snapshot> RenderWorker::latest() const {
    std::lock_guard lock(mutex_);
    return latest_;
}

std::shared_ptr<const Snapshot> RenderWorker::wait_newer(uint64_t serial, std::chrono::milliseconds timeout) const {
    std::unique_lock lock(mutex_);
    published_.wait_for(lock, timeout, [&] { return latest_ && latest_->serial > serial; });
    return latest_;
}

void RenderWorker::publish(std::shared_ptr<Snapshot> frame) {
    {
        std::lock_guard lock(mutex_);
        frame->serial = ++serial_;
        latest_ = std::move(frame);
    }
    published_.notify_all();
    if (on_publish_) on_publish_();
}

void RenderWorker::publish_error(uint64_t generation, std::string error) {
    auto frame = std::make_shared<Snapshot>();
    frame->generation = generation;
    frame->finished = true;
    frame->error = std::move(error);
    publish(std::move(frame));
}

namespace {

// The denoised radiance of `state` for the display, developed by render/outputs.h with the
// interactive filter (Save and `render --denoise` develop with the final one). `albedo` and `normal` keep the feature buffers of a full-resolution
// state between passes (empty: made here).
Image denoised_radiance(const RenderJob& job, const RenderState& state, std::vector<float>& albedo,
                        std::vector<float>& normal, DenoiseWorkspace& workspace) {
    DevelopOptions options;
    options.workspace = &workspace;
    options.denoise = Denoise::on;
    options.interactive = true;  // the live display: the a-trous filter (Save: the final one)
    options.sampling = job.settings;
    RenderEstimates estimates = render_estimates(state, kLayerRadiance | develop_reads(options));
    estimates.albedo = std::move(albedo);
    estimates.normal = std::move(normal);
    Developed developed = develop(*job.scene, std::move(estimates), options, kLayerRadiance | kLayerAlbedo | kLayerNormal);
    albedo = std::move(developed.albedo);
    normal = std::move(developed.normal);
    return std::move(developed.radiance);
}

}  // namespace

void RenderWorker::run() {
    // Below the UI thread: on a 2-core machine the OpenMP team would otherwise starve the
    // window. Linux nice values are per thread, and the team's threads, created by this
    // thread at its first parallel region, inherit it.
    setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), 10);
    // This thread's OpenMP team, started before a pass would start it and libgomp end the
    // viewer where a thread's stack does not fit the address space (core/memory.h): with as
    // many threads as fit, the image being the same at any count.
    if (const int fit = start_thread_team(); fit < omp_get_max_threads()) {
        omp_set_num_threads(fit);
        start_thread_team();
    }
    constexpr double kPreviewBudget = 0.010;  // seconds for the first preview pass
    RenderJob job;
    RenderState state;  // the estimate of `job`, at full resolution
    RegionHooks region;  // before the driver, which holds it
    std::optional<RegionOverShare> shared;  // with ranks: the region over this rank's rows
    if (ranks_) shared.emplace(region, ranks_->hooks());
    PassHooks* hooks = ranks_ ? static_cast<PassHooks*>(&*shared) : &region;
    uint64_t job_rays = 0, job_nonfinite = 0;  // with ranks: every rank's, gathered after a pass
    bool job_unsent = false;  // with ranks: `job` is not yet theirs
    auto send_job = [&] {
        if (job_unsent) ranks_->start_job(*job.source, job.settings, state.tracks_halves());
        job_unsent = false;
    };
    std::optional<ProgressiveDriver> driver;
    std::vector<int> previews;
    size_t next_preview = 0;
    double seconds = 0;
    double seconds_per_pixel = 0;  // measured cost, carried across edits
    std::vector<float> albedo, normal;  // the full-resolution feature buffers of `job`
    std::shared_ptr<const FeatureBuffers> features;  // the same for the feature views, made once
    DenoiseWorkspace denoise_planes;    // kept between frames
    // The feature views' buffers of `job` at full resolution: the denoiser's when it made them.
    auto full_features = [&] {
        if (!features) {
            auto f = std::make_shared<FeatureBuffers>();
            f->width = job.scene->renderer.width;
            f->height = job.scene->renderer.height;
            if (!albedo.empty() && !normal.empty()) f->albedo = albedo, f->normal = normal;
            else feature_buffers(*job.scene, job.settings, f->width, f->height, f->albedo, f->normal);
            features = std::move(f);
        }
        return features;
    };

    for (;;) {
        send_job();
        StopRule rule;
        // Which rule ends the refinement, if any (called under the lock).
        auto stop_reason = [&]() -> std::optional<StopReason> {
            if (!driver || next_preview < previews.size()) return std::nullopt;
            return driver->stop_reason(rule_);
        };
        // A feature view asked for while no pass is coming: the newest full frame again, with
        // the feature layers (under the lock).
        auto features_due = [&] {
            return features_.load() && driver && latest_ && latest_->generation == job.generation &&
                   latest_->scale == 1 && latest_->error.empty() && !latest_->features;
        };
        std::shared_ptr<const Snapshot> republish;
        {
            std::unique_lock lock(mutex_);
            changed_.wait(lock, [&] {
                return quit_ || pending_ || (driver && !paused_ && !stop_reason()) || features_due();
            });
            if (quit_) return;
            if (!pending_ && !(driver && !paused_ && !stop_reason())) republish = latest_;
            if (pending_) {
                job = std::move(*pending_);
                pending_.reset();
                stop_.store(false);  // under the lock: a newer submit sets it again after this
                const int w = job.scene->renderer.width, h = job.scene->renderer.height;
                // The estimate render applies, before allocating (render_state.h).
                const std::string image = std::to_string(w) + "x" + std::to_string(h) + " image";
                if (std::string shortfall = memory_shortfall(render_memory_bytes(w, h, false, true), "the render of a " + image);
                    !shortfall.empty()) {
                    driver.reset();
                    lock.unlock();
                    publish_error(job.generation, std::move(shortfall));
                    continue;
                }
                try {
                    state.reset(w, h);
                    state.track_halves();  // for Save's final denoiser
                } catch (const std::bad_alloc&) {
                    driver.reset();
                    lock.unlock();
                    publish_error(job.generation, "not enough memory for the render state of a " + image);
                    continue;
                }
                albedo.clear();
                normal.clear();
                features.reset();
                driver.emplace(*job.scene, job.settings, state, rule_, hooks);
                job_unsent = ranks_ != nullptr;  // sent outside the lock: the ranks may be busy
                job_rays = job_nonfinite = 0;
                previews = preview_scales(w, h, seconds_per_pixel, kPreviewBudget);
                next_preview = 0;
                seconds = 0;
                if (paused_) continue;  // an edit while paused shows nothing new until resumed
            }
            rule = rule_;
            region.region = region_;
        }
        send_job();

        const int w = job.scene->renderer.width, h = job.scene->renderer.height;
        if (republish) {
            try {
                auto frame = std::make_shared<Snapshot>(*republish);
                frame->features = full_features();
                frame->hit_depth = hit_depths(frame->depth, frame->sample_count);
                publish(std::move(frame));
            } catch (const std::bad_alloc&) {
                driver.reset();
                publish_error(job.generation, "not enough memory for the feature layers of a " + std::to_string(w) +
                                                  "x" + std::to_string(h) + " image");
            }
            continue;
        }
        const auto start = Clock::now();
        auto frame = std::make_shared<Snapshot>();
        bool shared_pass = false;  // inside a pass shared with the other ranks
        // An allocation that fails here (a preview, a pass's buffers, the frame's copies) is
        // the window's error, not an abort of the viewer; the job is dropped.
        try {
        if (next_preview < previews.size()) {
            const int scale = previews[next_preview];
            RenderState preview(scaled(w, scale), scaled(h, scale));
            if (!kr::render_pass(*job.scene, job.settings, preview, &stop_)) continue;
            seconds += seconds_since(start);
            ++next_preview;
            frame->scale = scale;
            frame->radiance = preview.radiance();
            std::vector<float> preview_albedo, preview_normal;
            if (denoise_.load())
                frame->denoised = denoised_radiance(job, preview, preview_albedo, preview_normal, denoise_planes);
            if (features_.load()) {
                auto f = std::make_shared<FeatureBuffers>();
                f->width = preview.width;
                f->height = preview.height;
                if (preview_albedo.empty() || preview_normal.empty())
                    feature_buffers(*job.scene, job.settings, f->width, f->height, f->albedo, f->normal);
                else f->albedo = std::move(preview_albedo), f->normal = std::move(preview_normal);
                frame->features = std::move(f);
                frame->hit_depth = hit_depths(preview.mean_depth(), preview.sample_count());
            }
        } else {
            if (ranks_) {
                // Every rank runs the pass to its end: they exchange rows after it.
                if (std::string error = ranks_->begin_pass(rule, region.region); !error.empty()) {
                    driver.reset();
                    publish_error(job.generation, std::move(error));
                    continue;
                }
                shared_pass = true;
                driver->pass(rule);
                ranks_->end_pass(state, job_rays, job_nonfinite);
                shared_pass = false;
            }
            // A pass stopped early is always an edit's: the next turn starts the new job.
            else if (!driver->pass(rule, &stop_)) continue;
            const double dt = seconds_since(start);
            seconds += dt;
            // Only full passes: tiny previews are dominated by per-pass overheads.
            seconds_per_pixel = dt / (double(w) * h);
            frame->radiance = state.radiance();
            if (denoise_.load()) {
                if ((albedo.empty() || normal.empty()) && features) albedo = features->albedo, normal = features->normal;
                frame->denoised = denoised_radiance(job, state, albedo, normal, denoise_planes);
            }
        }
        frame->generation = job.generation;
        frame->spp = state.passes;
        frame->seconds = seconds;
        frame->full_seconds = driver->seconds();
        frame->rays = ranks_ ? job_rays : state.rays;
        frame->relative_error = frame->spp >= 2 ? state.relative_error() : INFINITY;
        frame->nonfinite_samples = ranks_ ? job_nonfinite : state.nonfinite_samples;
        if (frame->scale == 1) {
            record_pixel_statistics(state, *frame);
            if (features_.load()) {
                frame->features = full_features();
                frame->hit_depth = hit_depths(frame->depth, frame->sample_count);
            }
        }
        } catch (const std::bad_alloc&) {
            if (shared_pass) {
                // The other ranks wait for this one's rows: only the end of the job frees them.
                std::fprintf(stderr, "error: not enough memory for rendering a %dx%d image on rank 0\n", w, h);
                std::fflush(stderr);
                std::_Exit(1);
            }
            driver.reset();
            publish_error(job.generation, "not enough memory for rendering a " + std::to_string(w) + "x" +
                                              std::to_string(h) + " image");
            continue;
        }
        {
            std::lock_guard lock(mutex_);
            frame->max_passes = rule_.max_passes;
            frame->stopped_by = stop_reason();
            frame->finished = frame->stopped_by.has_value();
        }
        publish(std::move(frame));
    }
}

}  // namespace kr::viewer
