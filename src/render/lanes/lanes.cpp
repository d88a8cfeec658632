// Path tracing of several samples at once, their paths in the lanes of SIMD registers: which
// target's kernels (targets.h) trace a batch, and the calls into them. Casting rays, hit
// records, Sobol numbers, the light choice, the `brief` and `cone` light samples, every
// material's scattering, throughput and Russian roulette run lane-wise: the physics through
// the same templates as one path (vertex.h), the lanes' own maths as copies of core's,
// operation for operation; the other light samples, emission weights and other estimators'
// numbers run per lane through the same functions as one path (path.h). So every path is the
// one trace_sample gives, up to rounding. docs/performance.md ("Paths in lanes" and after)
// has what it buys.
//
// The kernels are kernels.cpp, compiled once per target: four double lanes for any x86-64
// CPU and for x86-64-v3 (AVX2, FMA), eight single-precision lanes for x86-64-v3 and sixteen
// for x86-64-v4 (AVX-512). Under `best` the single-precision lanes of the highest level the
// CPU has (cpu_level, levels.h) run where float_lanes_fit says the scene's sizes and
// radiances keep their rounding far below what an image shows (they then agree with one path
// to about 1e-6 per step; tests/test_lanes.cpp), the double ones elsewhere. Without AVX2
// paths are traced one at a time: GCC emulates what SSE2 lacks (64-bit compares, per-lane
// shifts, 32-bit multiplies) lane by lane, so the kernels for any CPU are 2.5 times slower
// than one path at a time (docs/performance.md); they run only when the settings' `kernels`
// ask for them, for tests and comparisons.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "core/sampling.h"
#include "render/accel.h"
#include "render/lanes/levels.h"
#include "render/lanes/pixel_sums.h"
#include "render/lanes/targets.h"
#include "render/path.h"
#include "render/precision.h"
#include "render/trace.h"

namespace kr {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A target's row of targets.h, as the choice below reads it.
struct Target {
    LaneKernels id;
    CpuLevel level;
    bool single;  // single-precision lanes
    size_t max_spheres_beside_embree, max_spheres_own;
    const lanes::TargetKernels* kernels;
};
#define KR_LANE_TARGET_ROW(id, label, level, real, width, beside_embree, own)                              \
    Target{LaneKernels::id, CpuLevel::level, sizeof(real) < sizeof(double), size_t(beside_embree), size_t(own), \
           &lanes::id::kernels},
const Target kTargets[] = {KR_LANE_TARGETS(KR_LANE_TARGET_ROW)};
#undef KR_LANE_TARGET_ROW
static_assert(std::size(kTargets) == size_t(LaneKernels::one_path));

// A target's row: LaneKernels is made from the same rows in the same order (targets.h).
const Target& target(LaneKernels kernels) { return kTargets[size_t(kernels)]; }

// Whether this build has the target's kernels and this CPU runs them.
bool runs(const Target& t) { return t.kernels->built && t.level <= cpu_level(); }

// The target of the highest level this CPU runs, of those from x86-64-v3 on (the kernels for
// any CPU are slower than one path) in the precision asked; one path where there is none.
LaneKernels highest(bool single) {
    const Target* best = nullptr;
    for (const Target& t : kTargets)
        if (t.single == single && t.level >= CpuLevel::x86_64_v3 && runs(t) && (!best || t.level > best->level))
            best = &t;
    return best ? best->id : LaneKernels::one_path;
}

// A target where this CPU runs it, else one path.
LaneKernels if_runs(LaneKernels kernels) { return runs(target(kernels)) ? kernels : LaneKernels::one_path; }

// Where lanes can cast a scene's rays: one leaf of our BVH, or the lane tree
// (SphereBvh::lanes_cast), not the plain path. Scenes with Embree's tree only cast rays one by
// one.
bool lanes_cast(const RenderScene& scene) { return !scene.linear_scan && scene.bvh.lanes_cast(); }

// The kernels the CPU and the settings pick, before a scene has a say: under `best` the
// single-precision lanes of the highest level the CPU has.
LaneKernels pick(LaneChoice choice) {
    switch (choice) {
    case LaneChoice::best: return highest(true);
    case LaneChoice::float8: return if_runs(LaneKernels::x86_64_v3_float);
    case LaneChoice::double_lanes: return highest(false);
    case LaneChoice::any: return if_runs(LaneKernels::x86_64);
    case LaneChoice::off: return LaneKernels::one_path;
    }
    return LaneKernels::one_path;
}

// The same, worked out once per choice.
LaneKernels choice_kernels(LaneChoice choice) {
    static const auto picked = [] {
        std::array<LaneKernels, lane_choice_names.names.size()> kernels{};
        for (size_t c = 0; c < kernels.size(); ++c) kernels[c] = pick(LaneChoice(c));
        return kernels;
    }();
    return picked[size_t(choice)];
}

// The camera rays' kernels for these: the double lanes of the highest level up to theirs (the
// single-precision targets take theirs), worked out once per target.
const lanes::TargetKernels* camera_kernels(LaneKernels kernels) {
    static const auto of = [] {
        std::array<const lanes::TargetKernels*, size_t(LaneKernels::one_path) + 1> camera{};
        for (const Target& row : kTargets) {
            const Target* best = nullptr;
            for (const Target& t : kTargets)
                if (!t.single && t.level <= row.level && runs(t) && (!best || t.level > best->level)) best = &t;
            camera[size_t(row.id)] = best ? best->kernels : nullptr;
        }
        return camera;  // one_path: none
    }();
    return of[size_t(kernels)];
}

}  // namespace

bool float_lanes_fit(const RenderScene& scene) {
    // The largest distance is bounded by the camera's (its lens included) and the spheres'
    // distances from the origin, as rays start at the camera or on a sphere.
    double largest = length(scene.camera.position) + std::max(scene.camera.lens_radius, 0.0), smallest_radius = kInf;
    for (const SphereGeom& s : scene.spheres) {
        largest = std::max(largest, length(s.centre) + s.radius);
        smallest_radius = std::min(smallest_radius, s.radius);
    }
    if (!(std::isfinite(largest) && smallest_radius > 0)) return false;
    // Absolute range: the lanes square distances and radii, which must stay normal floats
    // (2^-126..2^128) with room for the products they enter; lengths of 2^-40..2^40 do.
    if (!(smallest_radius >= 0x1.0p-40 && largest <= 0x1.0p40)) return false;
    // Light: every nonzero radiance and intensity within 2^-60..2^60, which leaves single
    // precision's range (2^-126..2^128) room for the factors a light sample multiplies in.
    const auto in_range = [](const Color& c) {
        for (int k = 0; k < 3; ++k)
            if (c[k] != 0 && !(std::abs(c[k]) >= 0x1.0p-60 && std::abs(c[k]) <= 0x1.0p60)) return false;
        return true;
    };
    for (const RenderLight& light : scene.lights)
        if (!in_range(light.power)) return false;
    // Gaps: surfaces and lights no nearer each other than the lanes' rounding resolves.
    // Sizes (last, the dearest): each sphere's tests round to well under its radius
    // (float_sizes_fit, precision.h), once per pass.
    return scene.float_gaps_resolved && float_sizes_fit(scene);
}

LaneKernels cpu_lane_kernels(LaneChoice choice) { return choice_kernels(choice); }

LaneKernels casting_kernels(const RenderScene& scene, const RenderSettings& settings) {
    if (!lanes_cast(scene)) return LaneKernels::one_path;
    LaneKernels kernels = choice_kernels(settings.kernels);
    if (kernels != LaneKernels::one_path && target(kernels).single && !float_lanes_fit(scene))
        kernels = highest(false);
    if (kernels == LaneKernels::one_path) return kernels;
    // Kernels asked for by name run wherever they can (to measure them); `best` only up to
    // the sphere count (beyond one leaf) where one path at a time becomes the faster: down
    // Embree's tree where `automatic` built it beside the lanes' tree, else down our own.
    const Target& t = target(kernels);
    const bool beside_embree = scene.bvh.backend() == AccelBackend::embree;
    size_t most = beside_embree ? t.max_spheres_beside_embree : t.max_spheres_own;
    if (most == kThisCpusLimit) most = beside_embree ? lane_tree_limits().beside_embree : lane_tree_limits().own;
    if (settings.kernels == LaneChoice::best && !scene.bvh.one_leaf() && scene.spheres.size() > most)
        return LaneKernels::one_path;
    return kernels;
}

LaneKernels lane_kernels(const RenderScene& scene, const RenderSettings& settings) {
    // Whitted renders trace one path at a time (docs/performance.md: lanes would not pay).
    return settings.integrator == Integrator::wrt ? LaneKernels::one_path : casting_kernels(scene, settings);
}

void camera_hits(LaneKernels kernels, const RenderScene& scene, const Ray* rays, int count, Hit* hits) {
    if (kernels == LaneKernels::one_path || count < 2) {
        for (int k = 0; k < count; ++k) {
            hits[k] = Hit();
            scene.intersects(rays[k], hits[k]);
        }
        return;
    }
    int spheres[kSampleBatch];
    for (int first = 0; first < count; first += kSampleBatch) {
        const int n = std::min(kSampleBatch, count - first);
        target(kernels).kernels->closest_spheres(scene, rays + first, n, spheres);
        for (int k = 0; k < n; ++k) hits[first + k] = lanes_sphere_hit(scene, rays[first + k], spheres[k]);
    }
}

Hit lanes_sphere_hit(const RenderScene& scene, const Ray& ray, int sphere) {
    Hit hit;
    if (sphere >= 0 && !scene.hit_on(ray, sphere, hit)) scene.intersects(ray, hit);
    return hit;
}

void camera_rays(const RenderScene& scene, const RenderSettings& settings, int width, int height, const int* xs,
                 const int* ys, Sampler* const* samplers, int count, Ray* rays) {
    if (const lanes::TargetKernels* kernels = camera_kernels(choice_kernels(settings.kernels)))
        return kernels->camera_rays(scene, width, height, xs, ys, samplers, count, rays);
    for (int k = 0; k < count; ++k) rays[k] = camera_ray(scene, width, height, xs[k], ys[k], *samplers[k]);
}

void trace_samples(const RenderScene& scene, const RenderSettings& settings, const Ray* rays, Sampler* const* samplers,
                   int count, SampleResult* results) {
    const LaneKernels kernels = count > 1 ? lane_kernels(scene, settings) : LaneKernels::one_path;
    bool camera_rays = kernels != LaneKernels::one_path;  // as the lanes take them
    for (int k = 0; k < count && camera_rays; ++k)
        camera_rays =
            rays[k].tmin == 0 && rays[k].tmax == kInf && rays[k].from_sphere < 0 && rays[k].to_sphere < 0;
    if (camera_rays) return target(kernels).kernels->trace_rays(scene, settings, rays, samplers, count, results);
    for (int k = 0; k < count; ++k) results[k] = trace_sample(scene, settings, rays[k], *samplers[k]);
}

bool camera_surfaces(LaneKernels kernels, const RenderScene& scene, int width, int height, const int* xs,
                     const int* ys, const uint32_t* keys, const uint32_t* index_reversed, int count, int* spheres,
                     float* normals) {
    if (kernels == LaneKernels::one_path || !target(kernels).kernels->camera_surfaces) return false;
    target(kernels).kernels->camera_surfaces(scene, width, height, xs, ys, keys, index_reversed, count, spheres,
                                             normals);
    return true;
}

bool sobol_camera_lanes(LaneKernels kernels) {
    return kernels != LaneKernels::one_path && target(kernels).kernels->trace_sobol_camera != nullptr;
}

void trace_sobol_camera_samples(LaneKernels kernels, const RenderScene& scene, const RenderSettings& settings,
                                int width, int height, const int* xs, const int* ys, const uint32_t* keys,
                                const uint32_t* index_reversed, int count, SampleResult* results) {
    if (count > 1 && sobol_camera_lanes(kernels))
        return target(kernels).kernels->trace_sobol_camera(scene, settings, width, height, xs, ys, keys,
                                                           index_reversed, count, results);
    // Other kernels, or a batch of one sample (one path): the samplers made.
    for (int first = 0; first < count; first += kSampleBatch) {
        const int n = std::min(kSampleBatch, count - first);
        std::vector<Sampler> samplers;
        samplers.reserve(size_t(n));
        Sampler* pointers[kSampleBatch];
        for (int k = 0; k < n; ++k) {
            const uint32_t reversed = index_reversed[first + k];  // reverse_bits is its own inverse
            samplers.emplace_back(keys[first + k], reverse_bits(reversed), reversed);
            pointers[k] = &samplers.back();
        }
        trace_camera_samples(scene, settings, width, height, xs + first, ys + first, pointers, n, results + first);
    }
}

void trace_camera_samples(const RenderScene& scene, const RenderSettings& settings, int width, int height,
                          const int* xs, const int* ys, Sampler* const* samplers, int count, SampleResult* results) {
    const LaneKernels kernels = count > 1 ? lane_kernels(scene, settings) : LaneKernels::one_path;
    bool sobol = sobol_camera_lanes(kernels);
    for (int k = 0; k < count && sobol; ++k) sobol = samplers[k]->sobol() && samplers[k]->dimension() == 0;
    if (sobol)
        return target(kernels).kernels->trace_camera(scene, settings, width, height, xs, ys, samplers, count, results);
    Ray rays[kSampleBatch];
    for (int first = 0; first < count; first += kSampleBatch) {
        const int n = std::min(kSampleBatch, count - first);
        camera_rays(scene, settings, width, height, xs + first, ys + first, samplers + first, n, rays);
        trace_samples(scene, settings, rays, samplers + first, n, results + first);
    }
}

bool avx2_accumulation() { return choice_kernels(LaneChoice::double_lanes) != LaneKernels::one_path; }

AccumulateBatch accumulation(bool avx2) {
    // The double lanes of the highest level from x86-64-v3 on, where asked and run; else any
    // x86-64's.
    const LaneKernels v3 = choice_kernels(LaneChoice::double_lanes);
    return (avx2 && v3 != LaneKernels::one_path ? target(v3) : target(LaneKernels::x86_64)).kernels->accumulate;
}

void accumulate(const PixelSums& sums, const size_t* pixels, const SampleResult* results, int count, bool avx2,
                uint64_t& rays, uint64_t& nonfinite) {
    accumulation(avx2)(sums, pixels, results, count, rays, nonfinite);
}

}  // namespace kr
