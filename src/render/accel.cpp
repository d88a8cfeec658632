#include "render/accel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/module.h"
#include "render/lanes/lanes.h"
#include "render/lanes/levels.h"
#include "render/render_scene.h"

namespace kr {

namespace {

constexpr int kBins = 16;
// Sets of up to this many spheres (four blocks) are leaves, larger ones always split. Testing
// the blocks of a small set is cheaper than the box tests that would cull some of them: walls
// are spheres with huge boxes that every ray enters (docs/performance.md, "Ray casting: one
// leaf, blocks of four, culls": scene 6 as a tree against one leaf).
constexpr int kMaxLeafSpheres = 16;
// The lanes' tree (LaneTree) ends in leaves of up to this many spheres: the lanes test a
// node's box for all their rays at once, which costs about what one sphere does.
constexpr int kLaneLeafSpheres = 4;
// The float lanes' scan of up to kLaneScanMaxSpheres (LaneTree::clusters) tests a box before
// clusters of up to this many spheres (docs/performance.md, "Sixteen single-precision lanes",
// "More than 16 spheres": the cluster sizes measured on 46 spheres).
constexpr int kLaneClusterSpheres = 8;
// From this many spheres, AccelBackend::automatic takes Embree where the build has it
// (docs/performance.md, "Design choices and their figures": whole renders of the stress
// scenes, ours against Embree's).
constexpr size_t kEmbreeFromSpheres = 33;
constexpr int kMaxTreeDepth = 60;    // traversal stack size; deeper sets become leaves
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Box {
    double lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf};
    void grow(const double* l, const double* h) {
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], l[a]);
            hi[a] = std::max(hi[a], h[a]);
        }
    }
    double half_area() const {
        const double x = hi[0] - lo[0], y = hi[1] - lo[1], z = hi[2] - lo[2];
        return (x < 0) ? 0 : x * y + y * z + z * x;
    }
};

struct BuildItem {
    double lo[3], hi[3], centre[3];
    double radius;  // kept exactly: (hi - lo) / 2 loses a tiny sphere far from the origin
    int id;
};

int blocks_for(int spheres) { return (spheres + 3) / 4; }

struct Builder {
    std::vector<BuildItem> items;
    std::vector<BvhNode>& nodes;
    std::vector<SphereBlock>& blocks;
    int max_leaf = kMaxLeafSpheres;
    int depth = 0;

    uint32_t make_leaf(uint32_t node, int begin, int end) {
        // Largest first: big spheres (walls, floors) are candidates for almost every ray, so
        // grouping them leaves blocks of small ones that most rays skip whole.
        std::sort(items.begin() + begin, items.begin() + end, [](const BuildItem& a, const BuildItem& b) {
            return a.radius > b.radius || (a.radius == b.radius && a.id < b.id);
        });
        nodes[node].index = static_cast<uint32_t>(blocks.size());
        nodes[node].blocks = static_cast<uint16_t>(blocks_for(end - begin));
        for (int first = begin; first < end; first += 4) {
            SphereBlock b;
            for (int lane = 0; lane < 4; ++lane) {
                const int k = first + lane;
                if (k < end) {
                    const BuildItem& it = items[k];
                    const double r = it.radius;
                    b.cx[lane] = it.centre[0];
                    b.cy[lane] = it.centre[1];
                    b.cz[lane] = it.centre[2];
                    b.r2[lane] = r * r;
                    b.id[lane] = it.id;
                } else {
                    b.cx[lane] = b.cy[lane] = b.cz[lane] = 0;
                    b.r2[lane] = -1;
                    b.id[lane] = -2;  // never a ray's from/to sphere (those are >= -1)
                }
            }
            blocks.push_back(b);
        }
        return node;
    }

    uint32_t build(int begin, int end, int level) {
        depth = std::max(depth, level + 1);
        const uint32_t node = static_cast<uint32_t>(nodes.size());
        nodes.emplace_back();
        Box bounds, centres;
        for (int i = begin; i < end; ++i) {
            bounds.grow(items[i].lo, items[i].hi);
            centres.grow(items[i].centre, items[i].centre);
        }
        for (int a = 0; a < 3; ++a) {
            nodes[node].lo[a] = bounds.lo[a];
            nodes[node].hi[a] = bounds.hi[a];
        }
        const int n = end - begin;
        if (n <= max_leaf || level + 1 >= kMaxTreeDepth) return make_leaf(node, begin, end);

        // Where to split: binned SAH over the centroid extent of each axis, costs in blocks
        // of four spheres.
        double best_cost = kInf;
        int best_axis = -1, best_bin = 0;
        for (int a = 0; a < 3; ++a) {
            const double extent = centres.hi[a] - centres.lo[a];
            if (!(extent > 0)) continue;
            Box bin_box[kBins];
            int bin_count[kBins] = {};
            for (int i = begin; i < end; ++i) {
                const int b = std::min(kBins - 1, int(kBins * (items[i].centre[a] - centres.lo[a]) / extent));
                bin_box[b].grow(items[i].lo, items[i].hi);
                ++bin_count[b];
            }
            // Sweep from the right to get suffix areas, then from the left.
            double right_area[kBins];
            int right_count[kBins];
            Box acc;
            int count = 0;
            for (int b = kBins - 1; b > 0; --b) {
                acc.grow(bin_box[b].lo, bin_box[b].hi);
                count += bin_count[b];
                right_area[b] = acc.half_area();
                right_count[b] = count;
            }
            acc = Box();
            count = 0;
            for (int b = 0; b + 1 < kBins; ++b) {
                acc.grow(bin_box[b].lo, bin_box[b].hi);
                count += bin_count[b];
                if (count == 0 || right_count[b + 1] == 0) continue;
                const double cost = acc.half_area() * blocks_for(count) +
                                    right_area[b + 1] * blocks_for(right_count[b + 1]);
                if (cost < best_cost) {
                    best_cost = cost;
                    best_axis = a;
                    best_bin = b;
                }
            }
        }
        int mid;
        if (best_axis >= 0) {
            const double extent = centres.hi[best_axis] - centres.lo[best_axis];
            auto it = std::partition(items.begin() + begin, items.begin() + end, [&](const BuildItem& s) {
                const int b = std::min(kBins - 1, int(kBins * (s.centre[best_axis] - centres.lo[best_axis]) / extent));
                return b <= best_bin;
            });
            mid = static_cast<int>(it - items.begin());
            nodes[node].axis = static_cast<uint8_t>(best_axis);
        } else {
            // All centres coincide (or SAH found nothing): split the list in half.
            mid = begin + n / 2;
        }
        build(begin, mid, level + 1);
        const uint32_t second = build(mid, end, level + 1);
        nodes[node].index = second;
        return node;
    }
};

// Accepted distance of each lane's sphere for `ray` within [ray.tmin, tmax], or +inf.
// The same root choice as the scalar sphere_roots + accept rules of render_scene.cpp,
// written without branches so all four lanes go together. `shadow`: an any-hit query,
// whose finite segment end gets the tolerance of kSegmentEndTolerance.
template <bool kShadow>
inline __attribute__((always_inline)) v4d block_distances(const SphereBlock& b, const Ray& ray, double tmax) {
    const v4d inf = v4d{} + kInf, zero = v4d{};
    const v4d fx = ray.o.x - load_lanes(b.cx), fy = ray.o.y - load_lanes(b.cy), fz = ray.o.z - load_lanes(b.cz);
    const v4d r2 = load_lanes(b.r2);
    const v4d half_b = fx * ray.d.x + fy * ray.d.y + fz * ray.d.z;
    // Discriminant from the line's distance to the centre (no cancellation).
    const v4d px = fx - half_b * ray.d.x, py = fy - half_b * ray.d.y, pz = fz - half_b * ray.d.z;
    const v4d disc = r2 - (px * px + py * py + pz * pz);
    const v4d c = (fx * fx + fy * fy + fz * fz) - r2;
    v4l ids;
    __builtin_memcpy(&ids, b.id, sizeof ids);
    const v4l origin = ids == static_cast<int64_t>(ray.from_sphere);
    const v4l into = ray.into_from_sphere ? ~v4l{} : v4l{};
    // Most lanes miss: the line passes the sphere by, the sphere lies behind an origin
    // outside it, the ray leaves its own sphere or ends on this one. Skip the square root and
    // division when all four do.
    v4l candidate = (disc >= 0) & ~((c > 0) & (half_b > 0) & ~origin) & (~origin | into) &
                    (ids != static_cast<int64_t>(ray.to_sphere));
    if (tmax < kInf) {
        // A finite segment (shadow rays; closest hits once one is found): from outside, the
        // near root c / (-half_b + sqrt(disc)) is at least c / (2 |half_b|), so a sphere with
        // c > 2 |half_b| tmax starts beyond the end. Walls behind a lamp go here. The factor
        // covers the rounding of the three terms (c itself is cancellation-prone, hence the
        // margin on its own magnitude).
        constexpr double kMargin = 16 * std::numeric_limits<double>::epsilon();
        const v4d f2 = fx * fx + fy * fy + fz * fz;
        const v4l beyond = ~origin & (c > kMargin * (f2 + r2)) & (c > (-2.0 * (1.0 + kMargin)) * half_b * tmax);
        candidate &= ~beyond;
    }
    if (!any_lane(candidate)) return inf;
    const v4d root = sqrt_lanes(select(disc > 0, disc, zero));
    // Vieta: q = -b - sign(b) sqrt(disc); roots q and c / q (both 0 when q is).
    const v4d q = -half_b - select(half_b >= 0, root, -root);
    const v4d t0 = select(q != 0, c / q, zero);
    const v4d t_near = select(t0 < q, t0, q), t_far = select(t0 < q, q, t0);
    v4d end = v4d{} + tmax;
    if constexpr (kShadow) {
        if (tmax < kInf) {
            const v4d fx_abs = select(fx < 0, -fx, fx), fy_abs = select(fy < 0, -fy, fy),
                      fz_abs = select(fz < 0, -fz, fz);
            end = tmax - kSegmentEndTolerance * (fx_abs + fy_abs + fz_abs + tmax);
        }
    }
    // Only roots ahead of the origin (t > 0); the origin's own sphere only when entering it.
    const v4l near_ok = ~origin & (t_near >= ray.tmin) & (t_near > 0) & (t_near <= end);
    const v4l far_ok = (t_far >= ray.tmin) & (t_far > 0) & (t_far <= end) & (~origin | into);
    const v4d t = select(near_ok, t_near, select(far_ok, t_far, inf));
    return select(candidate, t, inf);
}

// Takes the nearest of a block's lane distances if it improves on `best` (the lanes were
// computed with `best` as their end, so they are <= best; ties keep the first found: an
// earlier block, then the lower lane). Shared by the one-leaf loop and the tree's leaves.
inline __attribute__((always_inline)) bool take_nearest(const SphereBlock& b, v4d t, double& best, int& best_id) {
    const double nearest = std::min(std::min(t[0], t[1]), std::min(t[2], t[3]));
    if (!(nearest < best || (best_id < 0 && nearest < kInf))) return false;
    const v4l is_nearest = t == nearest;
    const int lane = is_nearest[0] ? 0 : is_nearest[1] ? 1 : is_nearest[2] ? 2 : 3;
    best = nearest;
    best_id = static_cast<int>(b.id[lane]);
    return true;
}

// One leaf (scenes of up to 16 spheres): its blocks in turn, no box to test and no
// reciprocals to compute.
template <bool kAny>
inline __attribute__((always_inline)) int scan_leaf(const std::vector<SphereBlock>& blocks, uint32_t count,
                                                    const Ray& ray, double& t_best) {
    double best = ray.tmax;
    int best_id = -1;
    for (uint32_t k = 0; k < count; ++k)
        if (take_nearest(blocks[k], block_distances<kAny>(blocks[k], ray, best), best, best_id) && kAny) break;
    t_best = best;
    return best_id;
}

}  // namespace

// Our tree for one path at a time, above one leaf: the binary SAH tree collapsed into nodes
// of up to four children, whose four boxes one ray tests together in the four lanes (the
// binary tree's one box at a time took twice the box tests and a cache line a box). The
// boxes stay in double precision: own takes the scenes outside Embree's single-precision
// range too.
struct WideBvh {
    struct alignas(32) Node {
        double lo[3][4], hi[3][4];  // the children's boxes by axis; an empty slot lo +inf, hi -inf
        int32_t child[4];           // >= 0: a node; < 0: a leaf, ~(its first block)
        uint16_t blocks[4];         // a leaf's blocks (BvhNode's); 0 for a node or an empty slot
    };
    std::vector<Node> nodes;
    int depth = 0;
};

namespace {

// Collapses the binary subtree at `b` into WideBvh nodes: a node's children are its binary
// node's two, each inner one replaced by its two children while there are fewer than four,
// the largest box (by area: the likeliest to be entered) first.
int32_t collapse_wide(const std::vector<BvhNode>& bin, uint32_t b, WideBvh& wide, int level) {
    wide.depth = std::max(wide.depth, level + 1);
    const auto half_area = [&](uint32_t n) {
        const double x = bin[n].hi[0] - bin[n].lo[0], y = bin[n].hi[1] - bin[n].lo[1], z = bin[n].hi[2] - bin[n].lo[2];
        return x * y + y * z + z * x;
    };
    uint32_t kids[4] = {b + 1, bin[b].index, 0, 0};
    int count = 2;
    while (count < 4) {
        int pick = -1;
        for (int k = 0; k < count; ++k)
            if (bin[kids[k]].blocks == 0 && (pick < 0 || half_area(kids[k]) > half_area(kids[pick]))) pick = k;
        if (pick < 0) break;
        const uint32_t n = kids[pick];
        kids[pick] = n + 1;
        kids[count++] = bin[n].index;
    }
    const uint32_t at = static_cast<uint32_t>(wide.nodes.size());
    wide.nodes.emplace_back();
    for (int k = 0; k < 4; ++k)
        for (int a = 0; a < 3; ++a) {
            wide.nodes[at].lo[a][k] = k < count ? bin[kids[k]].lo[a] : kInf;
            wide.nodes[at].hi[a][k] = k < count ? bin[kids[k]].hi[a] : -kInf;
        }
    for (int k = 0; k < 4; ++k) {
        int32_t ref = ~int32_t(0);  // an empty slot: its box is never entered
        uint16_t blocks = 0;
        if (k < count) {
            const BvhNode& n = bin[kids[k]];
            blocks = n.blocks;
            ref = n.blocks > 0 ? ~int32_t(n.index) : collapse_wide(bin, kids[k], wide, level + 1);
        }
        wide.nodes[at].child[k] = ref;
        wide.nodes[at].blocks[k] = blocks;
    }
    return int32_t(at);
}

// One ray down the wide tree: the four boxes of a node at once, the entered children taken
// nearest first (the others stacked with their entry distance, dropped when a closer hit has
// been found since). A box's slabs in double precision, its far distances widened by
// 2 gamma(3) (pbrt's bound) so that rounding never culls a grazing hit.
template <bool kAny>
inline __attribute__((always_inline)) int traverse_wide(const WideBvh& tree, const std::vector<SphereBlock>& blocks,
                                                        const Ray& ray, double& t_best) {
    constexpr double kWiden = 1.0 + 2.0 * 3.0 * std::numeric_limits<double>::epsilon();
    double best = ray.tmax;
    int best_id = -1;
    const double o[3] = {ray.o.x, ray.o.y, ray.o.z};
    const double d[3] = {ray.d.x, ray.d.y, ray.d.z};
    v4d org[3], inv[3];
    int near_is_hi[3];
    for (int a = 0; a < 3; ++a) {
        const double r = 1.0 / d[a];  // +-inf for a zero component, by its sign
        org[a] = splat(o[a]);
        inv[a] = splat(r);
        near_is_hi[a] = std::signbit(r);
    }
    const v4d tmin = splat(ray.tmin);
    struct Entry {
        int32_t ref;
        uint32_t blocks;
        double t;
    };
    Entry stack[3 * kMaxTreeDepth + 4];
    int top = 0;
    Entry e{0, 0, ray.tmin};  // the root; then the nearest child entered, or the stack's top
    for (;;) {
        if (e.ref < 0) {
            const uint32_t first = uint32_t(~e.ref), end = first + e.blocks;
            for (uint32_t k = first; k < end; ++k)
                if (take_nearest(blocks[k], block_distances<kAny>(blocks[k], ray, best), best, best_id) && kAny) {
                    t_best = best;
                    return best_id;
                }
        } else {
            const WideBvh::Node& n = tree.nodes[size_t(e.ref)];
            v4d enter = tmin, leave = splat(best);
            for (int a = 0; a < 3; ++a) {
                const v4d lo = load_lanes(n.lo[a]), hi = load_lanes(n.hi[a]);
                const v4d t0 = ((near_is_hi[a] ? hi : lo) - org[a]) * inv[a];
                const v4d t1 = ((near_is_hi[a] ? lo : hi) - org[a]) * inv[a] * kWiden;
                enter = select(t0 > enter, t0, enter);  // NaN (0 * inf) leaves the bound unchanged
                leave = select(t1 < leave, t1, leave);
            }
            const v4l entered = enter <= leave;
            double t[4];
            __builtin_memcpy(t, &enter, sizeof t);
            // The entered children nearest last (an any-hit walk keeps no order): all but the
            // last stacked, the last taken next.
            int order[4], hits = 0;
            for (int k = 0; k < 4; ++k)
                if (entered[k]) {
                    int at = hits++;
                    if constexpr (!kAny)
                        while (at > 0 && t[order[at - 1]] < t[k]) {
                            order[at] = order[at - 1];
                            --at;
                        }
                    order[at] = k;
                }
            if (hits > 0) {
                for (int h = 0; h + 1 < hits; ++h) stack[top++] = {n.child[order[h]], n.blocks[order[h]], t[order[h]]};
                const int k = order[hits - 1];
                e = {n.child[k], n.blocks[k], t[k]};
                continue;
            }
        }
        // Next, the top of the stack that still lies before the closest hit found so far.
        do {
            if (top == 0) {
                t_best = best;
                return best_id;
            }
            e = stack[--top];
        } while (e.t > best);
    }
}

}  // namespace

bool embree_available() {
#ifdef KEITHRAY_HAVE_EMBREE
    return true;
#else
    return false;
#endif
}

const EmbreeModule& embree_module() {
    if (!embree_available())
        throw std::runtime_error("this build of keithray has no Embree (libembree-dev was not found)");
    static const EmbreeHost host{accepted_root};
    return *static_cast<const EmbreeModule*>(load_module("embree", &host, "Embree", "libembree3"));
}

bool embree_fits(const std::vector<SphereGeom>& spheres) {
    double extent = 0;
    for (const SphereGeom& s : spheres) extent = std::max(extent, length(s.centre) + s.radius);
    return extent >= kEmbreeExtentMin && extent <= kEmbreeExtentMax;
}

namespace {

std::vector<BuildItem> build_items(const std::vector<SphereGeom>& spheres) {
    std::vector<BuildItem> items;
    items.reserve(spheres.size());
    for (size_t i = 0; i < spheres.size(); ++i) {
        const SphereGeom& s = spheres[i];
        BuildItem it;
        const double c[3] = {s.centre.x, s.centre.y, s.centre.z};
        for (int a = 0; a < 3; ++a) {
            it.centre[a] = c[a];
            it.lo[a] = c[a] - s.radius;
            it.hi[a] = c[a] + s.radius;
        }
        it.radius = s.radius;
        it.id = static_cast<int>(i);
        items.push_back(it);
    }
    return items;
}

// Each sphere's box for the lanes, padded by 2^-20 of its extent from the origin: far more than
// the rounding of a hit's distance in either kind of lane, so a box never culls a hit its
// spheres give.
std::vector<BuildItem> lane_items(const std::vector<SphereGeom>& spheres) {
    std::vector<BuildItem> items = build_items(spheres);
    for (BuildItem& it : items) {
        const double pad = 0x1.0p-20 * (std::abs(it.centre[0]) + std::abs(it.centre[1]) + std::abs(it.centre[2]) +
                                        it.radius);
        for (int a = 0; a < 3; ++a) {
            it.lo[a] -= pad;
            it.hi[a] += pad;
        }
    }
    return items;
}

// A box in floats, rounded outward; false where it leaves float's range (far inside it, for
// the slab products).
bool float_box(const double* lo, const double* hi, float* flo, float* fhi) {
    constexpr double kFloatMax = 0x1.0p100;
    for (int a = 0; a < 3; ++a) {
        if (!(std::abs(lo[a]) < kFloatMax && std::abs(hi[a]) < kFloatMax)) return false;
        flo[a] = std::nextafter(float(lo[a]), -std::numeric_limits<float>::infinity());
        fhi[a] = std::nextafter(float(hi[a]), std::numeric_limits<float>::infinity());
    }
    return true;
}

LaneSphere<float> lane_sphere_f(const SphereGeom& s, int id) {
    const double l1 = std::abs(s.centre.x) + std::abs(s.centre.y) + std::abs(s.centre.z);
    return {float(s.centre.x), float(s.centre.y), float(s.centre.z), float(s.radius * s.radius), float(l1),
            int32_t(id)};
}

// The float lanes' scan (LaneTree::clusters): first, alone, the spheres whose box spans at
// least a quarter of the scene's (by half area: a box most rays enter, floors and walls), the
// largest first, as they end most rays early; then the others in clusters of up to
// kLaneClusterSpheres, the leaves of our builder over them, each tested after its box (a
// cluster of one without). The same hits as the tree: the boxes are the tree's kind.
void build_scan_clusters(const std::vector<SphereGeom>& spheres, LaneTree& tree) {
    std::vector<BuildItem> items = lane_items(spheres);
    Box scene;
    for (const BuildItem& it : items) scene.grow(it.lo, it.hi);
    const auto wide = [&](const BuildItem& it) {
        Box own;
        own.grow(it.lo, it.hi);
        return 4 * own.half_area() >= scene.half_area();
    };
    const auto rest = std::stable_partition(items.begin(), items.end(), wide);
    std::stable_sort(items.begin(), rest, [](const BuildItem& a, const BuildItem& b) { return a.radius > b.radius; });
    const auto add = [&](const std::vector<int>& ids, const double* lo, const double* hi) {
        LaneCluster c;
        c.first = uint32_t(tree.scan_f.size());
        c.count = uint16_t(ids.size());
        c.boxed = ids.size() > 1 && float_box(lo, hi, c.lo, c.hi);
        for (int id : ids) tree.scan_f.push_back(lane_sphere_f(spheres[size_t(id)], id));
        tree.clusters.push_back(c);
    };
    for (auto it = items.begin(); it != rest; ++it) add({it->id}, it->lo, it->hi);
    std::vector<BvhNode> nodes;
    std::vector<SphereBlock> blocks;
    Builder builder{std::vector<BuildItem>(rest, items.end()), nodes, blocks};
    builder.max_leaf = kLaneClusterSpheres;
    if (builder.items.empty()) return;
    builder.build(0, static_cast<int>(builder.items.size()), 0);
    for (const BvhNode& n : nodes) {
        if (n.blocks == 0) continue;
        std::vector<int> ids;
        for (uint32_t b = n.index; b < n.index + n.blocks; ++b)
            for (int lane = 0; lane < 4; ++lane)
                if (blocks[b].id[lane] >= 0) ids.push_back(int(blocks[b].id[lane]));
        add(ids, n.lo, n.hi);
    }
}

// The lanes' tree: our builder with small leaves over lane_items, then its boxes in floats
// (the traversal's result is the one-leaf scan's). Empty where the boxes leave float's range.
LaneTree build_lane_tree(const std::vector<SphereGeom>& spheres) {
    LaneTree tree;
    std::vector<BvhNode> nodes;
    std::vector<SphereBlock> blocks;
    Builder builder{lane_items(spheres), nodes, blocks};
    builder.max_leaf = kLaneLeafSpheres;
    builder.build(0, static_cast<int>(spheres.size()), 0);
    tree.nodes.reserve(nodes.size());
    for (const BvhNode& n : nodes) {
        LaneNode ln;
        if (!float_box(n.lo, n.hi, ln.lo, ln.hi)) return {};
        ln.axis = n.axis;
        if (n.blocks > 0) {
            ln.index = static_cast<uint32_t>(tree.spheres_d.size());
            for (uint32_t b = n.index; b < n.index + n.blocks; ++b)
                for (int lane = 0; lane < 4; ++lane) {
                    if (blocks[b].id[lane] < 0) continue;
                    const SphereGeom& s = spheres[size_t(blocks[b].id[lane])];
                    const double l1 = std::abs(s.centre.x) + std::abs(s.centre.y) + std::abs(s.centre.z);
                    const int32_t id = int32_t(blocks[b].id[lane]);
                    tree.spheres_d.push_back({s.centre.x, s.centre.y, s.centre.z, s.radius * s.radius, l1, id});
                    tree.spheres_f.push_back(lane_sphere_f(s, id));
                }
            ln.count = static_cast<uint16_t>(tree.spheres_d.size() - ln.index);
        } else {
            ln.index = n.index;
        }
        tree.nodes.push_back(ln);
    }
    tree.depth = builder.depth;
    if (tree.spheres_f.size() <= kLaneScanMaxSpheres) build_scan_clusters(spheres, tree);
    return tree;
}

}  // namespace

LaneTreeLimits lane_tree_limits(const CpuModel& cpu) {
    // Where the sixteen float lanes' scan meets Embree's one path and our tree's, measured per
    // kind of CPU (`bench --stress N --accel own,embree` with the limits raised, `--kernels
    // off` for our tree's one path).
    if (cpu.amd && cpu.family == 26) return {2800, 3000};
    return {1800, 2048};
}

LaneTreeLimits lane_tree_limits() {
    static const LaneTreeLimits limits = lane_tree_limits(cpu_model());
    return limits;
}

void SphereBvh::build(const std::vector<SphereGeom>& spheres, AccelBackend backend) {
    static std::atomic<uint64_t> builds{0};
    build_id_ = ++builds;
    nodes_.clear();
    blocks_.clear();
    depth_ = 0;
    embree_.reset();
    embree_functions_ = nullptr;
    wide_.reset();
    lane_tree_ = {};
    if (backend != AccelBackend::embree && spheres.size() > size_t(kMaxLeafSpheres) &&
        spheres.size() <= (backend == AccelBackend::own ? lane_tree_limits().own : lane_tree_limits().beside_embree))
        lane_tree_ = build_lane_tree(spheres);
    if (backend == AccelBackend::embree) {
        const EmbreeModule& functions = embree_module();
        embree_ = functions.build(spheres);
        embree_functions_ = &functions;
        return;
    }
    if (backend == AccelBackend::automatic && embree_available() && spheres.size() >= kEmbreeFromSpheres &&
        embree_fits(spheres)) {
        // Embree is only the faster choice here: where it fails (its module or libembree3
        // missing, no device on this CPU, or its build runs out of memory), our own tree
        // takes the scene.
        try {
            const EmbreeModule& functions = embree_module();
            embree_ = functions.build(spheres);
            embree_functions_ = &functions;
            return;
        } catch (const std::runtime_error&) {
            // embree_ stays empty: on to our tree
        }
    }
    Builder builder{build_items(spheres), nodes_, blocks_};
    if (spheres.empty()) return;
    builder.build(0, static_cast<int>(spheres.size()), 0);
    depth_ = builder.depth;
    if (nodes_.size() > 1) {
        auto wide = std::make_shared<WideBvh>();
        wide->nodes.reserve(nodes_.size() / 2 + 1);
        collapse_wide(nodes_, 0, *wide, 0);
        wide_ = std::move(wide);
    }
}

// A version of each entry point per CPU level (KR_LEVEL_CLONES, lanes/levels.h).
KR_LEVEL_CLONES int SphereBvh::closest(const Ray& ray, double& t) const {
    if (embree_) return embree_functions_->closest(*embree_, ray, t);
    if (nodes_.empty()) return -1;
    if (wide_) return traverse_wide<false>(*wide_, blocks_, ray, t);
    return scan_leaf<false>(blocks_, nodes_[0].blocks, ray, t);
}

KR_LEVEL_CLONES bool SphereBvh::any(const Ray& ray) const {
    if (embree_) return embree_functions_->any(*embree_, ray);
    if (nodes_.empty()) return false;
    double t;
    if (wide_) return traverse_wide<true>(*wide_, blocks_, ray, t) >= 0;
    return scan_leaf<true>(blocks_, nodes_[0].blocks, ray, t) >= 0;
}

}  // namespace kr
