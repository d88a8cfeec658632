// The viewer's accumulation buffer. Each pass renders one sample per pixel into a scratch
// kr::RenderState (so samples, RNG streams and seeding are exactly the core renderer's),
// then adds it to running sums with Neumaier compensation: a naive double sum of 10^6
// samples of 0.1 is off by 1.3e-11 relative; this one stays within an ulp or two.
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "render/progressive.h"

namespace kr::viewer {

class Accumulator {
public:
    void reset(int width, int height);

    // Renders one pass with kr::render_pass (planned by RenderState::plan_pass on the totals
    // for adaptive allocation) and adds it. If `stop` ends the pass early it
    // returns false and adds nothing (the caller restarts anyway).
    bool render_pass(const RenderScene& scene, const RenderSettings& settings,
                     const std::atomic<bool>* stop = nullptr);

    // Adaptive sampling towards relative error `target` (RenderState::update_adaptive on the
    // totals): later passes sample only the pixels still above their share. Returns their
    // count; 0 means the image meets the target. clear_adaptive() samples every pixel again.
    size_t update_adaptive(double target);
    void clear_adaptive() {
        scratch_.active.clear();
        totals_.active.clear();
    }

    // Adds a one-pass state: its samples per pixel in `pass.radiance_sum` etc.
    void add(const RenderState& pass);

    // The running totals as a RenderState (radiance_sum holds the compensated sums), for
    // RenderState::relative_error() and the counters.
    const RenderState& totals() const { return totals_; }
    int passes() const { return totals_.passes; }
    int width() const { return totals_.width; }
    int height() const { return totals_.height; }

    // Per-pixel mean radiance (black where no sample landed).
    Image mean() const;

private:
    RenderState totals_;
    std::vector<Color> raw_sum_;       // uncorrected running sums per pixel
    std::vector<Color> compensation_;  // Neumaier's running correction per pixel
    RenderState scratch_;              // keeps sample_index across passes: the RNG streams
};

}  // namespace kr::viewer
