// The estimators' samplers: the Owen-scrambled Sobol sampler's net property, uniformity
// (chi-square), unbiasedness on analytic integrands, and independence between dimensions.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

#include "render/sampler.h"

using namespace kr;

namespace {

// The first `count` 2-D points of dimension pair `pair` of one pixel.
std::vector<Vec2> sobol_points(uint64_t pixel, int pair, uint32_t first, uint32_t count) {
    std::vector<Vec2> points;
    for (uint32_t i = first; i < first + count; ++i) {
        Sampler sampler(Estimator::sobol, 7, pixel, i, 1);
        Vec2 p = sampler.pixel();
        for (int d = 0; d < pair; ++d) p = sampler.next_2d();
        points.push_back(p);
    }
    return points;
}

// Upper chi-square quantile at p = 0.001 for `dof` degrees of freedom (Wilson-Hilferty).
double chi_square_limit(int dof) {
    const double z = 3.09, k = dof;
    const double t = 1 - 2 / (9 * k) + z * std::sqrt(2 / (9 * k));
    return k * t * t * t;
}

}  // namespace

TEST(Sobol, FirstDimensionsAreTheSobolSequence) {
    const uint32_t x[] = {0, 1u << 31, 1u << 30, 3u << 30};
    const uint32_t y[] = {0, 1u << 31, 3u << 30, 1u << 30};
    for (uint32_t i = 0; i < 4; ++i) {
        EXPECT_EQ(sobol_dimension0(i), x[i]);
        EXPECT_EQ(sobol_dimension1(i), y[i]);
    }
    EXPECT_EQ(reverse_bits(1u), 1u << 31);
    EXPECT_EQ(reverse_bits(0x12345678u), 0x1e6a2c48u);
}

// The second dimension against its definition: the index's bits pick columns of the
// generator matrix, Pascal's triangle mod 2 (column k+1 = column k xor column k shifted
// down a bit, from the top bit), xor-ed together.
TEST(Sobol, SecondDimensionIsItsGeneratorMatrix) {
    uint32_t column[32];
    column[0] = 1u << 31;
    for (int k = 1; k < 32; ++k) column[k] = column[k - 1] ^ (column[k - 1] >> 1);
    Rng rng(5, 6);
    for (int trial = 0; trial < 20000; ++trial) {
        const uint32_t index = trial < 256 ? uint32_t(trial) : rng.next_u32();
        uint32_t expected = 0;
        for (int k = 0; k < 32; ++k)
            if (index & (1u << k)) expected ^= column[k];
        ASSERT_EQ(sobol_dimension1(index), expected) << index;
    }
}

// The lanes draw Sobol numbers in SIMD lanes of words (render/lanes/) with the
// same templates: every lane must give the bits one word gives.
#pragma GCC diagnostic ignored "-Wpsabi"  // the lanes stay in this function
TEST(Sobol, LanesGiveWhatOneWordGives) {
    typedef uint32_t v8w __attribute__((vector_size(32)));
    Rng rng(8, 9);
    for (int trial = 0; trial < 2000; ++trial) {
        v8w key, index_reversed, dimension;
        for (int k = 0; k < 8; ++k) {
            key[k] = rng.next_u32();
            index_reversed[k] = rng.next_u32();
            dimension[k] = rng.next_u32() % 64;
        }
        const v8w reversed = reverse_bits(key);
        const SobolDimension<v8w> lanes(key, index_reversed, dimension);
        const v8w x = lanes.x(), y = lanes.y();
        for (int k = 0; k < 8; ++k) {
            ASSERT_EQ(reversed[k], reverse_bits(key[k]));
            const SobolDimension<uint32_t> one(key[k], index_reversed[k], dimension[k]);
            ASSERT_EQ(x[k], one.x());
            ASSERT_EQ(y[k], one.y());
        }
    }
}

// An Owen scramble is a bijection that maps each dyadic interval onto a dyadic interval of
// the same size: two fractions sharing their top k bits still share them after scrambling.
TEST(Sobol, OwenScrambleKeepsDyadicIntervalsTogether) {
    Rng rng(3, 4);
    for (int trial = 0; trial < 2000; ++trial) {
        const uint32_t seed = rng.next_u32(), a = rng.next_u32();
        const int k = trial % 32;
        const uint32_t high_mask = k == 0 ? 0u : ~0u << (32 - k);
        const uint32_t b = (a & high_mask) | (rng.next_u32() & ~high_mask);
        EXPECT_EQ(owen_scramble(a, seed) & high_mask, owen_scramble(b, seed) & high_mask);
    }
    std::set<uint32_t> images;
    for (uint32_t v = 0; v < 4096; ++v) images.insert(owen_scramble(v << 20, 99) >> 20);
    EXPECT_EQ(images.size(), 4096u);  // bijective on the top 12 bits
}

// Every prefix of 2^m samples (and every aligned block after it) of every dimension pair
// puts exactly one point in each elementary interval of area 2^-m: 2^a by 2^(m-a) cells.
TEST(Sobol, EveryPowerOfTwoPrefixIsANet) {
    for (uint64_t pixel : {0ull, 1ull, 12345ull}) {
        for (int pair : {0, 1, 4, 11, 20, 57}) {  // the camera's and vertices' up to depth 11
            for (int m = 0; m <= 8; ++m) {
                const uint32_t n = 1u << m;
                for (uint32_t first : {0u, n, 5 * n}) {
                    const std::vector<Vec2> points = sobol_points(pixel, pair, first, n);
                    for (int a = 0; a <= m; ++a) {
                        const int nx = 1 << a, ny = 1 << (m - a);
                        std::vector<int> cells(n, 0);
                        for (const Vec2& p : points) {
                            ASSERT_TRUE(p.x > 0 && p.x < 1 && p.y > 0 && p.y < 1);
                            cells[int(p.y * ny) * nx + int(p.x * nx)] += 1;
                        }
                        for (int c : cells)
                            ASSERT_EQ(c, 1) << "pixel " << pixel << " pair " << pair << " m " << m
                                            << " first " << first << " cells " << nx << "x" << ny;
                    }
                }
            }
        }
    }
}

// Across pixels each sample is uniform: chi-square over a 16 x 16 grid of one sample index
// of many pixels, for 2-D pairs and for 1-D dimensions.
TEST(Sobol, SamplesAreUniformAcrossPixels) {
    constexpr int kGrid = 16, kPixels = 25600;
    for (uint32_t index : {0u, 1u, 3u, 1000u}) {
        std::vector<int> cells(kGrid * kGrid, 0), cells_1d(kGrid * kGrid, 0);
        for (int pixel = 0; pixel < kPixels; ++pixel) {
            Sampler sampler(Estimator::sobol, 1, pixel, index, 1);
            sampler.pixel();
            const Vec2 p = sampler.next_2d();
            cells[int(p.y * kGrid) * kGrid + int(p.x * kGrid)] += 1;
            const double u = sampler.next_1d();
            const double v = sampler.next_1d();
            cells_1d[int(v * kGrid) * kGrid + int(u * kGrid)] += 1;
        }
        for (const std::vector<int>* grid : {&cells, &cells_1d}) {
            const double expected = double(kPixels) / (kGrid * kGrid);
            double chi2 = 0;
            for (int c : *grid) chi2 += (c - expected) * (c - expected) / expected;
            EXPECT_LT(chi2, chi_square_limit(kGrid * kGrid - 1)) << "index " << index;
        }
    }
}

// Unbiased on a smooth integrand at power-of-two and other counts, with far lower error
// than independent random samples.
TEST(Sobol, UnbiasedWithLowerErrorThanUniform) {
    auto f = [](Vec2 p) { return std::sin(3 * p.x) * std::exp(p.y); };
    const double exact = (1 - std::cos(3.0)) / 3 * (std::exp(1.0) - 1);
    constexpr int kTrials = 2000;
    for (int spp : {1, 16, 37}) {
        double mean[2] = {0, 0}, mse[2] = {0, 0};
        for (int e = 0; e < 2; ++e) {
            const Estimator est = e == 0 ? Estimator::uniform : Estimator::sobol;
            for (int t = 0; t < kTrials; ++t) {
                double sum = 0;
                for (int i = 0; i < spp; ++i) {
                    Sampler sampler(est, 5, t, i, spp);
                    sampler.pixel();
                    sum += f(sampler.next_2d());  // the lens pair: a dimension past the first
                }
                const double estimate = sum / spp;
                mean[e] += estimate / kTrials;
                mse[e] += (estimate - exact) * (estimate - exact) / kTrials;
            }
            EXPECT_NEAR(mean[e], exact, 4 * std::sqrt(mse[e] / kTrials)) << "spp " << spp;
        }
        if (spp == 16) EXPECT_LT(mse[1], mse[0] / 20);
        if (spp == 37) EXPECT_LT(mse[1], mse[0] / 8);
    }
}

// Different dimensions of one sample are independent: E[u_i u_j] = 1/4 for every pair of
// dimensions, including the two axes of one pair and dimensions of different pairs.
TEST(Sobol, DimensionsAreUncorrelated) {
    constexpr int kDims = 8, kPixels = 4000, kSpp = 16;
    double sum[kDims][kDims] = {};
    for (int pixel = 0; pixel < kPixels; ++pixel)
        for (int i = 0; i < kSpp; ++i) {
            Sampler sampler(Estimator::sobol, 2, pixel, i, kSpp);
            double u[kDims];
            const Vec2 a = sampler.pixel();
            u[0] = a.x, u[1] = a.y;
            const Vec2 b = sampler.next_2d();
            u[2] = b.x, u[3] = b.y;
            u[4] = sampler.next_1d();
            const Vec2 c = sampler.next_2d();
            u[5] = c.x, u[6] = c.y;
            u[7] = sampler.next_1d();
            for (int p = 0; p < kDims; ++p)
                for (int q = 0; q < p; ++q) sum[p][q] += u[p] * u[q];
        }
    // Per pixel the 16 products average to within a few 1e-3 of 1/4; across pixels the
    // mean's standard error is about 0.07 / sqrt(16 * 4000) = 3e-4.
    for (int p = 0; p < kDims; ++p)
        for (int q = 0; q < p; ++q)
            EXPECT_NEAR(sum[p][q] / (kPixels * kSpp), 0.25, 2e-3) << "dimensions " << p << ", " << q;
}

// The stratified estimator (the brief's) keeps its strata; its other dimensions are the
// uniform stream, and an index past e^2 is uniform too.
TEST(Sobol, UniformAndStratifiedDrawFromTheirStream) {
    Sampler a(Estimator::uniform, 9, 4, 2, 16), b(Rng::for_sample(9, 4, 2));
    const Vec2 pa = a.pixel(), pb = b.pixel();
    EXPECT_EQ(pa.x, pb.x);
    EXPECT_EQ(pa.y, pb.y);
    EXPECT_EQ(a.next_1d(), b.next_1d());
    const Vec2 s = Sampler(Estimator::stratified, 9, 4, 5, 16).pixel();  // stratum (1, 1) of 4x4
    EXPECT_TRUE(s.x >= 0.25 && s.x < 0.5 && s.y >= 0.25 && s.y < 0.5);
}

// A path vertex may leave out the numbers it does not read: those it reads, and every later
// dimension, are the same as when all five are drawn, for the scrambled dimensions and for
// the uniform stream behind them.
TEST(Sobol, VertexNumbersLeftOutDoNotShiftOthers) {
    const unsigned all = Sampler::use_light_pick | Sampler::use_light | Sampler::use_lobe | Sampler::use_bsdf |
                         Sampler::use_roulette;
    for (Estimator estimator : {Estimator::sobol, Estimator::uniform})
        for (unsigned use : {0u, unsigned(Sampler::use_light | Sampler::use_bsdf), unsigned(Sampler::use_lobe)}) {
            Sampler full(estimator, 3, 41, 9, 1), partial(estimator, 3, 41, 9, 1);
            full.pixel();
            partial.pixel();
            full.skip_2d();
            partial.skip_2d();
            for (int vertex = 0; vertex < 4; ++vertex) {
                const Sampler::VertexNumbers a = full.next_vertex(all), b = partial.next_vertex(use);
                if (use & Sampler::use_light) {
                    EXPECT_EQ(a.light.x, b.light.x);
                    EXPECT_EQ(a.light.y, b.light.y);
                }
                if (use & Sampler::use_bsdf) EXPECT_EQ(a.bsdf.x, b.bsdf.x);
                if (use & Sampler::use_lobe) EXPECT_EQ(a.lobe, b.lobe);
                EXPECT_GT(a.bsdf.x, 0.0);
            }
            const Vec2 a = full.next_2d(), b = partial.next_2d();
            EXPECT_EQ(a.x, b.x) << estimator_names.name(estimator);
            EXPECT_EQ(a.y, b.y);
        }
}

// render_pass works out a row's keys at once (Sampler::pixel_keys, in vectors where the CPU
// has them): each the key of its pixel, for rows of any length and any start.
TEST(Sobol, RowOfPixelKeysIsEachPixelsKey) {
    for (uint64_t seed : {0ull, 7ull, 1ull << 40})
        for (uint64_t first : {0ull, 511ull, (1ull << 33) - 5})
            for (size_t count : {size_t(1), size_t(7), size_t(16), size_t(37), size_t(512)}) {
                std::vector<uint32_t> keys(count + 1, 0xdeadbeefu);
                Sampler::pixel_keys(seed, first, count, keys.data());
                for (size_t i = 0; i < count; ++i) EXPECT_EQ(keys[i], Sampler::pixel_key(seed, first + i)) << i;
                EXPECT_EQ(keys[count], 0xdeadbeefu);  // nothing past the row
            }
}

// render_pass keeps each pixel's Sobol key (Sampler::pixel_key) and builds its samplers from
// it: the same numbers as the sampler built from the seed and the pixel.
TEST(Sobol, SamplerFromThePixelKeyIsTheSame) {
    for (uint64_t seed : {0ull, 7ull, 1ull << 40})
        for (uint64_t pixel : {0ull, 1ull, 262143ull, 1ull << 33})
            for (uint32_t index : {0u, 1u, 5u, 4095u}) {
                Sampler from_seed(Estimator::sobol, seed, pixel, index, 16);
                Sampler from_key(Sampler::pixel_key(seed, pixel), index);
                EXPECT_EQ(from_key.sobol_key(), from_seed.sobol_key());
                EXPECT_EQ(from_key.index_reversed(), from_seed.index_reversed());
                const Vec2 a = from_seed.pixel(), b = from_key.pixel();
                EXPECT_EQ(a.x, b.x);
                EXPECT_EQ(a.y, b.y);
                for (int d = 0; d < 12; ++d) EXPECT_EQ(from_seed.next_1d(), from_key.next_1d()) << d;
            }
}
