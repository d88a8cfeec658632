// Ray casting in lanes, for kernels.cpp (included after math.h): the closest hit and the
// shadow test of the lanes' rays against the up to 16 spheres of a one-leaf scene, tested in
// turn, or against a larger scene's spheres down its lane tree or, in the float lanes up to
// kLaneScanMaxSpheres, its clusters (accel.h).
#pragma once

#include "render/lanes/math.h"

// A sphere as the ray tests read it: the centre, the squared radius, |centre|_1 and its index.
using TestSphere = LaneSphere<real>;

// accepted_root (render_scene.cpp) of the lanes' rays against one sphere: the distance per lane, or
// +inf. The rays start at tmin = 0 (trace_lanes checks). kShadow: segments with an end and a
// target sphere; closest-hit rays have neither. Where q = 0 the roots come out as +-inf, NaN
// and 0, none of which is accepted, as accepted_root rejects that case; where disc < 0 the
// square root is NaN and the lane is rejected too.
template <bool kShadow>
KR_LANES vf sphere_lanes(const V3& o, const V3& d, vm from, vm into, vf tmax, vm to, const TestSphere& sphere,
                        vm id, vm lanes = ~vm{}) {
    const real r2 = sphere.r2;
    const V3 f{o.x - sphere.x, o.y - sphere.y, o.z - sphere.z};
    const vf b = dot(f, d);
    const V3 p{f.x - b * d.x, f.y - b * d.y, f.z - b * d.z};
    const vf disc = r2 - dot(p, p);
    const vf c = dot(f, f) - r2;
    const vm origin = from == id;
    // Most spheres miss every lane: the line passes them by, or they lie behind an origin
    // outside them, or (shadow rays) they are the target or begin beyond the segment's end
    // (from outside, the near root is at least c / (2 |b|), as in accel.cpp). Then the square
    // root and division are skipped.
    vm candidate = lanes & (disc >= 0) & ~((c > 0) & (b > 0) & ~origin);
    if constexpr (kShadow) {
        constexpr real kMargin = 16 * std::numeric_limits<real>::epsilon();
        const vf f2 = dot(f, f);
        const vm beyond = ~origin & (c > kMargin * (f2 + r2)) & (c > real(-2 * (1 + kMargin)) * b * tmax);
        candidate &= ~beyond & (to != id);
    }
    if (!any_lane(candidate)) return splat(kInf);
    const vf root = sqrt_lanes(disc);
    const vf q = -b - select(sign_bit(b), -root, root);  // copysign(root, b)
    const vf t0 = c / q;
    const vm t0_first = t0 < q;
    const vf t_near = select(t0_first, t0, q), t_far = select(t0_first, q, t0);
    vm near_ok = ~origin & (t_near > 0) & candidate, far_ok = (t_far > 0) & (~origin | into) & candidate;
    if constexpr (kShadow) {
        const vf f_l1 = abs_lanes(f.x) + abs_lanes(f.y) + abs_lanes(f.z);
        // kSegmentEndTolerance, in the lanes' precision
        constexpr real kEndTolerance = 64 * std::numeric_limits<real>::epsilon();
        const vf end = select(tmax < kInf, tmax - kEndTolerance * (f_l1 + tmax), tmax);
        near_ok &= t_near <= end;
        far_ok &= t_far <= end;
    }
    return select(near_ok, t_near, select(far_ok, t_far, splat(kInf)));
}

// The closest sphere of each live lane's ray from o along d (its index and distance; -1 where
// none). from, into: the sphere each ray leaves, and whether it heads into it.
KR_LANES void closest_lanes(const TestSphere* spheres, size_t count, const V3& o, const V3& d, vm from, vm into,
                            vm alive, vf& best, vm& best_id) {
    best = splat(kInf);
    best_id = vm{} - 1;
    vm id{};  // s in every lane, counted along (not broadcast from s for every sphere)
    for (size_t s = 0; s < count; ++s, id += 1) {
        const vf t = sphere_lanes<false>(o, d, from, into, vf{}, vm{}, spheres[s], id);
        const vm nearer = t < best;  // ties keep the lower index, as the linear scan does
        best = select(nearer, t, best);
        best_id = nearer ? id : best_id;
    }
    best_id = alive ? best_id : vm{} - 1;
}

#ifdef KR_LANES_FLOAT
// Whether one sphere blocks each shadow segment, accepted_root's answer without its roots (no
// square root, division or branch): the segment, shortened as accepted_root shortens it,
// - from outside the sphere, is blocked where its nearest point to the centre lies inside;
// - from inside (a light around the shading point), where its end lies outside;
// - from the sphere's own surface, where it heads inside (`into`) and its chord, -2b, ends
//   before the segment does.
// The shortening takes |o|_1 + |centre|_1 for accepted_root's |o - centre|_1 (no smaller, so
// no crossing it ignores is counted): `end_base` is the segment's part, tmax less the
// tolerance of tmax + |o|_1.
constexpr real kEndTolerance = 64 * std::numeric_limits<real>::epsilon();  // kSegmentEndTolerance
KR_LANES vm segment_blocked_lanes(const V3& o, const V3& d, vm from, vm into, vf end_base, vm to,
                                  const TestSphere& sphere, vm id) {
    const V3 f{o.x - sphere.x, o.y - sphere.y, o.z - sphere.z};
    const vf b = dot(f, d), f2 = dot(f, f), two_b = b + b;
    const vf end = end_base - kEndTolerance * sphere.centre_l1;
#ifdef KR_LANES_V4
    const vf nearest_t = _mm512_maskz_min_ps(0xffff, _mm512_maskz_max_ps(0xffff, -b, vf{}), end);  // (GCC 12 warns of the unmasked forms)
#else
    const vf nearest_t = _mm256_min_ps(_mm256_max_ps(-b, vf{}), end);
#endif
    const vf nearest2 = f2 + nearest_t * (two_b + nearest_t);  // |f + t d|^2
    const vf end2 = f2 + end * (two_b + end);
    const vm crosses = f2 > sphere.r2 ? vm(nearest2 < sphere.r2) : vm(end2 > sphere.r2);
    const vm own_crosses = into & (-two_b <= end);
    return (from == id ? own_crosses : crosses) & (to != id);
}
#endif

// The shadow segments' end as the eight float lanes' test takes it (segment_blocked_lanes);
// the other lanes read tmax itself.
KR_LANES vf segment_end(const V3& o, vf tmax) {
#ifdef KR_LANES_FLOAT
    const vf o_l1 = abs_lanes(o.x) + abs_lanes(o.y) + abs_lanes(o.z);
    return select(tmax < kInf, tmax - kEndTolerance * (tmax + o_l1), tmax);
#else
    (void)o;
    return tmax;
#endif
}

// Whether anything blocks each shadow segment (lanes outside `cast` are left unblocked). The
// double lanes take accepted_root's roots, operation for operation, so that their paths stay
// those of one path to the last bit; the single-precision ones the cheaper test above.
KR_LANES vm occluded_lanes(const TestSphere* spheres, size_t count, const V3& o, const V3& d, vm from, vm into,
                          vf tmax, vm to, vm cast) {
    vm blocked = vm{};
    const vf end = segment_end(o, tmax);
    vm id{};
    for (size_t s = 0; s < count; ++s, id += 1)
#ifdef KR_LANES_FLOAT
        blocked |= segment_blocked_lanes(o, d, from, into, end, to, spheres[s], id);
#else
        blocked |= sphere_lanes<true>(o, d, from, into, end, to, spheres[s], id) < kInf;
#endif
    return blocked & cast;
}

// ---- Larger scenes: the lane tree (LaneTree, accel.h), walked by all lanes together ----

// The lanes' rays for the box tests: origins and reciprocal directions (a zero component
// taken as 2^-60 of its sign, so that no product is 0 * inf; the ray moves 2^-60 of a
// distance off its line, far below the boxes' padding).
struct SlabLanes {
    V3 o, inv;
};
KR_LANES SlabLanes slab_lanes(const V3& o, const V3& d) {
    constexpr real kTiny = real(0x1.0p-60);
    const auto away = [](vf x) {
        return select(abs_lanes(x) < kTiny, select(sign_bit(x), splat(-kTiny), splat(kTiny)), x);
    };
    return {o, {real(1) / away(d.x), real(1) / away(d.y), real(1) / away(d.z)}};
}
KR_LANES vf min_lanes(vf a, vf b) { return select(a < b, a, b); }
KR_LANES vf max_lanes(vf a, vf b) { return select(a > b, a, b); }

// The lanes whose ray meets a node's box ahead of its origin, no farther than `limit`. The
// entry and exit distances are widened by 2^-18 of themselves, beyond the rounding of the
// slabs and of a hit's distance in either kind of lane (the boxes' padding covers what is
// relative to the spheres' own size), so a box never culls a hit the one-leaf scan finds.
template <class Box>  // LaneNode or LaneCluster
KR_LANES vm box_lanes(const Box& node, const SlabLanes& r, vf limit) {
    constexpr real kWiden = real(0x1.0p-18);
    const vf x0 = (real(node.lo[0]) - r.o.x) * r.inv.x, x1 = (real(node.hi[0]) - r.o.x) * r.inv.x;
    const vf y0 = (real(node.lo[1]) - r.o.y) * r.inv.y, y1 = (real(node.hi[1]) - r.o.y) * r.inv.y;
    const vf z0 = (real(node.lo[2]) - r.o.z) * r.inv.z, z1 = (real(node.hi[2]) - r.o.z) * r.inv.z;
    const vf enter = max_lanes(max_lanes(min_lanes(x0, x1), min_lanes(y0, y1)), max_lanes(min_lanes(z0, z1), vf{}));
    const vf leave = min_lanes(min_lanes(max_lanes(x0, x1), max_lanes(y0, y1)), max_lanes(z0, z1));
    const vf near = enter * (1 - kWiden);
    return (near <= leave * (1 + kWiden)) & (near <= limit);
}

// Which child of an inner node the lanes visit first: the one on the side most of `lanes`'
// rays come from.
KR_LANES bool descend_negative(const V3& d, int axis, vm lanes) {
    const vf along = axis == 0 ? d.x : axis == 1 ? d.y : d.z;
    int negative = 0, count = 0;
    for (int k = 0; k < kLanes; ++k) {
        count += lanes[k] != 0;
        negative += (lanes[k] != 0) & (along[k] < 0);
    }
    return 2 * negative > count;
}

constexpr int kLaneStack = 128;  // the tree is at most 60 levels deep (accel.cpp)

// A leaf's or a cluster's spheres [first, end), by their scene indices: the nearest hits of
// the lanes in `lanes` merged into best and best_id (ties keep the lower index, as the one
// leaf's scan in index order does).
KR_LANES void closest_among(const TestSphere* first, const TestSphere* end, const V3& o, const V3& d, vm from,
                            vm into, vm lanes, vf& best, vm& best_id) {
    for (const TestSphere* sphere = first; sphere != end; ++sphere) {
        const vm id = vm{} + lane_int(sphere->id);
        const vf t = sphere_lanes<false>(o, d, from, into, vf{}, vm{}, *sphere, id, lanes);
        const vm nearer = (t < best) | ((t == best) & (best_id > id));
        best = select(nearer, t, best);
        best_id = nearer ? id : best_id;
    }
}

// The lanes whose shadow segment (ending at `end`, segment_end's) a leaf's or a cluster's
// spheres [first, end) block.
KR_LANES vm blocked_among(const TestSphere* first, const TestSphere* last, const V3& o, const V3& d, vm from,
                          vm into, vf end, vm to) {
    vm blocked = vm{};
    for (const TestSphere* sphere = first; sphere != last; ++sphere)
#ifdef KR_LANES_FLOAT
        blocked |= segment_blocked_lanes(o, d, from, into, end, to, *sphere, vm{} + lane_int(sphere->id));
#else
        blocked |= sphere_lanes<true>(o, d, from, into, end, to, *sphere, vm{} + lane_int(sphere->id)) < kInf;
#endif
    return blocked;
}

// closest_lanes over the tree: the same answer as testing every sphere in index order (ties
// keep the lower index).
KR_LANES void closest_tree(const LaneNode* nodes, const TestSphere* spheres, const V3& o, const V3& d, vm from,
                           vm into, vm alive, vf& best, vm& best_id) {
    best = splat(kInf);
    best_id = vm{} - 1;
    const SlabLanes slab = slab_lanes(o, d);
    uint32_t stack[kLaneStack];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const uint32_t index = stack[--top];
        const LaneNode& node = nodes[index];
        const vm enter = alive & box_lanes(node, slab, best);
        if (!any_lane(enter)) continue;
        if (node.count > 0) {
            closest_among(spheres + node.index, spheres + node.index + node.count, o, d, from, into, ~vm{}, best,
                          best_id);
        } else {
            uint32_t first = index + 1, second = node.index;
            if (descend_negative(d, node.axis, enter)) std::swap(first, second);
            stack[top++] = second;
            stack[top++] = first;
        }
    }
    best_id = alive ? best_id : vm{} - 1;
}

// occluded_lanes over the tree.
KR_LANES vm occluded_tree(const LaneNode* nodes, const TestSphere* spheres, const V3& o, const V3& d, vm from,
                          vm into, vf tmax, vm to, vm cast) {
    vm blocked = vm{};
    const vf end = segment_end(o, tmax);
    const SlabLanes slab = slab_lanes(o, d);
    uint32_t stack[kLaneStack];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const vm open = cast & ~blocked;
        if (!any_lane(open)) break;
        const uint32_t index = stack[--top];
        const LaneNode& node = nodes[index];
        const vm enter = open & box_lanes(node, slab, tmax);
        if (!any_lane(enter)) continue;
        if (node.count > 0) {
            blocked |= blocked_among(spheres + node.index, spheres + node.index + node.count, o, d, from, into, end, to);
        } else {
            uint32_t first = index + 1, second = node.index;
            if (descend_negative(d, node.axis, enter)) std::swap(first, second);
            stack[top++] = second;
            stack[top++] = first;
        }
    }
    return blocked & cast;
}

// ---- Up to kLaneScanMaxSpheres: every sphere, a cluster at a time (LaneTree::clusters) ----

// closest_lanes over the clusters: a boxed one's spheres are tested where a live lane's ray
// enters its box before its nearest hit so far. The same answer as testing every sphere in
// index order (ties keep the lower index).
KR_LANES void closest_clusters(const LaneCluster* clusters, size_t count, const TestSphere* spheres, const V3& o,
                               const V3& d, vm from, vm into, vm alive, vf& best, vm& best_id) {
    best = splat(kInf);
    best_id = vm{} - 1;
    const SlabLanes slab = slab_lanes(o, d);
    for (const LaneCluster* cluster = clusters; cluster != clusters + count; ++cluster) {
        // (Lanes outside the box skip the spheres' roots too.)
        const vm enter = cluster->boxed ? alive & box_lanes(*cluster, slab, best) : ~vm{};
        if (!any_lane(enter)) continue;
        const TestSphere* first = spheres + cluster->first;
        closest_among(first, first + cluster->count, o, d, from, into, enter, best, best_id);
    }
    best_id = alive ? best_id : vm{} - 1;
}

// occluded_lanes over the clusters, until every cast lane is blocked.
KR_LANES vm occluded_clusters(const LaneCluster* clusters, size_t count, const TestSphere* spheres, const V3& o,
                              const V3& d, vm from, vm into, vf tmax, vm to, vm cast) {
    vm blocked = vm{};
    const vf end = segment_end(o, tmax);
    const SlabLanes slab = slab_lanes(o, d);
    for (const LaneCluster* cluster = clusters; cluster != clusters + count; ++cluster) {
        const vm open = cast & ~blocked;
        if (!any_lane(open)) break;
        if (cluster->boxed && !any_lane(open & box_lanes(*cluster, slab, tmax))) continue;
        const TestSphere* first = spheres + cluster->first;
        blocked |= blocked_among(first, first + cluster->count, o, d, from, into, end, to);
    }
    return blocked & cast;
}
