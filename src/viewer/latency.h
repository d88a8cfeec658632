// --measure-latency: the time from an edit (an orbit nudge, as a mouse drag makes) to the
// first frame of the new image on screen, and the UI frame timing while the render runs.
// GL-free: the window reports its frames and makes the edits this asks for.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace kr::viewer {

// The p-quantile (0..1) of `v`, by nearest rank; 0 when empty.
double percentile(std::vector<double> v, double p);

class LatencyMeasure {
public:
    using Clock = std::chrono::steady_clock;

    explicit LatencyMeasure(int edits = 0) : edits_(edits) {}

    // Edits still to time.
    bool running() const { return done_ < edits_; }

    // Once per drawn frame. `current`: the frame on screen is of the latest edit's image, at
    // 1/`scale` resolution. Returns the horizontal orbit nudge (pixels) to make now, if any:
    // the caller applies it before the next frame, and its time counts from `now`.
    std::optional<double> on_frame(Clock::time_point now, bool current, int scale);

    // A UI frame drawn while the render runs: seconds of work and since the previous frame.
    void record_frame(double work, double interval);

    // The lines --measure-latency prints: edit latency, frame interval and frame work.
    std::string report() const;

private:
    int edits_ = 0, done_ = 0;
    bool waiting_ = false;  // an edit was made; its first frame is awaited
    Clock::time_point edit_time_{}, next_edit_{};
    std::vector<double> latencies_;  // seconds
    std::vector<int> scales_;
    std::vector<double> frame_work_, frame_intervals_;  // seconds
};

}  // namespace kr::viewer
