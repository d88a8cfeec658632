// The SIMD targets: each a build of the path-tracing kernels (kernels.cpp) for one CPU level
// (levels.h) and one lane type. CMake reads the rows below and compiles kernels.cpp once per
// row (CMakeLists.txt, "SIMD lanes"); lanes.cpp picks among them. A new target is a row here
// and its lane type in math.h.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/enum_names.h"

// X(id, what `--version` and the stats call it, CPU level, lane number type, lanes, the most
//   spheres `best` gives it beyond one BVH leaf beside Embree's tree, the same down our own
//   tree). The sphere limits: where one path at a time becomes the faster, measured on the
//   stress scenes (docs/performance.md, "Switch points"); the sixteen float lanes' are the
//   lane tree's own limits, measured per kind of CPU: kThisCpusLimit, lane_tree_limits() of
//   the CPU it runs on (accel.h), looked up when a scene's kernels are chosen, so that the
//   rows stay constants.
#define KR_LANE_TARGETS(X)                                                                            \
    X(x86_64_v3_float, "x86-64-v3 float lanes", x86_64_v3, float, 8, 768, 1024)                    \
    X(x86_64_v3, "x86-64-v3 lanes", x86_64_v3, double, 4, 128, 320)                                 \
    X(x86_64, "x86-64 lanes", x86_64, double, 4, 128, 320)                                          \
    X(x86_64_v4_float, "x86-64-v4 float lanes", x86_64_v4, float, 16, kThisCpusLimit, kThisCpusLimit)

namespace kr {

inline constexpr size_t kThisCpusLimit = 0;  // a sphere limit of the CPU's own (above)

struct PixelSums;
struct Ray;
struct RenderScene;
struct RenderSettings;
struct SampleResult;
class Sampler;

// What traces a batch of paths: one of the targets above, or one path at a time.
#define KR_LANE_TARGET_ID(id, ...) id,
enum class LaneKernels { KR_LANE_TARGETS(KR_LANE_TARGET_ID) one_path };
#undef KR_LANE_TARGET_ID
#define KR_LANE_TARGET_LABEL(id, label, ...) label,
inline constexpr EnumNames<LaneKernels, size_t(LaneKernels::one_path) + 1> lane_kernels_names{
    {KR_LANE_TARGETS(KR_LANE_TARGET_LABEL) "one path"}};
#undef KR_LANE_TARGET_LABEL

// Whether the kernels trace in single precision, and how many paths at a time (one for one path).
#define KR_LANE_TARGET_SINGLE(id, label, level, real, ...) \
    case LaneKernels::id: return sizeof(real) < sizeof(double);
constexpr bool single_precision(LaneKernels kernels) {
    switch (kernels) {
        KR_LANE_TARGETS(KR_LANE_TARGET_SINGLE)
    case LaneKernels::one_path: break;
    }
    return false;
}
#undef KR_LANE_TARGET_SINGLE
#define KR_LANE_TARGET_WIDTH(id, label, level, real, width, ...) \
    case LaneKernels::id: return width;
constexpr int lane_count(LaneKernels kernels) {
    switch (kernels) {
        KR_LANE_TARGETS(KR_LANE_TARGET_WIDTH)
    case LaneKernels::one_path: break;
    }
    return 1;
}
#undef KR_LANE_TARGET_WIDTH

namespace lanes {

// A target's entry points (kernels.cpp says what each does); null where the target has none:
// the single-precision targets take their camera rays from a double one (camera_rays), and
// only they make camera rays from Sobol keys (trace_sobol_camera, trace_camera,
// camera_surfaces).
struct TargetKernels {
    bool built;  // false where this build cannot compile the target (CMakeLists.txt)
    void (*camera_rays)(const RenderScene& scene, int width, int height, const int* xs, const int* ys,
                        Sampler* const* samplers, int count, Ray* rays);
    void (*trace_rays)(const RenderScene& scene, const RenderSettings& settings, const Ray* rays,
                       Sampler* const* samplers, int count, SampleResult* results);
    void (*trace_sobol_camera)(const RenderScene& scene, const RenderSettings& settings, int width, int height,
                               const int* xs, const int* ys, const uint32_t* keys, const uint32_t* index_reversed,
                               int count, SampleResult* results);
    void (*trace_camera)(const RenderScene& scene, const RenderSettings& settings, int width, int height,
                         const int* xs, const int* ys, Sampler* const* samplers, int count, SampleResult* results);
    // A batch's samples added to their pixels (pixel_sums.h's accumulate).
    void (*accumulate)(const PixelSums& sums, const size_t* pixels, const SampleResult* results, int count,
                       uint64_t& rays, uint64_t& nonfinite);
    // The closest sphere of each of `count` rays from the camera (no from or to sphere, tmin 0,
    // tmax infinite), -1 where none: the paths' first cast alone.
    void (*closest_spheres)(const RenderScene& scene, const Ray* rays, int count, int* spheres);
    // The first surfaces of `count` camera samples given as trace_sobol_camera takes them: the
    // sphere each ray hits first (-1: none) and the unit normal there facing the ray (3 floats).
    void (*camera_surfaces)(const RenderScene& scene, int width, int height, const int* xs, const int* ys,
                            const uint32_t* keys, const uint32_t* index_reversed, int count, int* spheres,
                            float* normals);
};

// Each target's, defined by its build of kernels.cpp.
#define KR_LANE_TARGET_DECLARE(id, ...) \
    namespace id {                      \
    extern const TargetKernels kernels; \
    }
KR_LANE_TARGETS(KR_LANE_TARGET_DECLARE)
#undef KR_LANE_TARGET_DECLARE

}  // namespace lanes
}  // namespace kr
