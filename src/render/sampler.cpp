#include "render/sampler.h"

#include <algorithm>
#include <cmath>

#include "core/vectorise.h"
#include "render/lanes/levels.h"

namespace kr {

Sampler::Sampler(Estimator estimator, uint64_t seed, uint64_t pixel, uint32_t index, int target)
    : estimator_(estimator),
      sobol_key_(pixel_key(seed, pixel)),
      index_(index),
      index_reversed_(reverse_bits(index)),
      target_(std::max(target, 1)) {
    // Sobol samples draw every number from the sequence, so only the others need a stream.
    if (estimator != Estimator::sobol) rng_ = Rng::for_sample(seed, pixel, index);
}

KR_LOOP_CLONES
void Sampler::pixel_keys(uint64_t seed, uint64_t first_pixel, size_t count, uint32_t* keys) {
    KR_INDEPENDENT_ITERATIONS
    for (size_t i = 0; i < count; ++i) keys[i] = pixel_key(seed, first_pixel + i);
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

}  // namespace kr
