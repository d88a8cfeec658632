// The scripted runs in the window (their GL-free rules: viewer/script.h, latency.h): the
// command line's edits before the first frame, the latency measurement's nudges, the
// screenshot, stats and scene written once the passes are in, the window shot,
// --measure-idle.
#pragma once

#include <functional>

#include "core/image.h"
#include "viewer/latency.h"
#include "viewer/script.h"
#include "viewer/ui_context.h"
#include "viewer/view_options.h"

namespace kr::viewer {

class ScriptRun {
public:
    // Reads the framebuffer region back, as drawn so far this frame.
    using ReadBack = std::function<Rgb8Image(const PixelRect&)>;

    explicit ScriptRun(const ViewOptions& options);

    // Before the first frame: the command line's edits. False (error printed) when the run
    // fails at once.
    bool start(PanelContext& ctx);
    // Once per drawn frame, after the image is drawn and before the panels are: true when
    // the run is over. `submit` hands the model's state to the render thread at once.
    bool step(PanelContext& ctx, const PixelRect& image, const ReadBack& read, const std::function<void()>& submit);
    // Once the run is over and the panels are drawn: --window-shot.
    void window_shot(const ReadBack& read, int fb_w, int fb_h);
    // --measure-idle, on every wake-up whether or not a frame is drawn: true when over.
    // `pause` pauses the render and wakes a redraw.
    bool idle_step(PanelContext& ctx, const std::function<void()>& pause);
    // A UI frame drawn while the render runs (--measure-latency's frame figures).
    void record_frame(double work, double interval) { latency_.record_frame(work, interval); }
    bool measuring_latency() const { return latency_.running(); }
    int status() const { return status_; }

private:
    const ViewOptions& options_;
    int status_ = 0;  // the exit status
    LatencyMeasure latency_;
    IdleMeasure idle_;
    UiClock::time_point start_{};
};

}  // namespace kr::viewer
