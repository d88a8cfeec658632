#include "viewer/latency.h"

#include <algorithm>
#include <cstdio>

namespace kr::viewer {

namespace {

constexpr auto kEditSpacing = std::chrono::milliseconds(300);  // between a frame and the next edit
constexpr size_t kMaxFrames = 100000;                           // frame timings kept

double seconds(std::chrono::steady_clock::duration d) { return std::chrono::duration<double>(d).count(); }

}  // namespace

double percentile(std::vector<double> v, double p) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, size_t(p * double(v.size() - 1) + 0.5))];
}

std::optional<double> LatencyMeasure::on_frame(Clock::time_point now, bool current, int scale) {
    if (!running()) return std::nullopt;
    if (waiting_) {
        // The frame drawn this iteration is the first of the edited generation.
        if (current) {
            latencies_.push_back(seconds(now - edit_time_));
            scales_.push_back(scale);
            waiting_ = false;
            ++done_;
            next_edit_ = now + kEditSpacing;
        }
        return std::nullopt;
    }
    // The next nudge while full-resolution passes run, alternately right and left.
    if (!current || scale != 1 || now < next_edit_) return std::nullopt;
    edit_time_ = now;
    waiting_ = true;
    return done_ % 2 == 0 ? 4.0 : -4.0;
}

void LatencyMeasure::record_frame(double work, double interval) {
    if (frame_work_.size() < kMaxFrames) frame_work_.push_back(work);
    if (frame_intervals_.size() < kMaxFrames) frame_intervals_.push_back(interval);
}

std::string LatencyMeasure::report() const {
    char text[768];
    std::snprintf(text, sizeof text,
                  "latency (edit -> first frame of the new image drawn), %zu edits: median %.1f ms, "
                  "90th percentile %.1f ms, max %.1f ms; coarsest preview: 1/%d\n"
                  "UI frame interval while rendering: median %.1f ms, 95th percentile %.1f ms, max %.1f ms "
                  "(%zu frames)\n"
                  "UI frame work (events, panels, upload, draw, swap): median %.1f ms, 95th percentile %.1f ms\n",
                  latencies_.size(), 1e3 * percentile(latencies_, 0.5), 1e3 * percentile(latencies_, 0.9),
                  1e3 * percentile(latencies_, 1.0), scales_.empty() ? 1 : *std::max_element(scales_.begin(), scales_.end()),
                  1e3 * percentile(frame_intervals_, 0.5), 1e3 * percentile(frame_intervals_, 0.95),
                  1e3 * percentile(frame_intervals_, 1.0), frame_intervals_.size(), 1e3 * percentile(frame_work_, 0.5),
                  1e3 * percentile(frame_work_, 0.95));
    return text;
}

}  // namespace kr::viewer
