// The viewer's accumulation buffer. Each pass renders into a scratch kr::RenderState (so
// samples, RNG streams and seeding are exactly the core renderer's), which
// RenderState::merge adds to the totals with compensated sums only when the pass completes:
// an edit that cancels a pass leaves the totals as they were.
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

    // The noise rule (noise_target_met on the totals): true when the image meets the rule's
    // target; otherwise later passes sample only the pixels still above their share.
    // clear_adaptive() samples every pixel again.
    bool noise_target_met(const StopRule& rule);
    void clear_adaptive() {
        scratch_.clear_adaptive();
        totals_.clear_adaptive();
    }

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
    RenderState scratch_;  // keeps sample_index across passes: the RNG streams
};

}  // namespace kr::viewer
