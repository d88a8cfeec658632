#include "core/sampling.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace kr {

void sin_cos_turns(double t, double& sin_out, double& cos_out) {
    // t = k/4 + r with |r| <= 1/8 turn, so the angle x = 2 pi r lies in [-pi/4, pi/4].
    const double quarter = std::nearbyint(4.0 * t);
    const double x = 2.0 * kPi * (t - 0.25 * quarter);
    const double x2 = x * x;
    // Taylor series to x^15 / x^16: the first omitted term is below 3e-16 at pi/4.
    const double s = x * (1 + x2 * (-1.0 / 6 + x2 * (1.0 / 120 + x2 * (-1.0 / 5040 + x2 * (1.0 / 362880 +
                     x2 * (-1.0 / 39916800 + x2 * (1.0 / 6227020800 + x2 * (-1.0 / 1307674368000))))))));
    const double c = 1 + x2 * (-1.0 / 2 + x2 * (1.0 / 24 + x2 * (-1.0 / 720 + x2 * (1.0 / 40320 +
                     x2 * (-1.0 / 3628800 + x2 * (1.0 / 479001600 + x2 * (-1.0 / 87178291200 +
                     x2 * (1.0 / 20922789888000))))))));
    // Rotate by k quarter turns.
    switch (static_cast<int64_t>(quarter) & 3) {
        case 0: sin_out = s; cos_out = c; break;
        case 1: sin_out = c; cos_out = -s; break;
        case 2: sin_out = -s; cos_out = -c; break;
        default: sin_out = -c; cos_out = s; break;
    }
}

Vec2 sample_concentric_disk(double u1, double u2) {
    // Map to [-1,1]^2, then squares to concentric circles (angles in turns).
    const double a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0;
    if (a == 0 && b == 0) return {0, 0};
    double r, turns;
    if (std::abs(a) > std::abs(b)) {
        r = a;
        turns = 0.125 * (b / a);
    } else {
        r = b;
        turns = 0.25 - 0.125 * (a / b);
    }
    double s, c;
    sin_cos_turns(turns, s, c);
    return {r * c, r * s};
}

Vec3 sample_cosine_hemisphere(double u1, double u2) {
    const Vec2 d = sample_concentric_disk(u1, u2);
    const double z = std::sqrt(std::max(0.0, 1.0 - d.x * d.x - d.y * d.y));
    return {d.x, d.y, z};
}

Vec3 sample_uniform_sphere(double u1, double u2) {
    const double z = 1.0 - 2.0 * u1;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    double s, c;
    sin_cos_turns(u2, s, c);
    return {r * c, r * s, z};
}

Vec3 sample_uniform_cone(double u1, double u2, double one_minus_cos_max) {
    // cos(theta) uniform in [cos_max, 1]; 1 - cos = u * (1 - cos_max) keeps precision.
    const double one_minus_cos = u1 * one_minus_cos_max;
    const double sin2 = one_minus_cos * (2.0 - one_minus_cos);
    const double sin_theta = std::sqrt(std::max(0.0, sin2));
    double s, c;
    sin_cos_turns(u2, s, c);
    return {sin_theta * c, sin_theta * s, 1.0 - one_minus_cos};
}

}  // namespace kr
