// Ray casting acceleration: a bounding volume hierarchy over spheres whose leaves hold
// spheres in blocks of four, tested together (SIMD lanes). Double precision throughout, so
// the epsilon-free rules of Ray (from/to sphere) hold at every scale.
#pragma once

#include <cstdint>
#include <vector>

#include "core/math.h"

namespace kr {

struct Ray;
struct SphereGeom;

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
    // Sets of up to 16 spheres are one leaf; a binned surface-area heuristic splits larger ones.
    void build(const std::vector<SphereGeom>& spheres);

    // Closest sphere accepted by the ray's rules within [tmin, tmax]: its index and distance,
    // or -1. Picks an AVX2 version at run time where the CPU has it.
    int closest(const Ray& ray, double& t) const;
    // Whether any sphere is accepted within [tmin, tmax].
    bool any(const Ray& ray) const;

    size_t node_count() const { return nodes_.size(); }
    size_t block_count() const { return blocks_.size(); }
    int depth() const { return depth_; }

private:
    std::vector<BvhNode> nodes_;
    std::vector<SphereBlock> blocks_;
    int depth_ = 0;
};

}  // namespace kr
