// Sampling routines. Each maps uniform variates in [0,1)^2 to a distribution and,
// where the integrators need it, gives that distribution's density.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "core/math.h"

namespace kr {

struct Vec2 {
    double x = 0, y = 0;
};

// sin and cos of 2 pi t, the step of sin_cos_turns that works on one double and on SIMD lanes
// (GCC vector extensions, render/lanes/) alike: t = quarter/4 + r with |r| <= 1/8 turn,
// and (s, c) = (sin, cos)(2 pi r) by Taylor polynomials. Forced inline: lanes must not cross
// a call (render/lanes/lanes.h).
template <class T>
inline __attribute__((always_inline)) void sin_cos_eighth_turn(T t, T& quarter, T& s, T& c) {
    // Nearest integer by adding and removing 1.5 * 2^52, exact for |4t| < 2^51 (ties to even):
    // std::nearbyint is a libm call on baseline x86-64, which has no rounding instruction.
    constexpr double kRoundingShift = 0x1.8p52;
    quarter = (4.0 * t + kRoundingShift) - kRoundingShift;
    const T x = 2.0 * kPi * (t - 0.25 * quarter);  // in [-pi/4, pi/4]
    const T x2 = x * x;
    // Taylor series to x^15 / x^16: the first omitted term is below 3e-16 at pi/4.
    s = x * (1 + x2 * (-1.0 / 6 + x2 * (1.0 / 120 + x2 * (-1.0 / 5040 + x2 * (1.0 / 362880 +
        x2 * (-1.0 / 39916800 + x2 * (1.0 / 6227020800 + x2 * (-1.0 / 1307674368000))))))));
    c = 1 + x2 * (-1.0 / 2 + x2 * (1.0 / 24 + x2 * (-1.0 / 720 + x2 * (1.0 / 40320 +
        x2 * (-1.0 / 3628800 + x2 * (1.0 / 479001600 + x2 * (-1.0 / 87178291200 +
        x2 * (1.0 / 20922789888000))))))));
}

// sin and cos of 2 pi t (t in turns), to about 1e-15: reduced to an eighth of a turn and
// evaluated by Taylor polynomials. The samplers call it for every direction; libm's general
// sincos was a tenth of the render time.
// Inline and without branches: the quarter turn is random per sample, so a switch on it
// mispredicts three times in four.
inline void sin_cos_turns(double t, double& sin_out, double& cos_out) {
    double quarter, s, c;
    sin_cos_eighth_turn(t, quarter, s, c);
    // Rotate by k quarter turns: (sin, cos) -> (s, c), (c, -s), (-s, -c), (-c, s).
    const int64_t k = static_cast<int64_t>(quarter) & 3;
    const bool odd = k & 1;
    const double sin_mag = odd ? c : s, cos_mag = odd ? s : c;
    sin_out = (k & 2) ? -sin_mag : sin_mag;
    cos_out = ((k + 1) & 2) ? -cos_mag : cos_mag;
}

// Natural logarithm of a positive, finite, normal x, within about 1 ulp, for one double (U =
// uint64_t) and for SIMD lanes (U: the lanes' bits as unsigned integers) alike: the brief
// light sampler takes one per shading point, and libm's is a call per lane. Other inputs
// give garbage: callers check the range (log_positive below).
template <class T, class U>
inline __attribute__((always_inline)) T log_normal_positive(T x) {
    // x = 2^k m with m in [sqrt(1/2), sqrt(2)): offsetting the bits by those of sqrt(1/2)
    // puts k + 1023 in the exponent field without a comparison (as musl's log does).
    constexpr uint64_t kSqrtHalfBits = 0x3fe6a09e667f3bcdull, kMantissa = (1ull << 52) - 1;
    U bits;
    __builtin_memcpy(&bits, &x, sizeof bits);
    bits += 0x3ff0000000000000ull - kSqrtHalfBits;
    U k_bits = (bits >> 52) + (0x4338000000000000ull - 1023);  // the bits of 1.5 * 2^52 + k
    bits = (bits & kMantissa) + kSqrtHalfBits;
    T m, k;
    __builtin_memcpy(&m, &bits, sizeof m);
    __builtin_memcpy(&k, &k_bits, sizeof k);
    k = k - 0x1.8p52;
    // log m = 2 atanh(s) = 2s + s tail, s = (m - 1) / (m + 1), |s| <= 0.1716: the odd series
    // to s^21, whose first omitted term is below 1e-17 of the sum.
    const T f = m - 1.0;
    const T s = f / (m + 1.0);
    const T s2 = s * s;
    const T tail = s2 * (2.0 / 3 + s2 * (2.0 / 5 + s2 * (2.0 / 7 + s2 * (2.0 / 9 + s2 * (2.0 / 11 +
                   s2 * (2.0 / 13 + s2 * (2.0 / 15 + s2 * (2.0 / 17 + s2 * (2.0 / 19 + s2 * (2.0 / 21))))))))));
    // k ln 2 in two parts, the first with trailing zero bits so that k times it is exact.
    constexpr double kLn2High = 0x1.62e42fee00000p-1, kLn2Low = 0x1.a39ef35793c76p-33;
    // 2s = f - s f, so log m = f - s (f - tail): f is exact and the rest a small correction.
    return k * kLn2High + (f - (s * (f - tail) - k * kLn2Low));
}
// log_normal_positive's range.
inline constexpr double kSmallestNormal = std::numeric_limits<double>::min();
inline constexpr double kLargestFinite = std::numeric_limits<double>::max();
// One double: log_normal_positive in its range, libm outside it (0, subnormals, infinity,
// NaN and negatives keep their libm answers).
inline double log_positive(double x) {
    return x >= kSmallestNormal && x <= kLargestFinite ? log_normal_positive<double, uint64_t>(x) : std::log(x);
}

// Cosine-weighted direction about +z (Malley: concentric disk lifted to the hemisphere).
Vec3 sample_cosine_hemisphere(double u1, double u2);
inline double cosine_hemisphere_pdf(double cos_theta) { return cos_theta > 0 ? cos_theta * kInvPi : 0; }

// Uniform direction on the unit sphere.
Vec3 sample_uniform_sphere(double u1, double u2);
inline constexpr double uniform_sphere_pdf() { return 1.0 / (4.0 * kPi); }

// Uniform point on the unit disk (Shirley-Chiu concentric map: low distortion for strata).
Vec2 sample_concentric_disk(double u1, double u2);

// Uniform direction in the cone about +z with half-angle theta_max, given
// one_minus_cos_max = 1 - cos(theta_max) (passed directly: it is tiny for far lights and
// 1 - cos would cancel).
Vec3 sample_uniform_cone(double u1, double u2, double one_minus_cos_max);
inline double uniform_cone_pdf(double one_minus_cos_max) {
    return 1.0 / (2.0 * kPi * one_minus_cos_max);
}

// The brief's perturbation (eq. 2): a uniform point on the sphere of radius beta.
inline Vec3 perturbation(double beta, double u1, double u2) { return beta * sample_uniform_sphere(u1, u2); }

// Brief's eq. 2: mirror (or refracted) direction perturbed by roughness beta, renormalised.
inline Vec3 perturb_direction(const Vec3& dir, double beta, double u1, double u2) {
    if (beta <= 0) return dir;
    return normalize(dir + perturbation(beta, u1, u2));
}

}  // namespace kr
