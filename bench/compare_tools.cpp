// The viewer's per-frame cost of its inspect and compare tools (prints figures, asserts
// nothing): per new full-resolution frame, the render thread copies the pixel statistics
// into the snapshot, and the UI thread tone maps A, compares it with B and, in the error
// and noise views, makes the false-colour picture. Medians of 15 runs each, at 512x512
// and 1920x1080. Built and run by scripts/bench_viewer.sh (docs/viewer.md records them).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <random>
#include <vector>

#include "core/image_compare.h"
#include "viewer/compare_view.h"
#include "viewer/inspect.h"

using namespace kr;
using namespace kr::viewer;

namespace {

double median_ms(const std::function<void()>& step) {
    std::vector<double> ms;
    for (int i = 0; i < 15; ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        step();
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    std::nth_element(ms.begin(), ms.begin() + 7, ms.end());
    return ms[7];
}

}  // namespace

int main() {
    for (const auto& [w, h] : {std::pair{512, 512}, std::pair{1920, 1080}}) {
        // A state of 16 samples a pixel of noisy radiance, and a reference near it.
        std::mt19937 rng(1);
        std::uniform_real_distribution<double> u(0, 2);
        RenderState state(w, h);
        PixelBuffers& px = state.buffers();
        Rgb8Image reference{w, h, std::vector<uint8_t>(size_t(w) * size_t(h) * 3)};
        for (size_t i = 0; i < px.radiance_sum.size(); ++i) {
            px.radiance_sum[i] = Color(u(rng), u(rng), u(rng)) * 16;
            px.luminance_sq_sum[i] = 16 * 4 * u(rng);
            px.sample_count[i] = 16;
            for (int k = 0; k < 3; ++k) reference.bytes[3 * i + size_t(k)] = uint8_t(rng() % 256);
        }
        Snapshot frame;
        frame.radiance = state.radiance();
        Rgb8Image a;
        std::printf("%dx%d\n", w, h);
        std::printf("  render thread: pixel statistics into the snapshot  %7.2f ms\n",
                    median_ms([&] { record_pixel_statistics(state, frame); }));
        std::printf("  UI: tone map A                                      %7.2f ms\n",
                    median_ms([&] { a = tonemap(frame.radiance, ToneMap::sigmoid, 1); }));
        std::printf("  UI: PSNR and RMSE against B                         %7.2f ms\n",
                    median_ms([&] { (void)compare_figures(a, reference); }));
        std::printf("  UI: error view picture                              %7.2f ms\n", median_ms([&] {
                        const std::vector<float> e = pixel_errors(a, reference, ErrorMetric::absolute);
                        (void)false_colour_picture(e, w, h, robust_scale(e));
                    }));
        std::printf("  UI: noise view picture                              %7.2f ms\n", median_ms([&] {
                        (void)standard_error_map(frame, robust_scale(frame.standard_error));
                    }));
    }
}
