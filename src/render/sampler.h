// Where the uniform numbers of one sample of one pixel come from (the "estimator"):
// independent random numbers, the brief's stratified sub-pixel positions, or an
// Owen-scrambled Sobol sequence that stays stratified at every sample count.
#pragma once

#include <array>
#include <cstdint>

#include "core/rng.h"
#include "core/sampling.h"
#include "scene/scene.h"  // EnumNames

namespace kr {

// uniform:    every number from the pixel's PCG32 stream (the brief's "uniform random").
// stratified: the brief's estimator: sample i of s lies in sub-pixel stratum
//             (i mod e, i div e), e = floor(sqrt(s)); everything else uniform random.
// sobol:      every dimension pair from the 2-D Sobol (0,2)-sequence, with the sample index
//             shuffled and the points Owen-scrambled per pixel and per dimension (Burley
//             2020, "Practical hash-based Owen scrambling"). Any prefix of 2^k samples is a
//             stratified (0,k,2)-net in each pair, so it keeps its advantage with no target
//             count, including the viewer's unbounded accumulation.
enum class Estimator { uniform, stratified, sobol };
inline constexpr EnumNames<Estimator, 3> estimator_names{{"uniform", "stratified", "sobol"}};

// Sobol sequence building blocks (exposed for tests), all on 32-bit binary fractions. Inline:
// a path vertex draws five dimensions, and in a cheap scene that is a third of the work.
inline uint32_t reverse_bits(uint32_t x) {
    // Bytes by a byte swap, then the bits within each byte by three swap steps.
    x = __builtin_bswap32(x);
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    return ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
}

// van der Corput: the bits of the index mirrored.
inline uint32_t sobol_dimension0(uint32_t index) { return reverse_bits(index); }

// The second Sobol dimension: XOR of its generator matrix's columns for the index's bits,
// tabulated per index byte at compile time. Column k+1 = column k xor (column k >> 1) builds
// the upper-triangular Pascal matrix mod 2. The table holds the columns bit-reversed, the
// order the Owen scramble works in, which saves a reversal per sample (and reversal is
// linear over XOR, so reversing each column reverses the sum).
constexpr std::array<std::array<uint32_t, 256>, 4> sobol_dimension1_reversed_table() {
    std::array<uint32_t, 32> column{};  // reversed: the k-th column's top bit is bit 0 here
    column[0] = 1u;
    for (int k = 1; k < 32; ++k) column[k] = column[k - 1] ^ (column[k - 1] << 1);
    std::array<std::array<uint32_t, 256>, 4> table{};
    for (int b = 0; b < 4; ++b)
        for (uint32_t v = 0; v < 256; ++v)
            for (int bit = 0; bit < 8; ++bit)
                if (v & (1u << bit)) table[b][v] ^= column[8 * b + bit];
    return table;
}
inline constexpr auto kSobolDimension1ReversedBytes = sobol_dimension1_reversed_table();
inline uint32_t sobol_dimension1_reversed(uint32_t index) {
    const auto& t = kSobolDimension1ReversedBytes;
    return t[0][index & 0xff] ^ t[1][(index >> 8) & 0xff] ^ t[2][(index >> 16) & 0xff] ^ t[3][index >> 24];
}
inline uint32_t sobol_dimension1(uint32_t index) { return reverse_bits(sobol_dimension1_reversed(index)); }

// Laine-Karras style hash with Burley's constants: each step changes bit k only by a function
// of the bits below k (addition carries and multiplication by even constants only move
// information upwards), so applied to a bit-reversed fraction it is a nested, per-prefix
// random flip: an Owen scramble.
inline uint32_t laine_karras(uint32_t x, uint32_t seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

// Random Owen scramble of a binary fraction: bit k flips by a hash of the bits above it.
inline uint32_t owen_scramble(uint32_t fraction, uint32_t seed) {
    return reverse_bits(laine_karras(reverse_bits(fraction), seed));
}

// The numbers one sample of one pixel consumes, in a fixed order of dimensions: the
// sub-pixel position, the lens, then per path vertex the light choice, the light point, the
// BSDF lobe choice, the BSDF direction and Russian roulette.
class Sampler {
public:
    // The Sobol estimator scrambles this many dimensions (1-D or 2-D each): the sub-pixel
    // position, the lens and the first two path vertices (five each). Later ones come from
    // the pixel's PCG32 stream: little of the image depends on them, and scrambling costs
    // time (measured in docs/accuracy.md).
    static constexpr uint32_t kSobolDimensions = 12;

    // `target` is the sample count the stratified estimator divides the pixel for.
    Sampler(Estimator estimator, uint64_t seed, uint64_t pixel, uint32_t index, int target);
    // For tools and tests that trace rays by hand: the uniform estimator on one RNG stream.
    explicit Sampler(const Rng& rng) : estimator_(Estimator::uniform), rng_(rng) {}

    Vec2 pixel();  // sub-pixel position in [0,1)^2; call first

    double next_1d() {
        if (!scrambling()) return rng_.next();
        const Shuffle s = shuffle(dimension_++);
        // owen_scramble(sobol_dimension0(i)): the two bit reversals in between cancel.
        return to_unit(reverse_bits(laine_karras(s.index, s.seed)));
    }
    Vec2 next_2d() {
        if (!scrambling()) {
            const double u1 = rng_.next();
            return {u1, rng_.next()};
        }
        const Shuffle s = shuffle(dimension_++);
        return {to_unit(reverse_bits(laine_karras(s.index, s.seed))),
                // owen_scramble(sobol_dimension1(i)), its inner reversal taken by the table.
                to_unit(reverse_bits(laine_karras(sobol_dimension1_reversed(s.index), s.seed ^ 0xb5297a4du)))};
    }

    // One path vertex's five dimensions, in the fixed order below. Those `use` leaves out
    // are skipped, not computed (a scrambled one costs two or three hashes), and are 0; each
    // dimension keeps its meaning and the uniform stream its order, so the image is the same
    // as when all five are drawn.
    struct VertexNumbers {
        double light_pick = 0;
        Vec2 light;
        double lobe = 0;
        Vec2 bsdf;
        double roulette = 0;
    };
    enum VertexUse : unsigned { use_light_pick = 1, use_light = 2, use_lobe = 4, use_bsdf = 8, use_roulette = 16 };
    VertexNumbers next_vertex(unsigned use) {
        VertexNumbers v;
        v.light_pick = draw_1d(use & use_light_pick);
        v.light = draw_2d(use & use_light);
        v.lobe = draw_1d(use & use_lobe);
        v.bsdf = draw_2d(use & use_bsdf);
        v.roulette = draw_1d(use & use_roulette);
        return v;
    }

    // Skip a dimension (the lens of a pinhole camera, numbers a vertex does not read) without
    // computing it, so every later dimension is the same as when it is drawn.
    void skip_1d() {
        if (scrambling()) {
            ++dimension_;
        } else {
            rng_.next_u32(), rng_.next_u32();  // next() uses two
        }
    }
    void skip_2d() {
        if (scrambling()) {
            ++dimension_;
        } else {
            rng_.next_u32(), rng_.next_u32(), rng_.next_u32(), rng_.next_u32();
        }
    }

private:
    double draw_1d(bool used) {
        if (used) return next_1d();
        skip_1d();
        return 0;
    }
    Vec2 draw_2d(bool used) {
        if (used) return next_2d();
        skip_2d();
        return {};
    }
    struct Shuffle {
        uint32_t index;  // this dimension's shuffled sample index
        uint32_t seed;   // and the seed of its point scramble
    };
    bool scrambling() const { return estimator_ == Estimator::sobol && dimension_ < kSobolDimensions; }
    Shuffle shuffle(uint32_t dimension) const {
        // One independent scramble per (pixel, dimension). The index is shuffled first so that
        // different dimensions are not correlated through it; an Owen scramble of the index
        // keeps every aligned block of 2^k indices together, so prefixes stay nets. One
        // multiply-xorshift round makes the seeds: the Laine-Karras steps mix further.
        uint64_t h = (pixel_seed_ ^ (uint64_t(dimension) * 0x9e3779b97f4a7c15ull)) * 0xbf58476d1ce4e5b9ull;
        h ^= h >> 31;
        return {reverse_bits(laine_karras(index_reversed_, uint32_t(h))), uint32_t(h >> 32)};
    }
    // A 32-bit binary fraction to a double in (0, 1): the centre of its 2^-32 interval, so
    // the sample never lands on 0 (where some warps have a zero density) nor on 1.
    static double to_unit(uint32_t fraction) { return (double(fraction) + 0.5) * 0x1.0p-32; }

    Estimator estimator_;
    Rng rng_;
    uint64_t pixel_seed_ = 0;
    uint32_t index_ = 0;
    uint32_t index_reversed_ = 0;
    uint32_t dimension_ = 0;
    int target_ = 1;
};

}  // namespace kr
