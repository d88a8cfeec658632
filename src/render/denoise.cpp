#include "render/denoise.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/math.h"

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

// Where a pixel's variance is unknown (one sample): the luminance's variance over its 3x3
// neighbourhood, the variance of one sample where the neighbours are alike.
void fill_unknown_variance(int w, int h, const std::vector<float>& lum, std::vector<float>& var) {
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y)
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

// 3x3 binomial blur of a plane (borders renormalised): SVGF's prefilter of the variance
// before it scales the luminance stop.
void blur3(int w, int h, const std::vector<float>& v, std::vector<float>& out) {
    out.resize(v.size());
    constexpr float k[3] = {0.25f, 0.5f, 0.25f};
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
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
        }
}

void prepare(const DenoiseInput& in, Planes& p) {
    const Image& rad = *in.radiance;
    p.w = rad.width;
    p.h = rad.height;
    const size_t n = rad.pixels.size();
    if (in.variance.size() != 3 * n || in.albedo.size() != 3 * n || in.normal.size() != 3 * n || in.depth.size() != n)
        throw std::invalid_argument("denoise: a feature buffer's size is not the image's");
    for (int k = 0; k < 3; ++k) {
        p.c[k].resize(n);
        p.demod[k].resize(n);
    }
    for (auto& f : p.f) f.resize(n);
    p.var.resize(n);
    p.raw_var.resize(n);
    p.z.resize(n);
    p.zgrad.resize(n);
    std::vector<float>&lum = p.lum, &raw_lum = p.lum_raw;
    lum.resize(n);
    raw_lum.resize(n);
    const long count = long(n);
#pragma omp parallel for schedule(static)
    for (long li = 0; li < count; ++li) {
        const size_t i = size_t(li);
        float var = 0, raw_var = 0, l = 0, raw_l = 0;
        for (int k = 0; k < 3; ++k) {
            // Demodulation: the illumination is the radiance over the albedo.
            const float d = std::max(0.f, in.albedo[3 * i + size_t(k)]) + kAlbedoFloor;
            const float r = float(rad.pixels[i][k]);
            const float v = in.variance[3 * i + size_t(k)];
            p.demod[k][i] = d;
            p.c[k][i] = r / d;
            var += kLum[k] * kLum[k] * v / (d * d);
            raw_var += kLum[k] * kLum[k] * v;
            l += kLum[k] * r / d;
            raw_l += kLum[k] * r;
        }
        p.var[i] = std::isfinite(var) ? var : INFINITY;
        p.raw_var[i] = std::isfinite(raw_var) ? raw_var : INFINITY;
        lum[i] = l;
        raw_lum[i] = raw_l;
        // The feature vector: the averaged normal and how much of the pixel saw nothing.
        const float nx = in.normal[3 * i], ny = in.normal[3 * i + 1], nz = in.normal[3 * i + 2];
        const float len = std::sqrt(nx * nx + ny * ny + nz * nz);
        const float miss = std::max(0.f, 1.f - len);
        const float norm = std::sqrt(len * len + miss * miss);
        const float inv = norm > 0 ? 1 / norm : 0;
        p.f[0][i] = nx * inv;
        p.f[1][i] = ny * inv;
        p.f[2][i] = nz * inv;
        p.f[3][i] = norm > 0 ? miss * inv : 1;
        p.z[i] = float(in.depth[i]);
    }
    fill_unknown_variance(p.w, p.h, lum, p.var);
    fill_unknown_variance(p.w, p.h, raw_lum, p.raw_var);
    // The depth gradient: per axis the smaller one-sided difference (the smooth side at a
    // silhouette), summed over the axes so that any 3x3 tap's change on a plane stays below it.
    const int w = p.w, h = p.h;
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t i = size_t(y) * size_t(w) + size_t(x);
            auto side = [&](int dx, int dy) {
                const int xx = x + dx, yy = y + dy;
                if (xx < 0 || yy < 0 || xx >= w || yy >= h) return INFINITY;
                return std::fabs(p.z[size_t(yy) * size_t(w) + size_t(xx)] - p.z[i]);
            };
            float gx = std::min(side(-1, 0), side(1, 0)), gy = std::min(side(0, -1), side(0, 1));
            if (!std::isfinite(gx)) gx = 0;
            if (!std::isfinite(gy)) gy = 0;
            p.zgrad[i] = gx + gy;
        }
}

// One tap of an a-trous pass along a row: pixels [x0, x1) of the row at p, their taps at
// p + off. Compiled for AVX2 too where GCC can dispatch on the CPU (twice the lanes).
struct TapRow {
    const float *lum, *z, *inv_l, *inv_z, *f[4], *c[3], *var;
    float *sw, *sc[3], *sv;
};
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("avx2", "default")))
#endif
void add_tap(const TapRow& r, ptrdiff_t off, int x0, int x1, float tap, float sigma_normal) {
    const float *l = r.lum, *ql = r.lum + off, *z = r.z, *qz = r.z + off, *il = r.inv_l, *iz = r.inv_z;
    const float *f0 = r.f[0], *f1 = r.f[1], *f2 = r.f[2], *f3 = r.f[3];
    const float *q0 = f0 + off, *q1 = f1 + off, *q2 = f2 + off, *q3 = f3 + off;
    const float *qr = r.c[0] + off, *qg = r.c[1] + off, *qb = r.c[2] + off, *qv = r.var + off;
    float *aw = r.sw, *ar = r.sc[0], *ag = r.sc[1], *ab = r.sc[2], *av = r.sv;
#pragma omp simd
    for (int x = x0; x < x1; ++x) {
        // The edge stops, summed in one exponent.
        const float el = std::fabs(l[x] - ql[x]) * il[x];
        const float ez = std::fabs(z[x] - qz[x]) * iz[x];
        const float fd = f0[x] * q0[x] + f1[x] * q1[x] + f2[x] * q2[x] + f3[x] * q3[x];
        const float en = sigma_normal * std::max(0.f, 1.f - fd);
        const float wt = tap * fast_exp_neg(el + ez + en);
        aw[x] += wt;
        ar[x] += wt * qr[x];
        ag[x] += wt * qg[x];
        ab[x] += wt * qb[x];
        av[x] += wt * wt * qv[x];
    }
}

}  // namespace

Image denoise_atrous(const DenoiseInput& input, const AtrousParams& params, DenoiseWorkspace* workspace) {
    DenoiseWorkspace local;
    Planes& p = workspace ? *workspace : local;
    prepare(input, p);
    const int w = p.w, h = p.h;
    const size_t n = size_t(w) * size_t(h);
    Image out(w, h);
    if (n == 0) return out;
    std::vector<float>(&c2)[3] = p.c2;
    std::vector<float>&var2 = p.var2, &inv_l = p.inv_l, &inv_z = p.inv_z, &lum = p.lum, &var_blur = p.var_blur;
    for (auto* plane : {&c2[0], &c2[1], &c2[2], &var2, &inv_l, &inv_z, &lum}) plane->resize(n);
    constexpr float kTap[3] = {0.25f, 0.5f, 0.25f};
    blur3(w, h, p.var, var_blur);
    // One team of threads for every pass (each loop ends at a barrier).
#pragma omp parallel
    {
        const size_t row_len = size_t(w);
        std::vector<float> sw(row_len), sr(row_len), sg(row_len), sb(row_len), sv(row_len);
        for (int it = 0; it < params.iterations; ++it) {
            const int step = 1 << it;
            // Per pixel, the stops' scales for this pass: the luminance's by the standard
            // deviation (the first pass's variance 3x3-prefiltered; later passes' is filtered
            // already), the depth's by the gradient over the step.
            const float* var = it == 0 ? var_blur.data() : p.var.data();
            const float gate = params.sigma_luminance > 0 ? 1.f : 0.f, zscale = params.sigma_depth * float(step);
            const float *c0 = p.c[0].data(), *c1 = p.c[1].data(), *cb = p.c[2].data(), *zg = p.zgrad.data(),
                        *zz = p.z.data();
            float *lo = lum.data(), *ilo = inv_l.data(), *izo = inv_z.data();
#pragma omp for simd schedule(static)
            for (long i = 0; i < long(n); ++i) {
                lo[i] = kLum[0] * c0[i] + kLum[1] * c1[i] + kLum[2] * cb[i];
                const float sd = std::sqrt(std::max(0.f, var[i]));
                ilo[i] = gate / (params.sigma_luminance * sd + 1e-12f);
                izo[i] = 1 / (zscale * zg[i] + 1e-3f * zz[i] + 1e-9f);
            }
#pragma omp for schedule(static)
            for (int y = 0; y < h; ++y) {
                std::fill(sw.begin(), sw.end(), 0.f);
                std::fill(sr.begin(), sr.end(), 0.f);
                std::fill(sg.begin(), sg.end(), 0.f);
                std::fill(sb.begin(), sb.end(), 0.f);
                std::fill(sv.begin(), sv.end(), 0.f);
                const size_t row = size_t(y) * size_t(w);
                const TapRow r{lum.data() + row,
                               p.z.data() + row,
                               inv_l.data() + row,
                               inv_z.data() + row,
                               {p.f[0].data() + row, p.f[1].data() + row, p.f[2].data() + row, p.f[3].data() + row},
                               {p.c[0].data() + row, p.c[1].data() + row, p.c[2].data() + row},
                               p.var.data() + row,
                               sw.data(),
                               {sr.data(), sg.data(), sb.data()},
                               sv.data()};
                for (int ty = -1; ty <= 1; ++ty) {
                    const int yy = y + ty * step;
                    if (yy < 0 || yy >= h) continue;
                    for (int tx = -1; tx <= 1; ++tx) {
                        const int dx = tx * step;
                        // The tap's pixels within the image: x + dx in [0, w).
                        add_tap(r, (ptrdiff_t(yy) - y) * w + dx, std::max(0, -dx), std::min(w, w - dx),
                                kTap[tx + 1] * kTap[ty + 1], params.sigma_normal);
                    }
                }
                // The centre tap always counts, so the weights' sum is at least 1/4.
                float *o0 = c2[0].data() + row, *o1 = c2[1].data() + row, *o2 = c2[2].data() + row,
                      *ov = var2.data() + row;
#pragma omp simd
                for (size_t x = 0; x < row_len; ++x) {
                    const float inv = 1 / sw[x];
                    o0[x] = sr[x] * inv;
                    o1[x] = sg[x] * inv;
                    o2[x] = sb[x] * inv;
                    ov[x] = sv[x] * inv * inv;
                }
            }
#pragma omp single
            {
                for (int k = 0; k < 3; ++k) std::swap(p.c[k], c2[k]);
                std::swap(p.var, var2);
            }
        }
    }
    // Remodulate, then fade towards the raw radiance as its relative standard error drops
    // (the 3x3-prefiltered raw variance against the filtered luminance).
    std::vector<float>& raw_var = p.var_blur;
    blur3(w, h, p.raw_var, raw_var);
    const float t2 = params.fade_error * params.fade_error;
    const Image& raw = *input.radiance;
    const long count = long(n);
#pragma omp parallel for schedule(static)
    for (long li = 0; li < count; ++li) {
        const size_t i = size_t(li);
        const Color filtered{double(p.c[0][i] * p.demod[0][i]), double(p.c[1][i] * p.demod[1][i]),
                             double(p.c[2][i] * p.demod[2][i])};
        const double l = std::max(luminance(filtered), 0.0);
        double blend = 1;
        if (t2 > 0) {
            const double r2 = l > 0 ? raw_var[i] / (l * l) : (raw_var[i] > 0 ? INFINITY : 0.0);
            blend = std::isfinite(r2) ? r2 / (r2 + t2) : 1.0;
        }
        out.pixels[i] = raw.pixels[i] + blend * (filtered - raw.pixels[i]);
    }
    return out;
}

}  // namespace kr
