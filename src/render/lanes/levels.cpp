#include "render/lanes/levels.h"

namespace kr {

CpuLevel cpu_level() {
    static const CpuLevel level = [] {
#if defined(__x86_64__) && defined(__GNUC__)
        __builtin_cpu_init();
#ifdef __clang__  // Clang 14 knows no "x86-64-v3" here: the features of each level the code needs
        const bool v3 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
        const bool v4 = v3 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                        __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
#else
        const bool v3 = __builtin_cpu_supports("x86-64-v3");
        const bool v4 = __builtin_cpu_supports("x86-64-v4");
#endif
        return v4 ? CpuLevel::x86_64_v4 : v3 ? CpuLevel::x86_64_v3 : CpuLevel::x86_64;
#else
        return CpuLevel::x86_64;
#endif
    }();
    return level;
}

}  // namespace kr
