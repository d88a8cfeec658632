// The stop rules' progress and ETA (render/stop_rule.h), which the CLI's progress bar and the
// viewer's status bar show, and the name table of the reasons a render stops.
#include <gtest/gtest.h>

#include "render/options.h"
#include "render/stop_rule.h"

namespace kr {
namespace {

TEST(StopRule, ProgressTowardsThePasses) {
    StopRule rule;
    rule.max_passes = 64;
    // 16 of 64 passes in 8 s: a quarter done, 48 passes of 0.5 s left.
    const StopProgress p = stop_progress(rule, 16, 8.0, 0.04);
    EXPECT_DOUBLE_EQ(p.fraction, 0.25);
    EXPECT_DOUBLE_EQ(p.eta, 24.0);
    ASSERT_TRUE(p.nearest);
    EXPECT_EQ(*p.nearest, StopReason::passes);
}

TEST(StopRule, EtasAreInWallTimeAtItsMeasuredRate) {
    StopRule rule;
    rule.max_passes = 64;
    rule.seconds = 20;
    // 16 passes took 8 s of the engine's time and 24 s of wall time (the viewer's frames and
    // window beside them): 48 passes left at 1.5 s of wall time each, and the time rule's
    // 12 s left are 36 s of wall time; the time rule comes first.
    const StopProgress p = stop_progress(rule, 16, 8.0, 0.04, 24.0);
    EXPECT_DOUBLE_EQ(p.eta, 36.0);
    rule.seconds = 0;
    EXPECT_DOUBLE_EQ(stop_progress(rule, 16, 8.0, 0.04, 24.0).eta, 72.0);
    // Wall time shorter than the clock (rounding) is taken as the clock's.
    EXPECT_DOUBLE_EQ(stop_progress(rule, 16, 8.0, 0.04, 7.0).eta, 24.0);
}

TEST(StopRule, TheRuleNearestToEndingWins) {
    StopRule rule;
    rule.max_passes = 64;
    rule.seconds = 10;
    // 16 passes in 8 s: the time rule (80%, 2 s left) ends it before the passes (25%, 24 s).
    StopProgress p = stop_progress(rule, 16, 8.0, 0.04);
    EXPECT_EQ(*p.nearest, StopReason::time);
    EXPECT_DOUBLE_EQ(p.fraction, 0.8);
    EXPECT_DOUBLE_EQ(p.eta, 2.0);
    // The noise rule: 4% now, 2% wanted: four times the passes (48 more of 0.5 s), 1/4 there.
    rule.seconds = 0;
    rule.max_passes = kUnlimitedPasses;
    rule.noise = 0.02;
    p = stop_progress(rule, 16, 8.0, 0.04);
    EXPECT_EQ(*p.nearest, StopReason::noise);
    EXPECT_DOUBLE_EQ(p.fraction, 0.25);
    EXPECT_DOUBLE_EQ(p.eta, 24.0);
    // Before the error is known the noise rule says nothing.
    p = stop_progress(rule, 1, 0.5, -1);
    EXPECT_FALSE(p.nearest);
    EXPECT_EQ(p.fraction, -1);
    EXPECT_EQ(p.eta, -1);
}

TEST(StopRule, ReasonNamesAreTheFlags) {
    for (const StopReason r : {StopReason::passes, StopReason::time, StopReason::noise})
        EXPECT_EQ(stop_reason_names.parse(stop_reason_names.name(r)), r);
    EXPECT_EQ(stop_reason_names.name(StopReason::passes), "spp");
    EXPECT_EQ(stop_reason_names.name(StopReason::noise), "noise");
}

TEST(StopRule, RenderCapsAnOpenEndedRenderWithoutSpp) {
    RenderOptions options;
    RenderSettings settings;
    settings.target_spp = 32;
    EXPECT_EQ(render_stop_rule(options, settings).max_passes, 32);
    options.stop.noise = 0.01;
    EXPECT_TRUE(render_stop_rule(options, settings).open_ended());
    EXPECT_EQ(render_stop_rule(options, settings).max_passes, kMaxOpenEndedPasses);
    options.spp = 32;  // --spp bounds it
    EXPECT_EQ(render_stop_rule(options, settings).max_passes, 32);
}

}  // namespace
}  // namespace kr
