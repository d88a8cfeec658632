// Loops the compiler vectorises: the attribute that compiles a function for AVX-512 and AVX2
// beside the baseline, picked at run time (GCC function multi-versioning), and the pragma
// that says a loop's iterations are independent.
#pragma once

// Where GCC can dispatch on the CPU. Without FMA contraction (ISO C++ mode) the vector forms
// give the scalar ones' bits.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define KR_VECTOR_CLONES __attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
#else
#define KR_VECTOR_CLONES
#endif

// A loop whose iterations are independent (its arrays do not overlap): vectorised without
// run-time alias checks, which a loop over many arrays would exceed.
#if defined(__clang__)
#define KR_INDEPENDENT_ITERATIONS _Pragma("clang loop vectorize(assume_safety)")
#elif defined(__GNUC__)
#define KR_INDEPENDENT_ITERATIONS _Pragma("GCC ivdep")
#else
#define KR_INDEPENDENT_ITERATIONS
#endif
