// Small double-precision vector maths shared by the whole renderer.
#pragma once

#include <algorithm>
#include <cmath>

namespace kr {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInvPi = 1.0 / kPi;

struct Vec3 {
    double x = 0, y = 0, z = 0;

    constexpr Vec3() = default;
    constexpr Vec3(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}
    constexpr explicit Vec3(double v) : x(v), y(v), z(v) {}

    constexpr double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    constexpr Vec3& operator+=(const Vec3& b) { x += b.x; y += b.y; z += b.z; return *this; }
    constexpr Vec3& operator-=(const Vec3& b) { x -= b.x; y -= b.y; z -= b.z; return *this; }
    constexpr Vec3& operator*=(const Vec3& b) { x *= b.x; y *= b.y; z *= b.z; return *this; }
    constexpr Vec3& operator*=(double s) { x *= s; y *= s; z *= s; return *this; }
    constexpr Vec3& operator/=(double s) { return *this *= (1.0 / s); }
    constexpr bool operator==(const Vec3& b) const { return x == b.x && y == b.y && z == b.z; }
    constexpr bool operator!=(const Vec3& b) const { return !(*this == b); }
};

// Colours are RGB triples of radiance (or reflectance); same arithmetic.
using Color = Vec3;

constexpr Vec3 operator+(Vec3 a, const Vec3& b) { return a += b; }
constexpr Vec3 operator-(Vec3 a, const Vec3& b) { return a -= b; }
constexpr Vec3 operator*(Vec3 a, const Vec3& b) { return a *= b; }
constexpr Vec3 operator*(Vec3 a, double s) { return a *= s; }
constexpr Vec3 operator*(double s, Vec3 a) { return a *= s; }
constexpr Vec3 operator/(Vec3 a, double s) { return a /= s; }

constexpr double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double length(const Vec3& a) { return std::sqrt(dot(a, a)); }
inline Vec3 normalize(const Vec3& a) { return a / length(a); }
constexpr double max_component(const Vec3& a) { return std::max(a.x, std::max(a.y, a.z)); }
constexpr double max_abs_component(const Vec3& a) {
    return std::max(std::abs(a.x), std::max(std::abs(a.y), std::abs(a.z)));
}
constexpr double luminance(const Color& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }
constexpr bool is_black(const Color& c) { return c.x == 0 && c.y == 0 && c.z == 0; }
inline bool is_finite(const Vec3& a) {
    return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}

// Orthonormal basis around a unit vector n (Duff et al. 2017, branchless, no NaN at the poles).
struct Frame {
    Vec3 s, t, n;

    static Frame from_normal(const Vec3& n) {
        const double sign = std::copysign(1.0, n.z);
        const double a = -1.0 / (sign + n.z);
        const double b = n.x * n.y * a;
        return {Vec3(1 + sign * n.x * n.x * a, sign * b, -sign * n.x),
                Vec3(b, sign + n.y * n.y * a, -n.y), n};
    }
    Vec3 to_world(const Vec3& v) const { return s * v.x + t * v.y + n * v.z; }
    Vec3 to_local(const Vec3& v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
};

// Mirror reflection of the incident direction wi (pointing towards the surface) about n.
inline Vec3 reflect(const Vec3& wi, const Vec3& n) { return wi - 2.0 * dot(wi, n) * n; }

// Unpolarised Fresnel reflectance of a dielectric interface (exact, not Schlick).
// cos_i >= 0 on the incident side; eta_ratio = eta_incident / eta_transmitted.
inline double fresnel_dielectric(double cos_i, double eta_ratio) {
    cos_i = std::clamp(cos_i, 0.0, 1.0);
    const double sin2_t = eta_ratio * eta_ratio * (1.0 - cos_i * cos_i);
    if (sin2_t >= 1.0) return 1.0;  // total internal reflection
    const double cos_t = std::sqrt(1.0 - sin2_t);
    const double r_s = (eta_ratio * cos_i - cos_t) / (eta_ratio * cos_i + cos_t);
    const double r_p = (cos_i - eta_ratio * cos_t) / (cos_i + eta_ratio * cos_t);
    return 0.5 * (r_s * r_s + r_p * r_p);
}

}  // namespace kr
