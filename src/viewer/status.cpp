#include "viewer/status.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace kr::viewer {

RunStatus run_status(const Snapshot* frame, const ViewerSettings& settings, bool has_error, bool earlier_view) {
    RunStatus st;
    st.target = settings.render.target_spp;
    st.unlimited = settings.unlimited;
    if (!frame) {
        st.state = has_error ? RunState::error : earlier_view ? RunState::moving : RunState::starting;
        return st;
    }
    st.spp = frame->spp;
    st.preview = frame->scale > 1;
    st.elapsed = frame->seconds;
    st.mrays_per_second = frame->full_seconds > 0 ? double(frame->rays) / frame->full_seconds * 1e-6 : 0;
    st.noise = frame->spp >= 2 && std::isfinite(frame->relative_error) ? frame->relative_error : -1;

    // Progress towards each stop rule that is on; the first to be met ends the render.
    // ETAs at the rate measured in wall time (previews, frames and the window included).
    const StopProgress progress =
        stop_progress(settings.stop_rule(), frame->spp, frame->full_seconds, st.noise, frame->seconds);
    st.progress = progress.fraction;
    st.eta = progress.eta;
    if (progress.nearest) st.rule = stop_reason_names.name(*progress.nearest);

    // Done: a stop rule ended it, unless a raised target or "unlimited" lets it go on; or
    // the target was lowered below the passes already taken.
    const bool spp_rule_over =
        frame->stopped_by == StopReason::passes && (settings.unlimited || frame->spp < st.target);
    const bool done = (frame->finished && !spp_rule_over) ||
                      (!settings.unlimited && !st.preview && frame->spp >= st.target);
    if (has_error) st.state = RunState::error;
    else if (done) st.state = RunState::done;
    else if (settings.paused) st.state = RunState::paused;
    else st.state = RunState::rendering;
    if (done) st.eta = 0, st.progress = std::max(st.progress, 1.0);
    return st;
}

std::optional<RegionStatus> region_status(const Snapshot& frame, const PixelBox& box) {
    const int w = frame.radiance.width, h = frame.radiance.height;
    const size_t n = size_t(w) * size_t(h);
    if (frame.scale != 1 || frame.sample_count.size() != n || frame.standard_error.size() != n) return std::nullopt;
    const int x0 = std::max(0, box.x0), y0 = std::max(0, box.y0), x1 = std::min(w, box.x1), y1 = std::min(h, box.y1);
    if (x0 >= x1 || y0 >= y1) return std::nullopt;
    // The sums of RenderState::relative_error over the box: squared standard errors over
    // squared mean luminances.
    double samples = 0, error_sq = 0, signal_sq = 0;
    bool unknown = false;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const size_t i = size_t(y) * size_t(w) + size_t(x);
            samples += frame.sample_count[i];
            const double se = frame.standard_error[i];
            if (!std::isfinite(se)) unknown = true;
            error_sq += se * se;
            const double mean = luminance(frame.radiance.pixels[i]);
            signal_sq += mean * mean;
        }
    RegionStatus r;
    r.samples_per_pixel = samples / (double(x1 - x0) * double(y1 - y0));
    if (!unknown) r.noise = signal_sq > 0 ? std::sqrt(error_sq / signal_sq) : (error_sq > 0 ? -1 : 0);
    return r;
}

std::vector<bool> fit_status_fields(const std::vector<StatusField>& fields, double available, double spacing) {
    // The most important first (priority 0 always), each taken where it still fits: a field
    // too wide for what is left gives way, a smaller less important one may still show.
    std::vector<size_t> order(fields.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return fields[a].priority < fields[b].priority; });
    std::vector<bool> shown(fields.size(), false);
    double used = 0;
    int n = 0;
    for (size_t i : order) {
        const double need = fields[i].width + (n > 0 ? spacing : 0);
        if (fields[i].priority > 0 && used + need > available) continue;
        shown[i] = true;
        used += need;
        ++n;
    }
    return shown;
}

std::string format_noise(double noise) {
    char buf[32];
    const double percent = 100 * noise;
    if (percent >= 0.001) std::snprintf(buf, sizeof buf, "%.3g%%", std::min(percent, 999.0));
    else std::snprintf(buf, sizeof buf, "< 0.001%%");
    return buf;
}

std::string window_title(std::string_view scene_name, const RunStatus& status, bool dirty) {
    char spp[64];
    if (status.unlimited) std::snprintf(spp, sizeof spp, "%d spp (unlimited)", status.spp);
    else std::snprintf(spp, sizeof spp, "%d/%d spp", status.spp, status.target);
    return "keithray - " + std::string(scene_name) + (dirty ? " (edited)" : "") + " - " + spp + " - " +
           std::string(run_state_names.name(status.state));
}

std::optional<std::vector<double>> TypedFields::take(unsigned id) {
    auto it = held_.find(id);
    if (it == held_.end()) return std::nullopt;
    std::vector<double> values = std::move(it->second);
    held_.erase(it);
    return values;
}

const Image* shown_image_in_place(const Snapshot& frame, DenoiseView view, int width, int height) {
    if (frame.scale > 1 && width > 0 && height > 0) return nullptr;  // upscaled
    const bool denoised = frame.denoised.pixels.size() == frame.radiance.pixels.size();
    if (view == DenoiseView::off || !denoised) return &frame.radiance;
    return view == DenoiseView::on ? &frame.denoised : nullptr;  // split: composed
}

Image shown_radiance(const Snapshot& frame, DenoiseView view, int width, int height) {
    if (const Image* in_place = shown_image_in_place(frame, view, width, height)) return *in_place;
    const Image& denoised = frame.denoised;
    Image out;
    if (view == DenoiseView::off || denoised.pixels.size() != frame.radiance.pixels.size()) out = frame.radiance;
    else if (view == DenoiseView::on) out = denoised;
    else {
        out = frame.radiance;
        for (int y = 0; y < out.height; ++y)
            for (int x = out.width / 2; x < out.width; ++x) out.at(x, y) = denoised.at(x, y);
    }
    if (frame.scale > 1 && width > 0 && height > 0) out = upscale_linear(out, width, height);
    return out;
}

Rgb8Image displayed_picture(const Snapshot& frame, DenoiseView view, int width, int height,
                            const DisplaySettings& display) {
    return tonemap(shown_radiance(frame, view, width, height), display.tonemap, display.exposure_scale());
}

std::string_view shown_word(const Snapshot& frame, DenoiseView view) {
    if (view == DenoiseView::off || frame.denoised.pixels.size() != frame.radiance.pixels.size()) return "raw";
    return view == DenoiseView::on ? "denoised" : "split";
}

}  // namespace kr::viewer
