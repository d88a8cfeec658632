// The frames the viewer's render thread shows after an edit (prints figures, asserts nothing):
// for a scene, the worker renders the view until settled, then an orbit of DX pixels is
// submitted and every frame published after it is kept with its time. Each frame is taken as
// the display shows it (viewer/status.h displayed_picture: the default denoised display, a
// preview smoothly upscaled) and compared with the settled image of the new view (a raw
// render of --settle-spp samples at another seed): PSNR, in order, then the PSNR of the frame
// on screen at 0.25, 0.5, 1, 2, 3 and 10 s, and whether any frame was worse than the one
// before it. Then the render thread's passes per second against ProgressiveDriver's alone.
// Usage: keithray_bench_frames [SCENE.json] [--orbit DX] [--seconds S] [--settle-spp N]
//                              [--size WxH] [--raw] [--dump DIR] [--no-region] [--before S]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "bench_main.h"
#include "core/image_io.h"
#include "render/progressive.h"
#include "scene/load.h"
#include "viewer/navigation.h"
#include "viewer/render_worker.h"
#include "viewer/status.h"

using namespace kr;
using namespace kr::viewer;

namespace {

using Clock = std::chrono::steady_clock;

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

struct Recorded {
    double t = 0;
    std::shared_ptr<const Snapshot> frame;
};

}  // namespace

namespace {

int run(int argc, char** argv) {
    const char* file = "res/scenes/assignment_03.json";
    double orbit_px = 120, run_seconds = 10, before_seconds = 1;
    int settle_spp = 1024, width = 0, height = 0;
    bool raw = false, region_too = true;
    std::string dump;  // a folder: the settled image and each frame as shown, as PNG
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--orbit" && i + 1 < argc) orbit_px = std::atof(argv[++i]);
        else if (a == "--seconds" && i + 1 < argc) run_seconds = std::atof(argv[++i]);
        else if (a == "--settle-spp" && i + 1 < argc) settle_spp = std::atoi(argv[++i]);
        else if (a == "--size" && i + 1 < argc) std::sscanf(argv[++i], "%dx%d", &width, &height);
        else if (a == "--raw") raw = true;
        else if (a == "--no-region") region_too = false;
        else if (a == "--dump" && i + 1 < argc) dump = argv[++i];
        else if (a == "--before" && i + 1 < argc) before_seconds = std::atof(argv[++i]);
        else if (a.rfind("--", 0) == 0) throw std::invalid_argument("unknown option '" + a.substr(0, 40) + "' (--help lists them)");
        else file = argv[i];
    }
    Scene scene = load_scene_file(file).scene;
    if (width > 0 && height > 0) scene.renderer.width = width, scene.renderer.height = height;
    const int w = scene.renderer.width, h = scene.renderer.height;
    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    const DenoiseView view = raw ? DenoiseView::off : DenoiseView::on;
    std::printf("%s, %dx%d, %s display, orbit %.0f px\n", file, w, h, raw ? "raw" : "denoised", orbit_px);

    std::mutex mutex;
    std::vector<Recorded> frames;
    Clock::time_point edit_time{};
    RenderWorker* worker_ptr = nullptr;
    RenderWorker worker([&] {
        std::lock_guard lock(mutex);
        if (worker_ptr && edit_time != Clock::time_point{}) frames.push_back({seconds(Clock::now() - edit_time), worker_ptr->latest()});
    });
    worker_ptr = &worker;
    worker.set_denoise(!raw);
    StopRule open_ended;
    open_ended.max_passes = kUnlimitedPasses;
    // The view before the edit, refined for --before seconds (1 by default) (the render thread measures its pass).
    worker.submit({1, std::make_shared<const RenderScene>(prepare_scene(scene)), settings, open_ended, nullptr, {}});
    std::this_thread::sleep_for(std::chrono::duration<double>(before_seconds));

    // The orbit as the window makes it: about the target, stopping at surfaces.
    Camera& camera = scene.cameras[size_t(scene.camera)];
    camera = orbit_step(scene, camera, camera.target, orbit_px, 0, true);
    const auto moved = std::make_shared<const RenderScene>(prepare_scene(scene));
    {
        std::lock_guard lock(mutex);
        edit_time = Clock::now();
    }
    worker.submit({2, moved, settings, open_ended, nullptr, edit_time});
    std::this_thread::sleep_for(std::chrono::duration<double>(run_seconds));
    worker.set_paused(true);

    // The settled image of the new view: a raw render at another seed.
    RenderSettings settled_settings = settings;
    settled_settings.seed = settings.seed + 7919;
    RenderState settled(w, h);
    StopRule settle_rule;
    settle_rule.max_passes = settle_spp;
    render_until(*moved, settled_settings, settled, settle_rule);
    const Rgb8Image reference = tonemap(settled.radiance(), scene.display.tonemap, scene.display.exposure_scale());

    if (!dump.empty()) write_image(dump + "/settled.png", reference);
    std::vector<Recorded> kept;
    {
        std::lock_guard lock(mutex);
        for (const Recorded& r : frames)
            if (r.frame && r.frame->generation == 2 && r.frame->error.empty()) kept.push_back(r);
    }
    std::vector<double> psnrs;
    std::printf("   time    scale  spp    PSNR\n");
    bool worse = false;
    for (const Recorded& r : kept) {
        const Rgb8Image shown = displayed_picture(*r.frame, view, w, h, scene.display);
        psnrs.push_back(psnr(shown, reference));
        if (!dump.empty()) write_image(dump + "/frame" + std::to_string(psnrs.size()) + ".png", shown);
        const bool drop = psnrs.size() > 1 && psnrs.back() < psnrs[psnrs.size() - 2];
        worse = worse || drop;
        if (kept.size() <= 40 || r.frame->scale > 1 || r.frame->spp <= 16 || &r == &kept.back())
            std::printf("  %6.3f s  1/%-3d %4d  %6.2f dB%s\n", r.t, r.frame->scale, r.frame->spp, psnrs.back(),
                        drop ? "  (worse)" : "");
    }
    std::printf("  on screen at:");
    for (const double at : {0.25, 0.5, 1.0, 2.0, 3.0, 10.0}) {
        double value = -1;
        int spp = 0;
        for (size_t i = 0; i < kept.size() && kept[i].t <= at; ++i) value = psnrs[i], spp = kept[i].frame->spp;
        if (value < 0) std::printf("  %.2g s: none", at);
        else std::printf("  %.2g s: %.1f dB (%d spp)", at, value, spp);
    }
    for (const Recorded& r : kept)
        if (r.frame->scale == 1) {
            std::printf("\n  first full-resolution frame: %.3f s after the edit (%d spp)", r.t, r.frame->spp);
            break;
        }
    std::printf("\n  frames: %zu, %s\n", kept.size(), worse ? "some frame worse than the one before" : "each at least as good as the one before");
    if (!kept.empty()) {
        const Snapshot& last = *kept.back().frame;
        std::printf("  worker: %d spp in %.2f s wall (%.1f ms a pass, passes alone %.1f ms)\n", last.spp, last.seconds,
                    1e3 * last.seconds / std::max(1, last.spp), 1e3 * last.full_seconds / std::max(1, last.spp));
    }

    // A render region of about 4 % of the image (a centred box of a fifth of each side)
    // against the whole image: wall seconds from the edit to the target (the region's pixels
    // at it), medians of 3, interleaved.
    if (!region_too) return 0;
    const int target = 64;
    const PixelBox box{2 * w / 5, 2 * h / 5, 3 * w / 5, 3 * h / 5};
    std::vector<double> whole, region;
    for (int round = 0; round < 3; ++round)
        for (const bool boxed : {false, true}) {
            RenderWorker timed;
            timed.set_denoise(!raw);
            if (boxed) timed.set_region(box);
            StopRule rule;
            rule.max_passes = target;
            const auto t0 = Clock::now();
            timed.submit({1, moved, settings, rule, nullptr, {}});
            std::shared_ptr<const Snapshot> f;
            while (!(f && f->finished)) f = timed.wait_newer(f ? f->serial : 0, std::chrono::milliseconds(1000));
            (boxed ? region : whole).push_back(seconds(Clock::now() - t0));
        }
    std::sort(whole.begin(), whole.end());
    std::sort(region.begin(), region.end());
    std::printf("  to %d spp: whole image %.2f s, a region of %.1f %% of it %.2f s (%.1fx sooner)\n", target, whole[1],
                100.0 * (box.x1 - box.x0) * (box.y1 - box.y0) / (double(w) * h), region[1], whole[1] / region[1]);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    return kr::bench::bench_main(argc, argv, "keithray_bench_frames", "[SCENE.json] [--orbit DX] [--seconds S] [--settle-spp N] [--size WxH] [--raw] [--dump DIR] [--no-region] [--before S]", run);
}
