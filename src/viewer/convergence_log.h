// The convergence of the image on screen, GL-free: per full-resolution frame of one
// generation, time, spp, the estimated relative error and (with a reference) the true error,
// for the Stats panel's log-log plot, its CSV, and `--stats-json`.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "viewer/compare_view.h"
#include "viewer/inspect.h"
#include "viewer/render_worker.h"

namespace kr::viewer {

struct ConvergencePoint {
    double seconds = 0;         // render time of the generation (pauses excluded)
    int spp = 0;
    double estimated = 0;       // RenderState::relative_error(); infinite below 2 spp
    double rmse = -1, psnr = -1;  // against the reference, -1 without one
};

class ConvergenceLog {
public:
    // Adds a full-resolution frame (previews and repeats are ignored); a frame of another
    // generation starts a new log. `figures`: the frame against the reference, if any.
    void record(const Snapshot& frame, const std::optional<CompareFigures>& figures);
    const std::vector<ConvergencePoint>& points() const { return points_; }
    uint64_t generation() const { return generation_; }
    // "seconds,spp,estimated_relative_error,rmse,psnr", one row per point; empty cells where
    // a figure is unknown.
    std::string csv() const;

private:
    uint64_t generation_ = 0;
    std::vector<ConvergencePoint> points_;
};

// The figures of `--stats-json`: what the status bar and the compare panel show, as JSON.
struct StatsFigures {
    int spp = 0, target = 0;
    double elapsed = 0, mrays_per_second = 0;
    double noise = -1;  // estimated relative error, -1 before 2 spp
    std::string state;
    std::string image;                      // image A, as shown: "raw", "denoised" or "split" (status.h shown_word)
    std::optional<std::string> reference;  // image B's name when one is loaded
    std::optional<CompareFigures> figures;
    std::optional<PixelProbe> probe;
};
std::string stats_json(const StatsFigures& stats);

}  // namespace kr::viewer
