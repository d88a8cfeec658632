// The interactive denoiser, the edge-avoiding a-trous wavelet filter (render/denoise.h).
#include <algorithm>
#include <cmath>

#include "core/math.h"
#include "core/vectorise.h"
#include "render/lanes/levels.h"
#include "render/denoise.h"
#include "render/denoise_common.h"

namespace kr {

using namespace denoising;

namespace {

// One a-trous pass: what a row of it reads (the taps: the pass's input planes; the centre:
// the stops' scales) and writes (the next pass's planes), all w x h and row-major.
struct AtrousPass {
    const float *lum, *z, *f[4], *c[3], *var;  // the taps' luminance, depth, feature, radiance, variance
    const float *var_centre, *zgrad;           // the luminance stop's variance, the depth gradient
    float *out_c[3], *out_var, *out_lum;
    int w, h, step;
    float sigma_luminance, gate, zscale, sigma_normal;
};

// The pixels [x0, x1) of row `row` (its first pixel's index): all nine taps fused in one
// loop, the sums in registers. The template arguments say which taps lie inside the image
// (the rows above and below, the columns left and right), so the loop has no test per tap
// and reads no tap outside the image.
template <bool Up, bool Down, bool Left, bool Right>
[[gnu::always_inline]] inline void atrous_span(const AtrousPass& a, size_t row, int x0, int x1) {
    const ptrdiff_t dy = ptrdiff_t(a.step) * a.w, dx = a.step;
    const float* __restrict lum = a.lum + row;
    const float* __restrict z = a.z + row;
    const float *__restrict f0 = a.f[0] + row, *__restrict f1 = a.f[1] + row, *__restrict f2 = a.f[2] + row,
                *__restrict f3 = a.f[3] + row;
    const float *__restrict c0 = a.c[0] + row, *__restrict c1 = a.c[1] + row, *__restrict c2 = a.c[2] + row;
    const float* __restrict var = a.var + row;
    const float *__restrict vc = a.var_centre + row, *__restrict zg = a.zgrad + row;
    float *__restrict o0 = a.out_c[0] + row, *__restrict o1 = a.out_c[1] + row, *__restrict o2 = a.out_c[2] + row,
          *__restrict ov = a.out_var + row, *__restrict ol = a.out_lum + row;
    const float sigma_l = a.sigma_luminance, gate = a.gate, zscale = a.zscale, sigma_n = a.sigma_normal;
KR_INDEPENDENT_ITERATIONS
    for (int x = x0; x < x1; ++x) {
        // The stops' scales at the centre: the luminance's by the standard deviation, the
        // depth's by the gradient over the step.
        const float l = lum[x], zc = z[x], g0 = f0[x], g1 = f1[x], g2 = f2[x], g3 = f3[x];
        const float il = gate / (sigma_l * std::sqrt(std::max(0.f, vc[x])) + 1e-12f);
        const float iz = 1 / (zscale * zg[x] + 1e-3f * zc + 1e-9f);
        float sw = 0, sr = 0, sg = 0, sb = 0, sv = 0;
        // The tap at offset `off` of weight `k`: the edge stops, summed in one exponent.
        const auto tap = [&](ptrdiff_t off, float k) __attribute__((always_inline)) {
            const ptrdiff_t j = x + off;
            const float el = std::fabs(l - lum[j]) * il;
            const float ez = std::fabs(zc - z[j]) * iz;
            const float fd = g0 * f0[j] + g1 * f1[j] + g2 * f2[j] + g3 * f3[j];
            const float en = sigma_n * std::max(0.f, 1.f - fd);
            const float wt = k * fast_exp_neg(el + ez + en);
            sw += wt;
            sr += wt * c0[j];
            sg += wt * c1[j];
            sb += wt * c2[j];
            sv += wt * wt * var[j];
        };
        // The taps in the order of rows, then columns, with the B-spline's weights.
        if constexpr (Up) {
            if constexpr (Left) tap(-dy - dx, 1 / 16.f);
            tap(-dy, 1 / 8.f);
            if constexpr (Right) tap(-dy + dx, 1 / 16.f);
        }
        if constexpr (Left) tap(-dx, 1 / 8.f);
        tap(0, 1 / 4.f);
        if constexpr (Right) tap(dx, 1 / 8.f);
        if constexpr (Down) {
            if constexpr (Left) tap(dy - dx, 1 / 16.f);
            tap(dy, 1 / 8.f);
            if constexpr (Right) tap(dy + dx, 1 / 16.f);
        }
        // The centre tap always counts, so the weights' sum is at least 1/4.
        const float inv = 1 / sw;
        const float r = sr * inv, g = sg * inv, b = sb * inv;
        o0[x] = r;
        o1[x] = g;
        o2[x] = b;
        ov[x] = sv * inv * inv;
        ol[x] = kLum[0] * r + kLum[1] * g + kLum[2] * b;
    }
}

template <bool Up, bool Down>
[[gnu::always_inline]] inline void atrous_span_rows(const AtrousPass& a, size_t row, int x0, int x1, bool left,
                                                     bool right) {
    if (left && right) atrous_span<Up, Down, true, true>(a, row, x0, x1);
    else if (left) atrous_span<Up, Down, true, false>(a, row, x0, x1);
    else if (right) atrous_span<Up, Down, false, true>(a, row, x0, x1);
    else atrous_span<Up, Down, false, false>(a, row, x0, x1);
}

// Row y of a pass, in up to three spans: where the left taps are outside (x < step), where
// all are inside, where the right ones are outside (x >= w - step).
KR_LOOP_CLONES
void atrous_row(const AtrousPass& a, int y) {
    const size_t row = size_t(y) * size_t(a.w);
    const bool up = y - a.step >= 0, down = y + a.step < a.h;
    const int b0 = std::clamp(std::min(a.step, a.w - a.step), 0, a.w),
              b1 = std::clamp(std::max(a.step, a.w - a.step), 0, a.w);
    const int bounds[4] = {0, b0, b1, a.w};
    for (int s = 0; s < 3; ++s) {
        const int x0 = bounds[s], x1 = bounds[s + 1];
        if (x0 >= x1) continue;
        const bool left = x0 >= a.step, right = x0 < a.w - a.step;
        if (up && down) atrous_span_rows<true, true>(a, row, x0, x1, left, right);
        else if (up) atrous_span_rows<true, false>(a, row, x0, x1, left, right);
        else if (down) atrous_span_rows<false, true>(a, row, x0, x1, left, right);
        else atrous_span_rows<false, false>(a, row, x0, x1, left, right);
    }
}

}  // namespace

Image denoise_atrous(const DenoiseInput& input, const AtrousParams& params, DenoiseWorkspace* workspace,
                     const std::atomic<bool>* cancel) {
    DenoiseWorkspace local;
    DenoiseWorkspace& p = prepared_planes(input, workspace, local);
    const int w = p.w, h = p.h;
    const size_t n = size_t(w) * size_t(h);
    Image out(w, h);
    if (n == 0) return out;
    for (auto* plane :
         {&p.atrous.radiance[0], &p.atrous.radiance[1], &p.atrous.radiance[2], &p.atrous.variance, &p.atrous.luminance})
        plane->resize(n);
    // The first pass's luminance stop takes the variance 3x3-prefiltered; later passes' is
    // filtered already.
    blur3(w, h, p.base.variance, p.base.scratch);
    // One team of threads for every pass (each loop ends at a barrier). Whether to stop is
    // read by one thread before each pass and seen by all after the barrier that follows.
    bool cancelled = false;
#pragma omp parallel
    for (int it = 0; it < params.iterations; ++it) {
#pragma omp single
        cancelled = cancel && cancel->load(std::memory_order_relaxed);
        if (cancelled) break;
        const int step = 1 << it;
        const AtrousPass a{
            p.base.luminance.data(),
            p.base.depth.data(),
            {p.base.feature[0].data(), p.base.feature[1].data(), p.base.feature[2].data(), p.base.feature[3].data()},
            {p.base.radiance[0].data(), p.base.radiance[1].data(), p.base.radiance[2].data()},
            p.base.variance.data(),
            it == 0 ? p.base.scratch.data() : p.base.variance.data(),
            p.base.depth_gradient.data(),
            {p.atrous.radiance[0].data(), p.atrous.radiance[1].data(), p.atrous.radiance[2].data()},
            p.atrous.variance.data(),
            p.atrous.luminance.data(),
            w,
            h,
            step,
            params.sigma_luminance,
            params.sigma_luminance > 0 ? 1.f : 0.f,
            params.sigma_depth * float(step),
            params.sigma_normal};
#pragma omp for schedule(static)
        for (int y = 0; y < h; ++y) atrous_row(a, y);
#pragma omp single
        {
            for (int k = 0; k < 3; ++k) std::swap(p.base.radiance[k], p.atrous.radiance[k]);
            std::swap(p.base.variance, p.atrous.variance);
            std::swap(p.base.luminance, p.atrous.luminance);
        }
    }
    if (cancelled) return Image();
    remodulate_and_fade(input, params.fade_error, p, out);
    return out;
}

}  // namespace kr
