#include "viewer/render_worker.h"

#include "viewer/reproject.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <malloc.h>
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

bool FrameSchedule::due(double age, double since_last, double cost, double next_wait) const {
    const double interval = std::max(std::clamp(age_fraction * age, min_interval, max_interval), cost / cost_share);
    if (since_last >= interval) return true;
    const double early = interval - since_last, late = since_last + next_wait - interval;
    return since_last >= 0.5 * interval && late > early;
}

bool FrameSchedule::prior_first(double prior_seconds_per_pixel, double pass_seconds_per_pixel, double pixels) const {
    // Before its cost was measured, twice a pass's per pixel: it measures 0.9 to 2.1 times a
    // pass's at 512x512, 1.3 to 3 times at 1920x1080 (scenes 3, 4, 8 and gallery_100), where
    // a pass's alone let a dear one hold the first frame up.
    const double per_pixel = prior_seconds_per_pixel > 0 ? prior_seconds_per_pixel : 2 * pass_seconds_per_pixel;
    return per_pixel * pixels <= prior_budget;
}

bool frame_spp(int spp, int first) {
    if (spp < first) return false;
    return spp <= 8 ? (spp & (spp - 1)) == 0 : spp % 8 == 0;
}

int first_frame_spp(const RenderScene& scene) { return scene.camera.lens_radius > 0 ? 4 : 2; }

int next_frame_spp(int spp, int first) {
    int next = std::max(spp + 1, first);
    while (!frame_spp(next, first)) ++next;
    return next;
}

RenderWorker::RenderWorker(std::function<void()> on_publish, SharedPasses* ranks)
    : on_publish_(std::move(on_publish)), ranks_(ranks), thread_([this] { run(); }) {
    // A frame allocates its images afresh (about 30 MB at 512x512: the radiance, variance,
    // depth, halves and statistics), and glibc gives blocks this large their own mapping,
    // whose pages fault in zeroed each time and go back to the system when the UI drops the
    // frame: half of a frame's cost (docs/viewer.md). Kept in the heap instead, the next frame
    // reuses them. The viewer holds that memory while it runs.
    static const bool heap_kept = [] {
        mallopt(M_MMAP_THRESHOLD, 256 << 20);
        mallopt(M_TRIM_THRESHOLD, 512 << 20);
        return true;
    }();
    (void)heap_kept;
}

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
        if (job.edited == Clock::time_point{}) job.edited = Clock::now();
        pending_ = std::move(job);
        stop_.store(true);  // the pass in flight ends at its next row
    }
    changed_.notify_all();
}

void RenderWorker::set_paused(bool paused) {
    {
        std::lock_guard lock(mutex_);
        if (paused && !paused_) pause_start_ = Clock::now();
        if (!paused && paused_ && pause_start_ >= job_start_) paused_seconds_ += seconds_since(pause_start_);
        paused_ = paused;
    }
    changed_.notify_all();
}

void RegionHooks::before_plan(RenderState& state) {
    applied_ = false;
    if (!region) return;
    const int w = state.width, h = state.height;
    std::vector<uint8_t>& active = state.plan.active;
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

void RegionHooks::before_pass(RenderState& state) {
    rows_applied_ = false;
    if (!applied_) return;
    std::vector<uint8_t>& rows = state.active_rows;
    saved_rows_ = rows;  // empty: every row
    if (rows.empty()) rows.assign(size_t(state.height), 1);
    for (int y = 0; y < state.height; ++y)
        if (y < region->y0 || y >= region->y1) rows[size_t(y)] = 0;
    rows_applied_ = true;
}

void RegionHooks::after_pass(RenderState& state, bool) {
    if (applied_) state.plan.active.swap(saved_);
    if (rows_applied_) state.active_rows.swap(saved_rows_);
    saved_.clear();
    saved_rows_.clear();
    applied_ = rows_applied_ = false;
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

void RenderWorker::set_halves(bool on) {
    {
        std::lock_guard lock(mutex_);
        halves_.store(on);
    }
    changed_.notify_all();
}

void RenderWorker::set_schedule(const FrameSchedule& schedule) {
    std::lock_guard lock(mutex_);
    schedule_ = schedule;
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

// The display's denoised picture of `estimates` (the radiance, depth, variance and, for a
// Whitted render, the counts), developed by render/outputs.h with the interactive filter
// (Save and `render --denoise` develop with the final one), guided by `features` of their
// resolution, which are lent to the estimates for it (nothing is copied).
Image denoised_radiance(const RenderJob& job, RenderEstimates& estimates, DisplayFeatures& features,
                        DenoiseWorkspace& workspace, const std::atomic<bool>* cancel = nullptr) {
    DevelopOptions options;
    options.workspace = &workspace;
    options.cancel = cancel;
    options.denoise = Denoise::on;
    options.interactive = true;  // the live display: the a-trous filter (Save: the final one)
    options.sampling = job.settings;
    estimates.albedo = std::move(features.albedo);
    estimates.normal = std::move(features.normal);
    Image out = denoised_image(estimates, estimates.radiance, options);
    features.albedo = std::move(estimates.albedo);
    features.normal = std::move(estimates.normal);
    return out;
}

// The same within `box` only, over `base` (the job's previous denoised picture): the box is
// filtered as an image of its own, its edges as the image's borders, and the pixels outside it,
// whose samples a region's passes leave as they were, keep their picture.
Image denoised_radiance_in(const RenderJob& job, const RenderEstimates& estimates, const DisplayFeatures& features,
                           const PixelBox& box, const Image& base, DenoiseWorkspace& workspace,
                           const std::atomic<bool>* cancel = nullptr) {
    const int w = estimates.radiance.width, bw = box.x1 - box.x0, bh = box.y1 - box.y0;
    RenderEstimates crop;
    crop.radiance = Image(bw, bh);
    crop.depth.resize(size_t(bw) * bh);
    crop.variance.resize(size_t(bw) * bh);
    if (!estimates.samples.empty()) crop.samples.resize(size_t(bw) * bh);
    DisplayFeatures crop_features;
    crop_features.albedo.resize(3 * size_t(bw) * bh);
    crop_features.normal.resize(3 * size_t(bw) * bh);
    for (int y = 0; y < bh; ++y) {
        const size_t from = size_t(box.y0 + y) * size_t(w) + size_t(box.x0), to = size_t(y) * size_t(bw);
        std::copy_n(estimates.radiance.pixels.begin() + long(from), bw, crop.radiance.pixels.begin() + long(to));
        std::copy_n(estimates.depth.begin() + long(from), bw, crop.depth.begin() + long(to));
        std::copy_n(estimates.variance.begin() + long(from), bw, crop.variance.begin() + long(to));
        if (!crop.samples.empty()) std::copy_n(estimates.samples.begin() + long(from), bw, crop.samples.begin() + long(to));
        std::copy_n(features.albedo.begin() + long(3 * from), 3 * bw, crop_features.albedo.begin() + long(3 * to));
        std::copy_n(features.normal.begin() + long(3 * from), 3 * bw, crop_features.normal.begin() + long(3 * to));
    }
    const Image filtered = denoised_radiance(job, crop, crop_features, workspace, cancel);
    if (filtered.pixels.empty()) return filtered;  // cancelled
    Image out = base;
    for (int y = 0; y < bh; ++y)
        std::copy_n(filtered.pixels.begin() + long(y) * bw, bw,
                    out.pixels.begin() + long(size_t(box.y0 + y) * size_t(w) + size_t(box.x0)));
    return out;
}

// The job's earlier denoised picture of the whole image, where `previous` is one (null if not).
const Image* earlier_picture(const Snapshot* previous, uint64_t generation, int width, int height) {
    const bool same = previous && previous->generation == generation && previous->scale == 1 &&
                      previous->denoised.width == width && previous->denoised.height == height;
    return same ? &previous->denoised : nullptr;
}

}  // namespace

std::optional<PixelBox> denoised_box(const std::optional<PixelBox>& region, int width, int height,
                                     const Snapshot* previous, uint64_t generation, const std::vector<uint32_t>& samples) {
    if (!region) return std::nullopt;
    const PixelBox box{std::max(0, region->x0), std::max(0, region->y0), std::min(width, region->x1),
                       std::min(height, region->y1)};
    // An empty box, or one of most of the image: the whole image, as cheap and seamless.
    if (box.x0 >= box.x1 || box.y0 >= box.y1 || 2 * double(box.x1 - box.x0) * (box.y1 - box.y0) > double(width) * height)
        return std::nullopt;
    if (earlier_picture(previous, generation, width, height)) return box;
    // No earlier picture: only where no pixel outside the box has a sample yet (a job started
    // with a region), whose picture is then the raw radiance (black), as a filter would leave it.
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            if ((x < box.x0 || x >= box.x1 || y < box.y0 || y >= box.y1) && samples[size_t(y) * size_t(width) + size_t(x)])
                return std::nullopt;
    return box;
}

void DisplayFeatures::reset(int w, int h) {
    width = w, height = h, samples = whole = 0;
    sums = {};
    counts.clear();
    albedo.clear();
    normal.clear();
}

bool DisplayFeatures::refine_to(const RenderJob& job, int total, const std::optional<PixelBox>& box,
                                const std::atomic<bool>* cancel) {
    total = std::min(total, kFeatureSamples);
    if (total <= whole) return true;
    const PixelBox pixels = box.value_or(PixelBox{0, 0, width, height});
    if (!add_surface_samples(*job.scene, job.settings, width, height, pixels, total, counts, sums, cancel))
        return false;
    feature_buffers_from_sums(sums, counts, width, pixels, albedo, normal);
    samples = std::max(samples, total);
    if (!box) whole = total;
    return true;
}

void DisplayFeatures::take_preview(const DisplayFeatures& preview) {
    const int pw = preview.width, ph = preview.height;
    albedo.resize(3 * size_t(width) * size_t(height));
    normal.resize(albedo.size());
    // Pixel x's centre, (x + 1/2) / width of the film, lies in the preview's pixel
    // floor((x + 1/2) * pw / width): both images span the same film.
    std::vector<int> column(size_t(std::max(0, width)));
    for (int x = 0; x < width; ++x) column[size_t(x)] = std::min(pw - 1, int((2 * int64_t(x) + 1) * pw / (2 * int64_t(width))));
#pragma omp parallel for schedule(static)
    for (int y = 0; y < height; ++y) {
        const int py = std::min(ph - 1, int((2 * int64_t(y) + 1) * ph / (2 * int64_t(height))));
        for (int x = 0; x < width; ++x) {
            const size_t to = 3 * (size_t(y) * size_t(width) + size_t(x));
            const size_t from = 3 * (size_t(py) * size_t(pw) + size_t(column[size_t(x)]));
            std::copy_n(preview.albedo.begin() + long(from), 3, albedo.begin() + long(to));
            std::copy_n(preview.normal.begin() + long(from), 3, normal.begin() + long(to));
        }
    }
}

bool guides_full_frame(const DisplayFeatures& preview, int width, int height) {
    return preview.width > 0 && preview.height > 0 && 2 * preview.width >= width && 2 * preview.height >= height &&
           preview.albedo.size() == 3 * size_t(preview.width) * size_t(preview.height) &&
           preview.normal.size() == preview.albedo.size();
}

bool display_features_for_frame(DisplayFeatures& features, const RenderJob& job, const DisplayFeatures* preview,
                                const std::optional<PixelBox>& region, const std::atomic<bool>* cancel) {
    if (!region && features.samples == 0 && features.albedo.empty() && preview &&
        guides_full_frame(*preview, features.width, features.height)) {
        features.take_preview(*preview);
        return true;
    }
    // After a frame guided by the preview's buffers, both samples at once: every frame after
    // the first then has the same buffers however many frames the schedule made before it
    // (the image a scripted run or Save takes does not depend on the machine's speed).
    const bool took_preview = features.samples == 0 && !features.albedo.empty();
    return features.refine_to(job, took_preview ? kDisplayFeatureSamples : next_display_feature_samples(features),
                              region, cancel);
}

int next_display_feature_samples(const DisplayFeatures& features) {
    return std::min(kDisplayFeatureSamples, features.samples + 1);
}

std::optional<PixelBox> preview_box(const std::optional<PixelBox>& region, int width, int height, int scale) {
    if (!region) return std::nullopt;
    const int pw = scaled(width, scale), ph = scaled(height, scale);
    // The preview pixels that cover some of the region's: preview pixel i spans the image's
    // pixels [i * width / pw, (i + 1) * width / pw).
    const auto first = [&](int v, int size, int psize) { return int(int64_t(std::clamp(v, 0, size)) * psize / size); };
    const auto end = [&](int v, int size, int psize) {
        return int((int64_t(std::clamp(v, 0, size)) * psize + size - 1) / size);
    };
    return PixelBox{first(region->x0, width, pw), first(region->y0, height, ph), end(region->x1, width, pw),
                    end(region->y1, height, ph)};
}

void make_preview_frame(const RenderJob& job, int scale, bool denoise, bool features, DenoiseWorkspace& workspace,
                        Snapshot& frame, DisplayFeatures* kept, const std::optional<PixelBox>& region) {
    const int w = job.scene->renderer.width, h = job.scene->renderer.height;
    RenderState preview(scaled(w, scale), scaled(h, scale));
    // A render region's preview samples only the pixels over it, as its full passes do
    // (RegionHooks): the rows outside it skipped whole, the other pixels of its rows by the
    // plan's mask; they stay black, as they stay in its full frames.
    const std::optional<PixelBox> box = preview_box(region, w, h, scale);
    if (box) {
        preview.active_rows.assign(size_t(preview.height), 0);
        preview.plan.active.assign(size_t(preview.width) * size_t(preview.height), 0);
        for (int y = box->y0; y < box->y1; ++y) {
            preview.active_rows[size_t(y)] = 1;
            std::fill_n(preview.plan.active.begin() + long(size_t(y) * size_t(preview.width) + size_t(box->x0)),
                        box->x1 - box->x0, uint8_t(1));
        }
    }
    kr::render_pass(*job.scene, job.settings, preview);
    frame.scale = scale;
    frame.radiance = preview.radiance();
    DisplayFeatures preview_features;
    if (denoise || features) {
        preview_features.reset(preview.width, preview.height);
        preview_features.refine_to(job, kPreviewFeatureSamples, box);
    }
    if (denoise) {
        DevelopOptions reads;
        reads.denoise = Denoise::on;
        reads.interactive = true;
        reads.sampling = job.settings;
        RenderEstimates estimates = render_estimates(preview, develop_reads(reads) | kLayerRadiance);
        // The box alone unless it is empty or most of the preview (denoised_box's rule).
        const bool boxed = box && box->x0 < box->x1 && box->y0 < box->y1 &&
                           2 * double(box->x1 - box->x0) * (box->y1 - box->y0) <= double(preview.width) * preview.height;
        frame.denoised = boxed
                             ? denoised_radiance_in(job, estimates, preview_features, *box, estimates.radiance, workspace)
                             : denoised_radiance(job, estimates, preview_features, workspace);
    }
    if (features) {
        auto f = std::make_shared<FeatureBuffers>();
        f->width = preview.width;
        f->height = preview.height;
        f->albedo = kept ? preview_features.albedo : std::move(preview_features.albedo);
        f->normal = kept ? preview_features.normal : std::move(preview_features.normal);
        frame.features = std::move(f);
        frame.hit_depth = hit_depths(preview.mean_depth(), preview.sample_count());
    }
    // A region's preview has features over the region only: none to guide a full frame.
    if (kept) *kept = box ? DisplayFeatures{} : std::move(preview_features);
}

bool make_full_frame(const RenderJob& job, const RenderState& state, DisplayFeatures* features,
                     DenoiseWorkspace& workspace, Snapshot& frame, const Snapshot* previous,
                     const std::optional<PixelBox>& region, const std::atomic<bool>* cancel, bool with_halves) {
    const auto cancelled = [&] { return cancel && cancel->load(); };
    RenderEstimates estimates = render_estimates(
        state, kLayerRadiance | kLayerDepth | kLayerSamples | kLayerVariance | (with_halves ? kLayerHalves : 0u));
    if (cancelled()) return false;
    const std::optional<PixelBox> box =
        features ? denoised_box(region, state.width, state.height, previous, job.generation, estimates.samples) : std::nullopt;
    if (box) {
        const Image* earlier = earlier_picture(previous, job.generation, state.width, state.height);
        frame.denoised = denoised_radiance_in(job, estimates, *features, *box, earlier ? *earlier : estimates.radiance,
                                              workspace, cancel);
    }
    else if (features) frame.denoised = denoised_radiance(job, estimates, *features, workspace, cancel);
    if (cancelled()) return false;
    frame.radiance = std::move(estimates.radiance);
    record_pixel_statistics(state, std::move(estimates), frame);
    return true;
}

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
    double seconds_per_pixel = 0;  // measured cost, carried across edits
    DisplayFeatures display_features;  // of `job` at full resolution, for the display's filter
    DisplayFeatures preview_features;  // of `job`'s last preview (display_features_for_frame)
    std::shared_ptr<const FeatureBuffers> features;  // the feature views' (complete), made once
    DenoiseWorkspace denoise_planes;    // kept between frames
    std::shared_ptr<const Snapshot> last_full;  // the newest full frame made (a region's frames build on it)
    std::shared_ptr<const RenderScene> last_full_scene;  // and its job's scene and settings
    RenderSettings last_full_settings;
    // The best picture of the world so far, carried across camera moves (reproject.h): the
    // frame with the most samples of an earlier view of the same world, and what the current
    // job takes from it (made at its first full frame; none for a lens, a region or another world).
    std::optional<ViewHistory> history;
    std::shared_ptr<const RenderScene> history_scene;
    RenderSettings history_settings;
    int history_spp = 0;
    std::optional<Reprojection> prior;
    bool prior_made = false;
    // The prior's cost (the new view's first surfaces and the reprojection), measured per
    // pixel and carried across edits (0: none made yet; a pass's cost stands for it), and
    // whether the job's prior waits for its first full frame to be on screen (prior_budget).
    double prior_seconds_per_pixel = 0;
    bool prior_deferred = false;
    // The first surfaces of a view a prior was made for (`hits_generation`'s job): its frame,
    // kept as the history later, takes them instead of tracing them again.
    std::optional<ViewHits> view_hits_made;
    uint64_t hits_generation = 0;
    // Whether a frame of `scene` made with `settings` can stand for `job`'s view: the same
    // world, radiance estimated alike, a pinhole.
    auto fits_job = [&](const RenderScene& scene, const RenderSettings& settings) {
        const RenderSettings& a = job.settings;
        return reprojectable(scene) && reprojectable(*job.scene) && same_world(scene, *job.scene) &&
               a.integrator == settings.integrator && a.max_depth == settings.max_depth &&
               a.rr_depth == settings.rr_depth && a.light_sampling == settings.light_sampling;
    };
    auto history_fits = [&] { return history && history_scene && fits_job(*history_scene, history_settings); };
    // The newest full frame (an earlier job's) becomes the history when it could stand for
    // `job`'s view and has more samples than the history, or the history could not.
    auto keep_history = [&](const std::shared_ptr<const Snapshot>& last, const std::shared_ptr<const RenderScene>& scene,
                            const RenderSettings& settings) {
        if (!last || !scene || last->denoised.pixels.empty() || last->spp < 2 ||
            (history && history->generation == last->generation) || !fits_job(*scene, settings))
            return;
        if (history_fits() && last->spp <= history_spp) return;
        ViewHistory h;
        h.generation = last->generation;
        if (view_hits_made && hits_generation == last->generation) h.hits = std::move(*view_hits_made);
        else h.hits = view_hits(*scene, last->radiance.width, last->radiance.height, settings);
        view_hits_made.reset();
        h.picture = last->denoised;
        h.samples = last->sample_count;
        history = std::move(h);
        history_scene = scene;
        history_settings = settings;
        history_spp = last->spp;
    };
    // The job's prior (the newest full frame before its first, `earlier`, kept as the history
    // where it is the best picture of the world yet, then the view's first surfaces and the
    // reprojection), and its measured cost per pixel.
    struct Earlier {
        std::shared_ptr<const Snapshot> frame;
        std::shared_ptr<const RenderScene> scene;
        RenderSettings settings;
    } earlier;
    auto forget_history = [&] {
        history.reset();  // only the carried picture is lost, not the job
        history_scene.reset();
        history_spp = 0;
        prior.reset();
        view_hits_made.reset();
    };
    auto keep_earlier = [&] {
        try {
            keep_history(earlier.frame, earlier.scene, earlier.settings);
        } catch (const std::bad_alloc&) {
            forget_history();
        }
        earlier = {};
    };
    auto make_prior = [&](int w, int h) {
        const auto start = Clock::now();
        keep_earlier();
        try {
            if (!history_fits() || history->generation == job.generation) return;
            // An edit meanwhile stops both (rows not begun are skipped) and drops what they
            // made: the prior was this job's, and the new one makes its own.
            view_hits_made = view_hits(*job.scene, w, h, job.settings, &stop_);
            hits_generation = job.generation;
            if (!stop_.load()) prior = reproject(*job.scene, *view_hits_made, *history, &stop_);
            if (stop_.load()) {
                view_hits_made.reset();
                prior.reset();
                return;
            }
        } catch (const std::bad_alloc&) {
            forget_history();
            return;
        }
        prior_seconds_per_pixel = seconds_since(start) / std::max(1.0, double(w) * h);
    };
    // The full-resolution passes of `job` not yet in a frame, and when the last frame was made.
    bool unpublished = false;
    bool full_frame_made = false;
    Clock::time_point last_frame{};
    // What making a full frame costs (seconds, smoothed), carried across edits while the image
    // keeps its size (`frame_cost_pixels`): an edit's first frame often costs more than the
    // frames of a settled view (the window is still drawing the edit's previews beside it),
    // and alone it would space the next frame as if every frame cost that much.
    double frame_cost = 0, frame_cost_pixels = 0;
    // The feature views' buffers of `job` at full resolution: the display's, completed.
    auto full_features = [&] {
        if (!features) {
            display_features.refine_to(job, kFeatureSamples);
            auto f = std::make_shared<FeatureBuffers>();
            f->width = display_features.width;
            f->height = display_features.height;
            f->albedo = display_features.albedo;
            f->normal = display_features.normal;
            features = std::move(f);
        }
        return features;
    };
    // Wall seconds of `job` so far, less its pauses (under the lock).
    auto job_seconds = [&] {
        const double paused = paused_seconds_ + (paused_ && pause_start_ >= job_start_ ? seconds_since(pause_start_) : 0);
        return std::max(0.0, seconds_since(job_start_) - paused);
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
        // Save asked for the halves while no pass is coming: the newest full frame again, with
        // them (under the lock).
        auto halves_due = [&] {
            return halves_.load() && driver && latest_ && latest_->generation == job.generation &&
                   latest_->scale == 1 && latest_->error.empty() && !latest_->has_halves();
        };
        std::shared_ptr<const Snapshot> republish;
        bool publish_estimate = false;  // a frame of passes already taken (paused, stopped)
        // Whether this turn's full frame carries the halves: asked for (set_halves), or the
        // frame of a finished or paused render, which Save takes as it is.
        bool frame_halves = false;
        // A pause holds the passes once the job has a full-resolution frame: one that comes
        // during the previews (or with an edit) still brings the picture to its first full
        // frame, never a frozen preview (under the lock).
        auto refining = [&] { return driver && !(paused_ && full_frame_made) && !stop_reason(); };
        bool skip_previews = false;
        {
            std::unique_lock lock(mutex_);
            changed_.wait(lock, [&] {
                return quit_ || pending_ || refining() || features_due() || halves_due() ||
                       (driver && unpublished);
            });
            if (quit_) return;
            if (!pending_ && !refining()) {
                if (unpublished) publish_estimate = frame_halves = true;
                else republish = latest_;
            }
            if (pending_) {
                job = std::move(*pending_);
                prior.reset();
                prior_made = false;
                prior_deferred = false;
                earlier = {};
                pending_.reset();
                stop_.store(false);  // under the lock: a newer submit sets it again after this
                job_start_ = job.edited;
                paused_seconds_ = 0;
                if (paused_) pause_start_ = job_start_;
                const int w = job.scene->renderer.width, h = job.scene->renderer.height;
                // The estimate render applies, before allocating (outputs.h).
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
                display_features.reset(w, h);
                preview_features.reset(0, 0);
                features.reset();
                unpublished = false;
                full_frame_made = false;
                driver.emplace(*job.scene, job.settings, state, rule_, hooks);
                job_unsent = ranks_ != nullptr;  // sent outside the lock: the ranks may be busy
                job_rays = job_nonfinite = 0;
                // A render region's previews sample its pixels only: planned by its size.
                int pw = w, ph = h;
                if (region_) {
                    pw = std::max(1, std::clamp(region_->x1, 0, w) - std::clamp(region_->x0, 0, w));
                    ph = std::max(1, std::clamp(region_->y1, 0, h) - std::clamp(region_->y0, 0, h));
                }
                previews = preview_scales(pw, ph, seconds_per_pixel, kPreviewBudget);
                next_preview = 0;
            }
            skip_previews = paused_;
            rule = rule_;
            region.region = region_;
        }
        send_job();

        const int w = job.scene->renderer.width, h = job.scene->renderer.height;
        if (republish) {
            // No pass since the newest frame: the state is still its samples.
            try {
                auto frame = std::make_shared<Snapshot>(*republish);
                if (features_.load() && !frame->features) {
                    frame->features = full_features();
                    frame->hit_depth = hit_depths(frame->depth, frame->sample_count);
                }
                if (halves_.load() && !frame->has_halves()) frame->halves = state.halves();
                publish(std::move(frame));
            } catch (const std::bad_alloc&) {
                driver.reset();
                publish_error(job.generation, "not enough memory for the feature layers or halves of a " +
                                                  std::to_string(w) + "x" + std::to_string(h) + " image");
            }
            continue;
        }
        auto frame = std::make_shared<Snapshot>();
        bool shared_pass = false;  // inside a pass shared with the other ranks
        // An allocation that fails here (a preview, a pass's buffers, the frame's copies) is
        // the window's error, not an abort of the viewer; the job is dropped.
        try {
        if (publish_estimate) {
            // The passes since the last frame, now that no pass follows them (paused, or a
            // stop rule met): made below.
        } else if (next_preview < previews.size() && !skip_previews) {
            const int scale = previews[next_preview];
            ++next_preview;
            // Not stopped by an edit: a preview is short by design (preview_scales), and during a
            // drag, edits coming faster than previews would otherwise leave the window none.
            make_preview_frame(job, scale, denoise_.load(), features_.load(), denoise_planes, *frame, &preview_features,
                               region.region);
        } else {
            next_preview = previews.size();  // paused: straight to the full frame
            const auto start = Clock::now();
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
            // Only full passes: tiny previews are dominated by per-pass overheads.
            const double pass_seconds = seconds_since(start);
            // Per pixel the pass sampled: a render region's only (previews of the whole
            // image are planned from it after the region is cleared).
            double pass_pixels = double(w) * h;
            if (region.region)
                pass_pixels = std::max(1.0, double(std::clamp(region.region->x1, 0, w) - std::clamp(region.region->x0, 0, w)) *
                                                double(std::clamp(region.region->y1, 0, h) - std::clamp(region.region->y0, 0, h)));
            seconds_per_pixel = pass_seconds / pass_pixels;
            unpublished = true;
            // The frame schedule: is this pass's image worth making and drawing now?
            bool due = false;
            {
                std::lock_guard lock(mutex_);
                const int first = previews.empty() ? 1 : first_frame_spp(*job.scene);
                const bool by_schedule = frame_spp(state.passes, first) &&
                    (!full_frame_made ||
                     schedule_.due(job_seconds(), seconds_since(last_frame), frame_cost + display_cost_.load(),
                                   pass_seconds * (next_frame_spp(state.passes, first) - state.passes)));
                const bool last_before_a_stop = paused_ || stop_reason();  // a frame Save takes as it is
                frame_halves = halves_.load() || last_before_a_stop;
                const bool halves_wanted =
                    halves_.load() && !(latest_ && latest_->generation == job.generation && latest_->has_halves());
                due = by_schedule || last_before_a_stop || halves_wanted ||
                      (features_.load() && !(latest_ && latest_->features));
            }
            if (!due) continue;
        }
        if (frame->scale == 1) {
            // A full-resolution frame of the estimate: its radiance, the display's denoised
            // image (guided by feature buffers refined one more step each frame) and the
            // pixel statistics.
            // The feature buffers' refinement is paid once an edit: the schedule counts the rest.
            // (An edit meanwhile stops them, as it stops the frame below.)
            if (denoise_.load() &&
                !display_features_for_frame(display_features, job, &preview_features, region.region, &stop_))
                continue;
            if (!prior_made && denoise_.load()) {
                // The job's first full frame: the newest frame before it (an earlier job's) may
                // be the best picture of the world yet, and this view takes what it can of it:
                // now where that holds the frame up little (prior_budget), else once the frame
                // is on screen (the next frame carries it).
                prior_made = true;
                if (!region.region) {
                    earlier = {last_full, last_full_scene, last_full_settings};
                    bool first = false;
                    {
                        std::lock_guard lock(mutex_);
                        first = schedule_.prior_first(prior_seconds_per_pixel, seconds_per_pixel, double(w) * h);
                    }
                    if (first) make_prior(w, h);
                    else prior_deferred = true;
                }
            }
            const auto start = Clock::now();
            // An edit that comes meanwhile (stop_) drops this frame of the view it replaced:
            // the next turn starts the new job.
            if (!make_full_frame(job, state, denoise_.load() ? &display_features : nullptr, denoise_planes, *frame,
                                 last_full.get(), region.region, &stop_, frame_halves))
                continue;
            if (features_.load()) {
                frame->features = full_features();
                frame->hit_depth = hit_depths(frame->depth, frame->sample_count);
            }
            const double cost = seconds_since(start);
            const double pixels = double(w) * h;
            frame_cost = frame_cost_pixels == pixels ? 0.5 * (frame_cost + cost) : cost;
            frame_cost_pixels = pixels;
            full_frame_made = true;
            unpublished = false;
            last_frame = Clock::now();
        }
        frame->generation = job.generation;
        frame->spp = state.passes;
        frame->full_seconds = driver->seconds();
        frame->rays = ranks_ ? job_rays : state.rays;
        frame->relative_error = frame->spp >= 2 ? state.relative_error() : INFINITY;
        frame->nonfinite_samples = ranks_ ? job_nonfinite : state.nonfinite_samples;
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
            frame->seconds = job_seconds();
            frame->max_passes = rule_.max_passes;
            frame->stopped_by = stop_reason();
            frame->finished = frame->stopped_by.has_value();
        }
        if (frame->scale == 1) {
            // A frame still on its way to the job's target takes the earlier views' picture
            // where it stands for this view; the finished frame is the engine's own.
            if (prior && !frame->finished && !frame->denoised.pixels.empty())
                frame->carried_pixels = blend_history(frame->denoised, *prior, frame->spp,
                                                      frame->max_passes == kUnlimitedPasses ? 0 : frame->max_passes);
            last_full = frame;
            last_full_scene = job.scene;
            last_full_settings = job.settings;
        }
        const bool full_frame = frame->scale == 1, finished = frame->finished;
        publish(std::move(frame));
        // A prior put off by the job's first full frame (prior_budget): made now that the frame
        // is on screen, unless an edit waits or the job is done.
        if (prior_deferred && full_frame) {
            prior_deferred = false;
            if (!finished && !stop_.load()) make_prior(w, h);
            else keep_earlier();  // still the history for the next camera move, as before the frame
        }
        // The view's first surfaces, which the next camera move's prior needs for this view's
        // picture (keep_history): traced once a job, once its first full frame is on screen and
        // while no edit waits, so that the move's own first frame does not trace them too (a
        // scalar trace of every pixel's centre: at 1920x1080 about as long as a pass).
        if (full_frame && denoise_.load() && !region.region && !stop_.load() && reprojectable(*job.scene) &&
            !(view_hits_made && hits_generation == job.generation)) {
            try {
                view_hits_made = view_hits(*job.scene, w, h, job.settings, &stop_);
                hits_generation = job.generation;
                if (stop_.load()) view_hits_made.reset();  // cut short by an edit: the next move traces them
            } catch (const std::bad_alloc&) {
                view_hits_made.reset();  // the next move traces them itself
            }
        }
    }
}

}  // namespace kr::viewer
