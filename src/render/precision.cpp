#include "render/precision.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
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

    // Pairs of spheres whose surfaces come within a tolerance, found in a uniform grid over
    // the spheres' boxes grown by half the largest tolerance (no pair nearer is missed).
    double margin = 0;
    for (const SphereGeom& s : spheres)
        margin = std::max({margin, end_tolerance(s, kFloatEpsilon), 2 * hit_tolerance(s, s)});
    const auto emitting = [&](size_t s) {
        const int light = scene.sphere_light.empty() ? -1 : scene.sphere_light[s];
        return light >= 0 && emits(scene.area_lights[size_t(light)].radiance);
    };
    // Whether the pair's near zones stay small: each sphere's within the hit tolerance of the
    // other, and a light's within the end tolerance of any other surface.
    const auto pair_resolved = [&](size_t i, size_t j) {
        const SphereGeom &a = spheres[i], &b = spheres[j];
        const Vec3 apart = a.centre - b.centre;
        const double reach = a.radius + b.radius + margin;
        if (std::abs(apart.x) > reach || std::abs(apart.y) > reach || std::abs(apart.z) > reach) return true;
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
    // Cells of twice the median radius (plus the margin); a sphere whose grown box spans
    // more than 4 cells on an axis (the brief's walls) is paired with every other sphere.
    std::vector<double> radii;
    for (const SphereGeom& s : spheres) radii.push_back(s.radius);
    if (radii.empty()) return true;
    std::nth_element(radii.begin(), radii.begin() + ptrdiff_t(radii.size() / 2), radii.end());
    const double cell = 2 * radii[radii.size() / 2] + margin;
    const auto cell_of = [&](double x) { return int64_t(std::floor(x / cell)); };
    // Cell indices a double counts exactly (and an int64_t holds): beyond them a sphere is
    // paired with all, as a large one is.
    const auto countable = [&](const Vec3& v) {
        constexpr double kLargest = 0x1.0p52;
        return std::abs(v.x / cell) < kLargest && std::abs(v.y / cell) < kLargest && std::abs(v.z / cell) < kLargest;
    };
    struct Key {
        int64_t x, y, z;
        bool operator==(const Key&) const = default;
    };
    struct KeyHash {
        size_t operator()(const Key& k) const {
            return size_t(uint64_t(k.x) * 0x9E3779B97F4A7C15ull ^ uint64_t(k.y) * 0xC2B2AE3D27D4EB4Full ^
                          uint64_t(k.z) * 0x165667B19E3779F9ull);
        }
    };
    std::unordered_map<Key, std::vector<size_t>, KeyHash> grid;
    std::vector<size_t> large;
    const auto lower = [&](const SphereGeom& s) { return s.centre - Vec3(s.radius + margin / 2); };
    const auto upper = [&](const SphereGeom& s) { return s.centre + Vec3(s.radius + margin / 2); };
    for (size_t i = 0; i < spheres.size(); ++i) {
        const Vec3 lo = lower(spheres[i]), hi = upper(spheres[i]);
        if (!countable(lo) || !countable(hi)) {
            large.push_back(i);
            continue;
        }
        const int64_t x0 = cell_of(lo.x), y0 = cell_of(lo.y), z0 = cell_of(lo.z);
        const int64_t x1 = cell_of(hi.x), y1 = cell_of(hi.y), z1 = cell_of(hi.z);
        if (!(x1 - x0 < 4 && y1 - y0 < 4 && z1 - z0 < 4)) {
            large.push_back(i);
            continue;
        }
        for (int64_t x = x0; x <= x1; ++x)
            for (int64_t y = y0; y <= y1; ++y)
                for (int64_t z = z0; z <= z1; ++z) grid[{x, y, z}].push_back(i);
    }
    // Each pair of small spheres once: in the cell holding the lower corner of their boxes'
    // overlap.
    for (const auto& [key, members] : grid)
        for (size_t m = 0; m < members.size(); ++m)
            for (size_t n = m + 1; n < members.size(); ++n) {
                const SphereGeom &a = spheres[members[m]], &b = spheres[members[n]];
                const Vec3 la = lower(a), lb = lower(b);
                const Key first{cell_of(std::max(la.x, lb.x)), cell_of(std::max(la.y, lb.y)),
                                cell_of(std::max(la.z, lb.z))};
                if (first == key && !pair_resolved(members[m], members[n])) return false;
            }
    // The large spheres with every other (two large ones once).
    std::vector<char> is_large(spheres.size(), 0);
    for (size_t i : large) is_large[i] = 1;
    for (size_t i : large)
        for (size_t j = 0; j < spheres.size(); ++j)
            if (j != i && !(is_large[j] && j < i) && !pair_resolved(i, j)) return false;
    return true;
}

}  // namespace kr
