// CPU levels: the one way keithray builds code for several CPUs and picks one at run time.
//
// A level is a set of instructions x86-64 CPUs have together: x86-64 (SSE2, every CPU),
// x86-64-v3 (AVX2, FMA, BMI) and x86-64-v4 (AVX-512 F, BW, DQ, VL), as GCC and the psABI name
// them. Code meant for several levels is compiled once per level with that level's target
// options, and the level is picked at run time from what the CPU has. Two spellings of that,
// one list of levels and one CPU test:
//
// - KR_LEVEL_CLONES (or KR_LOOP_CLONES, below) on a function whose source is the same at
//   every level (a loop GCC vectorises, the BVH's block test): GCC compiles it for each level
//   (function multi-versioning) and the loader picks the highest the CPU has.
// - A source whose code differs per level (its lane type, its intrinsics: the SIMD kernels,
//   the pixel sums' accumulation) is compiled once per level by CMake, inside
//   KR_LEVEL_BEGIN / KR_LEVEL_END (the level's `#pragma GCC target`, so the headers included
//   before it stay x86-64 code: no inline function of theirs is emitted with the level's
//   instructions), and cpu_level() picks.
//
// cpu_level() asks the CPU what the clones' resolver asks it (__builtin_cpu_supports of the
// level), so both spellings pick the same level. Why not one spelling: a function clone must
// compile at every level, and the kernels' lane types (eight or sixteen floats) and
// intrinsics exist only at theirs; why not the other: a per-level source per vectorised loop
// would split a file by CPU instead of by concept.
#pragma once

namespace kr {

enum class CpuLevel { x86_64, x86_64_v3, x86_64_v4 };

// The highest level the CPU has (asked once). Without GCC's multi-versioning (Clang, the
// sanitizer builds) the same question, by the features of each level the code needs.
CpuLevel cpu_level();

// The CPU's maker and family (cpuid leaves 0 and 1; the family with its extension), what the
// lanes' switch points are measured per (accel.h, lane_tree_limits). {false, 0} off x86-64.
struct CpuModel {
    bool amd = false;
    int family = 0;
};
CpuModel cpu_model();

}  // namespace kr

// Where GCC multi-versions functions: not under a sanitizer (the loader runs the IFUNC
// resolver while relocating, before the sanitizer's runtime is up, and GCC instruments the
// resolver too: its __tsan_func_entry segfaults).
//
// Products and sums: where a level has FMA, GCC 12 fuses a * b + c into one instruction (in
// ISO C++ mode too), and a fused result may differ in its last bit. KR_LEVEL_CLONES compiles
// for the levels as they are (the BVH's block test fuses at x86-64-v3 and v4).
// KR_LOOP_CLONES, for loops GCC vectorises whose vector form at x86-64-v3 must give the
// x86-64 code's bits (the sampler, the adaptive plan, the denoisers), takes that level
// without FMA (GCC's "avx2"); their x86-64-v4 form fuses. KR_UNFUSED_BEGIN/END, for a
// per-level source's code that must give the x86-64 code's bits at every level (the pixel
// sums, pixel_sums.h), keeps every product unfused.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__) && \
    !defined(__SANITIZE_THREAD__)
#define KR_LEVEL_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#define KR_LOOP_CLONES __attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
#else
#define KR_LEVEL_CLONES
#define KR_LOOP_CLONES
#endif

// A per-level source's level, which CMake names (KR_LEVEL_x86_64_v3 or KR_LEVEL_x86_64_v4;
// none: x86-64): its code between KR_LEVEL_BEGIN and KR_LEVEL_END is compiled for it. GCC
// by its target pragma; Clang cannot mix targets in a file (its ABI check refuses calls
// between them), so CMake compiles such a source whole for its level there (-march), only
// where the build machine has it (CMakeLists.txt).
#define KR_LEVEL_PRAGMA(x) _Pragma(#x)
#if defined(__GNUC__) && !defined(__clang__) && defined(KR_LEVEL_x86_64_v4)
#define KR_LEVEL_BEGIN KR_LEVEL_PRAGMA(GCC push_options) KR_LEVEL_PRAGMA(GCC target("arch=x86-64-v4"))
#define KR_LEVEL_END KR_LEVEL_PRAGMA(GCC pop_options)
#elif defined(__GNUC__) && !defined(__clang__) && defined(KR_LEVEL_x86_64_v3)
#define KR_LEVEL_BEGIN KR_LEVEL_PRAGMA(GCC push_options) KR_LEVEL_PRAGMA(GCC target("arch=x86-64-v3"))
#define KR_LEVEL_END KR_LEVEL_PRAGMA(GCC pop_options)
#else
#define KR_LEVEL_BEGIN
#define KR_LEVEL_END
#endif
#if defined(__clang__)  // (to the end of the file: kernels.cpp includes such code last)
#define KR_UNFUSED_BEGIN KR_LEVEL_PRAGMA(clang fp contract(off))
#define KR_UNFUSED_END
#elif defined(__GNUC__) && (defined(KR_LEVEL_x86_64_v3) || defined(KR_LEVEL_x86_64_v4))
#define KR_UNFUSED_BEGIN KR_LEVEL_PRAGMA(GCC push_options) KR_LEVEL_PRAGMA(GCC target("no-fma"))
#define KR_UNFUSED_END KR_LEVEL_PRAGMA(GCC pop_options)
#else
#define KR_UNFUSED_BEGIN
#define KR_UNFUSED_END
#endif
