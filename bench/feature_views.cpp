// The cost of the viewer's feature views (prints figures, asserts nothing): the render
// thread's feature buffers (once per edit) and hit depths (per frame) and the UI's pictures
// (per frame), medians of 15 at the scene's resolution; then the render thread from an edit to
// its finished 8 spp, with the feature layers off (the default) and on, interleaved, medians
// of 5 each. Usage: keithray_bench_features [SCENE.json] (default res/scenes/assignment_03.json).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <memory>
#include <vector>

#include "bench_main.h"
#include "render/outputs.h"
#include "scene/load.h"
#include "viewer/inspect.h"
#include "viewer/render_worker.h"

using namespace kr;
using namespace kr::viewer;

namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    return v[v.size() / 2];
}

double median_ms(int runs, const std::function<void()>& step) {
    std::vector<double> ms;
    for (int i = 0; i < runs; ++i) {
        const auto t0 = Clock::now();
        step();
        ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    }
    return median(ms);
}

}  // namespace

namespace {

int run(int argc, char** argv) {
    const char* file = argc > 1 ? argv[1] : "res/scenes/assignment_03.json";
    const auto scene = std::make_shared<const RenderScene>(prepare_scene(load_scene_file(file).scene));
    RenderSettings settings = RenderSettings::from_scene(scene->renderer);
    settings.target_spp = 8;
    const int w = scene->renderer.width, h = scene->renderer.height;
    std::printf("%s, %dx%d\n", file, w, h);

    auto features = std::make_shared<FeatureBuffers>();
    features->width = w;
    features->height = h;
    std::printf("  render thread: feature buffers, once per edit     %8.2f ms\n", median_ms(5, [&] {
                    feature_buffers(*scene, settings, w, h, features->albedo, features->normal);
                }));
    RenderState state(w, h);
    for (int i = 0; i < 2; ++i) render_pass(*scene, settings, state);
    const std::vector<double> depth = state.mean_depth();
    const std::vector<uint32_t> samples = state.sample_count();
    std::vector<float> hit;
    std::printf("  render thread: hit depths, per frame               %8.2f ms\n",
                median_ms(15, [&] { hit = hit_depths(depth, samples); }));
    Snapshot frame;
    frame.radiance = state.radiance();
    frame.features = features;
    frame.hit_depth = hit;
    for (const ViewMode mode : {ViewMode::albedo, ViewMode::normal, ViewMode::depth})
        std::printf("  UI: %-6s view picture, per frame                %8.2f ms\n",
                    std::string(view_mode_names.name(mode)).c_str(),
                    median_ms(15, [&] { (void)feature_picture(frame, mode, w, h); }));

    // An edit to 8 spp on the render thread (previews, passes, the denoiser: the defaults).
    std::vector<double> off, on;
    for (int round = 0; round < 5; ++round)
        for (const bool layers : {false, true}) {
            RenderWorker worker;
            worker.set_features(layers);
            const auto t0 = Clock::now();
            worker.submit({1, scene, settings, StopRule{settings.target_spp}, nullptr, {}});
            std::shared_ptr<const Snapshot> f;
            while (!(f && f->finished)) f = worker.wait_newer(f ? f->serial : 0, std::chrono::milliseconds(1000));
            (layers ? on : off).push_back(std::chrono::duration<double>(Clock::now() - t0).count());
        }
    const double a = median(off), b = median(on);
    std::printf("  render thread: edit to 8 spp, feature layers off  %8.3f s\n", a);
    std::printf("  render thread: edit to 8 spp, feature layers on   %8.3f s  (x%.3f)\n", b, b / a);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    return kr::bench::bench_main(argc, argv, "keithray_bench_features", "[SCENE.json]", run);
}
