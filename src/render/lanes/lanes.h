// Four lanes of doubles (GCC vector extensions) and the few operations on them that the BVH's
// block test (accel.cpp) and the double-lane kernels (kernels.cpp) share, and KR_LANES, which
// keeps lanes from crossing a call.
#pragma once

#include <cmath>
#include <cstdint>

namespace kr {

// SSE2 pairs by default, one AVX register in the x86-64-v3 clone.
typedef double v4d __attribute__((vector_size(32)));
typedef int64_t v4l __attribute__((vector_size(32)));
typedef uint64_t v4u __attribute__((vector_size(32)));  // bits, shifted without sign

// Every helper taking or returning lanes is forced inline into its KR_LEVEL_CLONES caller
// (levels.h) or the kernels: a call would pass them by the x86-64 ABI, not the AVX2 one. So no lane crosses a non-inlined call, and GCC's note on the vector ABI does not apply
// (CMakeLists.txt turns it off: -Wno-psabi).
#define KR_LANES inline __attribute__((always_inline))

KR_LANES v4d splat(double x) { return v4d{} + x; }
KR_LANES v4d load_lanes(const double* p) {
    v4d v;
    __builtin_memcpy(&v, p, sizeof v);
    return v;
}
KR_LANES v4d sqrt_lanes(v4d x) { return v4d{std::sqrt(x[0]), std::sqrt(x[1]), std::sqrt(x[2]), std::sqrt(x[3])}; }
KR_LANES v4d select(v4l mask, v4d a, v4d b) { return mask ? a : b; }
// Whether any lane of a mask is set: the two halves or-ed as vectors first, which takes
// fewer instructions than extracting the four lanes one by one.
KR_LANES bool any_lane(v4l mask) {
    typedef int64_t v2l __attribute__((vector_size(16)));
    v2l low, high;
    __builtin_memcpy(&low, &mask, sizeof low);
    __builtin_memcpy(&high, reinterpret_cast<const char*>(&mask) + sizeof low, sizeof high);
    const v2l either = low | high;
    return (either[0] | either[1]) != 0;
}

}  // namespace kr
