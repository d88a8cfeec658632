// Where the uniform numbers of one sample of one pixel come from (the "estimator"):
// independent random numbers, the brief's stratified sub-pixel positions, or an
// Owen-scrambled Sobol sequence that stays stratified at every sample count.
#pragma once

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

// Sobol sequence building blocks (exposed for tests), all on 32-bit binary fractions.
uint32_t reverse_bits(uint32_t x);
uint32_t sobol_dimension0(uint32_t index);  // van der Corput: the bits of index mirrored
uint32_t sobol_dimension1(uint32_t index);  // the second Sobol dimension (Pascal matrix)
// Random Owen scramble of a binary fraction: bit k flips by a hash of the bits above it.
uint32_t owen_scramble(uint32_t fraction, uint32_t seed);

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
    double next_1d();
    Vec2 next_2d();

private:
    struct Shuffle {
        uint32_t index;  // this dimension's shuffled sample index
        uint32_t seed;   // and the seed of its point scramble
    };
    Shuffle shuffle(uint32_t dimension) const;

    Estimator estimator_;
    Rng rng_;
    uint64_t pixel_seed_ = 0;
    uint32_t index_ = 0;
    uint32_t dimension_ = 0;
    int target_ = 1;
};

}  // namespace kr
