// The planner of a progressive render: which pixels the next pass samples and how often.
// SamplePlan holds the noise rule's mask of pixels still above their share of the error
// (update_adaptive) and the adaptive allocation's samples per pixel with their carried-over
// fractions (plan_pass); both read the film's statistics (film.h). allocation.cpp.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "render/row_share.h"
#include "render/settings.h"

namespace kr {

struct RenderState;

// A RenderState's plan of the next pass, per pixel at the film's places (Film::row_start).
// Empty vectors mean every pixel, one sample each. render_pass reads it; the pass hooks of a
// render region narrow `active` around a pass.
struct SamplePlan {
    // The noise rule (update_adaptive): render_pass samples only pixels whose entry is 1
    // (empty: all of them).
    std::vector<uint8_t> active;
    // Samples per pixel in the next pass, set by plan_pass (empty: one each).
    std::vector<uint8_t> pass_samples;
    std::vector<float> sample_credit;  // adaptive allocation: fractions of a sample carried over
    std::array<std::vector<double>, 3> scratch;  // plan_pass's and update_adaptive's buffers

    // Samples every pixel again (no adaptive mask).
    void clear_adaptive() { active.clear(); }
    // No plan: every pixel, one sample each, nothing carried over.
    void clear();
};

// The bytes per pixel a SamplePlan holds once every buffer is in use: the adaptive mask, the
// pass plan and its credit, and the three scratch buffers.
inline constexpr uint64_t kPlanBytesPerPixel = 2 * sizeof(uint8_t) + sizeof(float) + 3 * sizeof(double);

inline constexpr int kAllocationWarmup = 8;        // passes of one sample each before adapting
inline constexpr double kAllocationFloor = 0.25;   // every pixel's share is at least this x mean
inline constexpr int kMaxPassSamples = 64;         // per pixel and pass

// Plans the next pass for `settings.allocation` (fills state.plan.pass_samples). Adaptive:
// after kAllocationWarmup passes, each active pixel's share of the pass (as many samples as
// active pixels) is proportional to its estimated standard deviation (3x3 guarded, as
// update_adaptive) plus a floor, which minimises the summed variance of the pixel means for
// the budget; fractions carry over between passes. Parallel over rows, with the rows' sums
// added in order: the plan does not depend on threads. With `share`, only this process's rows
// are planned (their pass_samples and sample_credit), from their and their neighbours'
// statistics and the image's sums.
void plan_pass(RenderState& state, const RenderSettings& settings, const RowShare* share = nullptr);

// Adaptive sampling towards an image relative error `target` (as Film::relative_error): a
// pixel stays active while the variance of its mean exceeds an equal share of the allowed
// total, target^2 * sum(mean^2) / pixels, or it has fewer than `min_samples` samples. When no
// pixel is active the image meets the target. Sets state.plan.active; returns the active
// count. With `share`, the mask is set on this process's rows (from their and their
// neighbours' statistics) and the count is the image's.
size_t update_adaptive(RenderState& state, double target, uint32_t min_samples = 16, const RowShare* share = nullptr);

// Whether plan_pass reads the image's statistics for the next pass (adaptive allocation
// after its warm-up).
bool plan_reads_statistics(const RenderSettings& settings, const RenderState& state);

}  // namespace kr
