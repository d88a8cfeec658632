// When a progressive render stops: the StopRule every driver of passes takes (the CLI, the
// viewer's render thread, MPI ranks), the StopReason that ended it with its name table, the
// noise rule's check, the test of which rule ends a render (stop_reason), and the progress
// and ETA towards the rule that ends first. A new rule is a member of StopRule, a StopReason
// and its test here, and its progress in stop_rule.cpp; its flag is a row of
// render/options.cpp.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <limits>
#include <optional>

#include "core/enum_names.h"
#include "render/render_state.h"

namespace kr {

// max_passes of a render without a pass limit (the viewer's "unlimited").
inline constexpr int kUnlimitedPasses = std::numeric_limits<int>::max();

// When a progressive render stops: after `max_passes`, after `seconds` of wall time (checked
// between passes), or when the estimated relative error reaches `noise` (adaptive sampling
// then spends passes only on pixels above their share of the error). 0 disables a rule.
struct StopRule {
    int max_passes = 1;
    double seconds = 0;
    double noise = 0;
    uint32_t min_samples = 16;  // per pixel before the noise rule trusts a variance
    int adapt_every = 4;        // passes between updates of the adaptive mask

    // Whether a time or noise rule can end the render before its passes.
    bool open_ended() const { return seconds > 0 || noise > 0; }
    bool operator==(const StopRule&) const = default;
};

// The rule that ended a render; the names are the flags' (`--spp`, `--time`, `--noise`).
enum class StopReason { passes, time, noise, cancelled };
inline constexpr EnumNames<StopReason, 4> stop_reason_names{{"spp", "time", "noise", "cancelled"}};

// The noise rule of a StopRule, as every driver of passes applies it: checked after pass
// `passes` when the rule has a target, from min_samples passes on and every adapt_every
// passes (the adaptive mask is updated at the same checks).
bool noise_check_due(const StopRule& rule, int passes);
// The check itself: true when the image's estimated relative error is within the target, or
// no pixel is above its share of it; otherwise updates `state`'s adaptive mask
// (update_adaptive; with `share`: on this process's rows, every process calling it after the
// same pass).
bool noise_target_met(RenderState& state, const StopRule& rule, const RowShare* share = nullptr);

// The rules a process decides by its own clock or counters, which differ between the
// processes of a shared render (the time): after every pass the driver makes each one
// decision for all of them (PassHooks::any). The others read numbers every process shares
// (the passes, the noise rule's combined sums).
inline constexpr StopReason kOwnStopRules[] = {StopReason::time};
inline constexpr size_t kOwnStopRuleCount = std::size(kOwnStopRules);
// Whether own rule `reason` (one of kOwnStopRules) ends the render by this process's clock
// (`seconds` spent in completed passes) and counters.
inline bool own_rule_met(const StopRule& rule, StopReason reason, const RenderState&, double seconds) {
    switch (reason) {
    case StopReason::time:
        return rule.seconds > 0 && seconds >= rule.seconds;
    default:
        return false;
    }
}

// What a driver of passes knows of a render, besides its state, when it asks whether to stop.
struct StopStatus {
    double seconds = 0;      // spent in completed passes (the time rule's clock)
    bool noise_met = false;  // the noise target the rule has now was met at its last check
    // With several processes: per kOwnStopRules entry, whether any process's own test said
    // stop after the last pass, in place of this process's own tests (nullptr: one process).
    const std::array<bool, kOwnStopRuleCount>* agreed = nullptr;
};
// The rule that ends the render now, if any, in this order: the noise target, the own rules
// (the time), the passes (state.passes counts towards rule.max_passes). (Inline, as the
// driver's test was: it runs before every pass.)
inline std::optional<StopReason> stop_reason(const StopRule& rule, const RenderState& state, const StopStatus& status) {
    if (status.noise_met && rule.noise > 0) return StopReason::noise;
    for (size_t k = 0; k < kOwnStopRuleCount; ++k)
        if (status.agreed ? (*status.agreed)[k] : own_rule_met(rule, kOwnStopRules[k], state, status.seconds))
            return kOwnStopRules[k];
    if (state.passes >= rule.max_passes) return StopReason::passes;
    return std::nullopt;
}

// Where a render stands against its StopRule, for a progress bar and its ETA.
struct StopProgress {
    double fraction = -1;             // 0..1 towards the rule nearest to ending it; -1: no rule
    double eta = -1;                  // seconds until the first rule is met; -1: unknown
    std::optional<StopReason> nearest;  // the rule `fraction` is towards
};

// After `passes` passes taking `seconds` (the time rule's clock), with the image's estimated
// relative error `noise` (<= 0: not known yet). The noise rule's ETA assumes the error falls
// as 1/sqrt(passes). `wall_seconds` (> 0) is the wall time the passes took with everything
// done beside them (the viewer's previews, frames and window): the ETAs are in it, at the
// rate it measures.
StopProgress stop_progress(const StopRule& rule, int passes, double seconds, double noise, double wall_seconds = 0);

}  // namespace kr
