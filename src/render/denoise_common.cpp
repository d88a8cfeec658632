// What both denoisers share (render/denoise_common.h).
#include "render/denoise_common.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/math.h"
#include "core/vectorise.h"
#include "render/lanes/levels.h"

namespace kr::denoising {

namespace {

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


}  // namespace

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

namespace {

// 3x3 binomial blur of a plane (borders renormalised): SVGF's prefilter of the variance
// before it scales the luminance stop. Row y; inside the border the weights sum to 1 exactly
// and the taps are added in the same order, so both loops give the same sums.
KR_LOOP_CLONES
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

}  // namespace

void blur3(int w, int h, const std::vector<float>& v, std::vector<float>& out) {
    out.resize(v.size());
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y) blur3_row(v.data(), out.data(), w, h, y);
}

namespace {

// prepare's per-pixel step, pixels [i0, i1): the demodulated radiance, the variances and
// luminances (demodulated and raw), the unit feature vector and the depth.
KR_LOOP_CLONES
void prepare_pixels(const DenoiseInput& in, DenoiseWorkspace& p, size_t i0, size_t i1) {
    const Color* __restrict rad = in.radiance->pixels.data();
    const Color* __restrict variance = in.variance.data();
    const float *__restrict albedo = in.albedo.data(), *__restrict normal = in.normal.data();
    // In the filter's unit (radiance_unit): the radiance over it, the variance over its square.
    const double inv_unit = 1 / p.unit, var_scale = p.var_scale;
    const double* __restrict depth = in.depth.data();
    DenoiseBasePlanes& b = p.base;
    float *__restrict d0 = b.albedo[0].data(), *__restrict d1 = b.albedo[1].data(), *__restrict d2 = b.albedo[2].data();
    float *__restrict c0 = b.radiance[0].data(), *__restrict c1 = b.radiance[1].data(),
          *__restrict c2 = b.radiance[2].data();
    float *__restrict f0 = b.feature[0].data(), *__restrict f1 = b.feature[1].data(),
          *__restrict f2 = b.feature[2].data(), *__restrict f3 = b.feature[3].data();
    float *__restrict var_out = b.variance.data(), *__restrict raw_var_out = b.raw_variance.data();
    float *__restrict lum = b.luminance.data(), *__restrict raw_lum = b.raw_luminance.data(),
          *__restrict z = b.depth.data();
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
            l += kLum[k] * c[k];  // as the a-trous passes take it from base.radiance
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
KR_LOOP_CLONES
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

void prepare(const DenoiseInput& in, DenoiseWorkspace& p) {
    const Image& rad = *in.radiance;
    p.w = rad.width;
    p.h = rad.height;
    const size_t n = rad.pixels.size();
    if (in.variance.size() != n || in.albedo.size() != 3 * n || in.normal.size() != 3 * n || in.depth.size() != n)
        throw std::invalid_argument("denoise: a feature buffer's size is not the image's");
    p.unit = radiance_unit(rad, p.base.scratch);
    // Divided twice: the square of a unit of 1e200 would overflow.
    p.var_scale = 1 / p.unit / p.unit;
    for (int k = 0; k < 3; ++k) {
        p.base.radiance[k].resize(n);
        p.base.albedo[k].resize(n);
    }
    for (auto& f : p.base.feature) f.resize(n);
    p.base.variance.resize(n);
    p.base.raw_variance.resize(n);
    p.base.depth.resize(n);
    p.base.depth_gradient.resize(n);
    p.base.luminance.resize(n);
    p.base.raw_luminance.resize(n);
    const int w = p.w, h = p.h;
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y) prepare_pixels(in, p, size_t(y) * size_t(w), size_t(y + 1) * size_t(w));
    fill_unknown_variance(w, h, p.base.luminance, p.base.variance);
    fill_unknown_variance(w, h, p.base.raw_luminance, p.base.raw_variance);
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y) depth_gradient_row(p.base.depth.data(), p.base.depth_gradient.data(), w, h, y);
}

}  // namespace

DenoiseWorkspace& prepared_planes(const DenoiseInput& input, DenoiseWorkspace* workspace, DenoiseWorkspace& local) {
    DenoiseWorkspace& p = workspace ? *workspace : local;
    prepare(input, p);
    return p;
}

namespace {

// remodulate_and_fade's pixels [i0, i1).
KR_LOOP_CLONES
void remodulate_and_fade_pixels(const Image& raw, const DenoiseWorkspace& p, const float* raw_var, float t2, Image& out,
                                size_t i0, size_t i1) {
    const DenoiseBasePlanes& b = p.base;
    const double unit = p.unit;
    const float *__restrict c0 = b.radiance[0].data(), *__restrict c1 = b.radiance[1].data(),
                *__restrict c2 = b.radiance[2].data();
    const float *__restrict d0 = b.albedo[0].data(), *__restrict d1 = b.albedo[1].data(),
                *__restrict d2 = b.albedo[2].data();
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

}  // namespace

void remodulate_and_fade(const DenoiseInput& input, float fade_error, DenoiseWorkspace& p, Image& out) {
    std::vector<float>& raw_var = p.base.scratch;
    blur3(p.w, p.h, p.base.raw_variance, raw_var);
    const float t2 = fade_error * fade_error;
    const Image& raw = *input.radiance;
    const size_t w = size_t(p.w);
#pragma omp parallel for schedule(static)
    for (int y = 0; y < p.h; ++y)
        remodulate_and_fade_pixels(raw, p, raw_var.data(), t2, out, size_t(y) * w, size_t(y + 1) * w);
}

}  // namespace kr::denoising
