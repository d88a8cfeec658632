// A batch's samples added to their pixels (pixel_sums.h), for kernels.cpp: compiled into each
// target's namespace for its CPU level, the x86-64-v3 form (a colour in one AVX register)
// where the level has it, else PixelSums::add per sample.
#pragma once

#include "render/lanes/levels.h"
#include "render/lanes/math.h"
#include "render/lanes/pixel_sums.h"

// The sums' bits are the x86-64 code's at every level: no product fused into a sum.
KR_UNFUSED_BEGIN

#if !defined(KR_LANES_V3) && !defined(KR_LANES_V4)
// A batch's samples added to their pixels in the order they were drawn (PixelSums::add each).
void accumulate_batch(const PixelSums& pixel_sums, const size_t* pixels, const SampleResult* results, int count,
                     uint64_t& rays, uint64_t& nonfinite) {
    const PixelSums sums = pixel_sums;  // in registers, not reloaded after each store
    uint64_t batch_rays = 0, dropped = 0;
    for (int k = 0; k < count; ++k) {
        batch_rays += results[k].rays;
        dropped += !sums.add(pixels[k], results[k]);
    }
    rays += batch_rays;
    nonfinite += dropped;
}
#else
// The same with a colour's three channels in one AVX register: the same IEEE operations per
// channel as PixelSums::add, so the same sums bit for bit, in about two thirds of its
// instructions.
KR_LANES void store_xyz(double* p, __m256d v) {
    _mm_storeu_pd(p, _mm256_castpd256_pd128(v));
    _mm_store_sd(p + 2, _mm256_extractf128_pd(v, 1));
}

// A pixel's sums, held in registers, stored.
KR_LANES void store_sums(const PixelSums& sums, size_t i, __m256d sum,
                                                                     __m256d lost, __m256d sq, double depth,
                                                                     double luminance_sq, uint32_t count) {
    store_xyz(&sums.radiance[i].x, sum);
    store_xyz(&sums.compensation[i].x, lost);
    store_xyz(&sums.radiance_sq[i].x, sq);
    sums.depth[i] = depth;
    sums.luminance_sq[i] = luminance_sq;
    sums.count[i] = count;
}

void accumulate_batch(const PixelSums& pixel_sums, const size_t* pixels,
                                                     const SampleResult* results, int count, uint64_t& rays,
                                                     uint64_t& nonfinite) {
    static_assert(offsetof(SampleResult, primary_distance) == 3 * sizeof(double), "one load reads a result's colour");
    if (count <= 0) return;
    const PixelSums sums = pixel_sums;
    const __m256i xyz = _mm256_setr_epi64x(-1, -1, -1, 0);  // the lanes of a Color read from a pixel's sums
    const __m256d zero = _mm256_setzero_pd();
    uint64_t batch_rays = 0, dropped = 0;
    // A planned pass gives a pixel its samples one after another: its sums stay in registers
    // until a sample of another pixel comes, instead of being reloaded from the stores just
    // made (a load that spans two stores waits for them to reach the cache).
    size_t held = pixels[0];
    __m256d sum = _mm256_maskload_pd(&sums.radiance[held].x, xyz);
    __m256d lost = _mm256_maskload_pd(&sums.compensation[held].x, xyz);
    __m256d sq = _mm256_maskload_pd(&sums.radiance_sq[held].x, xyz);
    double depth = sums.depth[held], luminance_sq = sums.luminance_sq[held];
    uint32_t samples = sums.count[held];
    for (int k = 0; k < count; ++k) {
        const SampleResult& r = results[k];
        const size_t i = pixels[k];
        batch_rays += r.rays;
        if (i != held) {
            store_sums(sums, held, sum, lost, sq, depth, luminance_sq, samples);
            held = i;
            sum = _mm256_maskload_pd(&sums.radiance[i].x, xyz);
            lost = _mm256_maskload_pd(&sums.compensation[i].x, xyz);
            sq = _mm256_maskload_pd(&sums.radiance_sq[i].x, xyz);
            depth = sums.depth[i];
            luminance_sq = sums.luminance_sq[i];
            samples = sums.count[i];
        }
        // The sample's colour, its fourth lane (the depth) cleared, and the new sums.
        const __m256d x = _mm256_blend_pd(_mm256_loadu_pd(&r.radiance.x), zero, 0b1000);
        const __m256d t = sum + x;
        // Finite (the sample, and the sum not overflowed): t - t is 0 in every lane.
        if (_mm256_movemask_pd(_mm256_cmp_pd(t - t, zero, _CMP_EQ_OQ)) != 0b1111) {
            ++dropped;
            continue;
        }
        // two_sum_error(sum, x, t) written out: Clang passes no AVX vector to a function
        // compiled without AVX.
        const __m256d x_part = t - sum;
        lost = lost + ((sum - (t - x_part)) + (x - x_part));
        sum = t;
        depth += r.primary_distance;
        const double lum = luminance(r.radiance);
        luminance_sq += lum * lum;
        sq = sq + x * x;
        samples += 1;
    }
    store_sums(sums, held, sum, lost, sq, depth, luminance_sq, samples);
    rays += batch_rays;
    nonfinite += dropped;
}
#endif
KR_UNFUSED_END
