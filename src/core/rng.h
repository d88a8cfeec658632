// Deterministic random numbers: one PCG32 stream per (seed, pixel, sample), so an image
// never depends on the thread count or on scheduling.
#pragma once

#include <cstdint>

namespace kr {

// SplitMix64 finaliser: a bijective 64-bit mix used to derive stream seeds.
constexpr uint64_t mix64(uint64_t z) {
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

// PCG32 (O'Neill 2014): 64-bit LCG state, xorshift-rotate output.
class Rng {
public:
    constexpr Rng() = default;
    constexpr Rng(uint64_t seed, uint64_t stream) { reseed(seed, stream); }

    // Independent stream for one sample of one pixel.
    static constexpr Rng for_sample(uint64_t seed, uint64_t pixel, uint64_t sample) {
        return Rng(mix64(seed ^ mix64(pixel)), mix64(sample + 0x632be59bd9b4e019ull * (pixel + 1)));
    }

    constexpr void reseed(uint64_t seed, uint64_t stream) {
        state_ = 0;
        inc_ = (stream << 1u) | 1u;
        next_u32();
        state_ += seed;
        next_u32();
    }

    constexpr uint32_t next_u32() {
        const uint64_t old = state_;
        state_ = old * 6364136223846793005ull + inc_;
        const uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
        const uint32_t rot = static_cast<uint32_t>(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
    }

    // Uniform in [0, 1): 53 random bits from two outputs, never exactly 1.
    constexpr double next() {
        const uint64_t hi = next_u32() >> 5;  // 27 bits
        const uint64_t lo = next_u32() >> 6;  // 26 bits
        return static_cast<double>((hi << 26) | lo) * 0x1.0p-53;
    }

private:
    uint64_t state_ = 0x853c49e6748fea9bull;
    uint64_t inc_ = 0xda3e39cb94b95bdbull;
};

}  // namespace kr
