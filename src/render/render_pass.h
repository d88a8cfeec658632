// One pass of a progressive render: each pixel's planned samples traced (in SIMD lanes where
// they can be) and added to its sums.
#pragma once

#include <atomic>

#include "render/render_scene.h"
#include "render/render_state.h"
#include "render/settings.h"
#include "render/trace.h"

namespace kr {

// Adds one sample to every pixel of `state`'s film, or the number its plan gives
// (state.plan.pass_samples; sample index = the pixel's own count of samples drawn), on the
// rows state.active_rows leaves on and the pixels the noise rule's mask does; where the film
// tracks the halves (Film::track_halves), a pass after an odd number of passes adds its
// samples to the half too, the others' halves staying as they are, bit for bit.
// Parallel over rows with OpenMP; each sample has its own RNG stream seeded by
// (seed, pixel, sample index), so the image does not depend on threads or scheduling.
// If `stop` becomes true the pass ends early and returns false; pixels it reached keep their
// sample, others do not: the state is then an unevenly sampled estimate, which
// ProgressiveDriver's users drop (the viewer stops a pass only for an edit).
bool render_pass(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                 const std::atomic<bool>* stop = nullptr);

// How render_pass adds a sample to its pixel's sums: SSE2 (any x86-64 CPU) or, where the CPU
// has AVX2, a colour's three channels in one register. Both give the same sums bit for bit.
enum class AccumulationIsa { sse2, avx2 };
bool accumulation_isa_available(AccumulationIsa isa);
// Adds `count` samples to the pixels `pixels` of `buffers` in order, as render_pass does (a
// sample that is not finite, or would overflow its pixel's sums, is dropped and counted in
// `nonfinite`). For tests.
void accumulate_samples(PixelBuffers& buffers, const size_t* pixels, const SampleResult* results, int count,
                        AccumulationIsa isa, uint64_t& nonfinite);

}  // namespace kr
