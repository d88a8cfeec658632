#include "render/stop_rule.h"

#include <algorithm>

namespace kr {

bool noise_check_due(const StopRule& rule, int passes) {
    return rule.noise > 0 && passes >= int(rule.min_samples) && passes % rule.adapt_every == 0;
}

bool noise_target_met(RenderState& state, const StopRule& rule, const RowShare* share) {
    // Every pixel within its share means the whole image is within the target too.
    return state.relative_error(share) <= rule.noise || update_adaptive(state, rule.noise, rule.min_samples, share) == 0;
}

StopProgress stop_progress(const StopRule& rule, int passes, double seconds, double noise, double wall_seconds) {
    StopProgress progress;
    // Wall seconds per second of the time rule's clock, and per pass.
    const double wall_ratio = wall_seconds > 0 && seconds > 0 ? std::max(1.0, wall_seconds / seconds) : 1.0;
    const double per_pass = passes > 0 ? seconds * wall_ratio / passes : 0;
    auto consider = [&](StopReason reason, double fraction, double eta) {
        fraction = std::clamp(fraction, 0.0, 1.0);
        if (fraction > progress.fraction) {
            progress.fraction = fraction;
            progress.nearest = reason;
        }
        if (eta >= 0 && (progress.eta < 0 || eta < progress.eta)) progress.eta = eta;
    };
    if (rule.max_passes != kUnlimitedPasses)
        consider(StopReason::passes, double(passes) / std::max(1, rule.max_passes),
                 per_pass > 0 ? std::max(0, rule.max_passes - passes) * per_pass : -1);
    if (rule.seconds > 0)
        consider(StopReason::time, seconds / rule.seconds, std::max(0.0, rule.seconds - seconds) * wall_ratio);
    if (rule.noise > 0 && noise > 0) {
        // The error falls as 1/sqrt(passes): the target needs passes * (noise / target)^2.
        const double ratio = rule.noise / noise;
        const double passes_left = passes * std::max(0.0, 1.0 / (ratio * ratio) - 1.0);
        consider(StopReason::noise, ratio * ratio, per_pass > 0 ? passes_left * per_pass : -1);
    }
    return progress;
}

}  // namespace kr
