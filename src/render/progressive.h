// ProgressiveDriver, the one driver of progressive passes (plan, pass, process exchange, stop
// rules) under the CLI (render_until), the viewer's render thread and MPI ranks. It includes
// the pieces it drives: the render state (render_state.h: its film, its planner and the rows a
// pass samples), one pass (render_pass.h) and the stop rules (stop_rule.h).
#pragma once

#include <array>
#include <atomic>
#include <functional>
#include <optional>

#include "render/render_pass.h"
#include "render/render_scene.h"
#include "render/render_state.h"
#include "render/settings.h"
#include "render/stop_rule.h"

namespace kr {

// The driver's extension points for a render shared by several processes (app/cluster.h
// deals pixels to MPI ranks through them). Each pixel's samples are drawn by one process in
// the single-process order, so the sums are those of one process, bit for bit.
class PassHooks {
public:
    virtual ~PassHooks() = default;
    // Before plan_pass: narrows the pixels the pass plans for (a render region, through
    // state.plan.active), so that its samples, as many as those pixels, go to them alone.
    // after_pass undoes it too.
    virtual void before_plan(RenderState&) {}
    // After plan_pass, before render_pass: narrows the pass to this process's pixels
    // (state.active_rows).
    virtual void before_pass(RenderState& state) = 0;
    // After render_pass: undoes before_pass; when `statistics`, the next step reads the
    // statistics of this process's rows and their neighbours (plan_pass, update_adaptive), so
    // the process must then hold those rows' radiance_sum, luminance_sq_sum and sample_count.
    virtual void after_pass(RenderState& state, bool statistics) = 0;
    // One stop decision for all processes: whether any of them says `stop` (each of
    // kOwnStopRules, e.g. --time).
    virtual bool any(bool stop) = 0;
    // The rows this process plans and samples, and the exchange of the per-row sums that the
    // plan, the noise rule and the estimated error add up (nullptr: every row, one process).
    virtual const RowShare* rows() const { return nullptr; }
};

// The one driver of progressive passes (yocto-gl's trace_samples): each pass() plans the
// pass (plan_pass, the planner), lets `hooks` narrow it to this process's pixels (the row
// share), renders it into the film (render_pass), shares what the next step reads, and
// applies the noise rule; stop_reason() says which rule ends the render (stop_rule.h). render_until loops over it for the CLI and MPI ranks; the
// viewer's render thread calls pass() between its previews and edits, with a cancel flag,
// under rules its user changes as it goes. The scene, settings, state and hooks must outlive
// the driver.
class ProgressiveDriver {
public:
    // A state restored from a checkpoint taken right after a noise check gets that check's
    // verdict again (a pure function of the sums), so it goes on exactly as if never stopped.
    ProgressiveDriver(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                      const StopRule& rule, PassHooks* hooks = nullptr);
    // One pass under `rule`. A changed noise target samples every pixel again until it is
    // checked. Returns false, and does nothing more, when `cancel` ended the pass early: the
    // state then holds part of a pass (render_pass) and is to be reset or dropped.
    bool pass(const StopRule& rule, const std::atomic<bool>* cancel = nullptr);
    // The rule that ends the render now, if any (kr::stop_reason): the noise target met at its
    // last check (while `rule` keeps that target), the time (with hooks: the processes' common
    // decision after the last pass), the passes.
    std::optional<StopReason> stop_reason(const StopRule& rule) const;
    // Seconds spent in completed passes (the time rule's clock).
    double seconds() const { return seconds_; }

private:
    const RenderScene& scene_;
    const RenderSettings& settings_;
    RenderState& state_;
    PassHooks* hooks_;
    double seconds_ = 0;
    std::array<bool, kOwnStopRuleCount> own_agreed_{};  // with hooks: the processes' decisions (StopStatus)
    std::optional<double> noise_checked_;  // the noise target the adaptive mask follows
    bool noise_met_ = false;               // ... and whether its last check met it
};

// Runs passes until a rule stops it: state.passes counts towards rule.max_passes, so a state
// restored from a checkpoint (render/checkpoint.h) goes on as if never stopped. `on_pass`,
// if given, is called after each pass (and its noise check) and may return false to cancel;
// `hooks` spread the passes over processes.
StopReason render_until(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                        const StopRule& rule, const std::function<bool(const RenderState&)>& on_pass = {},
                        PassHooks* hooks = nullptr);

}  // namespace kr
