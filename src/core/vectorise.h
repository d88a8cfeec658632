// Loops the compiler vectorises: the pragma that says a loop's iterations are independent.
// (Such a loop's function is compiled for each CPU level by KR_LEVEL_CLONES,
// render/lanes/levels.h.)
#pragma once

// A loop whose iterations are independent (its arrays do not overlap): vectorised without
// run-time alias checks, which a loop over many arrays would exceed.
#if defined(__clang__)
#define KR_INDEPENDENT_ITERATIONS _Pragma("clang loop vectorize(assume_safety)")
#elif defined(__GNUC__)
#define KR_INDEPENDENT_ITERATIONS _Pragma("GCC ivdep")
#else
#define KR_INDEPENDENT_ITERATIONS
#endif
