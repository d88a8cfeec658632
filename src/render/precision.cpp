#include "render/precision.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

namespace kr {

namespace {

constexpr double kFloatEpsilon = std::numeric_limits<float>::epsilon();
constexpr double kDoubleEpsilon = std::numeric_limits<double>::epsilon();

double norm_l1(const Vec3& v) { return std::abs(v.x) + std::abs(v.y) + std::abs(v.z); }

bool emits(const Color& c) { return c[0] != 0 || c[1] != 0 || c[2] != 0; }

}  // namespace

double near_surface_fraction(const SphereGeom& a, const SphereGeom& b, double tolerance) {
    // The distances from B's centre that count: B's radius give or take the tolerance.
    const double lo = std::max(b.radius - tolerance, 0.0), hi = b.radius + tolerance;
    const double d = length(a.centre - b.centre);
    if (d == 0) return a.radius >= lo && a.radius <= hi ? 1.0 : 0.0;
    // A's points lie at distances |r_a - d| to r_a + d from B's centre, their squares uniform
    // over A's area; the fraction is the overlap's share of that range of squares.
    const double x1 = std::max(lo, std::abs(a.radius - d)), x2 = std::min(hi, a.radius + d);
    if (!(x2 > x1)) return 0.0;
    return std::min(1.0, (x2 - x1) * (x2 + x1) / (4 * a.radius * d));
}

bool float_resolves_gaps(const RenderScene& scene) {
    const std::vector<SphereGeom>& spheres = scene.spheres;
    // The largest 1-norm of a point rays start from or aim at: on a sphere, or a point light.
    double extent = 0;
    for (const SphereGeom& s : spheres) extent = std::max(extent, norm_l1(s.centre) + std::sqrt(3.0) * s.radius);
    for (const PointLight& light : scene.point_lights) extent = std::max(extent, norm_l1(light.position));
    // A shadow segment towards a light is cut short by 64 epsilons of tmax + |o|_1 + |c|_1
    // (blocker B's centre), tmax + |o|_1 at most 3 extents; kFloatShadowEndUlps adds the
    // crossing's own rounding. Double precision's cut, the same in its epsilon, is "on the
    // surface" for both precisions.
    const auto end_tolerance = [&](const SphereGeom& blocker, double epsilon) {
        return kFloatShadowEndUlps * epsilon * (3 * extent + norm_l1(blocker.centre));
    };
    const auto hit_tolerance = [](const SphereGeom& a, const SphereGeom& b) {
        return kFloatHitUlps * kFloatEpsilon * (norm_l1(a.centre) + a.radius + norm_l1(b.centre) + b.radius);
    };

    // A point light within the float lanes' cut of a surface, but off it as double sees it.
    for (const PointLight& light : scene.point_lights) {
        if (!emits(light.intensity)) continue;
        for (const SphereGeom& s : spheres) {
            const double gap = std::abs(length(light.position - s.centre) - s.radius);
            if (gap > end_tolerance(s, kDoubleEpsilon) && gap < end_tolerance(s, kFloatEpsilon)) return false;
        }
    }

    // Pairs of spheres whose surfaces come within a tolerance: a sweep along x over the
    // spheres' boxes grown by the largest tolerance (no pair nearer is missed).
    double margin = 0;
    for (const SphereGeom& s : spheres)
        margin = std::max({margin, end_tolerance(s, kFloatEpsilon), 2 * hit_tolerance(s, s)});
    std::vector<size_t> order(spheres.size());
    std::iota(order.begin(), order.end(), size_t{0});
    std::sort(order.begin(), order.end(), [&](size_t i, size_t j) {
        return spheres[i].centre.x - spheres[i].radius < spheres[j].centre.x - spheres[j].radius;
    });
    const auto emitting = [&](size_t s) {
        const int light = scene.sphere_light.empty() ? -1 : scene.sphere_light[s];
        return light >= 0 && emits(scene.area_lights[size_t(light)].radiance);
    };
    // Whether the pair's near zones stay small: each sphere's within the hit tolerance of the
    // other, and a light's within the end tolerance of any other surface.
    const auto pair_resolved = [&](size_t i, size_t j) {
        const SphereGeom &a = spheres[i], &b = spheres[j];
        const double hit = hit_tolerance(a, b);
        if (near_surface_fraction(a, b, hit) > kFloatNearFraction ||
            near_surface_fraction(b, a, hit) > kFloatNearFraction)
            return false;
        if (emitting(i) && near_surface_fraction(a, b, end_tolerance(b, kFloatEpsilon)) > kFloatNearFraction)
            return false;
        if (emitting(j) && near_surface_fraction(b, a, end_tolerance(a, kFloatEpsilon)) > kFloatNearFraction)
            return false;
        return true;
    };
    for (size_t k = 0; k < order.size(); ++k) {
        const SphereGeom& a = spheres[order[k]];
        const double hi_x = a.centre.x + a.radius + margin;
        for (size_t m = k + 1; m < order.size(); ++m) {
            const SphereGeom& b = spheres[order[m]];
            if (b.centre.x - b.radius > hi_x) break;
            const Vec3 apart = a.centre - b.centre;
            const double reach = a.radius + b.radius + margin;
            if (std::abs(apart.y) > reach || std::abs(apart.z) > reach) continue;
            if (!pair_resolved(order[k], order[m])) return false;
        }
    }
    return true;
}

}  // namespace kr
