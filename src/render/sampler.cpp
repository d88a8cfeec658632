#include "render/sampler.h"

#include <algorithm>
#include <cmath>

namespace kr {

namespace {

// A 32-bit binary fraction to a double in (0, 1): the centre of its 2^-32 interval, so the
// sample never lands on 0 (where some warps have a zero density) nor on 1.
double to_unit(uint32_t fraction) { return (double(fraction) + 0.5) * 0x1.0p-32; }

}  // namespace

uint32_t reverse_bits(uint32_t x) {
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
    return (x >> 16) | (x << 16);
}

uint32_t sobol_dimension0(uint32_t index) { return reverse_bits(index); }

namespace {

// The second Sobol dimension's generator matrix, as XORs of its columns for each value of
// each index byte (4 x 256 entries): column k+1 = column k xor (column k >> 1) builds the
// upper-triangular Pascal matrix mod 2.
struct SobolTable {
    uint32_t byte_xor[4][256];
    SobolTable() {
        uint32_t column[32];
        column[0] = 1u << 31;
        for (int k = 1; k < 32; ++k) column[k] = column[k - 1] ^ (column[k - 1] >> 1);
        for (int b = 0; b < 4; ++b)
            for (uint32_t v = 0; v < 256; ++v) {
                uint32_t x = 0;
                for (int bit = 0; bit < 8; ++bit)
                    if (v & (1u << bit)) x ^= column[8 * b + bit];
                byte_xor[b][v] = x;
            }
    }
};
const SobolTable kSobolTable;

// Laine-Karras style hash with Burley's constants: each step changes bit k only by a function
// of the bits below k (addition carries and multiplication by even constants only move
// information upwards), so applied to a bit-reversed fraction it is a nested, per-prefix
// random flip: an Owen scramble.
uint32_t laine_karras(uint32_t x, uint32_t seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

}  // namespace

uint32_t sobol_dimension1(uint32_t index) {
    return kSobolTable.byte_xor[0][index & 0xff] ^ kSobolTable.byte_xor[1][(index >> 8) & 0xff] ^
           kSobolTable.byte_xor[2][(index >> 16) & 0xff] ^ kSobolTable.byte_xor[3][index >> 24];
}

uint32_t owen_scramble(uint32_t fraction, uint32_t seed) {
    return reverse_bits(laine_karras(reverse_bits(fraction), seed));
}

Sampler::Sampler(Estimator estimator, uint64_t seed, uint64_t pixel, uint32_t index, int target)
    : estimator_(estimator),
      rng_(Rng::for_sample(seed, pixel, index)),
      pixel_seed_(mix64(seed ^ mix64(pixel + 0x51ed270b2f4c1d3dull))),
      index_(index),
      target_(std::max(target, 1)) {}

Sampler::Shuffle Sampler::shuffle(uint32_t dimension) const {
    // One independent scramble per (pixel, dimension). The index is shuffled first so that
    // different dimensions are not correlated through it; an Owen scramble of the index
    // keeps every aligned block of 2^k indices together, so prefixes stay nets.
    const uint64_t h = mix64(pixel_seed_ ^ (uint64_t(dimension) * 0x9e3779b97f4a7c15ull));
    return {owen_scramble(index_, uint32_t(h)), uint32_t(h >> 32)};
}

Vec2 Sampler::pixel() {
    if (estimator_ == Estimator::sobol) return next_2d();
    const double u1 = rng_.next(), u2 = rng_.next();
    if (estimator_ == Estimator::stratified) {
        // Brief: e = floor(sqrt(s)); x_i = (w/e)(i mod e + xi1), y_i = (h/e)(floor(i/e) + xi2).
        const int e = static_cast<int>(std::sqrt(static_cast<double>(target_)));
        const int i = static_cast<int>(std::min<uint32_t>(index_, uint32_t(e) * uint32_t(e)));
        if (i < e * e) return {((i % e) + u1) / e, ((i / e) + u2) / e};
    }
    return {u1, u2};
}

double Sampler::next_1d() {
    if (estimator_ != Estimator::sobol || dimension_ >= kSobolDimensions) return rng_.next();
    const Shuffle s = shuffle(dimension_++);
    // owen_scramble(sobol_dimension0(i)): the two bit reversals in between cancel.
    return to_unit(reverse_bits(laine_karras(s.index, s.seed)));
}

Vec2 Sampler::next_2d() {
    if (estimator_ != Estimator::sobol || dimension_ >= kSobolDimensions) {
        const double u1 = rng_.next();
        return {u1, rng_.next()};
    }
    const Shuffle s = shuffle(dimension_++);
    return {to_unit(reverse_bits(laine_karras(s.index, s.seed))),
            to_unit(owen_scramble(sobol_dimension1(s.index), s.seed ^ 0xb5297a4du))};
}

}  // namespace kr
