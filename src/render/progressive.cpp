#include "render/progressive.h"

#include <chrono>

namespace kr {

ProgressiveDriver::ProgressiveDriver(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                                     const StopRule& rule, PassHooks* hooks)
    : scene_(scene), settings_(settings), state_(state), hooks_(hooks) {
    if (state.passes > 0 && noise_check_due(rule, state.passes)) {
        noise_checked_ = rule.noise;
        noise_met_ = noise_target_met(state, rule, hooks ? hooks->rows() : nullptr);
    }
}

bool ProgressiveDriver::pass(const StopRule& rule, const std::atomic<bool>* cancel) {
    if (noise_checked_ && *noise_checked_ != rule.noise) {
        state_.plan.clear_adaptive();  // the mask followed another target
        noise_met_ = false;
    }
    noise_checked_ = rule.noise;
    const auto start = std::chrono::steady_clock::now();
    const RowShare* share = hooks_ ? hooks_->rows() : nullptr;
    // The planner, the film, the row share: plan the pass, narrow it to this process's rows,
    // add its samples (and the halves': render_pass), then share what the next step reads.
    if (hooks_) hooks_->before_plan(state_);
    plan_pass(state_, settings_, share);
    if (hooks_) hooks_->before_pass(state_);
    if (!render_pass(scene_, settings_, state_, cancel)) return false;
    const bool noise_check = noise_check_due(rule, state_.passes);
    if (hooks_) hooks_->after_pass(state_, noise_check || plan_reads_statistics(settings_, state_));
    if (noise_check) noise_met_ = noise_target_met(state_, rule, share);
    seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (hooks_)
        for (size_t k = 0; k < kOwnStopRuleCount; ++k)
            own_agreed_[k] = hooks_->any(own_rule_met(rule, kOwnStopRules[k], state_, seconds_));
    return true;
}

std::optional<StopReason> ProgressiveDriver::stop_reason(const StopRule& rule) const {
    StopStatus status;
    status.seconds = seconds_;
    status.noise_met = noise_met_ && noise_checked_ == rule.noise;
    if (hooks_) status.agreed = &own_agreed_;
    return kr::stop_reason(rule, state_, status);
}

StopReason render_until(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                        const StopRule& rule, const std::function<bool(const RenderState&)>& on_pass,
                        PassHooks* hooks) {
    ProgressiveDriver driver(scene, settings, state, rule, hooks);
    for (;;) {
        if (const auto reason = driver.stop_reason(rule)) return *reason;
        driver.pass(rule);
        if (on_pass && !on_pass(state)) return StopReason::cancelled;
    }
}

}  // namespace kr
