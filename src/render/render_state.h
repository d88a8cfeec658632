// The state of a progressive render, as yocto-gl's trace state: the film (its sums, statistics
// and halves: film.h), the plan of the next pass (allocation.h), the rows a pass samples
// (row_share.h) and the render's counters. Three functions work over it, one per concept:
// plan_pass plans the pass, render_pass adds its samples to the film, and a shared render's
// PassHooks narrow it to this process's rows and exchange them (progressive.h).
#pragma once

#include <cstdint>
#include <vector>

#include "render/allocation.h"
#include "render/film.h"
#include "render/row_share.h"

namespace kr {

// The film is the base, so its readers are the state's (state.radiance(), state.width).
struct RenderState : Film {
    SamplePlan plan;  // the next pass's pixels and samples (allocation.h)
    // Per row, whether render_pass samples it at all (empty: every row): a process's share of
    // the rows (row_share.h) or a render region's, set around each pass by its PassHooks.
    std::vector<uint8_t> active_rows;
    int passes = 0;                  // completed passes
    uint64_t rays = 0;               // every ray cast: camera, bounce and shadow rays
    uint64_t nonfinite_samples = 0;  // samples dropped for NaN/Inf radiance

    RenderState() = default;
    RenderState(int w, int h) { reset(w, h); }
    // A fresh render of w x h pixels holding the rows `held` (Film::reset): no pass, no plan.
    void reset(int w, int h, std::vector<int> held = {});
};

// The bytes per pixel a RenderState holds once every buffer is in use: its film's (halves
// apart) and its plan's.
inline constexpr uint64_t kRenderStateBytesPerPixel = kFilmBytesPerPixel + kPlanBytesPerPixel;

// The memory of a process of a shared render that holds `rows` rows of `width` pixels and
// writes nothing (RenderState::reset's held rows): their state, and the buffers in which it
// sends its rows next to other processes' blocks (each at most twice: 4 kRowBlocks rows) and
// receives the rows next to its own blocks (2 kRowBlocks); with `halves`, their halves too.
inline uint64_t render_state_bytes(int width, size_t rows, bool halves = false) {
    const uint64_t per_pixel = kRenderStateBytesPerPixel + (halves ? kHalvesBytesPerPixel : 0);
    return uint64_t(width) * (uint64_t(rows) * per_pixel + 6 * kRowBlocks * kGuardRowBytesPerPixel);
}

}  // namespace kr
