// The progressive rendering API: settings + state + render_pass(), which adds one sample to
// every pixel. The CLI loops over it; the viewer calls it from its render thread.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "core/image.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "render/light.h"
#include "render/render_scene.h"
#include "render/sampler.h"

namespace kr {

enum class Integrator { wrt, pt, pt_naive };
inline constexpr EnumNames<Integrator, 3> integrator_names{{"wrt", "pt", "pt-naive"}};

// Distance recorded in the depth map for a primary ray that hits nothing.
inline constexpr double kMissDepth = 1e6;

// How a pass spreads its samples over the pixels: one each, or (adaptive) as many in total,
// each pixel's share in proportion to its estimated noise, once every pixel has a few
// samples. The brief's stratified estimator needs exactly its s samples per pixel, so it
// always gets one each.
enum class Allocation { uniform, adaptive };
inline constexpr EnumNames<Allocation, 2> allocation_names{{"uniform", "adaptive"}};

struct RenderSettings {
    Integrator integrator = Integrator::pt;
    Estimator estimator = Estimator::sobol;
    Allocation allocation = Allocation::adaptive;
    LightSampling light_sampling = LightSampling::brief;
    int max_depth = 6;          // scattering events per path, 0..kMaxDepth
    int target_spp = 1;         // s of the stratified estimator: e = floor(sqrt(s)) strata per axis
    int rr_depth = 3;           // Russian roulette from this many scattering events on
    uint64_t seed = 0;

    // Defaults from the scene file's renderer block.
    static RenderSettings from_scene(const RendererSettings& renderer);
};

struct RenderState {
    int width = 0, height = 0;
    std::vector<Color> radiance_sum;      // per pixel, sum of sample radiance
    std::vector<double> depth_sum;        // per pixel, sum of primary hit distances
    std::vector<double> luminance_sq_sum; // per pixel, sum of squared sample luminance
    std::vector<Color> radiance_sq_sum;   // per pixel and channel, sum of squared sample radiance
    std::vector<uint32_t> sample_count;   // per pixel, samples accumulated
    std::vector<uint32_t> sample_index;   // per pixel, samples drawn (accumulated + dropped)
    int passes = 0;                       // completed passes
    uint64_t rays = 0;                    // every ray cast: camera, bounce and shadow rays
    uint64_t nonfinite_samples = 0;       // samples dropped for NaN/Inf radiance
    // The noise rule (update_adaptive): render_pass samples only pixels whose entry is 1
    // (empty: all of them).
    std::vector<uint8_t> active;
    // Samples per pixel in the next pass, set by plan_pass (empty: one each).
    std::vector<uint8_t> pass_samples;
    std::vector<float> sample_credit;  // adaptive allocation: fractions of a sample carried over
    std::array<std::vector<double>, 3> allocation_scratch;  // plan_pass's and update_adaptive's buffers
    // The Sobol samplers' per-pixel keys (Sampler::pixel_key) for sobol_keys_seed: the same in
    // every pass, so render_pass works them out once (empty until a Sobol pass).
    std::vector<uint32_t> sobol_keys;
    uint64_t sobol_keys_seed = 0;

    RenderState() = default;
    RenderState(int w, int h) { reset(w, h); }
    void reset(int w, int h);
    Image radiance() const;                  // per-pixel mean radiance
    std::vector<double> mean_depth() const;  // per-pixel mean primary distance
    // Per pixel and channel, the variance of the mean radiance: the unbiased sample variance
    // over the count (infinite below two samples). What `keithray compare --statistical` tests.
    std::vector<Color> variance_of_mean() const;

    // Unbiased variance of one sample's luminance in pixel `i` (infinite below two samples).
    double sample_variance(size_t i) const;
    // Standard error of pixel `i`'s mean luminance, from its sample variance (infinite below
    // two samples).
    double pixel_standard_error(size_t i) const;
    // Estimated relative RMS error of the whole image: sqrt(sum of per-pixel variances of the
    // mean) / sqrt(sum of squared mean luminances). Infinite before two samples per pixel.
    double relative_error() const;

    // Adaptive sampling towards an image relative error `target` (as relative_error()): a
    // pixel stays active while the variance of its mean exceeds an equal share of the allowed
    // total, target^2 * sum(mean^2) / pixels, or it has fewer than `min_samples` samples.
    // When no pixel is active the image meets the target. Returns the active count.
    size_t update_adaptive(double target, uint32_t min_samples = 16);

    // Plans the next pass for `settings.allocation` (fills pass_samples). Adaptive: after
    // kAllocationWarmup passes, each active pixel's share of the pass (as many samples as
    // active pixels) is proportional to its estimated standard deviation (3x3 guarded, as
    // update_adaptive) plus a floor, which minimises the summed variance of the pixel means
    // for the budget; fractions carry over between passes. Parallel over rows, with the rows'
    // sums added in order: the plan does not depend on threads.
    void plan_pass(const RenderSettings& settings);
};

// The bytes per pixel a RenderState holds once every buffer is in use: the six sums and
// counts, the adaptive mask, the pass plan and its credit, the three allocation buffers and
// the Sobol keys.
inline constexpr uint64_t kRenderStateBytesPerPixel =
    2 * sizeof(Color) + 2 * sizeof(double) + 2 * sizeof(uint32_t) + 2 * sizeof(uint8_t) + sizeof(float) +
    3 * sizeof(double) + sizeof(uint32_t);

// An upper estimate of the memory a render of width x height pixels holds at its peak: the
// RenderState, then at the end the mean radiance (and, when blurred, two more radiance images),
// the mean depth, and the larger output stage: the two 8-bit images and their encoded bytes,
// or an EXR's 14 float layers and its encoded bytes.
uint64_t render_memory_bytes(int width, int height, bool blurred);

inline constexpr int kAllocationWarmup = 8;        // passes of one sample each before adapting
inline constexpr double kAllocationFloor = 0.25;   // every pixel's share is at least this x mean
inline constexpr int kMaxPassSamples = 64;         // per pixel and pass

// Adds one sample to every pixel of `state`, or the number state.pass_samples gives (sample
// index = the pixel's own count of samples drawn).
// Parallel over rows with OpenMP; each sample has its own RNG stream seeded by
// (seed, pixel, sample index), so the image does not depend on threads or scheduling.
// If `stop` becomes true the pass ends early and returns false; pixels it reached keep their
// sample, others do not, so the state stays a valid (unevenly sampled) estimate.
bool render_pass(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                 const std::atomic<bool>* stop = nullptr);

// When a progressive render stops: after `max_passes`, after `seconds` of wall time (checked
// between passes), or when the estimated relative error reaches `noise` (adaptive sampling
// then spends passes only on pixels above their share of the error). 0 disables a rule.
struct StopRule {
    int max_passes = 1;
    double seconds = 0;
    double noise = 0;
    uint32_t min_samples = 16;  // per pixel before the noise rule trusts a variance
    int adapt_every = 4;        // passes between updates of the adaptive mask
};

enum class StopReason { passes, time, noise, cancelled };

// The driver's extension points for a render shared by several processes (app/cluster.h
// deals pixels to MPI ranks through them). Each pixel's samples are drawn by one process in
// the single-process order, so the sums are those of one process, bit for bit.
class PassHooks {
public:
    virtual ~PassHooks() = default;
    // After plan_pass, before render_pass: narrows the pass to this process's pixels.
    virtual void before_pass(RenderState& state) = 0;
    // After render_pass: undoes before_pass; when `statistics`, the next step reads the whole
    // image's statistics (plan_pass, update_adaptive, relative_error), so every process must
    // then hold every pixel's radiance_sum, luminance_sq_sum and sample_count.
    virtual void after_pass(RenderState& state, bool statistics) = 0;
    // One stop decision for all processes: whether any of them says `stop` (e.g. --time).
    virtual bool any(bool stop) = 0;
};

// Whether plan_pass reads the image's statistics for the next pass (adaptive allocation
// after its warm-up).
bool plan_reads_statistics(const RenderSettings& settings, const RenderState& state);

// Runs passes until a rule stops it: state.passes counts towards rule.max_passes, so a state
// restored from a checkpoint (render/checkpoint.h) goes on as if never stopped. `on_pass`,
// if given, is called after each pass and may return false to cancel; `hooks` spread the
// passes over processes.
StopReason render_until(const RenderScene& scene, const RenderSettings& settings, RenderState& state,
                        const StopRule& rule, const std::function<bool(const RenderState&)>& on_pass = {},
                        PassHooks* hooks = nullptr);

// The camera's image coordinates in [0,1]^2 of a point (x, y) of the raster, where pixel
// (i, j) spans [i, i+1) x [j, j+1), top row first. The brief's references put each pixel half
// a pixel left of and half a pixel below that square (measured on all eight scenes: the
// discs of scene 5's lights sit 0.5 px right of and 0.5 px above ours, and shifting our
// renders so raised PSNR by 1.2 to 4 dB everywhere; docs/fidelity.md), so the camera sees
// (x - 1/2, y + 1/2).
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
// below has lanes) for Sobol samplers and a pinhole, each ray as one at a time gives it up
// to rounding.
void camera_rays(const RenderScene& scene, int width, int height, const int* xs, const int* ys,
                 Sampler* const* samplers, int count, Ray* rays);

// `count` samples at once, each as trace_sample gives it up to rounding. Path tracing takes
// camera rays in SIMD lanes (packet.cpp: eight paths in single precision, or four in double,
// as packet_kernels() below says), a lane starting the next sample as its path ends, where
// the scene is one leaf of our BVH; anything else goes one by one through trace_sample.
// render_pass hands it up to kSampleBatch samples: the more, the less time lanes idle at the
// batch's end.
inline constexpr int kSampleBatch = 64;
void trace_samples(const RenderScene& scene, const RenderSettings& settings, const Ray* rays, Sampler* const* samplers,
                   int count, SampleResult* results);

// camera_rays, then trace_samples: `count` camera samples at pixels (xs, ys). The
// single-precision lanes make a pinhole's camera rays themselves, eight at a time, for
// Sobol samplers (the same samples; packet.cpp).
void trace_camera_samples(const RenderScene& scene, const RenderSettings& settings, int width, int height,
                          const int* xs, const int* ys, Sampler* const* samplers, int count, SampleResult* results);

// How camera_rays and trace_samples trace (packet.cpp), process-wide. `best`: in SIMD lanes
// with the kernels built for x86-64-v3 where the CPU has AVX2 and FMA, else one path at a
// time (the kernels built for any x86-64 CPU are slower than that); eight paths in single
// precision where the scene's sizes fit it (float_lanes_fit), else four in double. `double`:
// always the four double lanes where the CPU has them; `any`: in lanes with the kernels for
// any CPU; `one_path`: one at a time. The last three are for tests and comparisons.
enum class PacketIsa { best, double_lanes, any, one_path };
inline constexpr EnumNames<PacketIsa, 4> packet_isa_names{{"best", "double", "any", "off"}};
void set_packet_isa(PacketIsa isa);
// What trace_samples runs for path tracing with these settings on this scene, as
// set_packet_isa, the CPU and the scene decide.
enum class PacketKernels { x86_64_v3_float, x86_64_v3, x86_64, one_path };
inline constexpr EnumNames<PacketKernels, 4> packet_kernels_names{
    {"x86-64-v3 float lanes", "x86-64-v3 lanes", "x86-64 lanes", "one path"}};
PacketKernels packet_kernels(const RenderScene& scene, const RenderSettings& settings);
// Whether single-precision lanes keep the scene: their rounding, about 2^-24 of the largest
// distance a sphere test meets, stays below 2^-12 of the smallest radius, every length is
// within 2^-40 to 2^40 (its square a normal float), and its lights' radiance stays far
// inside their range (2^-60 to 2^60; a light of 1e30 is double's).
bool float_lanes_fit(const RenderScene& scene);

}  // namespace kr
