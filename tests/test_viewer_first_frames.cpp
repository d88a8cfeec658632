// The viewer's first frames after an edit never get worse (model level, no window): the
// frames the render thread can publish, in their order (the previews from 1/16 to 1/2, then
// the full-resolution frames at 1, 2, ... spp), each taken as the window shows it with the
// default denoised display (viewer/status.h displayed_picture: a preview upscaled smoothly; the
// first full frame guided by the 1/2 preview's feature buffers, as display_features_for_frame does),
// compared with the settled image of the scene (a raw render of many samples at another seed).
// The render thread publishes some of these frames, by its schedule; any of them in order
// keeps the order. Every scene of res/scenes and res/scenes/examples, at a small size.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "render/progressive.h"
#include "scene/load.h"
#include "test_util.h"
#include "viewer/render_worker.h"
#include "viewer/status.h"

namespace {

using namespace kr;
using namespace kr::viewer;

constexpr int kWidth = 96;         // pixels across (the scene's aspect kept)
constexpr int kFullFrames = 8;     // full-resolution frames checked: up to 8 spp
constexpr int kSettledSpp = 128;   // the settled image's samples (16x the last frame's)
// A frame may be this much below the one before it: at 80 pixels across a full frame's PSNR
// moves by about 0.02-0.05 dB from one seed to another, while one more sample a pixel adds
// about 0.3 dB at 16 spp (and more before); a worse frame (a blocky preview, speckles) is
// 1-10 dB worse.
constexpr double kToleranceDb = 0.1;

std::vector<std::filesystem::path> all_scenes() {
    std::vector<std::filesystem::path> out;
    for (const auto* folder : {"scenes", "scenes/examples"})
        for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(KEITHRAY_RES_DIR) / folder))
            if (entry.path().extension() == ".json") out.push_back(entry.path());
    std::sort(out.begin(), out.end());
    return out;
}

TEST(FirstFrames, NeverWorseAfterAnEditOnEveryBundledScene) {
    for (const auto& file : all_scenes()) {
        SCOPED_TRACE(file.filename().string());
        Scene scene = load_scene_file(file).scene;
        const int w = kWidth, h = std::max(1, int(std::lround(double(kWidth) * scene.renderer.height / scene.renderer.width)));
        scene.renderer.width = w;
        scene.renderer.height = h;
        RenderJob job;
        job.scene = std::make_shared<const RenderScene>(prepare_scene(scene));
        job.settings = RenderSettings::from_scene(scene.renderer);

        RenderSettings settled_settings = job.settings;
        settled_settings.seed += 7919;
        RenderState settled(w, h);
        StopRule settle_rule;
        settle_rule.max_passes = kSettledSpp;
        render_until(*job.scene, settled_settings, settled, settle_rule);
        const Rgb8Image reference = tonemap(settled.radiance(), scene.display.tonemap, scene.display.exposure_scale());

        std::vector<std::pair<std::string, double>> frames;
        DenoiseWorkspace workspace;
        DisplayFeatures preview_features;  // the last preview's, which the first full frame takes
        for (const int scale : {8, 4, 2}) {
            Snapshot frame;
            make_preview_frame(job, scale, true, false, workspace, frame, &preview_features);
            frames.push_back({"1/" + std::to_string(scale) + " preview",
                              psnr(displayed_picture(frame, DenoiseView::on, w, h, scene.display), reference)});
        }
        RenderState state(w, h);
        StopRule rule;
        rule.max_passes = kFullFrames;
        ProgressiveDriver driver(*job.scene, job.settings, state, rule);
        DisplayFeatures features;
        features.reset(w, h);
        for (int spp = 1; spp <= kFullFrames; ++spp) {
            driver.pass(rule);
            if (!frame_spp(spp, first_frame_spp(*job.scene))) continue;
            display_features_for_frame(features, job, &preview_features, std::nullopt);
            Snapshot frame;
            make_full_frame(job, state, &features, workspace, frame);
            frames.push_back({std::to_string(spp) + " spp",
                              psnr(displayed_picture(frame, DenoiseView::on, w, h, scene.display), reference)});
        }
        std::string listing;
        for (const auto& [name, value] : frames) listing += name + " " + std::to_string(value).substr(0, 5) + " dB, ";
        for (size_t i = 1; i < frames.size(); ++i)
            EXPECT_GE(frames[i].second, frames[i - 1].second - kToleranceDb)
                << frames[i].first << " after " << frames[i - 1].first << ": " << listing;
    }
}

}  // namespace
