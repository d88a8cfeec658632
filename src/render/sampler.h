// Where the uniform numbers of one sample of one pixel come from (the "estimator"):
// independent random numbers, the brief's stratified sub-pixel positions, or an
// Owen-scrambled Sobol sequence that stays stratified at every sample count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "core/rng.h"
#include "core/sampling.h"
#include "core/enum_names.h"

namespace kr {

// uniform:    every number from the pixel's PCG32 stream (the brief's "uniform random").
// stratified: the brief's estimator: sample i of s lies in sub-pixel stratum
//             (i mod e, i div e), e = floor(sqrt(s)); everything else uniform random.
// sobol:      every dimension pair from the 2-D Sobol (0,2)-sequence, with the sample index
//             shuffled and the points Owen-scrambled per pixel and per dimension (Burley
//             2020, "Practical hash-based Owen scrambling"), at every depth. Any prefix of
//             2^k samples is a stratified (0,k,2)-net in each pair, so it keeps its advantage
//             with no target count, including the viewer's unbounded accumulation.
enum class Estimator { uniform, stratified, sobol };
inline constexpr EnumNames<Estimator, 3> estimator_names{{"uniform", "stratified", "sobol"}};

// Sobol sequence building blocks (exposed for tests), all on 32-bit binary fractions, each
// for one word (U = uint32_t) and for SIMD lanes of words (lanes/kernels.cpp) alike: integer
// operations, so both give the same bits. Forced inline: a path vertex draws five
// dimensions, and lanes must not cross a call (render/lanes/lanes.h).
#define KR_SOBOL_INLINE inline __attribute__((always_inline))

template <class U>
KR_SOBOL_INLINE U reverse_bits(U x) {
    if constexpr (std::is_integral_v<U>) {
        x = __builtin_bswap32(x);  // bytes by one instruction
    } else {
        // Bytes by two swap steps. The x86-64-v3 kernels reverse lanes with byte shuffles
        // of their own (lanes/kernels.cpp); these serve the kernels for any CPU.
        x = (x >> 16) | (x << 16);
        x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
    }
    // then the bits within each byte by three swap steps
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    return ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
}

// van der Corput: the bits of the index mirrored.
inline uint32_t sobol_dimension0(uint32_t index) { return reverse_bits(index); }

// The second Sobol dimension bit-reversed, the order the Owen scramble works in. Its
// generator matrix is Pascal's triangle mod 2: bit k of the index adds the polynomial
// (1 + z)^k (z: one bit up), so the fraction is the index polynomial with 1 + z put for its
// variable. Over GF(2), (1 + z)^(2^m) = 1 + z^(2^m), so five steps do it, each folding the
// upper half of every block of 2^(m+1) bits onto its lower half.
template <class U>
KR_SOBOL_INLINE U sobol_dimension1_reversed(U index) {
    index ^= (index >> 1) & 0x55555555u;
    index ^= (index >> 2) & 0x33333333u;
    index ^= (index >> 4) & 0x0f0f0f0fu;
    index ^= (index >> 8) & 0x00ff00ffu;
    return index ^ ((index >> 16) & 0x0000ffffu);
}
inline uint32_t sobol_dimension1(uint32_t index) { return reverse_bits(sobol_dimension1_reversed(index)); }

// Laine-Karras style hash with Burley's constants: each step changes bit k only by a function
// of the bits below k (addition carries and multiplication by even constants only move
// information upwards), so applied to a bit-reversed fraction it is a nested, per-prefix
// random flip: an Owen scramble.
template <class U>
KR_SOBOL_INLINE U laine_karras(U x, U seed) {
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

// A 32-bit integer hash with full avalanche (two multiply-xorshift rounds; Wellons'
// "lowbias32" constants).
template <class U>
KR_SOBOL_INLINE U hash32(U x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    return x ^ (x >> 16);
}

// reverse_bits as SobolDimension's default way to reverse; lanes/kernels.cpp's x86-64-v3 kernels
// pass one with instructions of their own.
struct BitReverse {
    template <class U>
    static KR_SOBOL_INLINE U apply(U x) {
        return reverse_bits(x);
    }
};

// One dimension of one Sobol sample: the sample index shuffled and the point scrambled by
// seeds of their own for each (pixel, dimension). The index is shuffled first so that
// different dimensions are not correlated through it; an Owen scramble of the index keeps
// every aligned block of 2^k indices together, so prefixes stay nets. Its two coordinates
// (x, y) are Sobol dimensions 0 and 1, Owen-scrambled; `key` is the pixel's, from its seed.
template <class U, class Reverse = BitReverse>
struct SobolDimension {
    U index, seed;
    KR_SOBOL_INLINE SobolDimension(U key, U index_reversed, U dimension) {
        const U h = hash32(key ^ (dimension * 0x9e3779b9u));
        index = Reverse::apply(laine_karras(index_reversed, h));
        seed = hash32(h + 0x632be5abu);
    }
    // owen_scramble(sobol_dimension0(index)): the two bit reversals in between cancel.
    KR_SOBOL_INLINE U x() const { return Reverse::apply(laine_karras(index, seed)); }
    // owen_scramble(sobol_dimension1(index)), its inner reversal left out of the matrix.
    KR_SOBOL_INLINE U y() const {
        return Reverse::apply(laine_karras(sobol_dimension1_reversed(index), seed ^ 0xb5297a4du));
    }
};

// The numbers one sample of one pixel consumes, in a fixed order of dimensions: the
// sub-pixel position, the lens, then per path vertex the light choice, the light point, the
// BSDF lobe choice, the BSDF direction and Russian roulette.
class Sampler {
public:
    // `target` is the sample count the stratified estimator divides the pixel for.
    Sampler(Estimator estimator, uint64_t seed, uint64_t pixel, uint32_t index, int target);
    // The Sobol estimator's sampler from its pixel's key (pixel_key), which render_pass keeps
    // per pixel: the same sampler as the constructor above gives.
    Sampler(uint32_t sobol_key, uint32_t index) : Sampler(sobol_key, index, reverse_bits(index)) {}
    // The same with reverse_bits(index) given (render_pass reuses it across pixels).
    Sampler(uint32_t sobol_key, uint32_t index, uint32_t index_reversed)
        : estimator_(Estimator::sobol), sobol_key_(sobol_key), index_(index), index_reversed_(index_reversed) {}
    // Makes this Sobol sampler the one Sampler(sobol_key, index, index_reversed) gives, in
    // place (render_pass reuses its batch's samplers: only these fields differ between them).
    void restart_sobol(uint32_t sobol_key, uint32_t index, uint32_t index_reversed) {
        sobol_key_ = sobol_key;
        index_ = index;
        index_reversed_ = index_reversed;
        dimension_ = 0;
    }
    // The Sobol numbers' key of a pixel for a seed: two SplitMix64 hashes.
    static uint32_t pixel_key(uint64_t seed, uint64_t pixel) {
        return uint32_t(mix64(seed ^ mix64(pixel + 0x51ed270b2f4c1d3dull)));
    }
    // The keys of `count` pixels from `first_pixel` on (a row's), in vectors where the CPU has them.
    static void pixel_keys(uint64_t seed, uint64_t first_pixel, size_t count, uint32_t* keys);
    // For tools and tests that trace rays by hand: the uniform estimator on one RNG stream.
    explicit Sampler(const Rng& rng) : estimator_(Estimator::uniform), rng_(rng) {}

    Vec2 pixel();  // sub-pixel position in [0,1)^2; call first

    double next_1d() {
        if (!sobol()) return rng_.next();
        return to_unit(next_dimension().x());
    }
    Vec2 next_2d() {
        if (!sobol()) {
            const double u1 = rng_.next();
            return {u1, rng_.next()};
        }
        const SobolDimension<uint32_t> d = next_dimension();
        return {to_unit(d.x()), to_unit(d.y())};
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
        if (sobol()) {
            ++dimension_;
        } else {
            rng_.next_u32(), rng_.next_u32();  // next() uses two
        }
    }
    void skip_2d() {
        if (sobol()) {
            ++dimension_;
        } else {
            rng_.next_u32(), rng_.next_u32(), rng_.next_u32(), rng_.next_u32();
        }
    }

    // The Sobol estimator's state, for drawing four samplers' numbers in SIMD lanes
    // (lanes/kernels.cpp): the pixel's key, the index bit-reversed, and the next dimension. The
    // lanes move each sampler on by the dimensions they drew.
    bool sobol() const { return estimator_ == Estimator::sobol; }
    uint32_t sobol_key() const { return sobol_key_; }
    uint32_t index_reversed() const { return index_reversed_; }
    uint32_t dimension() const { return dimension_; }
    void skip_dimensions(uint32_t count) { dimension_ += count; }

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
    // A 32-bit binary fraction to a double in (0, 1): the centre of its 2^-32 interval, so
    // the sample never lands on 0 (where some warps have a zero density) nor on 1.
    static double to_unit(uint32_t fraction) { return (double(fraction) + 0.5) * 0x1.0p-32; }

    SobolDimension<uint32_t> next_dimension() {
        return SobolDimension<uint32_t>(sobol_key_, index_reversed_, dimension_++);
    }

    Estimator estimator_;
    Rng rng_;  // the uniform and stratified estimators' stream
    uint32_t sobol_key_ = 0;
    uint32_t index_ = 0;
    uint32_t index_reversed_ = 0;
    uint32_t dimension_ = 0;
    int target_ = 1;
};

}  // namespace kr
