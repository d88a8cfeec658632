#include "render/lanes/levels.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <cpuid.h>
#endif
#include <cstring>

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

CpuModel cpu_model() {
    static const CpuModel model = [] {
        CpuModel m;
#if defined(__x86_64__) && defined(__GNUC__)
        unsigned a = 0, b = 0, c = 0, d = 0;
        if (!__get_cpuid(0, &a, &b, &c, &d)) return m;
        char vendor[13] = {};
        std::memcpy(vendor, &b, 4);
        std::memcpy(vendor + 4, &d, 4);
        std::memcpy(vendor + 8, &c, 4);
        m.amd = std::strcmp(vendor, "AuthenticAMD") == 0;
        if (!__get_cpuid(1, &a, &b, &c, &d)) return m;
        const int base = int((a >> 8) & 0xf), extended = int((a >> 20) & 0xff);
        m.family = base == 0xf ? base + extended : base;
#endif
        return m;
    }();
    return model;
}

}  // namespace kr
