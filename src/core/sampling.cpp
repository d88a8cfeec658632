#include "core/sampling.h"

#include <algorithm>

namespace kr {

Vec2 sample_concentric_disk(double u1, double u2) {
    // Map to [-1,1]^2, then squares to concentric circles.
    const double a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0;
    if (a == 0 && b == 0) return {0, 0};
    double r, phi;
    if (std::abs(a) > std::abs(b)) {
        r = a;
        phi = (kPi / 4.0) * (b / a);
    } else {
        r = b;
        phi = (kPi / 2.0) - (kPi / 4.0) * (a / b);
    }
    return {r * std::cos(phi), r * std::sin(phi)};
}

Vec3 sample_cosine_hemisphere(double u1, double u2) {
    const Vec2 d = sample_concentric_disk(u1, u2);
    const double z = std::sqrt(std::max(0.0, 1.0 - d.x * d.x - d.y * d.y));
    return {d.x, d.y, z};
}

Vec3 sample_uniform_sphere(double u1, double u2) {
    const double z = 1.0 - 2.0 * u1;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = 2.0 * kPi * u2;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

Vec3 sample_uniform_cone(double u1, double u2, double one_minus_cos_max) {
    // cos(theta) uniform in [cos_max, 1]; 1 - cos = u * (1 - cos_max) keeps precision.
    const double one_minus_cos = u1 * one_minus_cos_max;
    const double sin2 = one_minus_cos * (2.0 - one_minus_cos);
    const double sin_theta = std::sqrt(std::max(0.0, sin2));
    const double phi = 2.0 * kPi * u2;
    return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), 1.0 - one_minus_cos};
}

}  // namespace kr
