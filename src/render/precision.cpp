#include "render/precision.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

#include "render/lanes/vertex.h"

namespace kr {

namespace {

constexpr double kFloatEpsilon = std::numeric_limits<float>::epsilon();
constexpr double kDoubleEpsilon = std::numeric_limits<double>::epsilon();

double norm_l1(const Vec3& v) { return std::abs(v.x) + std::abs(v.y) + std::abs(v.z); }

bool emits(const Color& c) { return c[0] != 0 || c[1] != 0 || c[2] != 0; }

// An axis-aligned box of points rays can reach (float_reach_fits); empty until a point is added.
struct ReachBox {
    double lo[3] = {kInfinity, kInfinity, kInfinity}, hi[3] = {-kInfinity, -kInfinity, -kInfinity};

    static ReachBox around(const Vec3& centre, double half) {
        ReachBox b;
        for (int k = 0; k < 3; ++k) b.lo[k] = centre[k] - half, b.hi[k] = centre[k] + half;
        return b;
    }
    bool empty() const { return !(lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2]); }
    void add(const ReachBox& b) {
        for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], b.lo[k]), hi[k] = std::max(hi[k], b.hi[k]);
    }
    bool holds(const ReachBox& b) const {
        for (int k = 0; k < 3; ++k)
            if (b.lo[k] < lo[k] || b.hi[k] > hi[k]) return false;
        return true;
    }
    // This box grown by `by` on every side, clipped to `clip`.
    ReachBox grown_within(double by, const ReachBox& clip) const {
        ReachBox b;
        for (int k = 0; k < 3; ++k) b.lo[k] = std::max(lo[k] - by, clip.lo[k]), b.hi[k] = std::min(hi[k] + by, clip.hi[k]);
        return b;
    }
    // The farthest and the nearest distance of its points from p.
    double farthest(const Vec3& p) const {
        double sum = 0;
        for (int k = 0; k < 3; ++k) {
            const double d = std::max(std::abs(p[k] - lo[k]), std::abs(p[k] - hi[k]));
            sum += d * d;
        }
        return std::sqrt(sum);
    }
    double nearest(const Vec3& p) const {
        double sum = 0;
        for (int k = 0; k < 3; ++k) {
            const double d = std::max({lo[k] - p[k], p[k] - hi[k], 0.0});
            sum += d * d;
        }
        return std::sqrt(sum);
    }
};

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
    for (const RenderLight& light : scene.lights)
        if (vertex::light_kind(light.type).at_point) extent = std::max(extent, norm_l1(light.position));
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
    for (const RenderLight& light : scene.lights) {
        if (!vertex::light_kind(light.type).at_point || !emits(light.power)) continue;
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
        return light >= 0 && emits(scene.lights[size_t(light)].power);
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

bool float_sizes_fit(const RenderScene& scene) {
    // Every distance a test meets is within the scene's: the camera's (its lens included) and
    // the spheres' from the origin, as rays start at the camera or on a sphere.
    double largest = length(scene.camera.position) + std::max(scene.camera.lens_radius, 0.0);
    double smallest_radius = kInfinity;
    for (const SphereGeom& s : scene.spheres) {
        largest = std::max(largest, length(s.centre) + s.radius);
        smallest_radius = std::min(smallest_radius, s.radius);
    }
    if (!(std::isfinite(largest) && smallest_radius > 0)) return false;
    return largest <= kFloatSizeRatio * smallest_radius || float_reach_fits(scene);
}

bool float_reach_fits(const RenderScene& scene) {
    const std::vector<SphereGeom>& spheres = scene.spheres;
    const size_t n = spheres.size();
    const CameraModel& camera = scene.camera;
    const ReachBox lens = ReachBox::around(camera.position, std::max(camera.lens_radius, 0.0));
    // Where rays start or end outside the spheres: the lens and the point lights.
    ReachBox fixed_points = lens;
    for (const RenderLight& light : scene.lights)
        if (vertex::light_kind(light.type).at_point) fixed_points.add(ReachBox::around(light.position, 0));
    if (fixed_points.empty()) return false;  // a NaN position
    // Per sphere: its box, whether it counts whole, and the part rays reach so far.
    std::vector<ReachBox> box(n), reach(n);
    std::vector<char> whole(n);
    for (size_t s = 0; s < n; ++s) {
        box[s] = ReachBox::around(spheres[s].centre, spheres[s].radius);
        const int m = s < scene.sphere_material.size() ? scene.sphere_material[s] : -1;
        // Rays enter a material that transmits (a Fresnel split, vertex.inc's material_lobes).
        const bool enters = m < 0 || size_t(m) >= scene.materials.size() ||
                            vertex::material_lobes(scene.materials[size_t(m)].type).fresnel_split;
        const bool emitter = s < scene.sphere_light.size() && scene.sphere_light[s] >= 0;
        // The lens within (or touching) the ball: rays start inside it.
        const bool lens_inside = !(lens.nearest(spheres[s].centre) > spheres[s].radius);
        whole[s] = enters || emitter || lens_inside;
        if (whole[s]) reach[s] = box[s];
    }
    // The box of every reach but sphere s's: per side, the farthest value and the one after
    // it, with the sphere that gives the farthest (-1: the fixed points).
    struct Side {
        double best, next;
        long which;
    };
    Side low[3], high[3];
    // Rounds until no box grows. Each round's boxes only grow and stay within the spheres'
    // boxes; a scene that does not settle in kRounds keeps the global rule's answer (no).
    constexpr int kRounds = 64;
    bool settled = false;
    for (int round = 0; round < kRounds && !settled; ++round) {
        for (int k = 0; k < 3; ++k) {
            low[k] = {fixed_points.lo[k], kInfinity, -1};
            high[k] = {fixed_points.hi[k], -kInfinity, -1};
        }
        for (size_t s = 0; s < n; ++s) {
            if (reach[s].empty()) continue;
            for (int k = 0; k < 3; ++k) {
                const double lo = reach[s].lo[k], hi = reach[s].hi[k];
                if (lo < low[k].best) low[k] = {lo, low[k].best, long(s)};
                else low[k].next = std::min(low[k].next, lo);
                if (hi > high[k].best) high[k] = {hi, high[k].best, long(s)};
                else high[k].next = std::max(high[k].next, hi);
            }
        }
        settled = true;
        for (size_t s = 0; s < n; ++s) {
            if (whole[s]) continue;
            ReachBox others;
            for (int k = 0; k < 3; ++k) {
                others.lo[k] = low[k].which == long(s) ? std::min(low[k].next, fixed_points.lo[k]) : low[k].best;
                others.hi[k] = high[k].which == long(s) ? std::max(high[k].next, fixed_points.hi[k]) : high[k].best;
            }
            const SphereGeom& sphere = spheres[s];
            // Every origin outside the ball lies within `far` of its centre, and sees its
            // surface no farther than the tangent length.
            const double far = others.farthest(sphere.centre);
            const double tangent = std::sqrt(std::max(far * far - sphere.radius * sphere.radius, 0.0));
            const ReachBox reached = others.grown_within(tangent, box[s]);
            if (reached.empty() || reach[s].holds(reached)) continue;
            reach[s].add(reached);
            settled = false;
        }
    }
    if (!settled) return false;
    ReachBox all = fixed_points;
    for (const ReachBox& r : reach)
        if (!r.empty()) all.add(r);
    const double from_origin = all.farthest(Vec3(0));
    for (const SphereGeom& s : spheres) {
        const double limit = kFloatSizeRatio * s.radius;
        if (!(from_origin <= limit && length(s.centre) + s.radius <= limit && all.farthest(s.centre) <= limit))
            return false;
    }
    return true;
}

}  // namespace kr
