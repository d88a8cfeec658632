#include "render/denoise.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/math.h"
#include "core/vectorise.h"

namespace kr {

namespace {

constexpr float kLum[3] = {0.2126f, 0.7152f, 0.0722f};  // luminance(), core/math.h
// Added to the albedo before dividing it out: a black or missing first surface (a light, the
// background) is then filtered as radiance, and no division blows up.
constexpr float kAlbedoFloor = 0.02f;

// exp(-x) for x >= 0 as (1 - x/16)^16: within 0.02 of it, zero beyond 16, and plain
// arithmetic the compiler vectorises (an edge stop needs its shape, not its digits).
inline float fast_exp_neg(float x) {
    float y = std::max(0.f, 1.f - x * (1.f / 16));
    y *= y;
    y *= y;
    y *= y;
    return y * y;
}

using Planes = DenoiseWorkspace;

// At most this many pixels, evenly strided, give the image's scale.
constexpr size_t kScaleSamples = 16384;

// The filters' unit of radiance: a robust scale of the image, the 93rd percentile of the
// luminance of (a stride of) its pixels, or where that is black (a lamp alone in the dark)
// their mean. Both filters work on the radiance over this unit and multiply it back, so their
// result is proportional to the light's power (a render at power s times the lights is s
// times the image at power 1) over the loader's whole range: a value of 1e30 or 1e-30 never
// meets float's range (its square overflows or underflows), and the few absolute constants
// (the luminance floor of the selection's relative risks, the guards against dividing by
// zero) are fractions of the image's own brightness. The percentile is the one, of the 80th
// to the 97th and the mean with the brightest 1 % clipped, that changed the final filter's
// figures least (docs/denoising.md, "Units"): the scenes it was tuned on have units of 0.18
// (scene 4, dark) to 2.5 (scene 5), 1 in their geometric mean. The luminances are taken over
// the largest one in `scratch` (floats in [0, 1]). An image without a positive finite
// luminance has the unit 1.
double radiance_unit(const Image& radiance, std::vector<float>& scratch) {
    const size_t n = radiance.pixels.size(), stride = std::max<size_t>(1, n / kScaleSamples);
    double largest = 0;
    for (size_t i = 0; i < n; i += stride) {
        const double l = luminance(radiance.pixels[i]);
        if (std::isfinite(l)) largest = std::max(largest, l);
    }
    if (!(largest > 0)) return 1;
    scratch.clear();
    double sum = 0;
    for (size_t i = 0; i < n; i += stride) {
        const double l = luminance(radiance.pixels[i]);
        scratch.push_back(std::isfinite(l) ? float(std::max(0.0, l / largest)) : 0.f);
        sum += scratch.back();
    }
    const auto at = scratch.begin() + ptrdiff_t((scratch.size() - 1) * 93 / 100);
    std::nth_element(scratch.begin(), at, scratch.end());
    return largest * (*at > 0 ? double(*at) : sum / double(scratch.size()));
}


// Where a pixel's variance is unknown (one sample): the luminance's variance over its 3x3
// neighbourhood, the variance of one sample where the neighbours are alike.
void fill_unknown_variance(int w, int h, const std::vector<float>& lum, std::vector<float>& var) {
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y) {
        // Most rows have none: a count the compiler vectorises first.
        const float* row = var.data() + size_t(y) * size_t(w);
        int unknown = 0;
        for (int x = 0; x < w; ++x) unknown += !std::isfinite(row[x]);
        if (unknown == 0) continue;
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * size_t(w) + size_t(x);
            if (std::isfinite(var[i])) continue;
            double s = 0, s2 = 0;
            int n = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int xx = x + dx, yy = y + dy;
                    if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
                    const double l = lum[size_t(yy) * size_t(w) + size_t(xx)];
                    s += l;
                    s2 += l * l;
                    ++n;
                }
            var[i] = float(std::max(0.0, (s2 - s * s / n) / std::max(n - 1, 1)));
        }
    }
}

// 3x3 binomial blur of a plane (borders renormalised): SVGF's prefilter of the variance
// before it scales the luminance stop. Row y; inside the border the weights sum to 1 exactly
// and the taps are added in the same order, so both loops give the same sums.
KR_VECTOR_CLONES
void blur3_row(const float* v, float* out, int w, int h, int y) {
    constexpr float k[3] = {0.25f, 0.5f, 0.25f};
    const auto border = [&](int x) {
        float s = 0, ws = 0;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int xx = x + dx, yy = y + dy;
                if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
                const float wk = k[dx + 1] * k[dy + 1];
                s += wk * v[size_t(yy) * size_t(w) + size_t(xx)];
                ws += wk;
            }
        out[size_t(y) * size_t(w) + size_t(x)] = s / ws;
    };
    if (y == 0 || y == h - 1 || w < 3) {
        for (int x = 0; x < w; ++x) border(x);
        return;
    }
    const size_t row = size_t(y) * size_t(w);
    const float *__restrict up = v + row - w, *__restrict mid = v + row, *__restrict down = v + row + w;
    float* __restrict o = out + row;
    border(0);
    for (int x = 1; x < w - 1; ++x) {
        float s = 0;
        s += k[0] * k[0] * up[x - 1];
        s += k[1] * k[0] * up[x];
        s += k[2] * k[0] * up[x + 1];
        s += k[0] * k[1] * mid[x - 1];
        s += k[1] * k[1] * mid[x];
        s += k[2] * k[1] * mid[x + 1];
        s += k[0] * k[2] * down[x - 1];
        s += k[1] * k[2] * down[x];
        s += k[2] * k[2] * down[x + 1];
        o[x] = s;
    }
    border(w - 1);
}

void blur3(int w, int h, const std::vector<float>& v, std::vector<float>& out) {
    out.resize(v.size());
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y) blur3_row(v.data(), out.data(), w, h, y);
}

// prepare's per-pixel step, pixels [i0, i1): the demodulated radiance, the variances and
// luminances (demodulated and raw), the unit feature vector and the depth.
KR_VECTOR_CLONES
void prepare_pixels(const DenoiseInput& in, Planes& p, size_t i0, size_t i1) {
    const Color* __restrict rad = in.radiance->pixels.data();
    const Color* __restrict variance = in.variance.data();
    const float *__restrict albedo = in.albedo.data(), *__restrict normal = in.normal.data();
    // In the filter's unit (radiance_unit): the radiance over it, the variance over its square.
    const double inv_unit = 1 / p.unit, var_scale = p.var_scale;
    const double* __restrict depth = in.depth.data();
    float *__restrict d0 = p.demod[0].data(), *__restrict d1 = p.demod[1].data(), *__restrict d2 = p.demod[2].data();
    float *__restrict c0 = p.c[0].data(), *__restrict c1 = p.c[1].data(), *__restrict c2 = p.c[2].data();
    float *__restrict f0 = p.f[0].data(), *__restrict f1 = p.f[1].data(), *__restrict f2 = p.f[2].data(),
          *__restrict f3 = p.f[3].data();
    float *__restrict var_out = p.var.data(), *__restrict raw_var_out = p.raw_var.data(), *__restrict lum = p.lum.data(),
          *__restrict raw_lum = p.lum_raw.data(), *__restrict z = p.z.data();
KR_INDEPENDENT_ITERATIONS
    for (size_t i = i0; i < i1; ++i) {
        const float r[3] = {float(rad[i].x * inv_unit), float(rad[i].y * inv_unit), float(rad[i].z * inv_unit)};
        float d[3], c[3];
        float var = 0, raw_var = 0, l = 0, raw_l = 0;
        for (int k = 0; k < 3; ++k) {
            // Demodulation: the illumination is the radiance over the albedo.
            d[k] = std::max(0.f, albedo[3 * i + size_t(k)]) + kAlbedoFloor;
            c[k] = r[k] / d[k];
            const float v = float(variance[i][k] * var_scale);
            var += kLum[k] * kLum[k] * v / (d[k] * d[k]);
            raw_var += kLum[k] * kLum[k] * v;
            l += kLum[k] * c[k];  // as the a-trous passes take it from p.c
            raw_l += kLum[k] * r[k];
        }
        d0[i] = d[0];
        d1[i] = d[1];
        d2[i] = d[2];
        c0[i] = c[0];
        c1[i] = c[1];
        c2[i] = c[2];
        var_out[i] = std::isfinite(var) ? var : INFINITY;
        raw_var_out[i] = std::isfinite(raw_var) ? raw_var : INFINITY;
        lum[i] = l;
        raw_lum[i] = raw_l;
        // The feature vector: the averaged normal and how much of the pixel saw nothing.
        const float nx = normal[3 * i], ny = normal[3 * i + 1], nz = normal[3 * i + 2];
        const float len = std::sqrt(nx * nx + ny * ny + nz * nz);
        const float miss = std::max(0.f, 1.f - len);
        const float norm = std::sqrt(len * len + miss * miss);
        const float inv = norm > 0 ? 1 / norm : 0;
        f0[i] = nx * inv;
        f1[i] = ny * inv;
        f2[i] = nz * inv;
        f3[i] = norm > 0 ? miss * inv : 1;
        z[i] = float(depth[i]);
    }
}

// The depth gradient of row y: per axis the smaller one-sided difference (the smooth side at
// a silhouette; a side outside the image does not count), summed over the axes so that any
// 3x3 tap's change on a plane stays below it.
KR_VECTOR_CLONES
void depth_gradient_row(const float* z_plane, float* zgrad, int w, int h, int y) {
    const size_t row = size_t(y) * size_t(w);
    const float* __restrict z = z_plane + row;
    // A missing row above or below: read the row itself, its side taken as infinite.
    const bool has_up = y > 0, has_down = y + 1 < h;
    const float *__restrict up = has_up ? z - w : z, *__restrict down = has_down ? z + w : z;
    float* __restrict out = zgrad + row;
    const auto pixel = [&](int x, float left, float right) __attribute__((always_inline)) {
        const float zc = z[x];
        const float su = has_up ? std::fabs(up[x] - zc) : INFINITY, sd = has_down ? std::fabs(down[x] - zc) : INFINITY;
        float gx = std::min(left, right), gy = std::min(su, sd);
        if (!std::isfinite(gx)) gx = 0;
        if (!std::isfinite(gy)) gy = 0;
        out[x] = gx + gy;
    };
    if (w == 1) {
        pixel(0, INFINITY, INFINITY);
        return;
    }
    pixel(0, INFINITY, std::fabs(z[1] - z[0]));
    for (int x = 1; x < w - 1; ++x) pixel(x, std::fabs(z[x - 1] - z[x]), std::fabs(z[x + 1] - z[x]));
    pixel(w - 1, std::fabs(z[w - 2] - z[w - 1]), INFINITY);
}

void prepare(const DenoiseInput& in, Planes& p) {
    const Image& rad = *in.radiance;
    p.w = rad.width;
    p.h = rad.height;
    const size_t n = rad.pixels.size();
    if (in.variance.size() != n || in.albedo.size() != 3 * n || in.normal.size() != 3 * n || in.depth.size() != n)
        throw std::invalid_argument("denoise: a feature buffer's size is not the image's");
    p.unit = radiance_unit(rad, p.var_blur);
    // Divided twice: the square of a unit of 1e200 would overflow.
    p.var_scale = 1 / p.unit / p.unit;
    for (int k = 0; k < 3; ++k) {
        p.c[k].resize(n);
        p.demod[k].resize(n);
    }
    for (auto& f : p.f) f.resize(n);
    p.var.resize(n);
    p.raw_var.resize(n);
    p.z.resize(n);
    p.zgrad.resize(n);
    p.lum.resize(n);
    p.lum_raw.resize(n);
    const int w = p.w, h = p.h;
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y) prepare_pixels(in, p, size_t(y) * size_t(w), size_t(y + 1) * size_t(w));
    fill_unknown_variance(w, h, p.lum, p.var);
    fill_unknown_variance(w, h, p.lum_raw, p.raw_var);
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y) depth_gradient_row(p.z.data(), p.zgrad.data(), w, h, y);
}

// Both filters' start: the caller's workspace (or `local`), prepared for `input`.
Planes& prepared_planes(const DenoiseInput& input, DenoiseWorkspace* workspace, DenoiseWorkspace& local) {
    Planes& p = workspace ? *workspace : local;
    prepare(input, p);
    return p;
}

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
KR_VECTOR_CLONES
void atrous_row(const AtrousPass& a, int y) {
    const size_t row = size_t(y) * size_t(a.w);
    const bool up = y - a.step >= 0, down = y + a.step < a.h;
    const int b0 = std::clamp(std::min(a.step, a.w - a.step), 0, a.w), b1 = std::clamp(std::max(a.step, a.w - a.step), 0, a.w);
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

// The last step of both filters: the filtered demodulated radiance (p.c) times the albedo,
// then faded towards the raw radiance as its relative standard error drops (the
// 3x3-prefiltered raw variance against the filtered luminance), so a converged pixel keeps
// its raw value. A pixel whose p.c is NaN keeps its raw value exactly.
KR_VECTOR_CLONES
void remodulate_and_fade_pixels(const Image& raw, const Planes& p, const float* raw_var, float t2, Image& out,
                                size_t i0, size_t i1) {
    const double unit = p.unit;
    const float *__restrict c0 = p.c[0].data(), *__restrict c1 = p.c[1].data(), *__restrict c2 = p.c[2].data();
    const float *__restrict d0 = p.demod[0].data(), *__restrict d1 = p.demod[1].data(), *__restrict d2 = p.demod[2].data();
    const Color* __restrict in = raw.pixels.data();
    Color* __restrict o = out.pixels.data();
    // Selects rather than branches, so that the loop vectorises.
KR_INDEPENDENT_ITERATIONS
    for (size_t i = i0; i < i1; ++i) {
        // In the filter's unit (the fade's relative error), then in the radiance's.
        const Color f{double(c0[i] * d0[i]), double(c1[i] * d1[i]), double(c2[i] * d2[i])};
        const double l = std::max(luminance(f), 0.0), v = raw_var[i];
        const Color filtered{f.x * unit, f.y * unit, f.z * unit};
        const double r2 = l > 0 ? v / (l * l) : (v > 0 ? INFINITY : 0.0);
        const double blend = t2 > 0 && std::isfinite(r2) ? r2 / (r2 + t2) : 1.0;
        const bool keep = std::isnan(c0[i]);
        const Color r = in[i];
        o[i] = Color(keep ? r.x : r.x + blend * (filtered.x - r.x), keep ? r.y : r.y + blend * (filtered.y - r.y),
                     keep ? r.z : r.z + blend * (filtered.z - r.z));
    }
}

void remodulate_and_fade(const DenoiseInput& input, float fade_error, Planes& p, Image& out) {
    std::vector<float>& raw_var = p.var_blur;
    blur3(p.w, p.h, p.raw_var, raw_var);
    const float t2 = fade_error * fade_error;
    const Image& raw = *input.radiance;
    const size_t w = size_t(p.w);
#pragma omp parallel for schedule(static)
    for (int y = 0; y < p.h; ++y)
        remodulate_and_fade_pixels(raw, p, raw_var.data(), t2, out, size_t(y) * w, size_t(y + 1) * w);
}

}  // namespace

Image denoise_atrous(const DenoiseInput& input, const AtrousParams& params, DenoiseWorkspace* workspace) {
    DenoiseWorkspace local;
    Planes& p = prepared_planes(input, workspace, local);
    const int w = p.w, h = p.h;
    const size_t n = size_t(w) * size_t(h);
    Image out(w, h);
    if (n == 0) return out;
    for (auto* plane : {&p.c2[0], &p.c2[1], &p.c2[2], &p.var2, &p.lum2}) plane->resize(n);
    // The first pass's luminance stop takes the variance 3x3-prefiltered; later passes' is
    // filtered already.
    blur3(w, h, p.var, p.var_blur);
    // One team of threads for every pass (each loop ends at a barrier).
#pragma omp parallel
    for (int it = 0; it < params.iterations; ++it) {
        const int step = 1 << it;
        const AtrousPass a{p.lum.data(),
                           p.z.data(),
                           {p.f[0].data(), p.f[1].data(), p.f[2].data(), p.f[3].data()},
                           {p.c[0].data(), p.c[1].data(), p.c[2].data()},
                           p.var.data(),
                           it == 0 ? p.var_blur.data() : p.var.data(),
                           p.zgrad.data(),
                           {p.c2[0].data(), p.c2[1].data(), p.c2[2].data()},
                           p.var2.data(),
                           p.lum2.data(),
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
            for (int k = 0; k < 3; ++k) std::swap(p.c[k], p.c2[k]);
            std::swap(p.var, p.var2);
            std::swap(p.lum, p.lum2);
        }
    }
    remodulate_and_fade(input, params.fade_error, p, out);
    return out;
}

namespace {

// Whether neighbouring pixels i and j see the same surface: normals within about 25 degrees,
// albedos within 0.1, depths within twice the local gradient (a pixel is its own).
bool same_surface(const Planes& p, size_t i, size_t j) {
    float fd = 0, da = 0;
    for (int k = 0; k < 3; ++k) {
        const float d = p.demod[k][i] - p.demod[k][j];
        da += d * d;
    }
    for (const auto& f : p.f) fd += f[i] * f[j];
    return i == j || (fd > 0.9f && da < 0.01f && std::fabs(p.z[i] - p.z[j]) <= 2 * (p.zgrad[i] + 1e-3f * p.z[i]));
}

// The second half's weight in pixel i's mean: its share of the samples where both halves have
// some, else 1/2 (prepare_halves then gives both halves the mean itself). 1/2 without halves.
double second_half_share(const DenoiseInput& in, bool halves, size_t i) {
    if (!halves) return 0.5;
    const double n0 = in.half_count[0][i], n1 = in.half_count[1][i];
    return n0 > 0 && n1 > 0 ? n1 / (n0 + n1) : 0.5;
}

// Channel k of pixel i's demodulated mean from its halves (t: second_half_share).
float mean_of_halves(const Planes& p, int k, size_t i, double t) {
    return float(p.u[0][k][i] + t * (p.u[1][k][i] - p.u[0][k][i]));
}

// The guides of the final filter: per half g, the demodulated radiance u[g] and the variance
// of its mean v[g] (3x3-prefiltered). A pixel without two non-empty halves takes the mean for
// both, with the mean's variance.
void prepare_halves(const DenoiseInput& in, Planes& p) {
    const size_t n = size_t(p.w) * size_t(p.h);
    for (int g = 0; g < 2; ++g)
        for (int k = 0; k < 3; ++k) {
            p.u[g][k].resize(n);
            p.v[g][k].resize(n);
        }
    const bool halves = in.half[0] && in.half[1] && in.half[0]->pixels.size() == n && in.half[1]->pixels.size() == n &&
                        in.half_count[0].size() == n && in.half_count[1].size() == n;
    const double inv_unit = 1 / p.unit;
    const long count = long(n);
#pragma omp parallel for schedule(static)
    for (long li = 0; li < count; ++li) {
        const size_t i = size_t(li);
        const uint32_t n0 = halves ? in.half_count[0][i] : 0, n1 = halves ? in.half_count[1][i] : 0;
        const bool split = n0 > 0 && n1 > 0;
        for (int g = 0; g < 2; ++g) {
            // A half's mean has the variance of the pixel's mean times all samples over its own.
            const double share = split ? double(n0 + n1) / double(g == 0 ? n0 : n1) : 1.0;
            for (int k = 0; k < 3; ++k) {
                const float d = p.demod[k][i];
                const double r = split ? in.half[g]->pixels[i][k] : in.radiance->pixels[i][k];
                const float v = float(in.variance[i][k] * p.var_scale * share) / (d * d);
                p.u[g][k][i] = float(r * inv_unit) / d;  // as prepare_pixels takes it
                p.v[g][k][i] = std::isfinite(v) ? v : INFINITY;
            }
        }
    }
    for (int g = 0; g < 2; ++g) {
        p.own_var[g].assign(n, 0.f);
        for (int k = 0; k < 3; ++k) {
            fill_unknown_variance(p.w, p.h, p.u[g][k], p.v[g][k]);
            // The pixel's own variance, before the prefilter spreads its neighbours' into it:
            // the one Stein's risk estimate asks for (denoise_nlmeans).
            for (size_t i = 0; i < n; ++i) p.own_var[g][i] += p.v[g][k][i];
            blur3(p.w, p.h, p.v[g][k], p.var_blur);
            std::swap(p.v[g][k], p.var_blur);
        }
    }
    p.clamped.assign(n, 0);
    if (!halves) return;
    // Fireflies: a rare bright sample lands in one half only, so each half's value is clamped
    // to the range of the other half's 3x3 neighbourhood on the same surface (a highlight is
    // in both halves and stays; a pixel across an edge would widen the range on one side).
    // Biased, as the a-trous filter's luminance stop is, for far less error.
    for (int k = 0; k < 3; ++k) {
        std::vector<float>& clamped = p.var_blur;
        for (int g = 0; g < 2; ++g) {
            const std::vector<float>&mine = p.u[g][k], &other = p.u[1 - g][k];
            clamped.resize(n);
#pragma omp parallel for schedule(static)
            for (int y = 0; y < p.h; ++y)
                for (int x = 0; x < p.w; ++x) {
                    // The range over the same surface's pixels, and over all nine.
                    float lo = INFINITY, hi = -INFINITY, all_lo = INFINITY, all_hi = -INFINITY;
                    int count = 0;
                    const size_t i = size_t(y) * size_t(p.w) + size_t(x);
                    for (int yy = std::max(0, y - 1); yy <= std::min(p.h - 1, y + 1); ++yy)
                        for (int xx = std::max(0, x - 1); xx <= std::min(p.w - 1, x + 1); ++xx) {
                            const size_t j = size_t(yy) * size_t(p.w) + size_t(xx);
                            const float o = other[j];
                            all_lo = std::min(all_lo, o);
                            all_hi = std::max(all_hi, o);
                            if (!same_surface(p, i, j)) continue;
                            ++count;
                            lo = std::min(lo, o);
                            hi = std::max(hi, o);
                        }
                    // Fewer than 4 values on the surface say too little of the range: all nine.
                    clamped[i] = count >= 4 ? std::clamp(mine[i], lo, hi) : std::clamp(mine[i], all_lo, all_hi);
                }
            // Both halves are clamped against the other's unclamped values.
            std::swap(p.acc[g][k], clamped);
        }
        for (int g = 0; g < 2; ++g) std::swap(p.u[g][k], p.acc[g][k]);
    }
    // The raw candidate of a pixel whose halves were clamped is their clamped mean.
    p.clamped.assign(n, 0);
    const long count2 = long(n);
#pragma omp parallel for schedule(static)
    for (long li = 0; li < count2; ++li) {
        const size_t i = size_t(li);
        bool changed = false;
        for (int g = 0; g < 2; ++g)
            for (int k = 0; k < 3; ++k) changed |= p.u[g][k][i] != p.acc[g][k][i];
        if (!changed) continue;
        p.clamped[i] = 1;
        const double t = second_half_share(in, true, i);
        for (int k = 0; k < 3; ++k) p.c[k][i] = mean_of_halves(p, k, i, t);
    }
}

// One guide's patch distance terms along a row, for the pixels [x0, x1) of the row at `at`
// against those at `at + off` (Rousselle et al. 2012): per channel the squared difference
// less its expected noise, over eps + k^2 times the variance of the difference, averaged.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("avx2", "default")))
#endif
void patch_terms(const float* const u[3], const float* const v[3], size_t at, ptrdiff_t off, int x0, int x1, float k2,
                 float* out) {
    for (int x = x0; x < x1; ++x) out[x] = 0;
    for (int c = 0; c < 3; ++c) {
        const float *up = u[c] + at, *uq = u[c] + at + off, *vp = v[c] + at, *vq = v[c] + at + off;
#pragma omp simd
        for (int x = x0; x < x1; ++x) {
            const float d = up[x] - uq[x];
            const float noise = vp[x] + std::min(vp[x], vq[x]);
            out[x] += (d * d - noise) / (1e-10f + k2 * (vp[x] + vq[x]));
        }
    }
}


// One non-local means filter of both halves at distance scale k: p.acc[g] gets half g's
// sums with weights from the other half, and their weights (the centre's is 1).
void nlm_filter(const NlmParams& params, float k, Planes& p) {
    const int w = p.w, h = p.h;
    const size_t n = size_t(w) * size_t(h);
    for (int g = 0; g < 2; ++g) {
        p.hbox[g].assign(n, 0.f);
        for (auto& plane : p.acc[g]) plane.assign(n, 0.f);
    }
    const int r = std::max(0, params.radius), f = std::max(0, params.patch);
    const float k2 = k * k, inv_patch = 1.f / float((2 * f + 1) * (2 * f + 1));
    const float inv_albedo2 = 1.f / (params.sigma_albedo * params.sigma_albedo);
#pragma omp parallel
    {
        std::vector<float> terms(static_cast<size_t>(w)), wf(static_cast<size_t>(w));
        for (int oy = -r; oy <= r; ++oy)
            for (int ox = -r; ox <= r; ++ox) {
                // The pixels whose offset neighbour q = p + (ox, oy) lies in the image.
                const int x0 = std::max(0, -ox), x1 = std::min(w, w - ox), y0 = std::max(0, -oy), y1 = std::min(h, h - oy);
                if (x0 >= x1 || y0 >= y1) continue;
                const ptrdiff_t off = ptrdiff_t(oy) * w + ox;
                // 1. Per guide, the distance terms of each pixel, summed over the patch's
                //    columns (running sums; the row's ends repeat its first and last term).
#pragma omp for schedule(static)
                for (int y = y0; y < y1; ++y) {
                    const size_t row = size_t(y) * size_t(w);
                    for (int g = 0; g < 2; ++g) {
                        const float* const u[3] = {p.u[g][0].data(), p.u[g][1].data(), p.u[g][2].data()};
                        const float* const v[3] = {p.v[g][0].data(), p.v[g][1].data(), p.v[g][2].data()};
                        patch_terms(u, v, row, off, x0, x1, k2, terms.data());
                        float* hb = p.hbox[g].data() + row;
                        float sum = 0;
                        for (int dx = -f; dx <= f; ++dx) sum += terms[size_t(std::clamp(x0 + dx, x0, x1 - 1))];
                        for (int x = x0; x < x1; ++x) {
                            hb[x] = sum;
                            sum += terms[size_t(std::min(x + f + 1, x1 - 1))] - terms[size_t(std::max(x - f, x0))];
                        }
                    }
                }
                // 2. The patch distance (the column sums over the patch's rows, the image's
                //    ends repeated), its weight times the feature stops, and each half's
                //    sums with the other half's weights.
                const float zscale = params.sigma_depth * float(std::max(std::abs(ox), std::abs(oy)));
#pragma omp for schedule(static)
                for (int y = y0; y < y1; ++y) {
                    const size_t row = size_t(y) * size_t(w);
                    // Signed: q's row start lies before the plane's first pixel where x0 > 0.
                    const ptrdiff_t qrow = ptrdiff_t(row) + off;
                    const float *f0 = p.f[0].data() + row, *f1 = p.f[1].data() + row, *f2 = p.f[2].data() + row,
                                *f3 = p.f[3].data() + row, *q0 = p.f[0].data() + qrow, *q1 = p.f[1].data() + qrow,
                                *q2 = p.f[2].data() + qrow, *q3 = p.f[3].data() + qrow;
                    const float *a0 = p.demod[0].data() + row, *a1 = p.demod[1].data() + row,
                                *a2 = p.demod[2].data() + row, *b0 = p.demod[0].data() + qrow,
                                *b1 = p.demod[1].data() + qrow, *b2 = p.demod[2].data() + qrow;
                    const float *z = p.z.data() + row, *qz = p.z.data() + qrow, *zg = p.zgrad.data() + row;
#pragma omp simd
                    for (int x = x0; x < x1; ++x) {
                        const float fd = f0[x] * q0[x] + f1[x] * q1[x] + f2[x] * q2[x] + f3[x] * q3[x];
                        const float da0 = a0[x] - b0[x], da1 = a1[x] - b1[x], da2 = a2[x] - b2[x];
                        wf[size_t(x)] = params.sigma_normal * std::max(0.f, 1.f - fd) +
                                        (da0 * da0 + da1 * da1 + da2 * da2) * inv_albedo2 +
                                        std::fabs(z[x] - qz[x]) / (zscale * zg[x] + 1e-3f * z[x] + 1e-9f);
                    }
                    for (int g = 0; g < 2; ++g) {
                        const float* rows[16];
                        const int taps = std::min(2 * f + 1, 16);
                        for (int t = 0; t < taps; ++t)
                            rows[t] = p.hbox[g].data() + size_t(std::clamp(y + t - f, y0, y1 - 1)) * size_t(w);
                        // Guide g's weights filter the other half.
                        const int o = 1 - g;
                        float *sr = p.acc[o][0].data() + row, *sg = p.acc[o][1].data() + row,
                              *sb = p.acc[o][2].data() + row, *sw = p.acc[o][3].data() + row;
                        const float *ur = p.u[o][0].data() + qrow, *ug = p.u[o][1].data() + qrow,
                                    *ub = p.u[o][2].data() + qrow;
#pragma omp simd
                        for (int x = x0; x < x1; ++x) {
                            float dist = 0;
                            for (int t = 0; t < taps; ++t) dist += rows[t][x];
                            const float wt = fast_exp_neg(std::max(0.f, dist * inv_patch) + wf[size_t(x)]);
                            sw[x] += wt;
                            sr[x] += wt * ur[x];
                            sg[x] += wt * ug[x];
                            sb[x] += wt * ub[x];
                        }
                    }
                }
            }
    }
}

// A plane's mean over the (2 r + 1)^2 box around each pixel (the image's ends repeated).
void box_mean(int w, int h, int r, const std::vector<float>& in, std::vector<float>& tmp, std::vector<float>& out) {
    tmp.resize(in.size());
    out.resize(in.size());
    const float inv = 1.f / float((2 * r + 1) * (2 * r + 1));
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float s = 0;
            for (int d = -r; d <= r; ++d) s += in[size_t(y) * size_t(w) + size_t(std::clamp(x + d, 0, w - 1))];
            tmp[size_t(y) * size_t(w) + size_t(x)] = s;
        }
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float s = 0;
            for (int d = -r; d <= r; ++d) s += tmp[size_t(std::clamp(y + d, 0, h - 1)) * size_t(w) + size_t(x)];
            out[size_t(y) * size_t(w) + size_t(x)] = s * inv;
        }
}

}  // namespace

Image denoise_nlmeans(const DenoiseInput& input, const NlmParams& params, DenoiseWorkspace* workspace) {
    DenoiseWorkspace local;
    Planes& p = prepared_planes(input, workspace, local);
    Image out(p.w, p.h);
    if (out.pixels.empty()) return out;
    prepare_halves(input, p);
    const int w = p.w, h = p.h;
    const size_t n = out.pixels.size();
    const bool halves = input.half_count[0].size() == n && input.half_count[1].size() == n;
    // Each candidate's image (the halves averaged by their counts) and what it gains over the
    // raw mean: Stein's unbiased risk estimate per half, which a filter linear in the half it
    // filters allows (the weights come from the other half), |F - u|^2 - v + 2 (dF/du) v per
    // channel, dF/du the centre's share of the weights, 1 over their sum, less the raw half's
    // risk v: |F - u|^2 - 2 (1 - dF/du) v. The v is the pixel's own variance (unbiased; the
    // prefiltered one, which the patch distances use, carries bright neighbours' noise into a
    // dark pixel and makes its raw value look as noisy as theirs).
    // The gains are averaged over a box to tame their noise, each first divided by the
    // pixel's squared luminance plus 0.01 (the smaller of the candidate's and the raw one's,
    // in radiance), so that the box compares relative errors, as relMSE does: in absolute
    // terms a few bright noisy pixels outvote the dark ones beside them, whose every sample
    // was dark and which the filter would light with the bright ones' noise.
    const float strengths[2] = {params.k, params.k_weak};
    for (int c = 0; c < 2; ++c) {
        nlm_filter(params, strengths[c], p);
        for (auto& plane : p.cand[c]) plane.resize(n);
        p.own_gain[c].resize(n);
#pragma omp parallel for schedule(static)
        for (long li = 0; li < long(n); ++li) {
            const size_t i = size_t(li);
            const double t = second_half_share(input, halves, i);
            float gain = 0;
            for (int g = 0; g < 2; ++g) {
                const float inv = 1 / p.acc[g][3][i];
                float d2 = 0;
                for (int k = 0; k < 3; ++k) {
                    const float d = p.acc[g][k][i] * inv - p.u[g][k][i];
                    d2 += d * d;
                }
                gain += d2 - 2 * (1 - inv) * p.own_var[g][i];
            }
            float lum_f = 0, lum_raw = 0;
            for (int k = 0; k < 3; ++k) {
                const float f0 = p.acc[0][k][i] / p.acc[0][3][i], f1 = p.acc[1][k][i] / p.acc[1][3][i];
                p.cand[c][k][i] = float(f0 + t * (f1 - f0));
                lum_f += kLum[k] * p.cand[c][k][i] * p.demod[k][i];
                lum_raw += kLum[k] * mean_of_halves(p, k, i, t) * p.demod[k][i];
            }
            // Relative to the luminance (the risks are of the demodulated radiance: times the
            // albedo's square, its channels' mean).
            const float m = std::max(0.f, std::min(lum_f, lum_raw));
            const float a = (p.demod[0][i] + p.demod[1][i] + p.demod[2][i]) / 3;
            p.own_gain[c][i] = gain;
            p.cand[c][3][i] = gain * a * a / (m * m + 0.01f);
        }
        box_mean(w, h, params.select_radius, p.cand[c][3], p.hbox[0], p.hbox[1]);
        std::swap(p.cand[c][3], p.hbox[1]);
    }
    // Per pixel the candidate of the largest estimated gain over the box, or the raw mean
    // where neither gains (a converged or noiseless region). Then the pixel's own samples:
    // - where the box keeps the raw mean but the pixel's own estimate says a filter gains (a
    //   firefly among dark pixels, which the box's dark pixels outvote), that filter;
    // - where the box filters but the result lies more than own_error_stop of the pixel's own
    //   standard errors from its raw mean, the raw mean. By Chebyshev's inequality a mean is
    //   that far from its expectation with probability at most 1 / own_error_stop^2 (about
    //   1e-5, under one pixel of a 256x256 image): such a value is light the neighbours
    //   carried in, not the pixel's. A pixel whose
    //   samples are all alike (all dark: a shadow, or a caustic none of whose few paths hit)
    //   has no standard error to judge by and keeps the box's choice.
    // The raw candidate is the clamped mean, or where nothing was clamped NaN, which
    // remodulate_and_fade reads as the raw radiance, bit for bit.
    const float stop2 = params.own_error_stop * params.own_error_stop;
#pragma omp parallel for schedule(static)
    for (long li = 0; li < long(n); ++li) {
        const size_t i = size_t(li);
        int c = p.cand[1][3][i] < p.cand[0][3][i] ? 1 : 0;
        if (!(p.cand[c][3][i] < 0)) {
            c = 2;
            if (halves) {
                float best = 0;
                for (int o = 0; o < 2; ++o)
                    if (p.own_gain[o][i] < best) {
                        best = p.own_gain[o][i];
                        c = o;
                    }
            }
        } else if (halves && params.own_error_stop > 0) {
            const double t = second_half_share(input, true, i);
            float lum_f = 0, lum_raw = 0, var = 0;
            for (int k = 0; k < 3; ++k) {
                lum_f += kLum[k] * p.cand[c][k][i] * p.demod[k][i];
                lum_raw += kLum[k] * mean_of_halves(p, k, i, t) * p.demod[k][i];
                var += kLum[k] * kLum[k] * float(input.variance[i][k] * p.var_scale);
            }
            if (var > 0 && std::isfinite(var) && (lum_f - lum_raw) * (lum_f - lum_raw) > stop2 * var) c = 2;
        }
        if (c < 2)
            for (int k = 0; k < 3; ++k) p.c[k][i] = p.cand[c][k][i];
        else if (!p.clamped[i])
            p.c[0][i] = NAN;
    }
    remodulate_and_fade(input, params.fade_error, p, out);
    return out;
}

}  // namespace kr
