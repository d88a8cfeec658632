#include "viewer/accumulator.h"

namespace kr::viewer {

void Accumulator::reset(int width, int height) {
    totals_.reset(width, height);
    scratch_.reset(width, height);
}

bool Accumulator::render_pass(const RenderScene& scene, const RenderSettings& settings,
                              const std::atomic<bool>* stop) {
    // The plan comes from the totals' statistics (the scratch state holds one pass).
    totals_.plan_pass(settings);
    scratch_.follow_plan(totals_);
    const bool complete = kr::render_pass(scene, settings, scratch_, stop);
    if (complete) totals_.merge(scratch_);
    scratch_.clear_sums();
    return complete;
}

Image Accumulator::mean() const { return totals_.radiance(); }

bool Accumulator::noise_target_met(const StopRule& rule) {
    const bool met = kr::noise_target_met(totals_, rule);
    scratch_.follow_plan(totals_);
    return met;
}

}  // namespace kr::viewer
