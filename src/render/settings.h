// The settings of a render: which integrator, estimator, sample allocation, light sampling
// and SIMD kernels, the path depth, the samples per pixel and the seed. Every layer that
// renders (the progressive driver, the integrators, the CLI's and the viewer's shared flags)
// reads them from here.
#pragma once

#include <cstdint>

#include "core/enum_names.h"
#include "render/light.h"
#include "render/sampler.h"
#include "scene/scene.h"

namespace kr {

enum class Integrator { wrt, pt, pt_naive };
inline constexpr EnumNames<Integrator, 3> integrator_names{{"wrt", "pt", "pt-naive"}};

// How a pass spreads its samples over the pixels: one each, or (adaptive) as many in total,
// each pixel's share in proportion to its estimated noise, once every pixel has a few
// samples. The brief's stratified estimator needs exactly its s samples per pixel, so it
// always gets one each.
enum class Allocation { uniform, adaptive };
inline constexpr EnumNames<Allocation, 2> allocation_names{{"uniform", "adaptive"}};

// How camera_rays and trace_samples trace (render/trace.h, render/lanes/lanes.cpp). `best`: in SIMD lanes
// with the kernels built for x86-64-v3 where the CPU has AVX2 and FMA, else one path at a
// time (the kernels built for any x86-64 CPU are slower than that); paths in single precision
// where the scene's sizes fit it (float_lanes_fit): sixteen at a time where the CPU has
// AVX-512 (x86-64-v4), else eight; else four in double. `float8`: the eight float lanes even
// where sixteen run; `double`: always the four double lanes where the CPU has them; `any`: in
// lanes with the kernels for any CPU; `off`: one path at a time. All but `best` are for tests
// and comparisons; every choice gives the same paths up to rounding.
enum class LaneChoice { best, double_lanes, float8, any, off };
inline constexpr EnumNames<LaneChoice, 5> lane_choice_names{{"best", "double", "float8", "any", "off"}};

struct RenderSettings {
    Integrator integrator = Integrator::pt;
    Estimator estimator = Estimator::sobol;
    Allocation allocation = Allocation::adaptive;
    LightSampling light_sampling = LightSampling::brief;
    int max_depth = 6;          // scattering events per path, 0..kMaxDepth
    int target_spp = 1;         // s of the stratified estimator: e = floor(sqrt(s)) strata per axis
    int rr_depth = 3;           // Russian roulette from this many scattering events on
    uint64_t seed = 0;
    LaneChoice kernels = LaneChoice::best;  // which SIMD kernels trace the paths

    // Defaults from the scene file's renderer block.
    static RenderSettings from_scene(const RendererSettings& renderer);
};

}  // namespace kr
