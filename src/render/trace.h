// The tracing entry points: one radiance sample for a camera ray (trace_sample,
// integrator.cpp), and many at once in SIMD lanes where the settings' kernels and the scene
// allow (render/lanes/). The progressive driver (render/progressive.h) calls them per pass.
#pragma once

#include <cstdint>

#include "core/enum_names.h"
#include "core/math.h"
#include "render/lanes/targets.h"
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

// One sample's camera ray (CameraModel::generate), its sampler giving the sub-pixel position
// and the lens numbers (skipped for a pinhole): one path's, and the lanes' where a sampler
// is not a Sobol one at its first dimension.
inline Ray camera_ray(const RenderScene& scene, int width, int height, int x, int y, Sampler& sampler) {
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
// (skipped for a pinhole). Four at a time in SIMD lanes (lanes/lanes.cpp, where
// lane_kernels() below has lanes) for Sobol samplers (pinhole or thin lens), each ray as one at a time gives
// it up to rounding.
void camera_rays(const RenderScene& scene, const RenderSettings& settings, int width, int height, const int* xs, const int* ys,
                 Sampler* const* samplers, int count, Ray* rays);

// `count` samples at once, each as trace_sample gives it up to rounding. Path tracing takes
// camera rays in SIMD lanes (lanes/lanes.cpp: sixteen or eight paths in single precision, or
// four in double, as lane_kernels() below says), a lane starting the next sample as its path
// ends, where the scene is one leaf of our BVH; anything else goes one by one through
// trace_sample. render_pass hands it up to kSampleBatch samples: the more, the less time
// lanes idle at the batch's end (docs/performance.md, "Design choices and their figures").
inline constexpr int kSampleBatch = 512;
void trace_samples(const RenderScene& scene, const RenderSettings& settings, const Ray* rays, Sampler* const* samplers,
                   int count, SampleResult* results);

// camera_rays, then trace_samples: `count` camera samples at pixels (xs, ys). The
// single-precision lanes make the camera rays themselves (pinhole or thin lens), eight at a
// time, for Sobol samplers (the same samples; lanes/lanes.cpp).
void trace_camera_samples(const RenderScene& scene, const RenderSettings& settings, int width, int height,
                          const int* xs, const int* ys, Sampler* const* samplers, int count, SampleResult* results);

// The kernels whose lanes cast first hits for camera_hits and camera_surfaces: lane_kernels'
// choice for path tracing with these settings, whatever their integrator (once per image: under
// `best` the float lanes' size check may walk the scene's spheres).
LaneKernels casting_kernels(const RenderScene& scene, const RenderSettings& settings);
// The closest hit of each of `count` camera rays (from no sphere, over [0, inf); hit.sphere
// -1: none), as intersects gives it up to rounding: the sphere cast for in the lanes of
// `kernels` (casting_kernels), its hit then taken in double (RenderScene::hit_on), so that
// where the lanes find intersects' sphere (all but grazing rays) the hit is intersects' to
// double's rounding; one by one for one path. The viewer's first surfaces, and the feature
// buffers' (render/aov.h).
void camera_hits(LaneKernels kernels, const RenderScene& scene, const Ray* rays, int count, Hit* hits);
// camera_hits' rule for one ray whose closest sphere the lanes found (`sphere`, -1: none): its
// hit on that sphere in double, or where the double test misses it (a graze the lanes rounded
// into a hit) the closest hit one by one.
Hit lanes_sphere_hit(const RenderScene& scene, const Ray& ray, int sphere);
// The first surfaces of `count` camera samples of Sobol samplers known by their pixel keys and
// bit-reversed sample indices (as trace_sobol_camera_samples takes them), made and cast in the
// single-precision lanes of `kernels` (casting_kernels): the sphere each camera ray hits first
// (-1: none) and the unit normal there, facing the ray (3 floats a sample), to the lanes'
// rounding of one path's. False, and nothing written, where `kernels` are not such lanes (the
// caller traces one by one). The feature buffers' first hits (render/aov.h).
bool camera_surfaces(LaneKernels kernels, const RenderScene& scene, int width, int height, const int* xs,
                     const int* ys, const uint32_t* keys, const uint32_t* index_reversed, int count, int* spheres,
                     float* normals);

// What trace_samples runs for path tracing with these settings on this scene (a SIMD target
// of render/lanes/targets.h, or one path), as the settings' kernels, the CPU and the scene
// decide (under `best`, each target only up to the sphere count where one path at a time
// becomes the faster: lanes/lanes.cpp).
LaneKernels lane_kernels(const RenderScene& scene, const RenderSettings& settings);
// The kernels this CPU runs for `choice` before a scene has a say (a scene whose sizes keep
// the float lanes out gets the double ones): what `keithray --version` reports.
LaneKernels cpu_lane_kernels(LaneChoice choice);

// Whether these kernels (lane_kernels' answer) make camera rays and trace paths in lanes
// straight from Sobol samples given as keys and indices (trace_sobol_camera_samples): the
// float lanes.
bool sobol_camera_lanes(LaneKernels kernels);
// trace_camera_samples for `count` samples of Sobol samplers known by their pixel keys and
// bit-reversed sample indices, each the sampler Sampler(keys[i], reverse_bits(
// index_reversed[i])) before it has drawn anything; `kernels` is lane_kernels' answer for
// the scene and settings. Where sobol_camera_lanes(kernels) holds and the batch has more
// than one sample, no Sampler is made (render_pass's batches); otherwise the samplers are
// made and trace_camera_samples takes them.
void trace_sobol_camera_samples(LaneKernels kernels, const RenderScene& scene, const RenderSettings& settings,
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
