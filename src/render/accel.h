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
#include "render/lanes/levels.h"

namespace kr {

struct Ray;
struct SphereGeom;
struct EmbreeSpheres;  // accel_embree.cpp
struct EmbreeModule;
struct WideBvh;        // accel.cpp: our tree as it is walked, four children a node

// own:       our BVH. One leaf, without any box test, for up to 16 spheres: the faster one
//            for small scenes (the brief's have 5 to 10 spheres).
// embree:    Embree's BVH over user geometry whose intersection callbacks are our double-
//            precision sphere tests: the faster one for large scenes (docs/performance.md,
//            "Scaling").
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

// The sixteen single-precision lanes' sphere limits on this CPU, beyond one BVH leaf: up to
// `beside_embree` spheres AccelBackend::automatic builds the lanes' tree (lane_tree()) as
// well, above it Embree's tree, one path at a time, is the faster; up to `own`,
// AccelBackend::own builds it, above it one path down our own tree is the faster. Where the
// lanes' scan meets them depends on the CPU, so they are measured per kind of CPU
// (docs/performance.md, "Switch points"): an Intel Xeon 1,800 and 2,048, an AMD EPYC of
// family 26 (Zen 5) 2,800 and 3,000; other CPUs take the Xeon's. The eight float lanes and
// the double lanes stop earlier (lanes/targets.h).
struct LaneTreeLimits {
    size_t beside_embree, own;
};
LaneTreeLimits lane_tree_limits(const CpuModel& cpu);  // those measured on that kind of CPU
LaneTreeLimits lane_tree_limits();                     // this CPU's

// Four spheres in structure-of-arrays form. Unused lanes have r2 = -1 (never hit) and id -2.
struct alignas(32) SphereBlock {
    double cx[4], cy[4], cz[4], r2[4];
    int64_t id[4];  // sphere index; 64-bit to match the lanes of the distance masks
};

// The tree the SIMD lanes walk (lanes/kernels.cpp) for scenes of more than 16 spheres: our
// BVH with small leaves, its boxes in single precision rounded outward and padded (so that a
// box holds its spheres' hits as the lanes compute them), its spheres in leaf order in both
// precisions.
struct LaneNode {
    float lo[3], hi[3];
    uint32_t index = 0;  // leaf: first sphere in LaneTree's order; inner: the second child (the first is next)
    uint16_t count = 0;  // leaf: its spheres; 0 for an inner node
    uint8_t axis = 0;    // inner: split axis, to visit the nearer child first
};
template <class Real>
struct LaneSphere {
    Real x, y, z, r2;
    Real centre_l1;  // |centre|_1, for the single-precision lanes' shadow segments
    int32_t id;      // the sphere's index in the scene
};
// Up to this many spheres the float lanes scan them all, a cluster at a time, rather than
// walk the lane tree (docs/performance.md, "Switch points": where the scan is the cheaper,
// measured per lane count). It covers every lane tree built for the float lanes under
// `--kernels best` on every kind of CPU (lane_tree_limits().own): their tree walk runs only
// with kernels named for measuring, and the double lanes always walk it.
inline constexpr size_t kLaneScanMaxSpheres = 3072;
// Spheres near each other that the scan tests after their box (boxed), or a sphere it tests
// alone: scan_f[first, first + count).
struct LaneCluster {
    float lo[3], hi[3];  // padded and rounded outward as LaneNode's
    uint32_t first = 0;
    uint16_t count = 0;
    bool boxed = false;
};
struct LaneTree {
    std::vector<LaneNode> nodes;  // empty: no tree (a one-leaf scene, or Embree's only)
    std::vector<LaneSphere<float>> spheres_f;
    std::vector<LaneSphere<double>> spheres_d;
    // For a tree of up to kLaneScanMaxSpheres (else empty): what the float lanes scan, the
    // spheres by cluster (spheres whose boxes span a large part of the scene's first, alone).
    std::vector<LaneSphere<float>> scan_f;
    std::vector<LaneCluster> clusters;
    int depth = 0;
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

    // Whether the SIMD lanes (lanes/kernels.cpp) can cast this scene's rays: it is our one leaf (up
    // to 16 spheres), whose spheres they test in turn, or it has a lane tree (lane_tree()).
    bool lanes_cast() const { return (!embree_ && nodes_.size() == 1) || !lane_tree_.nodes.empty(); }
    // Whether it is our one leaf, which the lanes test sphere by sphere without a box.
    bool one_leaf() const { return !embree_ && nodes_.size() == 1; }
    // The tree the lanes walk, built beside ours or Embree's for more than 16 spheres: up to
    // lane_tree_limits()'s beside_embree under `automatic`, own under `own`, never under
    // `embree` (which so measures one path through Embree's tree).
    const LaneTree& lane_tree() const { return lane_tree_; }

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
    std::shared_ptr<const WideBvh> wide_;          // our tree for one path at a time; copies share it
    LaneTree lane_tree_;
    std::shared_ptr<const EmbreeSpheres> embree_;  // immutable once built: copies share it
    const EmbreeModule* embree_functions_ = nullptr;  // the module's, with embree_
    uint64_t build_id_ = 0;                        // a number per build() in this process
};

// Embree's side: the module keithray_embree.so (accel_embree.cpp, built where CMake found
// libembree-dev), loaded with libembree3 and TBB the first time a scene is given to Embree
// (core/module.h). The program passes it its sphere test; it returns its functions.
struct EmbreeHost {
    double (*accepted_root)(const SphereGeom& s, int index, const Ray& ray, bool shadow);
};
struct EmbreeModule {
    std::shared_ptr<const EmbreeSpheres> (*build)(const std::vector<SphereGeom>& spheres);
    int (*closest)(const EmbreeSpheres& accel, const Ray& ray, double& t);
    bool (*any)(const EmbreeSpheres& accel, const Ray& ray);
    const char* embree_version;
};
// Loads the module once; throws std::runtime_error (one line naming its file and what is
// missing) where this build has no Embree or the module or libembree3 cannot be loaded.
const EmbreeModule& embree_module();

}  // namespace kr
