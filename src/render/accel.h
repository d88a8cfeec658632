// Ray casting acceleration: a bounding volume hierarchy over spheres. Two of them, with the
// same answers: our own, whose leaves hold spheres in blocks of four tested together (SIMD
// lanes), and Embree's (libembree3, where the build found it), whose traversal is faster once
// the scene is a tree. Both decide hits in double precision with the same rules, so the
// epsilon-free rules of Ray (from/to sphere) hold at every scale (docs/performance.md,
// "Scaling").
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/math.h"
#include "core/enum_names.h"

namespace kr {

struct Ray;
struct SphereGeom;
struct EmbreeSpheres;  // accel_embree.cpp

// own:       our BVH. One leaf, without any box test, for up to 16 spheres: the faster one
//            for small scenes (the brief's have 5 to 10 spheres).
// embree:    Embree's BVH over user geometry whose intersection callbacks are our double-
//            precision sphere tests: the faster one for large scenes (ray casting alone 1.4x
//            at 1,000 to 100,000 spheres, whole renders 1.13x to 1.23x; docs/performance.md).
// automatic: embree for more than 32 spheres where the build has Embree and the spheres fit
//            its single precision (embree_fits), else own.
enum class AccelBackend { automatic, own, embree };
inline constexpr EnumNames<AccelBackend, 3> accel_backend_names{{"auto", "own", "embree"}};
// Whether this build can cast rays with Embree.
bool embree_available();
// Whether Embree's single-precision boxes and rays can hold these spheres: every sphere within
// 2^-50 to 2^50 of the origin at its farthest (kEmbreeExtentMin/Max). Outside that range
// Embree's float coordinates leave its valid range (1.8e18) or go denormal, and its box areas
// (squares) overflow or vanish; automatic then builds our double-precision BVH instead.
inline constexpr double kEmbreeExtentMin = 0x1.0p-50, kEmbreeExtentMax = 0x1.0p50;
bool embree_fits(const std::vector<SphereGeom>& spheres);

// Four spheres in structure-of-arrays form. Unused lanes have r2 = -1 (never hit) and id -2.
struct alignas(32) SphereBlock {
    double cx[4], cy[4], cz[4], r2[4];
    int64_t id[4];  // sphere index; 64-bit to match the lanes of the distance masks
};

struct BvhNode {
    double lo[3], hi[3];   // axis-aligned bounds of everything below
    uint32_t index = 0;    // leaf: first block; inner: the second child (the first is next)
    uint16_t blocks = 0;   // leaf: number of blocks; 0 for an inner node
    uint8_t axis = 0;      // inner: split axis, to visit the nearer child first
};

class SphereBvh {
public:
    // Our BVH: sets of up to 16 spheres are one leaf; a binned surface-area heuristic splits
    // larger ones. Or Embree's (see AccelBackend); `embree` without Embree in the build
    // throws std::runtime_error.
    void build(const std::vector<SphereGeom>& spheres, AccelBackend backend = AccelBackend::automatic);

    // Closest sphere accepted by the ray's rules within [tmin, tmax]: its index and distance,
    // or -1. Picks an AVX2 version at run time where the CPU has it.
    int closest(const Ray& ray, double& t) const;
    // Whether any sphere is accepted within [tmin, tmax].
    bool any(const Ray& ray) const;

    // Whether the build is our one leaf (up to 16 spheres), whose spheres packet tracing
    // (packet.cpp) tests in turn for four rays at once.
    bool packets() const { return !embree_ && nodes_.size() == 1; }

    // Whether this and `other` are copies of one build (their trees are the same).
    bool same_build(const SphereBvh& other) const { return build_id_ != 0 && build_id_ == other.build_id_; }
    // Which BVH the last build made (own or embree); the counts below are of our own BVH
    // (0 when Embree's was built).
    AccelBackend backend() const { return embree_ ? AccelBackend::embree : AccelBackend::own; }
    size_t node_count() const { return nodes_.size(); }
    size_t block_count() const { return blocks_.size(); }
    int depth() const { return depth_; }

private:
    std::vector<BvhNode> nodes_;
    std::vector<SphereBlock> blocks_;
    int depth_ = 0;
    std::shared_ptr<const EmbreeSpheres> embree_;  // immutable once built: copies share it
    uint64_t build_id_ = 0;                        // a number per build() in this process
};

// Embree's side (accel_embree.cpp, only in builds with Embree).
std::shared_ptr<const EmbreeSpheres> build_embree_spheres(const std::vector<SphereGeom>& spheres);
int embree_closest(const EmbreeSpheres& accel, const Ray& ray, double& t);
bool embree_any(const EmbreeSpheres& accel, const Ray& ray);

}  // namespace kr
