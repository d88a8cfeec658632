#include "viewer/status.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace kr::viewer {

RunStatus run_status(const Snapshot* frame, const ViewerSettings& settings, bool has_error) {
    RunStatus st;
    st.target = settings.render.target_spp;
    st.unlimited = settings.unlimited;
    if (!frame) {
        st.state = has_error ? RunState::error : RunState::starting;
        return st;
    }
    st.spp = frame->spp;
    st.preview = frame->scale > 1;
    st.elapsed = frame->seconds;
    st.mrays_per_second = frame->full_seconds > 0 ? double(frame->rays) / frame->full_seconds * 1e-6 : 0;
    st.noise = frame->spp >= 2 && std::isfinite(frame->relative_error) ? frame->relative_error : -1;

    // Progress towards each stop rule that is on; the first to be met ends the render.
    const double per_pass = frame->spp > 0 ? frame->full_seconds / frame->spp : 0;
    auto consider = [&](const char* rule, double fraction, double eta) {
        fraction = std::clamp(fraction, 0.0, 1.0);
        if (fraction > st.progress) {
            st.progress = fraction;
            st.rule = rule;
        }
        if (eta >= 0 && (st.eta < 0 || eta < st.eta)) st.eta = eta;
    };
    if (!settings.unlimited)
        consider("target", double(frame->spp) / std::max(1, st.target),
                 per_pass > 0 ? std::max(0, st.target - frame->spp) * per_pass : -1);
    if (settings.stop_seconds > 0)
        consider("time", frame->full_seconds / settings.stop_seconds,
                 std::max(0.0, settings.stop_seconds - frame->full_seconds));
    if (settings.stop_noise > 0 && st.noise > 0) {
        // The error falls as 1/sqrt(spp): the target needs spp * (noise / target)^2 passes.
        const double ratio = settings.stop_noise / st.noise;
        const double passes_left = frame->spp * std::max(0.0, 1.0 / (ratio * ratio) - 1.0);
        consider("noise", ratio * ratio, per_pass > 0 ? passes_left * per_pass : -1);
    }

    // Done: a stop rule ended it, unless a raised target or "unlimited" lets it go on; or
    // the target was lowered below the passes already taken.
    const bool spp_rule_over = std::string_view(frame->stopped_by) == "spp" && (settings.unlimited || frame->spp < st.target);
    const bool done = (frame->finished && !spp_rule_over) ||
                      (!settings.unlimited && !st.preview && frame->spp >= st.target);
    if (has_error) st.state = RunState::error;
    else if (done) st.state = RunState::done;
    else if (settings.paused) st.state = RunState::paused;
    else st.state = RunState::rendering;
    if (done) st.eta = 0, st.progress = std::max(st.progress, 1.0);
    return st;
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

}  // namespace kr::viewer
