// The scripted runs of `keithray view` (the tests, docs/viewer.md's measurements): the
// edits given on the command line, how many passes a screenshot waits for, the time limit
// and the idle CPU measurement. GL-free: the window draws, reads back and writes files.
#pragma once

#include <chrono>
#include <functional>

#include "viewer/model.h"
#include "viewer/view_options.h"

namespace kr::viewer {

// The window's edit path: applies `change` as an edit of `kind`; false if refused.
using EditFunction = std::function<bool(Edit kind, const std::function<void(Scene&, ViewerSettings&)>& change)>;

// --aperture, --orbit and --click-focus, in that order, through `edit` (as the mouse and the
// panels edit). Prints the focal distance --click-focus sets; false (error printed) when
// its ray hits nothing.
bool apply_script_edits(const ViewOptions& options, ViewerModel& model, const EditFunction& edit);

// The full-resolution passes a screenshot or scene save waits for: --frames N (at most the
// target unless refinement is unlimited), else the target.
int script_passes_needed(const ViewOptions& options, const ViewerSettings& settings);

// True, with the error printed, once a scripted run started at `start` is past --timeout.
bool script_timed_out(const ViewOptions& options, std::chrono::steady_clock::time_point start,
                      std::chrono::steady_clock::time_point now);

// Process CPU time (all threads), seconds.
double process_cpu_seconds();

// --measure-idle S: the process's CPU over S seconds once the render is done, then again
// paused (unlimited), each printed as % of a core. Phases: rendering to the target,
// settling, measuring (done), settling after the pause, measuring (paused).
class IdleMeasure {
public:
    using Clock = std::chrono::steady_clock;
    enum class Step {
        wait,     // nothing to do
        pause,    // the caller pauses the render with unlimited refinement now
        finished  // both figures printed
    };

    explicit IdleMeasure(double seconds = 0) : seconds_(seconds) {}

    // On every wake-up of the window; `done`: the render has reached its target.
    Step step(Clock::time_point now, bool done);

private:
    double seconds_;
    int phase_ = 0;
    Clock::time_point phase_start_{};
    double cpu_start_ = 0;
};

}  // namespace kr::viewer
