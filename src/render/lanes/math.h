// The lanes' types and maths, for kernels.cpp (included there, in the target's namespace,
// compiled for its CPU level): four doubles, eight or sixteen floats, 3-vectors of lanes, and
// lane-wise copies of core's sampling maths, operation for operation; with them the lanes are
// vertex.h's lane type (Lanes, at the end).
#pragma once

// The target's lanes (CMake names the target: KR_LANE_TARGET_<id>, targets.h): four doubles,
// or (KR_LANES_FLOAT) eight floats for x86-64-v3 or (with KR_LANES_V4) sixteen for x86-64-v4,
// with masks and indices as integers of the same width, and 32-bit words for the Sobol
// numbers. KR_LANES_V3: the x86-64-v3 forms of the few steps GCC's vector extensions have no
// good form for; KR_LANES_V4: the AVX-512 ones.
#include <limits>

#include "render/lanes/lanes.h"

constexpr double kInf = std::numeric_limits<double>::infinity();

#if defined(KR_LANE_TARGET_x86_64_v4_float)
#define KR_LANES_FLOAT 1
#define KR_LANES_V4 1
#elif defined(KR_LANE_TARGET_x86_64_v3_float)
#define KR_LANES_FLOAT 1
#define KR_LANES_V3 1
#elif defined(KR_LANE_TARGET_x86_64_v3)
#define KR_LANES_V3 1
#endif
#if defined(KR_LANES_V4)
using real = float;
using lane_int = int32_t;
typedef float vf __attribute__((vector_size(64)));
typedef int32_t vm __attribute__((vector_size(64)));
typedef uint32_t vw __attribute__((vector_size(64)));
constexpr int kLanes = 16;
#elif defined(KR_LANES_FLOAT)
using real = float;
using lane_int = int32_t;
typedef float vf __attribute__((vector_size(32)));
typedef int32_t vm __attribute__((vector_size(32)));
typedef uint32_t vw __attribute__((vector_size(32)));
constexpr int kLanes = 8;
#else
using real = double;
using lane_int = int64_t;
using vf = v4d;
using vm = v4l;
typedef uint32_t vw __attribute__((vector_size(16)));
constexpr int kLanes = 4;
#endif
static_assert(sizeof(vf) == sizeof(vm) && sizeof(vf) == kLanes * sizeof(real));

KR_LANES vf splat(double x) { return vf{} + real(x); }
KR_LANES vf select(vm mask, vf a, vf b) { return mask ? a : b; }
KR_LANES vf sqrt_lanes(vf x) {
#if defined(KR_LANES_V4)
    return _mm512_maskz_sqrt_ps(0xffff, x);  // (the unmasked form's undefined start warns in GCC 12)
#elif defined(KR_LANES_FLOAT)
    return _mm256_sqrt_ps(x);
#else
    return kr::sqrt_lanes(x);
#endif
}

#if defined(KR_LANES_V4)
// Whether any lane of a mask is set: one vptestmd into a mask register, tested.
KR_LANES bool any_lane(vm mask) {
    __m512i bits;
    __builtin_memcpy(&bits, &mask, sizeof bits);
    return _mm512_test_epi32_mask(bits, bits) != 0;
}
#elif defined(KR_LANES_V3)
// Whether any lane of a mask is set, by one vptest (lanes.h's any_lane reduces the lanes in
// five instructions).
KR_LANES bool any_lane(vm mask) {
    __m256i bits;
    __builtin_memcpy(&bits, &mask, sizeof bits);
    return !_mm256_testz_si256(bits, bits);
}
#endif

// A mask's lanes as bits (lane k at bit k), for loops over its set lanes only.
KR_LANES unsigned lane_bits(vm mask) {
#if defined(KR_LANES_V4)
    __m512i bits;
    __builtin_memcpy(&bits, &mask, sizeof bits);
    return _mm512_test_epi32_mask(bits, bits);
#elif defined(KR_LANES_FLOAT)
    __m256 bits;
    __builtin_memcpy(&bits, &mask, sizeof bits);
    return unsigned(_mm256_movemask_ps(bits));  // masks are all ones or zeros: their sign bits
#elif defined(KR_LANES_V3)
    __m256d bits;
    __builtin_memcpy(&bits, &mask, sizeof bits);
    return unsigned(_mm256_movemask_pd(bits));
#else
    unsigned bits = 0;
    for (int k = 0; k < kLanes; ++k) bits |= unsigned(mask[k] != 0) << k;
    return bits;
#endif
}

KR_LANES vf abs_lanes(vf x) { return select(x < 0, -x, x); }
// a * b + c rounded once where GCC builds the target with fused multiply-adds (x86-64-v3 and
// v4), as it contracts such sums elsewhere; written out where a sum must not depend on whether
// GCC finds the product in the sum's block (kernels.cpp, the path loop's stages). The x86-64
// target has no fused form, and Clang builds the levels unfused (CMakeLists.txt): a * b + c.
KR_LANES vf mul_add_lanes(vf a, vf b, vf c) {
#if defined(__clang__)
    return a * b + c;
#elif defined(KR_LANES_V4)
    return _mm512_fmadd_ps(a, b, c);
#elif defined(KR_LANES_FLOAT)
    return _mm256_fmadd_ps(a, b, c);
#elif defined(KR_LANES_V3)
    return _mm256_fmadd_pd(a, b, c);
#else
    return a * b + c;
#endif
}
KR_LANES vm sign_bit(vf x) {  // all ones where x is negative (-0 included)
    vm bits;
    __builtin_memcpy(&bits, &x, sizeof bits);
    return bits < 0;
}

// Three lane vectors: a 3-vector per lane.
struct V3 {
    vf x, y, z;
};
KR_LANES V3 operator+(const V3& a, const V3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
KR_LANES V3 operator-(const V3& a, const V3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
KR_LANES V3 operator*(const V3& a, vf s) { return {a.x * s, a.y * s, a.z * s}; }
KR_LANES V3 operator*(const V3& a, const V3& b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
KR_LANES V3 operator-(const V3& a) { return {-a.x, -a.y, -a.z}; }
KR_LANES V3 mul_add_lanes(const V3& a, vf b, const V3& c) {
    return {mul_add_lanes(a.x, b, c.x), mul_add_lanes(a.y, b, c.y), mul_add_lanes(a.z, b, c.z)};
}
KR_LANES vf dot(const V3& a, const V3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
KR_LANES V3 select(vm mask, const V3& a, const V3& b) {
    return {select(mask, a.x, b.x), select(mask, a.y, b.y), select(mask, a.z, b.z)};
}
KR_LANES Vec3 lane(const V3& v, int k) { return {v.x[k], v.y[k], v.z[k]}; }
KR_LANES void set_lane(V3& v, int k, const Vec3& value) { v.x[k] = value.x, v.y[k] = value.y, v.z[k] = value.z; }

// ---- Lane-wise copies of the one-path routines, operation for operation ----

// sin_cos_turns (core/sampling.h): the same reduction and polynomials, then the quarter
// turns lane-wise.
#ifdef KR_LANES_FLOAT
// sin_cos_eighth_turn in single precision: rounding by 1.5 * 2^23, and the Taylor polynomials
// to x^9 and x^10, whose first omitted terms are below 3e-8 at pi/4.
KR_LANES void sin_cos_eighth_turn(vf t, vf& quarter, vf& s, vf& c) {
    constexpr float kRoundingShift = 0x1.8p23f;
    quarter = (4.0f * t + kRoundingShift) - kRoundingShift;
    const vf x = float(2 * kPi) * (t - 0.25f * quarter);
    const vf x2 = x * x;
    s = x * (1 + x2 * (float(-1.0 / 6) + x2 * (float(1.0 / 120) + x2 * (float(-1.0 / 5040) + x2 * float(1.0 / 362880)))));
    c = 1 + x2 * (-0.5f + x2 * (float(1.0 / 24) + x2 * (float(-1.0 / 720) + x2 * (float(1.0 / 40320) +
        x2 * float(-1.0 / 3628800)))));
}
#endif
KR_LANES void sin_cos_turns_lanes(vf t, vf& sin_out, vf& cos_out) {
    vf quarter, s, c;
    sin_cos_eighth_turn(t, quarter, s, c);
    const vm k = __builtin_convertvector(quarter, vm) & 3;
    const vm odd = (k & 1) != 0;
    const vf sin_mag = select(odd, c, s), cos_mag = select(odd, s, c);
    sin_out = select((k & 2) != 0, -sin_mag, sin_mag);
    cos_out = select(((k + 1) & 2) != 0, -cos_mag, cos_mag);
}

// sample_concentric_disk (core/sampling.cpp).
KR_LANES void concentric_disk_lanes(vf u1, vf u2, vf& x, vf& y) {
    const vf a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0;
    const vm centre = (a == 0) & (b == 0);
    const vm a_major = abs_lanes(a) > abs_lanes(b);
    const vf r = select(a_major, a, b);
    const vf ratio = select(a_major, b, a) / r;
    const vf turns = select(a_major, 0.125 * ratio, 0.25 - 0.125 * ratio);
    vf s, c;
    sin_cos_turns_lanes(turns, s, c);
    x = select(centre, vf{}, r * c), y = select(centre, vf{}, r * s);
}

// sample_cosine_hemisphere (core/sampling.cpp): the concentric disk lifted to the hemisphere.
KR_LANES V3 cosine_hemisphere_lanes(vf u1, vf u2) {
    vf x, y;
    concentric_disk_lanes(u1, u2, x, y);
    const vf one_minus = 1.0 - x * x - y * y;
    return {x, y, sqrt_lanes(select(one_minus > 0, one_minus, vf{}))};
}

// Frame::from_normal(n).to_world(local) (core/math.h).
KR_LANES V3 to_world_lanes(const V3& n, const V3& local) {
    const vf sign = select(sign_bit(n.z), splat(-1.0), splat(1.0));
    const vf a = -1.0 / (sign + n.z);
    const vf b = n.x * n.y * a;
    const V3 s{1 + sign * n.x * n.x * a, sign * b, -sign * n.x};
    const V3 t{b, sign + n.y * n.y * a, -n.y};
    return s * local.x + t * local.y + n * local.z;
}

// log_normal_positive (core/sampling.h) of the lanes: a positive, finite, normal x.
KR_LANES vf log_lanes(vf x) {
#ifdef KR_LANES_FLOAT
    // The same steps in single precision: x = 2^k m with m in [sqrt(1/2), sqrt(2)), then
    // log m = f - s (f - tail) with s = (m - 1) / (m + 1), the odd series to s^9 (its first
    // omitted term is below 1e-9 of the sum), and k ln 2.
    constexpr int32_t kSqrtHalfBits = 0x3f3504f3, kMantissa = (1 << 23) - 1;
    vm bits;
    __builtin_memcpy(&bits, &x, sizeof bits);
    bits += 0x3f800000 - kSqrtHalfBits;
    const vf k = __builtin_convertvector((bits >> 23) - 127, vf);
    bits = (bits & kMantissa) + kSqrtHalfBits;
    vf m;
    __builtin_memcpy(&m, &bits, sizeof m);
    const vf f = m - 1.0f;
    const vf s = f / (m + 1.0f);
    const vf s2 = s * s;
    const vf tail = s2 * (float(2.0 / 3) + s2 * (0.4f + s2 * (float(2.0 / 7) + s2 * float(2.0 / 9))));
    return k * float(0x1.62e42fefa39efp-1) + (f - s * (f - tail));  // ln 2
#else
    return log_normal_positive<vf, v4u>(x);
#endif
}

// log_positive (core/sampling.h) in `lanes`: log_lanes in its range, libm outside it.
KR_LANES vf log_positive_lanes(vf x, vm lanes) {
    const vm normal = (x >= std::numeric_limits<real>::min()) & (x <= std::numeric_limits<real>::max());
    vf log = log_lanes(select(normal, x, splat(1.0)));
    if (any_lane(lanes & ~normal))
        for (int k = 0; k < kLanes; ++k)
            if (lanes[k] && !normal[k]) log[k] = std::log(x[k]);
    return log;
}

// std::expm1 of the lanes in `lanes`. The double lanes call it lane by lane, as one path
// does. The float ones, for x <= 0 (BriefProposal's only use): x = k ln 2 + r with |r| <=
// ln 2 / 2, expm1(r) by its Taylor polynomial to r^7 (the first omitted term is below 2e-8
// relative), then 2^k expm1(r) + (2^k - 1), exact but for the last rounding where k is 0.
KR_LANES vf expm1_lanes(vf x, vm lanes) {
#ifdef KR_LANES_FLOAT
    (void)lanes;
    constexpr float kRoundingShift = 0x1.8p23f;
    const vf clamped = select(x < -87.0f, splat(-87.0), x);  // 2^k stays normal; expm1 is -1 there
    const vf k = (clamped * float(1.0 / 0x1.62e42fefa39efp-1) + kRoundingShift) - kRoundingShift;  // 1 / ln 2
    // r = x - k ln 2, with ln 2 in two parts whose first times k is exact
    const vf r = (clamped - k * 0x1.62e400p-1f) - k * float(0x1.62e42fefa39efp-1 - 0x1.62e400p-1);
    const vf r2 = r * r;
    const vf p = r + r2 * (0.5f + r * (float(1.0 / 6) + r * (float(1.0 / 24) + r * (float(1.0 / 120) +
                 r * (float(1.0 / 720) + r * float(1.0 / 5040))))));
    const vm exponent = (__builtin_convertvector(k, vm) + 127) << 23;
    vf scale;
    __builtin_memcpy(&scale, &exponent, sizeof scale);
    return scale * p + (scale - 1.0f);
#else
    vf out = x;
    for (unsigned left = lane_bits(lanes); left != 0; left &= left - 1) {
        const int k = __builtin_ctz(left);
        out[k] = std::expm1(x[k]);
    }
    return out;
#endif
}

// sample_uniform_sphere (core/sampling.cpp).
KR_LANES V3 uniform_sphere_lanes(vf u1, vf u2) {
    const vf z = 1.0 - 2.0 * u1;
    const vf one_minus = 1.0 - z * z;
    const vf r = sqrt_lanes(select(0.0 < one_minus, one_minus, vf{}));
    vf s, c;
    sin_cos_turns_lanes(u2, s, c);
    return {r * c, r * s, z};
}

// sample_uniform_cone (core/sampling.cpp).
KR_LANES V3 uniform_cone_lanes(vf u1, vf u2, vf one_minus_cos_max) {
    const vf one_minus_cos = u1 * one_minus_cos_max;
    const vf sin2 = one_minus_cos * (2.0 - one_minus_cos);
    const vf sin_theta = sqrt_lanes(select(0.0 < sin2, sin2, vf{}));
    vf s, c;
    sin_cos_turns_lanes(u2, s, c);
    return {sin_theta * c, sin_theta * s, 1.0 - one_minus_cos};
}

KR_LANES V3 normalize_lanes(const V3& a) {  // normalize (core/math.h): a / length(a)
    const vf length = sqrt_lanes(dot(a, a));
    return {a.x / length, a.y / length, a.z / length};
}

// The lanes as vertex.h's lane type: its physics (materials, light samples, MIS, Russian
// roulette) runs on these, the same code one path runs on doubles.
struct Lanes {
    using Real = vf;
    using Scalar = real;
    using Mask = vm;
    using Vec = V3;
    using Index = vm;
    static constexpr int kWidth = kLanes;
    static KR_LANES vm index(int i) { return vm{} + lane_int(i); }
    static KR_LANES vf splat(double x) { return vf{} + real(x); }
    static KR_LANES vf select(vm m, vf a, vf b) { return m ? a : b; }
    static KR_LANES vm select(vm m, vm a, vm b) { return m ? a : b; }
    static KR_LANES V3 select(vm m, const V3& a, const V3& b) {
        return {m ? a.x : b.x, m ? a.y : b.y, m ? a.z : b.z};
    }
    static KR_LANES bool any(vm m) { return any_lane(m); }
    static KR_LANES vm mask_not(vm m) { return ~m; }
    static KR_LANES vf sqrt(vf x) { return sqrt_lanes(x); }
    static KR_LANES real lane(vf x, int k) { return x[k]; }
    static KR_LANES void set_lane(vf& x, int k, double value) { x[k] = value; }
    static KR_LANES unsigned bits(vm m) { return lane_bits(m); }
    static KR_LANES void sin_cos_turns(vf t, vf& s, vf& c) { sin_cos_turns_lanes(t, s, c); }
    static KR_LANES void concentric_disk(vf u1, vf u2, vf& x, vf& y) { concentric_disk_lanes(u1, u2, x, y); }
    static KR_LANES V3 cosine_hemisphere(vf u1, vf u2) { return cosine_hemisphere_lanes(u1, u2); }
    static KR_LANES V3 uniform_sphere(vf u1, vf u2) { return uniform_sphere_lanes(u1, u2); }
    static KR_LANES V3 uniform_cone(vf u1, vf u2, vf one_minus_cos_max) {
        return uniform_cone_lanes(u1, u2, one_minus_cos_max);
    }
    static KR_LANES V3 to_world(const V3& n, const V3& local) { return to_world_lanes(n, local); }
    static KR_LANES V3 normalize(const V3& a) { return normalize_lanes(a); }
    static KR_LANES vf log_positive(vf x, vm lanes) { return log_positive_lanes(x, lanes); }
    static KR_LANES vf expm1(vf x, vm lanes) { return expm1_lanes(x, lanes); }
};
