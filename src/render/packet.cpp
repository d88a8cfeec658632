// Path tracing of several samples at once, their paths in the lanes of SIMD registers (AVX2
// where the CPU has it). Casting rays, hit records, Sobol numbers, the light choice, the
// `brief` and `cone` light samples, every material's scattering, throughput and Russian
// roulette run lane-wise: the physics through the same templates as one path (vertex.h),
// the lanes' own maths as copies of core's, operation for operation; the other light
// samples, emission weights and other estimators' numbers run per lane through the same
// functions as one path (path.h). So every path is the one trace_sample gives, up to
// rounding. docs/performance.md ("Paths in lanes" and after) has what it buys.
//
// The kernels are in packet_lanes.inc, compiled four times: four double lanes for any
// x86-64 CPU and for x86-64-v3 (AVX2, FMA), eight single-precision lanes for x86-64-v3 and
// sixteen for x86-64-v4 (AVX-512). The v3 ones run where the CPU has those (the CPU is asked
// once, at the first call): the single-precision lanes where float_lanes_fit says the
// scene's sizes and radiances keep their rounding far below what an image shows (they then
// agree with one path to about 1e-6 per step; tests/test_packet.cpp), sixteen of them where
// the CPU has AVX-512; the double ones elsewhere. Without AVX2 paths are traced
// one at a time: GCC emulates what SSE2 lacks (64-bit compares, per-lane shifts, 32-bit
// multiplies) lane by lane, so the kernels for any CPU are 2.5 times slower than one path at
// a time (docs/performance.md); they run only when the settings' `kernels` ask for them, for
// tests and comparisons.
#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/sampling.h"
#include "render/lanes.h"
#include "render/path.h"
#include "render/precision.h"
#include "render/trace.h"
#include "render/vertex.h"

// Clang builds (the sanitizer presets) compile this whole file for x86-64-v3 where CMake's
// KEITHRAY_CLANG_V3_KERNELS asks, instead of the target pragma below (CMakeLists.txt).
#if defined(KR_PACKET_FILE_V3) && defined(__AVX2__) && defined(__FMA__) && !defined(KR_X86_64_V3)
#define KR_X86_64_V3 1
#endif
// The sixteen float lanes (x86-64-v4: AVX-512 F, BW, DQ, VL) beside them: GCC by its target
// pragma wherever it builds the v3 kernels, Clang where CMake compiles the file for x86-64-v4.
#if defined(KR_X86_64_V3) && (!defined(KR_PACKET_FILE_V3) || (defined(__AVX512F__) && defined(__AVX512BW__) && \
                                                             defined(__AVX512DQ__) && defined(__AVX512VL__)))
#define KR_X86_64_V4 1
#endif

#ifdef KR_X86_64_V3
#include <immintrin.h>
#endif

namespace kr {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// A one-leaf scene has at most 16 spheres: the lanes keep its per-sphere values in fixed
// columns of 16.
constexpr size_t kMaxPacketSpheres = 16;

#ifdef KR_X86_64_V4
// Whether the CPU has GFNI, for the sixteen lanes' Sobol bit reversal (lane_sobol.inc).
bool cpu_has_gfni() {
    static const bool has = [] {
        __builtin_cpu_init();
        return __builtin_cpu_supports("gfni") != 0;
    }();
    return has;
}
#endif

// Where packets apply: path tracing on a scene whose rays the lanes can cast (one leaf of our
// BVH, or the lane tree: SphereBvh::packets), not the plain path. Scenes with Embree's tree
// only cast rays one by one.
bool packets_apply(const RenderScene& scene, const RenderSettings& settings) {
    return settings.integrator != Integrator::wrt && !scene.linear_scan && scene.bvh.packets();
}

// One sample's camera ray (CameraModel::generate), its sampler giving the sub-pixel position
// and the lens numbers (skipped for a pinhole).
Ray camera_ray(const RenderScene& scene, int width, int height, int x, int y, Sampler& sampler) {
    const CameraModel& camera = scene.camera;
    const Vec2 sub = sampler.pixel();
    Vec2 lens;
    if (camera.lens_radius > 0) lens = sampler.next_2d();
    else sampler.skip_2d();  // a pinhole's image stays the same as a tiny lens's
    const Vec2 film = raster_to_camera(x + sub.x, y + sub.y, width, height);
    const CameraRay cr = camera.generate(film.x, film.y, lens.x, lens.y);
    Ray ray;
    ray.o = cr.origin;
    ray.d = cr.direction;
    return ray;
}

}  // namespace

namespace packet_any {
#include "render/packet_lanes.inc"
}  // namespace packet_any

#ifdef KR_X86_64_V3
#ifndef KR_PACKET_FILE_V3
#pragma GCC push_options
#pragma GCC target("arch=x86-64-v3")
#endif
#define KR_PACKET_TARGET_V3
namespace packet_v3 {
#include "render/packet_lanes.inc"
}  // namespace packet_v3
#define KR_PACKET_FLOAT8
namespace packet_f8 {
#include "render/packet_lanes.inc"
}  // namespace packet_f8
#undef KR_PACKET_FLOAT8
#undef KR_PACKET_TARGET_V3
#ifndef KR_PACKET_FILE_V3
#pragma GCC pop_options
#endif
#endif

#ifdef KR_X86_64_V4
#ifndef KR_PACKET_FILE_V3
#pragma GCC push_options
#pragma GCC target("arch=x86-64-v4")
#endif
// Sixteen single-precision lanes: the same source as packet_f8 (KR_PACKET_FLOAT8: single
// precision), KR_PACKET_FLOAT16 picking the AVX-512 forms of its few intrinsics.
#define KR_PACKET_FLOAT8
#define KR_PACKET_FLOAT16
namespace packet_f16 {
#include "render/packet_lanes.inc"
}  // namespace packet_f16
#undef KR_PACKET_FLOAT16
#undef KR_PACKET_FLOAT8
#ifndef KR_PACKET_FILE_V3
#pragma GCC pop_options
#endif
#endif

namespace {

bool cpu_has_v3() {
#ifdef KR_X86_64_V3
    static const bool has = [] {
        __builtin_cpu_init();
#ifdef __clang__  // Clang 14 knows no "x86-64-v3" here: its two features this file's code needs
        return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
        return __builtin_cpu_supports("x86-64-v3") != 0;
#endif
    }();
    return has;
#else
    return false;
#endif
}

bool cpu_has_v4() {
#ifdef KR_X86_64_V4
    static const bool has = [] {
        __builtin_cpu_init();
#ifdef __clang__  // as above: the AVX-512 subsets x86-64-v4 names
        return cpu_has_v3() && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
               __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
#else
        return __builtin_cpu_supports("x86-64-v4") != 0;
#endif
    }();
    return has;
#else
    return false;
#endif
}

// The single-precision lanes the CPU runs best: sixteen with AVX-512, else eight.
PacketKernels float_kernels() {
    return cpu_has_v4() ? PacketKernels::x86_64_v4_float : PacketKernels::x86_64_v3_float;
}

// The kernels the CPU and the settings pick, before a scene has a say (camera rays are the
// double lanes' in both kinds of v3 lanes).
PacketKernels isa_kernels(const RenderSettings& settings) {
    switch (settings.kernels) {
    case PacketIsa::best: return cpu_has_v3() ? float_kernels() : PacketKernels::one_path;
    case PacketIsa::float8: return cpu_has_v3() ? PacketKernels::x86_64_v3_float : PacketKernels::one_path;
    case PacketIsa::double_lanes: return cpu_has_v3() ? PacketKernels::x86_64_v3 : PacketKernels::one_path;
    case PacketIsa::any: return PacketKernels::x86_64;
    case PacketIsa::one_path: return PacketKernels::one_path;
    }
    return PacketKernels::one_path;
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
    for (const AreaLight& light : scene.area_lights)
        if (!in_range(light.radiance)) return false;
    for (const PointLight& light : scene.point_lights)
        if (!in_range(light.intensity)) return false;
    // Gaps: surfaces and lights no nearer each other than the lanes' rounding resolves.
    // Sizes (last, the dearest): each sphere's tests round to well under its radius
    // (float_sizes_fit, precision.h), once per pass.
    return scene.float_gaps_resolved && float_sizes_fit(scene);
}

PacketKernels cpu_kernels(PacketIsa isa) {
    RenderSettings settings;
    settings.kernels = isa;
    return isa_kernels(settings);
}

namespace {

// The most spheres each kind of lanes takes under `best` (beyond one leaf) before one path at
// a time is the faster: down Embree's tree where `automatic` built it beside the lanes' tree,
// else down our own. Measured on the stress scenes, one thread, CPU time (`bench --stress N
// --accel own,embree --kernels K --cpu-time --threads 1`; docs/performance.md, "Switch
// points"). The sixteen float lanes' are the lane tree's own limits (accel.h).
size_t lanes_max_spheres(PacketKernels kernels, bool beside_embree) {
    switch (kernels) {
    case PacketKernels::x86_64_v4_float: return beside_embree ? kLaneTreeMaxSpheres : kLaneOwnMaxSpheres;
    case PacketKernels::x86_64_v3_float: return beside_embree ? 768 : 1024;
    case PacketKernels::x86_64_v3:
    case PacketKernels::x86_64: return beside_embree ? 128 : 320;
    case PacketKernels::one_path: break;
    }
    return std::numeric_limits<size_t>::max();
}

}  // namespace

PacketKernels packet_kernels(const RenderScene& scene, const RenderSettings& settings) {
    if (!packets_apply(scene, settings)) return PacketKernels::one_path;
    PacketKernels kernels = isa_kernels(settings);
    if ((kernels == PacketKernels::x86_64_v3_float || kernels == PacketKernels::x86_64_v4_float) &&
        !float_lanes_fit(scene))
        kernels = PacketKernels::x86_64_v3;
    // Kernels asked for by name run wherever they can (to measure them); `best` only where
    // they are the faster.
    if (settings.kernels == PacketIsa::best && !scene.bvh.one_leaf() &&
        scene.spheres.size() > lanes_max_spheres(kernels, scene.bvh.backend() == AccelBackend::embree))
        return PacketKernels::one_path;
    return kernels;
}

void camera_rays(const RenderScene& scene, const RenderSettings& settings, int width, int height, const int* xs,
                 const int* ys, Sampler* const* samplers, int count, Ray* rays) {
    switch (isa_kernels(settings)) {
#ifdef KR_X86_64_V3
    case PacketKernels::x86_64_v4_float:
    case PacketKernels::x86_64_v3_float:
    case PacketKernels::x86_64_v3: return packet_v3::camera_rays(scene, width, height, xs, ys, samplers, count, rays);
#endif
    case PacketKernels::x86_64: return packet_any::camera_rays(scene, width, height, xs, ys, samplers, count, rays);
    default:
        for (int k = 0; k < count; ++k) rays[k] = camera_ray(scene, width, height, xs[k], ys[k], *samplers[k]);
    }
}

void trace_samples(const RenderScene& scene, const RenderSettings& settings, const Ray* rays, Sampler* const* samplers,
                   int count, SampleResult* results) {
    const PacketKernels kernels = count > 1 ? packet_kernels(scene, settings) : PacketKernels::one_path;
    bool camera_rays = kernels != PacketKernels::one_path;  // as trace_packet takes them
    for (int k = 0; k < count && camera_rays; ++k)
        camera_rays =
            rays[k].tmin == 0 && rays[k].tmax == kInf && rays[k].from_sphere < 0 && rays[k].to_sphere < 0;
    if (camera_rays) {
#ifdef KR_X86_64_V4
        if (kernels == PacketKernels::x86_64_v4_float)
            return packet_f16::trace_packet(scene, settings, rays, samplers, count, results);
#endif
#ifdef KR_X86_64_V3
        if (kernels == PacketKernels::x86_64_v3_float)
            return packet_f8::trace_packet(scene, settings, rays, samplers, count, results);
        if (kernels == PacketKernels::x86_64_v3)
            return packet_v3::trace_packet(scene, settings, rays, samplers, count, results);
#endif
        packet_any::trace_packet(scene, settings, rays, samplers, count, results);
    } else {
        for (int k = 0; k < count; ++k) results[k] = trace_sample(scene, settings, rays[k], *samplers[k]);
    }
}

bool sobol_camera_lanes(PacketKernels kernels) {
    return kernels == PacketKernels::x86_64_v4_float || kernels == PacketKernels::x86_64_v3_float;
}

void trace_sobol_camera_samples(PacketKernels kernels, const RenderScene& scene, const RenderSettings& settings,
                                int width, int height, const int* xs, const int* ys, const uint32_t* keys,
                                const uint32_t* index_reversed, int count, SampleResult* results) {
#ifdef KR_X86_64_V4
    if (count > 1 && kernels == PacketKernels::x86_64_v4_float)
        return packet_f16::trace_sobol_camera_lanes(scene, settings, width, height, xs, ys, keys, index_reversed, count,
                                                    results);
#endif
#ifdef KR_X86_64_V3
    if (count > 1 && kernels == PacketKernels::x86_64_v3_float)
        return packet_f8::trace_sobol_camera_lanes(scene, settings, width, height, xs, ys, keys, index_reversed, count,
                                                   results);
#endif
    (void)kernels;
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
#ifdef KR_X86_64_V3
    const PacketKernels kernels = count > 1 ? packet_kernels(scene, settings) : PacketKernels::one_path;
    bool sobol = sobol_camera_lanes(kernels);
    for (int k = 0; k < count && sobol; ++k) sobol = samplers[k]->sobol() && samplers[k]->dimension() == 0;
    if (sobol) {
#ifdef KR_X86_64_V4
        if (kernels == PacketKernels::x86_64_v4_float)
            return packet_f16::trace_camera_lanes(scene, settings, width, height, xs, ys, samplers, count, results);
#endif
        return packet_f8::trace_camera_lanes(scene, settings, width, height, xs, ys, samplers, count, results);
    }
#endif
    Ray rays[kSampleBatch];
    for (int first = 0; first < count; first += kSampleBatch) {
        const int n = std::min(kSampleBatch, count - first);
        camera_rays(scene, settings, width, height, xs + first, ys + first, samplers + first, n, rays);
        trace_samples(scene, settings, rays, samplers + first, n, results + first);
    }
}

}  // namespace kr
