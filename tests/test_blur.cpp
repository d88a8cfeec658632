// The box blur (--blur R): a separable running sum, checked against the direct sum over each
// pixel's clamped box.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/image.h"

using namespace kr;

namespace {

// The definition: each pixel is the mean over the (2r+1)^2 box around it, clamped to the
// image, as two 1-D passes (rows, then columns) of direct sums.
Image naive_blur(const Image& src, int r) {
    auto pass = [r](const Image& in, bool horizontal) {
        Image out(in.width, in.height);
        const int n = horizontal ? in.width : in.height, lines = horizontal ? in.height : in.width;
        for (int line = 0; line < lines; ++line)
            for (int i = 0; i < n; ++i) {
                const int lo = std::max(0, i - r), hi = std::min(n - 1, i + r);
                Color sum;
                for (int j = lo; j <= hi; ++j) sum += horizontal ? in.at(j, line) : in.at(line, j);
                (horizontal ? out.at(i, line) : out.at(line, i)) = sum / double(hi - lo + 1);
            }
        return out;
    };
    return pass(pass(src, true), false);
}

Image random_image(int w, int h, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    Image img(w, h);
    for (Color& c : img.pixels) c = {u(rng), u(rng), 3 * u(rng)};
    return img;
}

// Largest difference relative to the pixel's magnitude (and at least 1).
double max_relative_difference(const Image& a, const Image& b) {
    double worst = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            const double x = a.pixels[i][k], y = b.pixels[i][k];
            worst = std::max(worst, std::abs(x - y) / std::max({1.0, std::abs(x), std::abs(y)}));
        }
    return worst;
}

}  // namespace

TEST(BoxBlur, RunningSumEqualsTheDirectSumToRounding) {
    uint32_t seed = 1;
    for (const auto [w, h] : {std::pair{1, 1}, {1, 9}, {9, 1}, {17, 11}, {64, 48}})
        for (int r : {1, 2, 3, 5, 8, 31}) {
            const Image src = random_image(w, h, seed++);
            const Image fast = box_blur(src, r), slow = naive_blur(src, r);
            ASSERT_EQ(fast.width, w);
            ASSERT_EQ(fast.height, h);
            EXPECT_LT(max_relative_difference(fast, slow), 1e-13) << w << "x" << h << " r=" << r;
        }
}

TEST(BoxBlur, RadiusLargerThanTheImageGivesItsMean) {
    const Image src = random_image(13, 7, 42);
    Color mean;
    for (const Color& c : src.pixels) mean += c;
    mean = mean / double(src.pixels.size());
    for (int r : {13, 100, 4096}) {
        const Image out = box_blur(src, r);
        EXPECT_LT(max_relative_difference(out, naive_blur(src, r)), 1e-13);
        for (const Color& c : out.pixels)
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], mean[k], 1e-13);
    }
}

TEST(BoxBlur, ZeroRadiusReturnsTheInput) {
    const Image src = random_image(5, 4, 3);
    EXPECT_EQ(box_blur(src, 0).pixels, src.pixels);
}

// A firefly of 1e20 beside values near 1: once it leaves the window the small values it
// was summed with must still be there (a plain running sum would give 0 or garbage).
TEST(BoxBlur, FireflyDoesNotSwallowItsNeighbours) {
    Image src = random_image(40, 3, 7);
    src.at(5, 1) = {1e20, 1e20, 1e20};
    const Image fast = box_blur(src, 2), slow = naive_blur(src, 2);
    EXPECT_LT(max_relative_difference(fast, slow), 1e-13);
    EXPECT_GT(fast.at(30, 1).x, 0.1);  // far from the firefly: of the order of the inputs
}

// A non-finite pixel spoils only the boxes that contain it, as the direct sum does.
TEST(BoxBlur, NonFinitePixelSpoilsOnlyItsBoxes) {
    Image src = random_image(30, 1, 9);
    src.at(10, 0) = {INFINITY, 0.5, NAN};
    const Image fast = box_blur(src, 3), slow = naive_blur(src, 3);
    for (int x = 0; x < 30; ++x) {
        const bool inside = std::abs(x - 10) <= 3;
        EXPECT_EQ(std::isinf(fast.at(x, 0).x), inside) << x;
        EXPECT_EQ(std::isnan(fast.at(x, 0).z), inside) << x;
        EXPECT_NEAR(fast.at(x, 0).y, slow.at(x, 0).y, 1e-13) << x;
        if (!inside) EXPECT_NEAR(fast.at(x, 0).x, slow.at(x, 0).x, 1e-13) << x;
    }
}
