// The physics of a path vertex, written once over the lane type: the materials' lobes,
// scattering and smooth (diffuse) lobe, the Fresnel split, the pinhole camera's ray
// direction, the choice of a light, the spherical lights' `brief` and `cone` samples, the
// light a sample brings with its MIS weight, the lights' densities and the MIS weight of
// emission a BSDF-sampled ray finds, crossing a dielectric and Russian roulette. One path
// (material.cpp, light.cpp, path.cpp, integrator.cpp) instantiates it with OnePath, one double
// wide; the SIMD kernels (kernels.cpp) with their lanes, four doubles, or eight or sixteen
// floats. So a new material or light is written here, once, for both.
//
// A lane type L gives: Real (the numbers), Scalar (one lane's number), Mask (comparisons of
// Reals), Index (indices) and Vec (three Reals, with +, -, unary -, * by a Real or a Vec, and
// dot found by argument-dependent lookup); kWidth lanes; and the few operations the code below
// needs: splat, index (an int in every lane), select (of Reals, Vecs, Masks and Indices), any,
// mask_not, sqrt, lane/set_lane/on (one lane, for the rare steps done one lane at a time), and
// the maths of sampling: sin_cos_turns, concentric_disk, cosine_hemisphere, uniform_sphere,
// uniform_cone, to_world (Frame::from_normal), normalize, log_positive and expm1 (of the lanes
// a mask names). OnePath's are core's scalar functions; the lanes' are their lane-wise copies,
// operation for operation, so the lanes trace one path's paths up to rounding.
//
// The templates themselves are in vertex.inc, which this header includes into kr::vertex and
// kernels.cpp into each build of the kernels (vertex.inc says why). They are forced
// inline (KR_LANES, lanes.h): lanes must not cross a call. Their expressions keep the lanes'
// operation order, and with it where the x86-64-v3 kernels fuse multiply-adds.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/math.h"
#include "core/sampling.h"
#include "render/lanes/lanes.h"
#include "render/light.h"
#include "scene/scene.h"

namespace kr {

namespace vertex {

// One path: the lane type of width one, on core's scalar maths.
struct OnePath {
    using Real = double;
    using Scalar = double;
    using Mask = bool;
    using Vec = Vec3;
    using Index = int;
    static constexpr int kWidth = 1;
    static KR_LANES int index(int i) { return i; }
    static KR_LANES double splat(double x) { return x; }
    static KR_LANES double select(bool m, double a, double b) { return m ? a : b; }
    static KR_LANES bool select(bool m, bool a, bool b) { return m ? a : b; }
    static KR_LANES int select(bool m, int a, int b) { return m ? a : b; }
    static KR_LANES Vec3 select(bool m, const Vec3& a, const Vec3& b) { return m ? a : b; }
    static KR_LANES bool any(bool m) { return m; }
    static KR_LANES bool mask_not(bool m) { return !m; }
    static KR_LANES double sqrt(double x) { return std::sqrt(x); }
    static KR_LANES double lane(double x, int) { return x; }
    static KR_LANES void set_lane(double& x, int, double value) { x = value; }
    static KR_LANES unsigned bits(bool m) { return m; }  // the set lanes as bits
    static KR_LANES void sin_cos_turns(double t, double& s, double& c) { kr::sin_cos_turns(t, s, c); }
    static KR_LANES void concentric_disk(double u1, double u2, double& x, double& y) {
        const Vec2 d = sample_concentric_disk(u1, u2);
        x = d.x, y = d.y;
    }
    static KR_LANES Vec3 cosine_hemisphere(double u1, double u2) { return sample_cosine_hemisphere(u1, u2); }
    static KR_LANES Vec3 uniform_sphere(double u1, double u2) { return sample_uniform_sphere(u1, u2); }
    static KR_LANES Vec3 uniform_cone(double u1, double u2, double one_minus_cos_max) {
        return sample_uniform_cone(u1, u2, one_minus_cos_max);
    }
    static KR_LANES Vec3 to_world(const Vec3& n, const Vec3& local) { return Frame::from_normal(n).to_world(local); }
    static KR_LANES Vec3 normalize(const Vec3& v) { return kr::normalize(v); }
    static KR_LANES double log_positive(double x, bool) { return kr::log_positive(x); }
    static KR_LANES double expm1(double x, bool) { return std::expm1(x); }
};

// One path's material, as the vertex code reads a material (the lanes read columns by sphere):
// its type, and any parameter by its member (`param<&Material::eta>(m)`, vertex.inc).
struct OneMaterial {
    const Material& m;
    KR_LANES bool is(MaterialType type) const { return m.type == type; }
    template <auto member>
    KR_LANES const auto& get() const {
        return m.*member;
    }
};

#include "render/lanes/vertex.inc"

}  // namespace vertex
}  // namespace kr
