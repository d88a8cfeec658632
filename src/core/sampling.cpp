#include "core/sampling.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace kr {

Vec2 sample_concentric_disk(double u1, double u2) {
    // Map to [-1,1]^2, then squares to concentric circles (angles in turns). Written with
    // selects, not branches: which of |a|, |b| is larger is a coin toss per sample.
    const double a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0;
    if (a == 0 && b == 0) return {0, 0};
    const bool a_major = std::abs(a) > std::abs(b);
    const double r = a_major ? a : b;
    const double ratio = (a_major ? b : a) / r;
    const double turns = a_major ? 0.125 * ratio : 0.25 - 0.125 * ratio;
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
