// The final denoiser, joint non-local means over the two halves of the samples
// (render/denoise.h).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/math.h"
#include "render/denoise.h"
#include "render/denoise_common.h"

namespace kr {

using namespace denoising;

namespace {

// Whether neighbouring pixels i and j see the same surface: normals within about 25 degrees,
// albedos within 0.1, depths within twice the local gradient (a pixel is its own).
bool same_surface(const DenoiseWorkspace& p, size_t i, size_t j) {
    float fd = 0, da = 0;
    for (int k = 0; k < 3; ++k) {
        const float d = p.base.albedo[k][i] - p.base.albedo[k][j];
        da += d * d;
    }
    for (const auto& f : p.base.feature) fd += f[i] * f[j];
    return i == j ||
           (fd > 0.9f && da < 0.01f &&
            std::fabs(p.base.depth[i] - p.base.depth[j]) <= 2 * (p.base.depth_gradient[i] + 1e-3f * p.base.depth[i]));
}

// The second half's weight in pixel i's mean: its share of the samples where both halves have
// some, else 1/2 (prepare_halves then gives both halves the mean itself). 1/2 without halves.
double second_half_share(const DenoiseInput& in, bool halves, size_t i) {
    if (!halves) return 0.5;
    const double n0 = in.half_count[0][i], n1 = in.half_count[1][i];
    return n0 > 0 && n1 > 0 ? n1 / (n0 + n1) : 0.5;
}

// Channel k of pixel i's demodulated mean from its halves (t: second_half_share).
float mean_of_halves(const DenoiseWorkspace& p, int k, size_t i, double t) {
    return float(p.nlm.half_radiance[0][k][i] + t * (p.nlm.half_radiance[1][k][i] - p.nlm.half_radiance[0][k][i]));
}

// The guides of the final filter: per half g, the demodulated radiance (nlm.half_radiance[g])
// and the variance of its mean (nlm.half_variance[g], 3x3-prefiltered). A pixel without two non-empty halves takes the mean for
// both, with the mean's variance.
void prepare_halves(const DenoiseInput& in, DenoiseWorkspace& p) {
    const size_t n = size_t(p.w) * size_t(p.h);
    for (int g = 0; g < 2; ++g)
        for (int k = 0; k < 3; ++k) {
            p.nlm.half_radiance[g][k].resize(n);
            p.nlm.half_variance[g][k].resize(n);
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
                const float d = p.base.albedo[k][i];
                const double r = split ? in.half[g]->pixels[i][k] : in.radiance->pixels[i][k];
                const float v = float(in.variance[i][k] * p.var_scale * share) / (d * d);
                p.nlm.half_radiance[g][k][i] = float(r * inv_unit) / d;  // as prepare_pixels takes it
                p.nlm.half_variance[g][k][i] = std::isfinite(v) ? v : INFINITY;
            }
        }
    }
    for (int g = 0; g < 2; ++g) {
        p.nlm.own_variance[g].assign(n, 0.f);
        for (int k = 0; k < 3; ++k) {
            fill_unknown_variance(p.w, p.h, p.nlm.half_radiance[g][k], p.nlm.half_variance[g][k]);
            // The pixel's own variance, before the prefilter spreads its neighbours' into it:
            // the one Stein's risk estimate asks for (denoise_nlmeans).
            for (size_t i = 0; i < n; ++i) p.nlm.own_variance[g][i] += p.nlm.half_variance[g][k][i];
            blur3(p.w, p.h, p.nlm.half_variance[g][k], p.base.scratch);
            std::swap(p.nlm.half_variance[g][k], p.base.scratch);
        }
    }
    p.clamped.assign(n, 0);
    if (!halves) return;
    // Fireflies: a rare bright sample lands in one half only, so each half's value is clamped
    // to the range of the other half's 3x3 neighbourhood on the same surface (a highlight is
    // in both halves and stays; a pixel across an edge would widen the range on one side).
    // Biased, as the a-trous filter's luminance stop is, for far less error.
    for (int k = 0; k < 3; ++k) {
        std::vector<float>& clamped = p.base.scratch;
        for (int g = 0; g < 2; ++g) {
            const std::vector<float>&mine = p.nlm.half_radiance[g][k], &other = p.nlm.half_radiance[1 - g][k];
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
            // Both halves are clamped against the other's unclamped values: the clamped ones
            // wait in nlm.sums[0], then become the halves' radiance, and nlm.sums[0] keeps the
            // unclamped ones for the comparison below.
            std::swap(p.nlm.sums[0][g][k], clamped);
        }
        for (int g = 0; g < 2; ++g) std::swap(p.nlm.half_radiance[g][k], p.nlm.sums[0][g][k]);
    }
    // The raw candidate of a pixel whose halves were clamped is their clamped mean.
    p.clamped.assign(n, 0);
    const long count2 = long(n);
#pragma omp parallel for schedule(static)
    for (long li = 0; li < count2; ++li) {
        const size_t i = size_t(li);
        bool changed = false;
        for (int g = 0; g < 2; ++g)
            for (int k = 0; k < 3; ++k) changed |= p.nlm.half_radiance[g][k][i] != p.nlm.sums[0][g][k][i];
        if (!changed) continue;
        p.clamped[i] = 1;
        const double t = second_half_share(in, true, i);
        for (int k = 0; k < 3; ++k) p.base.radiance[k][i] = mean_of_halves(p, k, i, t);
    }
}

// One guide's patch distance terms along a row, for the pixels [x0, x1) of the row at `at`
// against those at `at + off` (Rousselle et al. 2012): per channel the squared difference
// less its expected noise, over the variance of the difference (plus a guard), summed. A
// candidate's distance scale k divides it by k^2 later.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
__attribute__((target_clones("avx2", "default")))
#endif
void patch_terms(const float* const u[3], const float* const v[3], size_t at, ptrdiff_t off, int x0, int x1,
                 float* out) {
    for (int x = x0; x < x1; ++x) out[x] = 0;
    for (int c = 0; c < 3; ++c) {
        const float *up = u[c] + at, *uq = u[c] + at + off, *vp = v[c] + at, *vq = v[c] + at + off;
#pragma omp simd
        for (int x = x0; x < x1; ++x) {
            const float d = up[x] - uq[x];
            const float noise = vp[x] + std::min(vp[x], vq[x]);
            out[x] += (d * d - noise) / (1e-10f + vp[x] + vq[x]);
        }
    }
}


// The candidates made: the first params.candidate_count, at least one.
int candidates_made(const NlmParams& params) { return std::clamp(params.candidate_count, 1, kMaxNlmCandidates); }

// The candidates' non-local means filters of both halves, in one sweep over the window's
// offsets (the patch distances are taken once; a candidate scales them by 1/k^2):
// p.nlm.sums[c][g] gets half g's sums with candidate c's weights from the other half, and
// their weights (the centre's is 1).
void nlm_filter(const NlmParams& params, DenoiseWorkspace& p) {
    const int w = p.w, h = p.h;
    const size_t n = size_t(w) * size_t(h);
    const int count = candidates_made(params);
    for (int g = 0; g < 2; ++g) p.nlm.distance[g].assign(n, 0.f);
    for (int c = 0; c < count; ++c)
        for (auto& half : p.nlm.sums[c])
            for (auto& plane : half) plane.assign(n, 0.f);
    const int r = std::max(0, params.radius), f = std::max(0, params.patch);
    const float inv_patch = 1.f / float((2 * f + 1) * (2 * f + 1));
    const float inv_albedo2 = 1.f / (params.sigma_albedo * params.sigma_albedo);
    float inv_k2[kMaxNlmCandidates], sigma_normal[kMaxNlmCandidates];
    for (int c = 0; c < count; ++c) {
        inv_k2[c] = 1 / (params.candidates[c].k * params.candidates[c].k);
        sigma_normal[c] = params.candidates[c].sigma_normal;
    }
#pragma omp parallel
    {
        std::vector<float> terms(static_cast<size_t>(w)), normal_term(static_cast<size_t>(w)),
            other_terms(static_cast<size_t>(w)), distance(static_cast<size_t>(w));
        for (int oy = -r; oy <= r; ++oy)
            for (int ox = -r; ox <= r; ++ox) {
                // The pixels whose offset neighbour q = p + (ox, oy) lies in the image.
                const int x0 = std::max(0, -ox), x1 = std::min(w, w - ox), y0 = std::max(0, -oy),
                          y1 = std::min(h, h - oy);
                if (x0 >= x1 || y0 >= y1) continue;
                const ptrdiff_t off = ptrdiff_t(oy) * w + ox;
                // 1. Per guide, the distance terms of each pixel, summed over the patch's
                //    columns (running sums; the row's ends repeat its first and last term).
#pragma omp for schedule(static)
                for (int y = y0; y < y1; ++y) {
                    const size_t row = size_t(y) * size_t(w);
                    for (int g = 0; g < 2; ++g) {
                        const float* const u[3] = {p.nlm.half_radiance[g][0].data(), p.nlm.half_radiance[g][1].data(),
                                                   p.nlm.half_radiance[g][2].data()};
                        const float* const v[3] = {p.nlm.half_variance[g][0].data(), p.nlm.half_variance[g][1].data(),
                                                   p.nlm.half_variance[g][2].data()};
                        patch_terms(u, v, row, off, x0, x1, terms.data());
                        float* hb = p.nlm.distance[g].data() + row;
                        float sum = 0;
                        for (int dx = -f; dx <= f; ++dx) sum += terms[size_t(std::clamp(x0 + dx, x0, x1 - 1))];
                        for (int x = x0; x < x1; ++x) {
                            hb[x] = sum;
                            sum += terms[size_t(std::min(x + f + 1, x1 - 1))] - terms[size_t(std::max(x - f, x0))];
                        }
                    }
                }
                // 2. The patch distance (the column sums over the patch's rows, the image's
                //    ends repeated), the feature stops, and per candidate its weight and each
                //    half's sums with the other half's weights.
                const float zscale = params.sigma_depth * float(std::max(std::abs(ox), std::abs(oy)));
#pragma omp for schedule(static)
                for (int y = y0; y < y1; ++y) {
                    const size_t row = size_t(y) * size_t(w);
                    // Signed: q's row start lies before the plane's first pixel where x0 > 0.
                    const ptrdiff_t qrow = ptrdiff_t(row) + off;
                    const float *f0 = p.base.feature[0].data() + row, *f1 = p.base.feature[1].data() + row,
                                *f2 = p.base.feature[2].data() + row, *f3 = p.base.feature[3].data() + row,
                                *q0 = p.base.feature[0].data() + qrow, *q1 = p.base.feature[1].data() + qrow,
                                *q2 = p.base.feature[2].data() + qrow, *q3 = p.base.feature[3].data() + qrow;
                    const float *a0 = p.base.albedo[0].data() + row, *a1 = p.base.albedo[1].data() + row,
                                *a2 = p.base.albedo[2].data() + row, *b0 = p.base.albedo[0].data() + qrow,
                                *b1 = p.base.albedo[1].data() + qrow, *b2 = p.base.albedo[2].data() + qrow;
                    const float *z = p.base.depth.data() + row, *qz = p.base.depth.data() + qrow,
                                *zg = p.base.depth_gradient.data() + row;
#pragma omp simd
                    for (int x = x0; x < x1; ++x) {
                        const float fd = f0[x] * q0[x] + f1[x] * q1[x] + f2[x] * q2[x] + f3[x] * q3[x];
                        const float da0 = a0[x] - b0[x], da1 = a1[x] - b1[x], da2 = a2[x] - b2[x];
                        normal_term[size_t(x)] = std::max(0.f, 1.f - fd);
                        other_terms[size_t(x)] = (da0 * da0 + da1 * da1 + da2 * da2) * inv_albedo2 +
                                                 std::fabs(z[x] - qz[x]) / (zscale * zg[x] + 1e-3f * z[x] + 1e-9f);
                    }
                    for (int g = 0; g < 2; ++g) {
                        const float* rows[16];
                        const int taps = std::min(2 * f + 1, 16);
                        for (int t = 0; t < taps; ++t)
                            rows[t] = p.nlm.distance[g].data() + size_t(std::clamp(y + t - f, y0, y1 - 1)) * size_t(w);
#pragma omp simd
                        for (int x = x0; x < x1; ++x) {
                            float dist = 0;
                            for (int t = 0; t < taps; ++t) dist += rows[t][x];
                            distance[size_t(x)] = std::max(0.f, dist * inv_patch);
                        }
                        // Guide g's weights filter the other half.
                        const int o = 1 - g;
                        const float *ur = p.nlm.half_radiance[o][0].data() + qrow,
                                    *ug = p.nlm.half_radiance[o][1].data() + qrow,
                                    *ub = p.nlm.half_radiance[o][2].data() + qrow;
                        for (int c = 0; c < count; ++c) {
                            float *sr = p.nlm.sums[c][o][0].data() + row, *sg = p.nlm.sums[c][o][1].data() + row,
                                  *sb = p.nlm.sums[c][o][2].data() + row, *sw = p.nlm.sums[c][o][3].data() + row;
                            const float scale = inv_k2[c], stop = sigma_normal[c];
#pragma omp simd
                            for (int x = x0; x < x1; ++x) {
                                const float wt = fast_exp_neg(distance[size_t(x)] * scale + stop * normal_term[size_t(x)] +
                                                              other_terms[size_t(x)]);
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
    DenoiseWorkspace& p = prepared_planes(input, workspace, local);
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
    const int count = candidates_made(params);
    nlm_filter(params, p);
    for (int c = 0; c < count; ++c) {
        const auto& sums = p.nlm.sums[c];
        for (auto& plane : p.nlm.candidate[c]) plane.resize(n);
        p.nlm.own_gain[c].resize(n);
#pragma omp parallel for schedule(static)
        for (long li = 0; li < long(n); ++li) {
            const size_t i = size_t(li);
            const double t = second_half_share(input, halves, i);
            float gain = 0;
            for (int g = 0; g < 2; ++g) {
                const float inv = 1 / sums[g][3][i];
                float d2 = 0;
                for (int k = 0; k < 3; ++k) {
                    const float d = sums[g][k][i] * inv - p.nlm.half_radiance[g][k][i];
                    d2 += d * d;
                }
                gain += d2 - 2 * (1 - inv) * p.nlm.own_variance[g][i];
            }
            float lum_f = 0, lum_raw = 0;
            for (int k = 0; k < 3; ++k) {
                const float f0 = sums[0][k][i] / sums[0][3][i],
                            f1 = sums[1][k][i] / sums[1][3][i];
                p.nlm.candidate[c][k][i] = float(f0 + t * (f1 - f0));
                lum_f += kLum[k] * p.nlm.candidate[c][k][i] * p.base.albedo[k][i];
                lum_raw += kLum[k] * mean_of_halves(p, k, i, t) * p.base.albedo[k][i];
            }
            // Relative to the luminance (the risks are of the demodulated radiance: times the
            // albedo's square, its channels' mean).
            const float m = std::max(0.f, std::min(lum_f, lum_raw));
            const float a = (p.base.albedo[0][i] + p.base.albedo[1][i] + p.base.albedo[2][i]) / 3;
            p.nlm.own_gain[c][i] = gain;
            p.nlm.candidate[c][3][i] = gain * a * a / (m * m + 0.01f);
        }
        box_mean(w, h, params.select_radius, p.nlm.candidate[c][3], p.nlm.distance[0], p.nlm.distance[1]);
        std::swap(p.nlm.candidate[c][3], p.nlm.distance[1]);
    }
    // Per pixel the candidate of the largest estimated gain over the box, or the raw mean
    // where none gains (a converged or noiseless region). Then the pixel's own samples:
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
    constexpr int kRaw = -1;
#pragma omp parallel for schedule(static)
    for (long li = 0; li < long(n); ++li) {
        const size_t i = size_t(li);
        int c = 0;
        for (int o = 1; o < count; ++o)
            if (p.nlm.candidate[o][3][i] < p.nlm.candidate[c][3][i]) c = o;
        if (!(p.nlm.candidate[c][3][i] < 0)) {
            c = kRaw;
            if (halves) {
                float best = 0;
                for (int o = 0; o < count; ++o)
                    if (p.nlm.own_gain[o][i] < best) {
                        best = p.nlm.own_gain[o][i];
                        c = o;
                    }
            }
        } else if (halves && params.own_error_stop > 0) {
            const double t = second_half_share(input, true, i);
            float lum_f = 0, lum_raw = 0, var = 0;
            for (int k = 0; k < 3; ++k) {
                lum_f += kLum[k] * p.nlm.candidate[c][k][i] * p.base.albedo[k][i];
                lum_raw += kLum[k] * mean_of_halves(p, k, i, t) * p.base.albedo[k][i];
                var += kLum[k] * kLum[k] * float(input.variance[i][k] * p.var_scale);
            }
            if (var > 0 && std::isfinite(var) && (lum_f - lum_raw) * (lum_f - lum_raw) > stop2 * var) c = kRaw;
        }
        if (c != kRaw)
            for (int k = 0; k < 3; ++k) p.base.radiance[k][i] = p.nlm.candidate[c][k][i];
        else if (!p.clamped[i])
            p.base.radiance[0][i] = NAN;
    }
    remodulate_and_fade(input, params.fade_error, p, out);
    return out;
}

}  // namespace kr
