// The per-pixel sums a render pass adds its samples to, and the addition of a batch of
// samples to them: written once for one sample (PixelSums::add, SSE2 pairs), and for a CPU
// of level x86-64-v3 with a colour in one AVX register (accumulate.h, compiled into the
// kernels of each target: levels.h). render_pass.cpp calls accumulate.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/math.h"
#include "render/trace.h"

namespace kr {

// Two doubles in one SSE2 register (GCC vector extension): a Color's x and y travel together,
// z alone. Each lane does the same IEEE operations as the scalar code, so the sums are the
// same bits.
typedef double Pair __attribute__((vector_size(16)));
inline Pair load_pair(const double* p) {
    Pair v;
    __builtin_memcpy(&v, p, sizeof v);
    return v;
}
inline void store_pair(double* p, Pair v) { __builtin_memcpy(p, &v, sizeof v); }

// Compensated summation (Neumaier's, with Knuth's TwoSum for the rounding error of each
// addition: exact whichever term is larger, and without a branch), given t = sum + x.
// `sum` stays the plain running sum; `compensation` gathers what its roundings lost.
template <class T>
inline T two_sum_error(T sum, T x, T t) {
    const T x_part = t - sum;
    return (sum - (t - x_part)) + (x - x_part);
}

// The per-pixel sums one sample adds to (PixelBuffers' columns, their data pointers taken
// once per pass).
struct PixelSums {
    Color* radiance;
    Color* compensation;
    double* depth;
    double* luminance_sq;
    Color* radiance_sq;
    uint32_t* count;

    // Adds sample `r` to pixel `i`, unless it is not finite (NaN or Inf) or would overflow
    // the pixel's sum: the sums stay finite, so a sum plus a sample is finite only where the
    // sample is too, and one test of the new sums covers both. Returns whether it was added.
    bool add(size_t i, const SampleResult& r) const {
        double* sum = &radiance[i].x;
        const Pair sum_xy = load_pair(sum), x_xy = load_pair(&r.radiance.x);
        const double sum_z = sum[2], x_z = r.radiance.z;
        const Pair t_xy = sum_xy + x_xy;
        const double t_z = sum_z + x_z;
        // Finite: t - t is 0, not NaN, in every channel.
        const Pair zero_xy = t_xy - t_xy;
        if (!((zero_xy[0] + zero_xy[1]) + (t_z - t_z) == 0)) return false;
        store_pair(sum, t_xy);
        sum[2] = t_z;
        double* lost = &compensation[i].x;
        store_pair(lost, load_pair(lost) + two_sum_error(sum_xy, x_xy, t_xy));
        lost[2] += two_sum_error(sum_z, x_z, t_z);
        depth[i] += r.primary_distance;  // kMissDepth for a miss; a farther hit stays farther
        const double lum = luminance(r.radiance);
        luminance_sq[i] += lum * lum;
        double* sq = &radiance_sq[i].x;
        store_pair(sq, load_pair(sq) + x_xy * x_xy);
        sq[2] += x_z * x_z;
        count[i] += 1;
        return true;
    }
};

// A batch's samples added to their pixels in the order they were drawn: with the x86-64-v3
// target's code where `avx2` (and avx2_accumulation()), else one at a time by
// PixelSums::add. The sums are the same bits either way. `rays` gains the samples' rays,
// `nonfinite` the samples not added.
void accumulate(const PixelSums& sums, const size_t* pixels, const SampleResult* results, int count, bool avx2,
                uint64_t& rays, uint64_t& nonfinite);
// Whether this build and CPU have the x86-64-v3 accumulation.
bool avx2_accumulation();
// The addition accumulate makes, as a function a pass calls for each batch: the x86-64-v3
// target's where `avx2` and avx2_accumulation(), else any x86-64's.
using AccumulateBatch = void (*)(const PixelSums& sums, const size_t* pixels, const SampleResult* results, int count,
                                 uint64_t& rays, uint64_t& nonfinite);
AccumulateBatch accumulation(bool avx2);

}  // namespace kr
