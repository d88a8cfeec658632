// The tracing entry points: one radiance sample for a camera ray (trace_sample,
// integrator.cpp), and many at once in SIMD lanes where the settings' kernels and the scene
// allow (packet.cpp). The progressive driver (render/progressive.h) calls them per pass.
#pragma once

#include <cstdint>

#include "core/enum_names.h"
#include "core/math.h"
#include "render/render_scene.h"
#include "render/sampler.h"
#include "render/settings.h"

namespace kr {

// Distance recorded in the depth map for a primary ray that hits nothing (a hit farther
// away keeps its own distance, so it is never taken for a miss).
inline constexpr double kMissDepth = 1e6;

// The camera's image coordinates in [0,1]^2 of a point (x, y) of the raster, where pixel
// (i, j) spans [i, i+1) x [j, j+1), top row first. The brief's references put each pixel half
// a pixel left of and half a pixel below that square (docs/fidelity.md, "The references'
// pixel grid"), so the camera sees (x - 1/2, y + 1/2).
inline Vec2 raster_to_camera(double x, double y, int width, int height) {
    return {(x - 0.5) / width, (y + 0.5) / height};
}

// One radiance sample for a camera ray, for tests and tools: the integrator the settings name.
struct SampleResult {
    Color radiance;
    double primary_distance = kMissDepth;
    uint64_t rays = 0;
};
// `sampler` has given the sub-pixel and lens numbers already (or none, for a hand-made ray).
SampleResult trace_sample(const RenderScene& scene, const RenderSettings& settings, const Ray& ray,
                          Sampler& sampler);
// The camera rays of `count` samples of pixels (xs[i], ys[i]) of a width x height image, each
// sampler having given nothing yet: it gives the sub-pixel position and the lens numbers
// (skipped for a pinhole). Four at a time in SIMD lanes (packet.cpp, where packet_kernels()
// below has lanes) for Sobol samplers (pinhole or thin lens), each ray as one at a time gives
// it up to rounding.
void camera_rays(const RenderScene& scene, const RenderSettings& settings, int width, int height, const int* xs, const int* ys,
                 Sampler* const* samplers, int count, Ray* rays);

// `count` samples at once, each as trace_sample gives it up to rounding. Path tracing takes
// camera rays in SIMD lanes (packet.cpp: sixteen or eight paths in single precision, or four
// in double, as packet_kernels() below says), a lane starting the next sample as its path
// ends, where the scene is one leaf of our BVH; anything else goes one by one through
// trace_sample. render_pass hands it up to kSampleBatch samples: the more, the less time
// lanes idle at the batch's end (docs/performance.md, "Design choices and their figures").
inline constexpr int kSampleBatch = 512;
void trace_samples(const RenderScene& scene, const RenderSettings& settings, const Ray* rays, Sampler* const* samplers,
                   int count, SampleResult* results);

// camera_rays, then trace_samples: `count` camera samples at pixels (xs, ys). The
// single-precision lanes make the camera rays themselves (pinhole or thin lens), eight at a
// time, for Sobol samplers (the same samples; packet.cpp).
void trace_camera_samples(const RenderScene& scene, const RenderSettings& settings, int width, int height,
                          const int* xs, const int* ys, Sampler* const* samplers, int count, SampleResult* results);

// What trace_samples runs for path tracing with these settings on this scene, as the
// settings' kernels, the CPU and the scene decide (under `best`, each kind of lanes only up
// to the sphere count where one path at a time becomes the faster: packet.cpp).
enum class PacketKernels { x86_64_v3_float, x86_64_v3, x86_64, one_path, x86_64_v4_float };
inline constexpr EnumNames<PacketKernels, 5> packet_kernels_names{
    {"x86-64-v3 float lanes", "x86-64-v3 lanes", "x86-64 lanes", "one path", "x86-64-v4 float lanes"}};
PacketKernels packet_kernels(const RenderScene& scene, const RenderSettings& settings);
// The kernels this CPU runs for `isa` before a scene has a say (a scene whose sizes keep
// the float lanes out gets the double ones): what `keithray --version` reports.
PacketKernels cpu_kernels(PacketIsa isa);

// Whether these kernels (packet_kernels' answer) make camera rays and trace paths in lanes
// straight from Sobol samples given as keys and indices (trace_sobol_camera_samples): the
// float lanes.
bool sobol_camera_lanes(PacketKernels kernels);
// trace_camera_samples for `count` samples of Sobol samplers known by their pixel keys and
// bit-reversed sample indices, each the sampler Sampler(keys[i], reverse_bits(
// index_reversed[i])) before it has drawn anything; `kernels` is packet_kernels' answer for
// the scene and settings. Where sobol_camera_lanes(kernels) holds and the batch has more
// than one sample, no Sampler is made (render_pass's batches); otherwise the samplers are
// made and trace_camera_samples takes them.
void trace_sobol_camera_samples(PacketKernels kernels, const RenderScene& scene, const RenderSettings& settings,
                                int width, int height, const int* xs, const int* ys, const uint32_t* keys,
                                const uint32_t* index_reversed, int count, SampleResult* results);

// Whether single-precision lanes keep the scene: their rounding, about 2^-24 of the largest
// distance a sphere test meets, stays below 2^-12 of the sphere's radius (float_sizes_fit,
// render/precision.h: at once where the whole scene is within 2^12 smallest radii, else
// sphere by sphere over the points rays can reach), every length is
// within 2^-40 to 2^40 (its square a normal float), and its lights' radiance stays far
// inside their range (2^-60 to 2^60; a light of 1e30 is double's), and its rays resolve
// the gaps between its surfaces and lights (scene.float_gaps_resolved, render/precision.h).
bool float_lanes_fit(const RenderScene& scene);

}  // namespace kr
