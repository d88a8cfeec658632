// The viewer's scripted runs, latency measurement and save dialog, without a window
// (viewer/script.h, viewer/latency.h, viewer/save_dialog.h).
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/image_hdr.h"
#include "core/args.h"
#include "core/image_io.h"
#include "render/outputs.h"
#include "scene/load.h"
#include "test_util.h"
#include "viewer/inspect.h"
#include "viewer/latency.h"
#include "viewer/save_dialog.h"
#include "viewer/script.h"
#include "viewer/view_options.h"

namespace {

using namespace kr;
using namespace kr::viewer;
using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

ViewerModel scene3() {
    ViewerModel m;
    m.load(std::string(KEITHRAY_RES_DIR) + "/scenes/assignment_03.json");
    return m;
}

// Each edit waits for a full-resolution frame, is timed to the first frame of its image,
// and the next one waits 300 ms; nudges alternate right and left.
TEST(LatencyMeasure, TimesEachEditToItsFirstFrame) {
    LatencyMeasure m(2);
    const Clock::time_point t0{};
    EXPECT_TRUE(m.running());
    EXPECT_FALSE(m.on_frame(t0, true, 4));  // a preview: no edit yet
    EXPECT_EQ(m.on_frame(t0, true, 1), 4.0);
    EXPECT_FALSE(m.on_frame(t0 + milliseconds(10), false, 1));      // an older image
    EXPECT_FALSE(m.on_frame(t0 + milliseconds(20), true, 8));       // the first frame: 20 ms at 1/8
    EXPECT_FALSE(m.on_frame(t0 + milliseconds(100), true, 1));      // before the spacing
    EXPECT_EQ(m.on_frame(t0 + milliseconds(400), true, 1), -4.0);
    EXPECT_FALSE(m.on_frame(t0 + milliseconds(440), true, 2));      // 40 ms at 1/2
    EXPECT_FALSE(m.running());
    EXPECT_FALSE(m.on_frame(t0 + milliseconds(900), true, 1));
    m.record_frame(0.002, 0.016);
    const std::string report = m.report();
    EXPECT_NE(report.find("2 edits: median 40.0 ms"), std::string::npos) << report;  // nearest rank of {20, 40}
    EXPECT_NE(report.find("max 40.0 ms; coarsest preview: 1/8"), std::string::npos) << report;
    EXPECT_NE(report.find("median 16.0 ms, 95th percentile 16.0 ms, max 16.0 ms (1 frames)"), std::string::npos);
}

// Done, one second to settle, S seconds measured; then the caller pauses, and the same again.
TEST(IdleMeasure, MeasuresDoneThenAsksToPauseThenFinishes) {
    IdleMeasure idle(2);
    const Clock::time_point t0{};
    EXPECT_EQ(idle.step(t0, false), IdleMeasure::Step::wait);
    EXPECT_EQ(idle.step(t0 + milliseconds(100), true), IdleMeasure::Step::wait);   // done: settle
    EXPECT_EQ(idle.step(t0 + milliseconds(1200), true), IdleMeasure::Step::wait);  // measuring from here
    EXPECT_EQ(idle.step(t0 + milliseconds(2000), true), IdleMeasure::Step::wait);
    EXPECT_EQ(idle.step(t0 + milliseconds(3300), true), IdleMeasure::Step::pause);
    EXPECT_EQ(idle.step(t0 + milliseconds(4400), false), IdleMeasure::Step::wait);  // settled: measuring
    EXPECT_EQ(idle.step(t0 + milliseconds(5000), false), IdleMeasure::Step::wait);
    EXPECT_EQ(idle.step(t0 + milliseconds(6500), false), IdleMeasure::Step::finished);
}

TEST(Script, PassesNeededAndTimeout) {
    ViewOptions o;
    ViewerSettings s;
    s.render.target_spp = 8;
    EXPECT_EQ(script_passes_needed(o, s), 8);
    o.frames = 20;
    EXPECT_EQ(script_passes_needed(o, s), 8);
    s.unlimited = true;
    EXPECT_EQ(script_passes_needed(o, s), 20);
    o.timeout = 5;
    const Clock::time_point t0{};
    EXPECT_FALSE(script_timed_out(o, t0, t0 + milliseconds(5000)));
    EXPECT_TRUE(script_timed_out(o, t0, t0 + milliseconds(5001)));
}

// The scripted edits go through the edit path given, in order, and a focus click on the
// image centre of scene 3 makes a lens focused on what it hits.
TEST(Script, EditsGoThroughTheEditPath) {
    ViewerModel m = scene3();
    ViewOptions o;
    o.aperture = 0.25;
    o.orbit = std::make_pair(30.0, 0.0);
    o.click_focus = std::make_pair(m.scene().renderer.width / 2.0, m.scene().renderer.height / 2.0);
    std::vector<Edit> kinds;
    const Camera before = m.camera();
    ASSERT_TRUE(apply_script_edits(o, m, [&](Edit kind, const auto& change) {
        kinds.push_back(kind);
        return m.edit(kind, change);
    }));
    EXPECT_EQ(kinds, (std::vector<Edit>{Edit::lens, Edit::camera}));
    EXPECT_EQ(m.camera().type, CameraType::lens);
    EXPECT_EQ(m.camera().alpha, 0.25);
    EXPECT_TRUE(m.camera().position.x != before.position.x || m.camera().position.z != before.position.z);
    EXPECT_GT(m.camera().focal_distance, 0);
}

ViewOptions parse_view(std::vector<std::string> args) {
    args.insert(args.begin(), {"keithray", "view", "s.json"});
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    return parse_view_options(int(argv.size()), argv.data());
}

// The usage error a command line gives, or "" when it parses.
std::string usage_error(const std::vector<std::string>& args) {
    try {
        parse_view(args);
    } catch (const UsageError& e) {
        return e.message;
    }
    return "";
}

// Flags whose combination or values would mean nothing are refused by the command line
// alone, naming the flag: a drag of no selection, an empty, inverted or fractional region.
TEST(ViewOptions, FlagsThatWouldMeanNothingAreUsageErrors) {
    EXPECT_EQ(usage_error({"--select", "3,4", "--move-selection", "5,-6", "--region", "0,0", "8,8"}), "");
    const std::pair<std::vector<std::string>, const char*> cases[] = {
        {{"--move-selection", "5,-6"}, "--move-selection drags the selection: give --select X,Y too"},
        {{"--region", "10,10", "10,20"}, "--region X0,Y0 X1,Y1 refines the pixels [X0, X1) x [Y0, Y1): it needs X0 < X1"},
        {{"--region", "10,10", "20,10"}, "got \"10,10 20,10\", an empty region"},
        {{"--region", "30,30", "10,10"}, "got \"30,30 10,10\", an empty region"},
        {{"--region", "0.5,0", "8,8"}, "--region takes whole image pixels, got \"0.5,0 8,8\""},
    };
    for (const auto& [args, message] : cases) {
        const std::string error = usage_error(args);
        EXPECT_NE(error.find(message), std::string::npos) << error;
        EXPECT_EQ(error.find('\n'), std::string::npos) << error;
    }
}

// Pixels of the command line outside the image (checked once the scene's size is known,
// before a window opens): each refused naming its flag and the image's size.
TEST(ViewOptions, PixelsOutsideTheImageAreRefused) {
    const int w = 64, h = 48;
    EXPECT_EQ(script_problem(parse_view({"--select", "63,47", "--click-focus", "0,0", "--probe", "10,20", "--region", "0,0",
                                         "64,48"}),
                             w, h),
              "");
    const std::pair<std::vector<std::string>, const char*> cases[] = {
        {{"--select", "64,10"}, "--select 64,10 is outside the 64x48 image (pixels 0 to 63 across, 0 to 47 down)"},
        {{"--select", "-0.5,10", "--move-selection", "5,5"}, "--select -0.5,10 is outside the 64x48 image"},
        {{"--select", "3,900"}, "--select 3,900 is outside"},
        {{"--click-focus", "10,48"}, "--click-focus 10,48 is outside the 64x48 image"},
        {{"--probe", "-1,0"}, "--probe -1,0 is outside the 64x48 image"},
        {{"--region", "-1,0", "8,8"}, "--region -1,0 8,8 reaches outside the 64x48 image (at most 0,0 64,48)"},
        {{"--region", "60,40", "65,48"}, "--region 60,40 65,48 reaches outside"},
        {{"--region", "100,100", "200,200"}, "--region 100,100 200,200 reaches outside"},
    };
    for (const auto& [args, message] : cases) {
        const std::string problem = script_problem(parse_view(args), w, h);
        EXPECT_EQ(problem.rfind(message, 0), 0u) << problem;
    }
}

class ViewOutputs : public kr::test::ScratchDirTest {};

// Two outputs of one run naming one file (a saved image's depth file included) would both
// be written, the last one winning: refused before anything is opened, naming both flags.
// So is an output its writer would refuse, a folder.
TEST_F(ViewOutputs, TwoOutputsNamingOneFileAreRefused) {
    const std::string d = dir.string() + "/";
    auto problem = [&](std::vector<std::string> args) {
        ViewOptions o = parse_view(args);
        o.scene = dir / "s.json";
        return view_files_problem(o);
    };
    EXPECT_EQ(problem({"--frames", "1", "--screenshot", d + "a.ppm", "--save-image", d + "b.ppm", "--save-scene",
                       d + "c.json", "--stats-json", d + "d.json", "--status-file", d + "e.txt", "--window-shot",
                       d + "f.png"}),
              "");
    const std::pair<std::vector<std::string>, std::vector<const char*>> cases[] = {
        {{"--save-scene", d + "x.ppm", "--save-image", d + "x.ppm"}, {"--save-image ", "and --save-scene "}},
        {{"--screenshot", d + "x.ppm", "--save-image", d + "x.ppm"}, {"--screenshot ", "and --save-image "}},
        {{"--screenshot", d + "x-depth.ppm", "--save-image", d + "x.ppm"}, {"--screenshot ", "and --save-image's depth file "}},
        {{"--save-image", d + "x.ppm", "--window-shot", d + "sub/../x-depth.ppm"}, {"--window-shot ", "and --save-image's depth file "}},
        {{"--stats-json", d + "s.txt", "--status-file", d + "s.txt"}, {"--stats-json ", "and --status-file "}},
        {{"--screenshot", d + "w.png", "--window-shot", d + "w.png"}, {"--screenshot ", "and --window-shot "}},
    };
    for (const auto& [args, words] : cases) {
        const std::string p = problem(args);
        for (const char* word : words) EXPECT_NE(p.find(word), std::string::npos) << word << " in " << p;
        EXPECT_NE(p.find("are one file"), std::string::npos) << p;
    }
    std::filesystem::create_directories(dir / "folder.ppm");
    const std::string folder = problem({"--save-image", d + "folder.ppm"});
    EXPECT_EQ(folder.rfind("--save-image \"", 0), 0u) << folder;
    EXPECT_NE(folder.find("folder.ppm\": is a folder"), std::string::npos) << folder;
    // Saving the edited scene over its own file is what Save does.
    EXPECT_EQ(problem({"--save-scene", d + "s.json", "--frames", "1"}), "");
}

class SaveDialog : public kr::test::ScratchDirTest {};

TEST_F(SaveDialog, DefaultPathsAndWhatEachKindWrites) {
    ViewerModel m = scene3();
    const SavePaths paths = SavePaths::for_scene(m.scene());
    EXPECT_EQ(std::filesystem::path(paths.image).extension(), ".ppm");
    // Each format's button saves the image field under its extension, and that name is of
    // the button's kind.
    for (const kr::ImageFormatInfo& format : kr::kImageFormats) {
        const std::filesystem::path path = image_save_path(format.format, paths.image);
        EXPECT_EQ(path.extension(), format.extension);
        EXPECT_EQ(path.stem(), std::filesystem::path(paths.image).stem());
        EXPECT_EQ(image_save_kind(path), SaveKind(format.format));
    }
    EXPECT_EQ(std::filesystem::path(paths.scene).filename(), "assignment_03-edited.json");

    // No full-resolution image yet: nothing written.
    Snapshot preview;
    preview.scale = 2;
    EXPECT_THROW(save_output(kr::ImageFormat::ppm, dir / "a.ppm", m, &preview), std::exception);
    EXPECT_THROW(save_output(kr::ImageFormat::png, dir / "a.png", m, nullptr), std::exception);
    EXPECT_FALSE(std::filesystem::exists(dir / "a.ppm"));

    // A full-resolution frame of the current scene, with the layers Save develops.
    Snapshot full;
    full.generation = m.generation();
    full.radiance = Image(4, 3);
    full.depth.assign(12, 1.0);
    full.sample_count.assign(12, 1);
    full.variance.assign(12, Color());
    // The denoised display's image (the default) waits for a frame with the two halves of the
    // samples, which the final filter reads: a frame of a render still refining has none.
    ASSERT_NE(m.settings().denoise, DenoiseView::off);
    EXPECT_TRUE(save_waits_for_halves(kr::ImageFormat::ppm, m, &full));
    EXPECT_FALSE(save_waits_for_halves(SaveKind::scene, m, &full));
    EXPECT_THROW(save_output(kr::ImageFormat::ppm, dir / "a.ppm", m, &full), std::exception);
    EXPECT_FALSE(std::filesystem::exists(dir / "a.ppm"));
    m.edit(Edit::tone_map, [&](Scene&, ViewerSettings& s) { s.denoise = DenoiseView::off; });
    EXPECT_FALSE(save_waits_for_halves(kr::ImageFormat::ppm, m, &full));  // a raw image needs none
    m.edit(Edit::tone_map, [&](Scene&, ViewerSettings& s) { s.denoise = DenoiseView::on; });
    full.generation = m.generation();
    for (int h = 0; h < 2; ++h) {
        full.halves.mean[h] = Image(4, 3);
        full.halves.count[h].assign(12, 0);
    }
    EXPECT_FALSE(save_waits_for_halves(kr::ImageFormat::ppm, m, &full));
    EXPECT_EQ(save_output(kr::ImageFormat::ppm, dir / "a.ppm", m, &full), "saved " + (dir / "a.ppm").string());
    EXPECT_EQ(read_image(dir / "a.ppm").width, 4);
    EXPECT_EQ(read_image(dir / "a-depth.ppm").width, 4);
    save_output(kr::ImageFormat::pfm, dir / "a.pfm", m, &full);
    EXPECT_TRUE(std::filesystem::exists(dir / "a.pfm"));
    EXPECT_TRUE(std::filesystem::exists(dir / "a-depth.pfm"));
    // The kind is the name's format; a frame of an older scene is not saved.
    EXPECT_THROW(save_output(kr::ImageFormat::png, dir / "b.ppm", m, &full), std::exception);
    Snapshot old = full;
    --old.generation;
    EXPECT_THROW(save_output(kr::ImageFormat::ppm, dir / "c.ppm", m, &old), std::exception);
    EXPECT_FALSE(std::filesystem::exists(dir / "b.ppm") || std::filesystem::exists(dir / "c.ppm"));
    EXPECT_EQ(save_targets(kr::ImageFormat::exr, dir / "a.exr"), std::vector<std::filesystem::path>{dir / "a.exr"});
    EXPECT_EQ(save_targets(kr::ImageFormat::png, dir / "a.png").back(), dir / "a-depth.png");
    EXPECT_EQ(image_save_path(kr::ImageFormat::pfm, "x/out.exr"), std::filesystem::path("x/out.pfm"));
    EXPECT_EQ(image_save_kind("OUT.EXR"), SaveKind(kr::ImageFormat::exr));

    // The scene: written as saved, and the model counts as saved.
    ASSERT_TRUE(m.edit(Edit::renderer, [](Scene&, ViewerSettings& s) { s.render.max_depth = 2; }));
    ASSERT_TRUE(m.dirty());
    save_output(SaveKind::scene, dir / "s.json", m, nullptr);
    EXPECT_FALSE(m.dirty());
    EXPECT_EQ(load_scene_file(dir / "s.json").scene.renderer.depth, 2);
}

// What the Save panel writes of a frame is what `render -o` writes of the state the frame
// was taken from (render/outputs.h), for every format: every file, byte for byte.
TEST_F(SaveDialog, ImageFilesAreTheRenderOutputsOfTheSameState) {
    Scene scene = load_scene_file(std::string(KEITHRAY_RES_DIR) + "/scenes/assignment_06.json").scene;
    scene.renderer.width = 24;
    scene.renderer.height = 16;
    ViewerModel m;
    m.set_scene(scene);
    RenderState state(24, 16);
    state.track_halves();  // as the render thread and render --denoise do: the final filter's
    StopRule rule;
    rule.max_passes = 2;
    render_until(*m.prepared(), m.settings().render, state, rule);
    Snapshot frame;
    frame.generation = m.generation();
    frame.radiance = state.radiance();
    record_pixel_statistics(state, frame);
    frame.halves = state.halves();  // as the frame of a finished or paused render carries them

    // Raw and denoised (Save develops with the final filter over the halves, as render --denoise).
    for (const DenoiseView view : {DenoiseView::off, DenoiseView::on})
    for (const char* ext : {".ppm", ".png", ".exr", ".pfm"}) {
        m.edit(Edit::tone_map, [&](Scene&, ViewerSettings& s) { s.denoise = view; });
        const std::filesystem::path saved = dir / (std::string("saved") + ext), rendered = dir / (std::string("cli") + ext);
        save_output(image_save_kind(saved), saved, m, &frame);
        OutputRequest request;
        request.path = rendered;
        request.display = m.settings().tone;
        request.develop.denoise = view == DenoiseView::on ? Denoise::on : Denoise::off;
        request.develop.sampling = m.settings().render;
        write_files_atomic(output_files(*m.prepared(), state, request));
        const std::vector<std::filesystem::path> a = output_file_paths(saved), b = output_file_paths(rendered);
        ASSERT_EQ(a.size(), b.size()) << ext;
        EXPECT_EQ(a.size(), std::string(ext) == ".exr" ? 1u : 2u) << ext;
        for (size_t i = 0; i < a.size(); ++i) {
            EXPECT_FALSE(test::read_file(a[i]).empty()) << a[i];
            EXPECT_EQ(test::read_file(a[i]), test::read_file(b[i])) << a[i];
        }
    }
    // The EXR holds every layer.
    const HdrImage exr = read_hdr(dir / "saved.exr");
    EXPECT_EQ(exr.depth.size(), 24u * 16u);
    EXPECT_EQ(exr.albedo.size(), 3u * 24u * 16u);
    EXPECT_EQ(exr.normal.size(), 3u * 24u * 16u);
    EXPECT_EQ(exr.samples.size(), 24u * 16u);
    EXPECT_EQ(exr.variance.size(), 3u * 24u * 16u);
}

}  // namespace
