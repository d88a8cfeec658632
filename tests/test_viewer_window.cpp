// The real window under Xvfb: `keithray view` with scripted edits (a lens, a mouse orbit,
// a click-to-focus) accumulates N full-resolution passes, then reads back what the display
// shader drew. That must equal the headless render of the same state, which the viewer
// saves as JSON: deterministic seeding makes them equal up to float-vs-double rounding.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <regex>
#include <string>

#include <nlohmann/json.hpp>

#include "core/image.h"
#include "core/image_compare.h"
#include "core/image_formats.h"
#include "core/image_hdr.h"
#include "core/image_io.h"
#include "viewer/compare_view.h"
#include "viewer/inspect.h"
#include "viewer/navigation.h"
#include "viewer/outliner.h"
#include "viewer/scene_edit.h"
#include "render/outputs.h"
#include "render/render_scene.h"
#include "render/render_state.h"
#include "scene/load.h"
#include "scene/scene_list.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace {

using ViewRun = kr::test::CommandResult;

bool have_xvfb() { return std::system("command -v xvfb-run >/dev/null 2>&1") == 0; }

// xvfb-run with a screen big enough for the 512x512 image at 1:1 beside the panels.
// -noreset: a resetting Xvfb signals xvfb-run again after the last client leaves, and if that
// lands during xvfb-run's clean-up it exits 5 instead of keithray's status. -a searches for a
// free display from -n: a start of its own per process and call, so that two tests starting
// together (ctest -j) do not both take the first free number.
std::string xvfb_run() {
    static int calls = 0;
    const int start = 100 + int((unsigned(::getpid()) * 97u + unsigned(calls++) * 13u) % 20000u);
    return "xvfb-run -a -n " + std::to_string(start) + " -s '-screen 0 1280x1024x24 -noreset' ";
}

int max_channel_difference(const kr::Rgb8Image& a, const kr::Rgb8Image& b) {
    int worst = 0;
    for (size_t i = 0; i < a.bytes.size(); ++i) worst = std::max(worst, std::abs(int(a.bytes[i]) - int(b.bytes[i])));
    return worst;
}

class ViewerWindow : public testing::Test {
protected:
    fs::path dir;
    void SetUp() override {
        if (!have_xvfb()) GTEST_SKIP() << "xvfb-run is not installed (scripts/setup.sh installs it)";
        dir = fs::temp_directory_path() /
              ("keithray_view_" + std::string(testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
               std::to_string(::getpid()));
        fs::remove_all(dir);
        fs::create_directories(dir);
    }
    void TearDown() override {
        if (!dir.empty()) fs::remove_all(dir);
    }
    static std::string scene(int n) {
        return kr::test::brief_scene_file(n).string();
    }
    ViewRun keithray(std::string args, bool window) {
        // The window's pixels are compared with raw headless renders: the denoised display
        // (the viewer's default) is asked for by the tests about it, by name.
        if (args.rfind("view ", 0) == 0 && args.find("--denoise") == std::string::npos) args += " --denoise off";
        const std::string prefix = window ? xvfb_run() : "";
        return kr::test::run_command(prefix + "'" + KEITHRAY_EXE + "' " + args, dir);
    }
    // `keithray view` of brief scene n for `spp` passes with `flags`, in a window, then the
    // headless render of the same passes (with `render_flags`) into dir/headless.ppm, whose
    // failure is reported here. Returns the window's run.
    ViewRun view_and_render(int n, int spp, const std::string& flags, const std::string& render_flags = "") {
        const std::string passes = " --spp " + std::to_string(spp);
        const ViewRun v = keithray(
            "view '" + scene(n) + "'" + passes + " --frames " + std::to_string(spp) + " " + flags + " --timeout 300", true);
        const ViewRun r = keithray("render '" + scene(n) + "'" + passes + " -q " + render_flags + " -o '" +
                                       (dir / "headless.ppm").string() + "'",
                                   false);
        EXPECT_EQ(r.status, 0) << r.err;
        return v;
    }
};

}  // namespace

TEST_F(ViewerWindow, ScriptedEditsScreenshotMatchesHeadlessRender) {
    const fs::path shot = dir / "shot.ppm", saved = dir / "edited.json", headless = dir / "headless.ppm";
    const ViewRun v = keithray("view '" + scene(3) + "' --spp 3 --frames 3 --aperture 0.4 --orbit 60,-30"
                           " --click-focus 300,400 --screenshot '" + shot.string() + "' --save-scene '" +
                               saved.string() + "' --timeout 300",
                           true);
    ASSERT_EQ(v.status, 0) << v.out << v.err;
    EXPECT_NE(v.err.find("window GL:"), std::string::npos) << v.err;

    // The edits reached the scene: a thin lens, orbited, focused where the script clicked.
    const kr::Scene edited = kr::load_scene_file(saved).scene;
    const kr::Camera& cam = edited.cameras[size_t(edited.camera)];
    EXPECT_EQ(cam.type, kr::CameraType::lens);
    EXPECT_EQ(cam.alpha, 0.4);
    EXPECT_NE(cam.position, kr::Vec3(0, 0, -15));
    std::smatch m;
    ASSERT_TRUE(std::regex_search(v.out, m, std::regex("focal distance: ([0-9.e+-]+)"))) << v.out;
    EXPECT_EQ(cam.focal_distance, std::stod(m[1]));
    EXPECT_GT(cam.focal_distance, 1);
    EXPECT_EQ(edited.renderer.samples, 3);

    const ViewRun r = keithray("render '" + saved.string() + "' --spp 3 -q -o '" + headless.string() + "'", false);
    ASSERT_EQ(r.status, 0) << r.err;
    const kr::Rgb8Image a = kr::read_ppm(shot), b = kr::read_ppm(headless);
    ASSERT_EQ(a.width, b.width);
    ASSERT_EQ(a.height, b.height);
    EXPECT_LE(max_channel_difference(a, b), 1);
    EXPECT_GT(kr::psnr(a, b), 60);
    // And the edits changed the image: it is not the unedited view.
    const ViewRun plain = keithray("render '" + scene(3) + "' --spp 3 -q -o '" + (dir / "plain.ppm").string() + "'", false);
    ASSERT_EQ(plain.status, 0);
    EXPECT_LT(kr::psnr(a, kr::read_ppm(dir / "plain.ppm")), 30);
}

// The scripted --save-image goes through the Save panel's code, and writes what `render -o`
// writes of the same render for the same name: every file, byte for byte, in each format
// (the 8-bit image and its depth map, the EXR with every layer, the PFM and its depth).
TEST_F(ViewerWindow, SaveImageWritesWhatRenderWritesForTheSameName) {
    for (const std::string ext : {"ppm", "png", "exr", "pfm"}) {
        const fs::path saved = dir / ("saved." + ext), rendered = dir / ("rendered." + ext);
        // The viewer's Save develops as its display: denoised by default, as render --denoise.
        const std::string flags = " --spp 2 --seed 5 --exposure 0.5 --denoise on";
        const ViewRun v = keithray("view '" + scene(6) + "'" + flags + " --save-image '" + saved.string() +
                                       "' --timeout 300",
                                   true);
        ASSERT_EQ(v.status, 0) << v.out << v.err;
        EXPECT_NE(v.out.find("image: " + saved.string() + " (2 spp)"), std::string::npos) << v.out;
        const ViewRun r = keithray("render '" + scene(6) + "'" + flags + " -q -o '" + rendered.string() + "'", false);
        ASSERT_EQ(r.status, 0) << r.err;
        const std::vector<fs::path> a = kr::output_file_paths(saved), b = kr::output_file_paths(rendered);
        ASSERT_EQ(a.size(), ext == "exr" ? 1u : 2u);
        ASSERT_EQ(a.size(), b.size());
        for (size_t i = 0; i < a.size(); ++i) {
            const std::string bytes = kr::test::read_file(a[i]);
            EXPECT_GT(bytes.size(), 1000u) << a[i];
            EXPECT_TRUE(bytes == kr::test::read_file(b[i])) << a[i] << " differs from " << b[i];
        }
    }
    // Every layer is in the EXR.
    const kr::HdrImage exr = kr::read_hdr(dir / "saved.exr");
    EXPECT_FALSE(exr.depth.empty() || exr.albedo.empty() || exr.normal.empty() || exr.samples.empty() ||
                 exr.variance.empty());
}

// Image A is the image the window shows, denoised by default. With no --denoise flag:
// `view --save-image` writes what `render --denoise on` writes, byte for byte; the saved
// scene records the mode in its display block, so a plain `render` of it writes those bytes
// too; and the stats JSON's PSNR is that of the window's own screenshot against B.
TEST_F(ViewerWindow, DenoisedDisplayIsWhatSaveTheSavedSceneAndThePsnrUse) {
    const fs::path ref = dir / "ref.ppm", saved = dir / "saved.ppm", saved_scene = dir / "saved.json",
                   shot = dir / "shot.ppm", stats = dir / "stats.json";
    const std::string flags = " --spp 2 --seed 5";
    ASSERT_EQ(keithray("render '" + scene(6) + "' --spp 16 -q -o '" + ref.string() + "'", false).status, 0);
    // Not through keithray(), which asks for the raw display.
    const ViewRun v = kr::test::run_command(
        xvfb_run() + "'" + KEITHRAY_EXE + "' view '" + scene(6) + "'" + flags + " --frames 2 --reference '" +
            ref.string() + "' --save-image '" + saved.string() + "' --save-scene '" + saved_scene.string() +
            "' --screenshot '" + shot.string() + "' --stats-json '" + stats.string() + "' --timeout 300",
        dir);
    ASSERT_EQ(v.status, 0) << v.out << v.err;
    const auto render = [&](const std::string& what, const std::string& render_flags, const std::string& out) {
        const ViewRun r = keithray("render '" + what + "'" + render_flags + " -q -o '" + (dir / out).string() + "'", false);
        EXPECT_EQ(r.status, 0) << r.err;
        return kr::test::read_file(dir / out);
    };
    const std::string bytes = kr::test::read_file(saved);
    EXPECT_TRUE(bytes == render(scene(6), flags + " --denoise on", "denoised.ppm"));
    EXPECT_FALSE(bytes == render(scene(6), flags, "raw.ppm"));
    // The saved scene says "denoise": "on", and render reads it as it reads the tone map.
    EXPECT_EQ(nlohmann::json::parse(kr::test::read_file(saved_scene))["scene"]["display"]["denoise"], "on");
    EXPECT_TRUE(bytes == render(saved_scene.string(), " --seed 5", "from_scene.ppm"));

    // The live PSNR is of the image on screen (the interactive filter's denoised picture), and
    // the JSON says which image that is.
    const nlohmann::json j = nlohmann::json::parse(kr::test::read_file(stats));
    ASSERT_TRUE(j.contains("psnr")) << j.dump();
    EXPECT_EQ(j["image"], "denoised");
    const double shown = kr::psnr(kr::read_ppm(shot), kr::read_ppm(ref));
    const double raw = kr::psnr(kr::read_ppm(dir / "raw.ppm"), kr::read_ppm(ref));
    ASSERT_GT(std::abs(shown - raw), 1.0) << "the denoised and raw images must differ for this test to mean anything";
    // The screenshot is the display shader's picture: within one step of kr::tonemap per channel.
    EXPECT_NEAR(j["psnr"].get<double>(), shown, 0.25) << "raw: " << raw;
}

// Tone map options go to the display shader only; the screenshot follows kr::tonemap.
TEST_F(ViewerWindow, LinearToneMapScreenshotMatchesHeadless) {
    const fs::path shot = dir / "shot.ppm", headless = dir / "headless.ppm";
    const ViewRun v = view_and_render(7, 2, "--tonemap linear --screenshot '" + shot.string() + "'", "--tonemap linear");
    ASSERT_EQ(v.status, 0) << v.out << v.err;
    EXPECT_LE(max_channel_difference(kr::read_ppm(shot), kr::read_ppm(headless)), 1);
}

TEST_F(ViewerWindow, BrokenSceneFailsScriptedRunWithItsError) {
    const fs::path bad = dir / "bad.json";
    std::ofstream(bad) << "{ \"scene\": ";
    const ViewRun v = keithray("view '" + bad.string() + "' --frames 1 --screenshot '" + (dir / "x.ppm").string() + "'", true);
    EXPECT_EQ(v.status, 1);
    EXPECT_NE(v.err.find("bad.json"), std::string::npos) << v.err;
    EXPECT_FALSE(fs::exists(dir / "x.ppm"));
}

// The compare views: the screenshot is what the window shows of the image, computed here on
// the CPU from the headless render of the same passes (the same driver and sums) and the
// brief's reference, offered for its scene.
namespace {

fs::path reference(int n) { return kr::test::brief_reference_file(n); }

}  // namespace

TEST_F(ViewerWindow, SplitViewShowsTheRenderLeftAndTheReferenceRight) {
    const fs::path shot = dir / "shot.ppm", headless = dir / "headless.ppm";
    const ViewRun v = view_and_render(3, 2, "--view split --split 0.25 --screenshot '" + shot.string() + "'");
    ASSERT_EQ(v.status, 0) << v.out << v.err;
    const kr::Rgb8Image s = kr::read_ppm(shot), a = kr::read_ppm(headless), b = kr::read_ppm(reference(3));
    ASSERT_EQ(s.width, 512);
    ASSERT_EQ(s.height, 512);
    int worst_a = 0, wrong_b = 0;
    for (size_t i = 0; i < s.bytes.size(); ++i) {
        const size_t x = (i / 3) % 512;
        if (x < 128) worst_a = std::max(worst_a, std::abs(int(s.bytes[i]) - int(a.bytes[i])));
        else wrong_b += s.bytes[i] != b.bytes[i];
    }
    EXPECT_LE(worst_a, 1);   // the display shader's tone map, as in the tests above
    EXPECT_EQ(wrong_b, 0);   // image B as stored
    // And they differ: the split shows two images.
    EXPECT_GT(max_channel_difference(a, b), 10);
}

TEST_F(ViewerWindow, ErrorViewIsTheFalseColourOfTheErrorAgainstTheReference) {
    const fs::path shot = dir / "shot.ppm", headless = dir / "headless.ppm";
    const ViewRun v = view_and_render(4, 2, "--view error --error relative --screenshot '" + shot.string() + "'");
    ASSERT_EQ(v.status, 0) << v.out << v.err;
    const std::vector<float> errors =
        kr::viewer::pixel_errors(kr::read_ppm(headless), kr::read_ppm(reference(4)), kr::viewer::ErrorMetric::relative);
    const kr::Rgb8Image expected =
        kr::false_colour_picture(errors, 512, 512, kr::viewer::robust_scale(errors));
    const kr::Rgb8Image s = kr::read_ppm(shot);
    ASSERT_EQ(s.width, 512);
    EXPECT_EQ(max_channel_difference(s, expected), 0);
}

TEST_F(ViewerWindow, SamplesViewShowsUniformAllocationAsOneColour) {
    const fs::path shot = dir / "shot.ppm";
    const ViewRun v = keithray("view '" + scene(1) + "' --spp 3 --frames 3 --allocation uniform --view samples"
                                   " --screenshot '" + shot.string() + "' --timeout 300",
                               true);
    ASSERT_EQ(v.status, 0) << v.out << v.err;
    const kr::Rgb8Image s = kr::read_ppm(shot);
    const auto top = kr::viridis(1.0);  // every pixel has the most samples: the top colour
    int wrong = 0;
    for (size_t i = 0; i < s.bytes.size(); ++i) wrong += s.bytes[i] != top[i % 3];
    EXPECT_EQ(wrong, 0);
}

// Missing item 4: the feature views show what `render --denoise on -o X.exr` writes in its
// albedo, normal and depth layers (the denoiser's feature buffers; the mean depth and the
// samples), mapped by the pictures of viewer/inspect.h: the window's pixels are those bytes,
// shown as they are, so they must be equal (no tolerance).
struct ExpectedViews {
    kr::Rgb8Image albedo, normal, depth;
    kr::HdrImage exr;
};
ExpectedViews expected_views(const fs::path& exr_file) {
    ExpectedViews e;
    e.exr = kr::read_hdr(exr_file);
    kr::viewer::FeatureBuffers f;
    f.width = e.exr.width;
    f.height = e.exr.height;
    f.albedo = e.exr.albedo;
    f.normal = e.exr.normal;
    e.albedo = kr::viewer::albedo_picture(f);
    e.normal = kr::viewer::normal_picture(f);
    const std::vector<float> hit =
        kr::viewer::hit_depths(std::vector<double>(e.exr.depth.begin(), e.exr.depth.end()), e.exr.samples);
    const auto range = kr::viewer::depth_range(hit);
    EXPECT_TRUE(range);
    if (range) e.depth = kr::viewer::depth_picture(hit, f.width, f.height, *range);
    return e;
}

TEST_F(ViewerWindow, FeatureViewsShowTheLayersRenderWritesInItsExr) {
    const ViewRun r = keithray("render '" + scene(3) + "' --spp 2 --denoise on -q -o '" + (dir / "r.exr").string() + "'", false);
    ASSERT_EQ(r.status, 0) << r.err;
    const ExpectedViews e = expected_views(dir / "r.exr");
    for (const std::string view : {"albedo", "normal", "depth"}) {
        const fs::path shot = dir / (view + ".ppm");
        const ViewRun v = keithray("view '" + scene(3) + "' --spp 2 --frames 2 --view " + view + " --screenshot '" +
                                       shot.string() + "' --timeout 300",
                                   true);
        ASSERT_EQ(v.status, 0) << v.out << v.err;
        const kr::Rgb8Image s = kr::read_ppm(shot);
        const kr::Rgb8Image& want = view == "albedo" ? e.albedo : view == "normal" ? e.normal : e.depth;
        ASSERT_EQ(s.width, want.width) << view;
        ASSERT_EQ(s.height, want.height) << view;
        EXPECT_EQ(max_channel_difference(s, want), 0) << view;
    }
    // The three pictures differ from each other and from the render.
    EXPECT_GT(max_channel_difference(e.albedo, e.normal), 100);
    EXPECT_GT(max_channel_difference(e.albedo, e.depth), 100);
}

TEST_F(ViewerWindow, LivePsnrEqualsThePsnrCommand) {
    const fs::path stats = dir / "stats.json", headless = dir / "headless.ppm";
    const ViewRun v = view_and_render(5, 4, "--probe 200,300 --stats-json '" + stats.string() + "'");
    ASSERT_EQ(v.status, 0) << v.out << v.err;
    const ViewRun p = keithray("psnr '" + headless.string() + "' '" + reference(5).string() + "'", false);
    ASSERT_EQ(p.status, 0) << p.err;
    const auto j = nlohmann::json::parse(kr::test::read_file(stats));
    EXPECT_EQ(j["spp"], 4);
    EXPECT_EQ(j["reference"], "assignment_05.ppm");
    EXPECT_NEAR(j["psnr"].get<double>(), std::stod(p.out), 0.01);  // psnr prints two decimals
    EXPECT_GT(j["rmse"].get<double>(), 0);
    EXPECT_GT(j["mrays_per_second"].get<double>(), 0);
    EXPECT_GT(j["noise"].get<double>(), 0);
    // The locked probe reads the headless image's pixel.
    const kr::Rgb8Image h = kr::read_ppm(headless);
    for (int k = 0; k < 3; ++k)
        EXPECT_EQ(j["probe"]["displayed"][size_t(k)].get<int>(), h.bytes[(300 * 512 + 200) * 3 + size_t(k)]);
    EXPECT_EQ(j["probe"]["samples"], 4);
}

// At 4x each image pixel is a 4x4 block of the pixel's tone-mapped value.
TEST_F(ViewerWindow, ZoomShowsBlocksOfTheImagesPixels) {
    const fs::path shot = dir / "shot.ppm", headless = dir / "headless.ppm";
    const ViewRun v = view_and_render(3, 1, "--zoom 4 --screenshot '" + shot.string() + "'");
    ASSERT_EQ(v.status, 0) << v.out << v.err;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(v.out, m, std::regex("image pixel ([0-9.]+),([0-9.]+) at ([0-9.]+) screen pixels")))
        << v.out;
    const double x0 = std::stod(m[1]), y0 = std::stod(m[2]);
    ASSERT_EQ(std::stod(m[3]), 4);
    const kr::Rgb8Image s = kr::read_ppm(shot), h = kr::read_ppm(headless);
    ASSERT_GT(s.width, 200);
    ASSERT_GT(s.height, 200);
    int worst = 0, uneven = 0;
    for (int r = 0; r < s.height; ++r)
        for (int c = 0; c < s.width; ++c) {
            // Whole blocks: the screenshot starts on a block's edge (x0, y0 are multiples of 1/4).
            const int ix = int(std::floor(x0 + c / 4.0 + 1e-9)), iy = int(std::floor(y0 + r / 4.0 + 1e-9));
            ASSERT_LT(ix, 512);
            ASSERT_LT(iy, 512);
            // The block's first screen pixel.
            const int c0 = int(std::ceil((ix - x0) * 4 - 1e-9)), r0 = int(std::ceil((iy - y0) * 4 - 1e-9));
            for (int k = 0; k < 3; ++k) {
                const uint8_t got = s.bytes[(size_t(r) * s.width + c) * 3 + k];
                worst = std::max(worst, std::abs(int(got) - int(h.bytes[(size_t(iy) * 512 + ix) * 3 + k])));
                uneven += got != s.bytes[(size_t(std::max(r0, 0)) * s.width + std::max(c0, 0)) * 3 + k];
            }
        }
    EXPECT_EQ(uneven, 0);
    EXPECT_LE(worst, 1);
}

// Real X input events (xdotool) on the real window, through tests/viewer_input.sh, which
// waits on the viewer's --status-file for each condition (bounded, never a fixed time).
namespace {

std::map<std::string, std::string> drive(const fs::path& dir, const std::string& scenario, int scene_number,
                                         const fs::path& scene_file = {}) {
    const std::string script = (fs::path(KEITHRAY_RES_DIR) / ".." / "tests" / "viewer_input.sh").string();
    const fs::path file = scene_file.empty() ? kr::test::brief_scene_file(scene_number) : scene_file;
    const kr::test::CommandResult r = kr::test::run_command(
        xvfb_run() + "bash '" + script + "' " + scenario + " '" + KEITHRAY_EXE +
            "' '" + file.string() + "' '" + dir.string() + "'",
        dir);
    std::map<std::string, std::string> out;
    std::istringstream lines(r.out);
    for (std::string line; std::getline(lines, line);)
        if (const size_t eq = line.find('='); eq != std::string::npos) out[line.substr(0, eq)] = line.substr(eq + 1);
    out["status"] = std::to_string(r.status);
    return out;
}

bool have_xdotool() { return std::system("command -v xdotool >/dev/null 2>&1") == 0; }

// Where the status line says the image lies in the window ("image=X,Y,fitS" or "X,Y,S"): its
// top-left corner and its scale, window pixels per image pixel.
struct ImagePlacement {
    double left = 0, top = 0, scale = 0;
};
::testing::AssertionResult image_placement(const std::string& field, ImagePlacement& out) {
    std::smatch m;
    if (!std::regex_match(field, m, std::regex("([0-9.]+),([0-9.]+),(fit)?([0-9.e+-]+)")))
        return ::testing::AssertionFailure() << "image=" << field;
    out = {std::stod(m[1]), std::stod(m[2]), std::stod(m[4])};
    return ::testing::AssertionSuccess();
}

}  // namespace

TEST_F(ViewerWindow, ClickWithOnePixelJitterLeavesTheImage) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "jitter_click", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["generation_after"], r["generation_before"]);  // no orbit, no restart
    EXPECT_EQ(r["spp_after"], r["spp_before"]);
    // The control: a real drag does orbit.
    r = drive(dir, "drag", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_NE(r["generation_after"], r["generation_before"]);
}

// K keeps what is on screen: with the default denoised display, image B is the denoised
// image (A against B: identical, where the raw estimate differs by the noise the denoiser
// removed), and the split view shows it right of the divider as the render view showed it.
TEST_F(ViewerWindow, KeepTakesTheDenoisedImageOnScreen) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "keep_shown", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["psnr"], "99.0000");  // kr::psnr's figure for identical images
    ImagePlacement placed;
    ASSERT_TRUE(image_placement(r["image"], placed));
    const double x0 = placed.left, y0 = placed.top, scale = placed.scale;
    const kr::Rgb8Image before = kr::read_ppm(dir / "render_view.ppm"), split = kr::read_ppm(dir / "split_view.ppm");
    ASSERT_EQ(before.width, split.width);
    ASSERT_EQ(before.height, split.height);
    // B's side of the divider, clear of the divider, the label and the window's edges.
    const kr::Scene full = kr::load_scene_file(kr::test::brief_scene_file(3)).scene;
    const int xa = int(x0 + 0.6 * full.renderer.width * scale), xb = int(x0 + 0.9 * full.renderer.width * scale);
    const int ya = int(y0 + 0.3 * full.renderer.height * scale), yb = int(y0 + 0.8 * full.renderer.height * scale);
    ASSERT_TRUE(xa >= 0 && ya >= 0 && xb <= before.width && yb <= before.height && xb > xa + 10 && yb > ya + 10)
        << r["image"] << " in " << before.width << "x" << before.height;
    double sum = 0;
    int n = 0;
    for (int y = ya; y < yb; ++y)
        for (int x = xa; x < xb; ++x)
            for (int k = 0; k < 3; ++k, ++n) {
                const size_t i = (size_t(y) * before.width + x) * 3 + k;
                sum += std::abs(int(before.bytes[i]) - int(split.bytes[i]));
            }
    // The shader's tone map and kr::tonemap's bytes differ by at most one step.
    EXPECT_LT(sum / n, 0.5) << "mean difference of B's half from the render view";
}

// An orbit drag with the button held: after each move of the pointer the window shows a
// frame of the camera that move made, before the button goes up, each different from the one
// before (tests/viewer_drag.py waits for each, bounded; the rate is scripts/bench_viewer.sh's).
TEST_F(ViewerWindow, FramesOfEachMovedCameraComeDuringADrag) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    const std::string script = (fs::path(KEITHRAY_RES_DIR) / ".." / "tests" / "viewer_drag.py").string();
    const kr::test::CommandResult r = kr::test::run_command(
        xvfb_run() + "python3 '" + script + "' test '" + KEITHRAY_EXE + "' '" +
            kr::test::brief_scene_file(3).string() + "' '" + dir.string() + "'",
        dir);
    std::map<std::string, std::string> out;
    std::istringstream lines(r.out);
    for (std::string line; std::getline(lines, line);)
        if (const size_t eq = line.find('='); eq != std::string::npos) out[line.substr(0, eq)] = line.substr(eq + 1);
    ASSERT_EQ(r.status, 0) << r.out << r.err;
    ASSERT_EQ(out.count("error"), 0u) << out["error"];
    EXPECT_EQ(out["steps"], "6");
    EXPECT_EQ(out["shown_during_drag"], "6");
    EXPECT_EQ(out["changed_during_drag"], "6");
    EXPECT_EQ(out["still_pressed"], "1");
    // While an earlier view's frame is on screen the status bar says so, not "starting".
    for (const char* wrong : {"starting", "rendering", "done"})
        EXPECT_EQ(out["states_with_an_earlier_view"].find(wrong), std::string::npos) << out["states_with_an_earlier_view"];
}

TEST_F(ViewerWindow, RaisingTheTargetKeepsTheSamplesAndTheTitleShowsSpp) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "raise_target", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["title"], "keithray - assignment_03.json - 2/2 spp - done");
    // The target is saved with the scene, so it counts as an unsaved edit.
    EXPECT_EQ(r["title_after"], "keithray - assignment_03.json (edited) - 4/4 spp - done");
    EXPECT_EQ(r["generation_after"], r["generation_before"]);  // continued, not restarted
}

TEST_F(ViewerWindow, EscQuits) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "esc", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["exit_status"], "0");
}

// With unsaved edits, Esc asks before quitting: the window is still there, and the F1 sent
// after it was handled (events are handled in order).
TEST_F(ViewerWindow, EscWithUnsavedEditsAsksFirst) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "esc_unsaved", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["running_after_esc"], "1");
    EXPECT_NE(r["generation_after"], r["generation_before"]);  // the held arrow key orbited
}

// Issue 47 B5, B6: with unsaved edits on a bundled scene, Esc asks; Return is "Save and
// quit", and since a bundled scene is never saved over, Save asks where; Return there saves
// NAME.json in the working folder (with the edit), and the viewer quits. The shipped file
// is as it was.
TEST_F(ViewerWindow, SaveAndQuitSavesABundledSceneElsewhereThenQuits) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    const std::string shipped = kr::test::read_file(kr::test::brief_scene_file(3));
    auto r = drive(dir, "save_and_quit", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["asked"], "save-where");
    EXPECT_EQ(r["exit_status"], "0");
    EXPECT_EQ(kr::test::read_file(kr::test::brief_scene_file(3)), shipped);
    ASSERT_TRUE(fs::exists(dir / "assignment_03.json"));
    const kr::Scene saved = kr::load_scene_file(dir / "assignment_03.json").scene;
    const kr::Scene file = kr::load_scene_file(kr::test::brief_scene_file(3)).scene;
    EXPECT_NE(saved.cameras[size_t(saved.camera)].position, file.cameras[size_t(file.camera)].position);  // the orbit
}

// Issue 45: Save EXR clicked while the render refines, with the denoised display: the frame
// shown then carries no halves of the samples (they cost every frame), so the save waits for
// the next frame, which does, and writes what `render --denoise on` writes of that many
// passes, byte for byte (uniform passes: the file's samples layer says how many).
TEST_F(ViewerWindow, SaveWhileRefiningWritesTheNextFrameAsRenderWould) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    nlohmann::json scene = nlohmann::json::parse(kr::test::read_file(kr::test::brief_scene_file(3)));
    scene["scene"]["renderer"]["dimensions"] = {96, 64};
    scene["scene"]["renderer"]["output"] = "saved.ppm";
    const fs::path file = dir / "small.json";
    std::ofstream(file) << scene.dump(2);
    auto r = drive(dir, "save_refining", 3, file);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["saved"], "1");
    EXPECT_EQ(r["error_after"], "0");
    const kr::HdrImage saved = kr::read_hdr(dir / "saved.exr");
    ASSERT_EQ(saved.samples.size(), 96u * 64u);
    const uint32_t passes = saved.samples[0];
    EXPECT_GE(passes, 1u);
    for (const uint32_t n : saved.samples) ASSERT_EQ(n, passes);
    const fs::path rendered = dir / "rendered.exr";
    const ViewRun cli = keithray("render '" + file.string() + "' --spp " + std::to_string(passes) +
                                     " --allocation uniform --denoise on -q -o '" + rendered.string() + "'",
                                 false);
    ASSERT_EQ(cli.status, 0) << cli.err;
    EXPECT_TRUE(kr::test::read_file(dir / "saved.exr") == kr::test::read_file(rendered))
        << "the saved image (" << passes << " passes) is not what render writes of them";
}

// Issue 47 B5: the status bar at the default size shows every field; at the minimum window,
// 640x400, the rate, elapsed time and progress bar give way and the state, spp, noise and
// PSNR stay (the window shots, bar_default.ppm and bar_small.ppm, are for the eye).
TEST_F(ViewerWindow, StatusBarKeepsTheFiguresAtTheMinimumWindow) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "status_bar", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["bar_default"], "state,spp,progress,time,rate,noise,psnr");
    const std::string small = r["bar_small"];
    for (const char* kept : {"state", "spp", "noise", "psnr"}) EXPECT_NE(small.find(kept), std::string::npos) << small;
    EXPECT_EQ(small.find("rate"), std::string::npos) << small;
    const kr::ImageFile shot = kr::read_image_file(dir / "bar_small.ppm");
    EXPECT_EQ(shot.rgb8.width, 640);
    EXPECT_EQ(shot.rgb8.height, 400);
    if (const char* keep = std::getenv("KEITHRAY_KEEP_SHOTS")) {
        fs::copy_file(dir / "bar_small.ppm", fs::path(keep) / "bar_small.ppm", fs::copy_options::overwrite_existing);
        fs::copy_file(dir / "bar_default.ppm", fs::path(keep) / "bar_default.ppm", fs::copy_options::overwrite_existing);
    }
}

// Esc then F1 reaching one frame (the viewer stopped while X queues them): the quit
// question opens, then the help over it. ImGui 1.86 aborted when a window appeared after a
// modal in the modal's first frame (the questions are now begun last in the frame).
TEST_F(ViewerWindow, EscThenF1InOneFrameAsksThenShowsTheHelp) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "esc_f1_one_frame", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["running_after_esc"], "1");
}

// Zoom, view and probe keys and clicks as a user gives them; none of them edits the scene.
TEST_F(ViewerWindow, ZoomKeysProbeClickAndMiddleDragPan) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "zoom_probe", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["generation_after"], r["generation_before"]);  // no click or drag moved the camera
    // Zoomed 2x about the pointer (250, 330): the image point under it stayed there, so the
    // probe (the pixel under the pointer) is that point's pixel in both layouts.
    double x = 0, y = 0, scale = 0;
    ASSERT_EQ(std::sscanf(r["zoomed"].c_str(), "%lf,%lf,%lf", &x, &y, &scale), 3) << r["zoomed"];
    EXPECT_EQ(scale, 2);
    int px = 0, py = 0;
    ASSERT_EQ(std::sscanf(r["probe"].c_str(), "%d,%d", &px, &py), 2) << r["probe"];
    EXPECT_EQ(px, int(std::floor((250 - x) / 2)));
    EXPECT_EQ(py, int(std::floor((330 - y) / 2)));
    // The middle drag of (40, -20) moved the zoomed image with the pointer.
    double x2 = 0, y2 = 0, scale2 = 0;
    ASSERT_EQ(std::sscanf(r["panned"].c_str(), "%lf,%lf,%lf", &x2, &y2, &scale2), 3) << r["panned"];
    EXPECT_EQ(x2 - x, 40);
    EXPECT_EQ(y2 - y, -20);
    EXPECT_EQ(scale2, 2);
    ASSERT_EQ(std::sscanf(r["wheel_zoomed"].c_str(), "%lf,%lf,%lf", &x, &y, &scale), 3) << r["wheel_zoomed"];
    EXPECT_EQ(scale, 2);
}

// Issue 34, defect 1, with real input: the first orbit (a 120-pixel left drag) in the
// default scene leaves the camera in no sphere; so does flying forward for 3 s (G, then W held).
TEST_F(ViewerWindow, FirstOrbitAndFlyStayOutOfTheWalls) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "first_orbit", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_NE(r["generation_after"], r["generation_before"]);
    EXPECT_EQ(r["inside"], "none");
    EXPECT_EQ(r["inside_after_fly"], "none");
}

// The first orbit's picture, scripted through the same orbit as the drag: the screenshot is
// the headless render of the saved scene, and it shows the room, not a black inside.
TEST_F(ViewerWindow, FirstOrbitScreenshotShowsTheRoom) {
    const fs::path shot = dir / "orbit.ppm", saved = dir / "orbit.json", headless = dir / "headless.ppm";
    const ViewRun v = keithray("view '" + scene(3) + "' --spp 2 --frames 2 --orbit 120,0 --screenshot '" + shot.string() +
                                   "' --save-scene '" + saved.string() + "' --timeout 300",
                               true);
    ASSERT_EQ(v.status, 0) << v.out << v.err;
    const kr::Scene edited = kr::load_scene_file(saved).scene;
    EXPECT_FALSE(kr::viewer::sphere_containing(edited, edited.cameras[size_t(edited.camera)].position));
    const ViewRun r = keithray("render '" + saved.string() + "' --spp 2 -q -o '" + headless.string() + "'", false);
    ASSERT_EQ(r.status, 0) << r.err;
    const kr::Rgb8Image a = kr::read_ppm(shot), b = kr::read_ppm(headless);
    ASSERT_EQ(a.width, b.width);
    EXPECT_LE(max_channel_difference(a, b), 1);
    double mean = 0;
    for (const uint8_t v8 : a.bytes) mean += v8;
    mean /= double(a.bytes.size());
    EXPECT_GT(mean, 40);  // the lit room (the camera inside a wall sees black)
}

// Issue 34, defect 10: the wheel zooms the image and keeps the samples; Shift+wheel dollies.
TEST_F(ViewerWindow, WheelZoomsTheImageShiftWheelDollies) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "wheel_zooms", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["generation_zoomed"], r["generation_before"]);
    // The quick turn zoomed about (200, 300), where the wheel turned: the image point under it
    // stayed under it (within a pixel of the zoom's rounding), not the point under (420, 120).
    double fx = 0, fy = 0, fs = 0, zx = 0, zy = 0, zs = 0;
    ASSERT_EQ(std::sscanf(r["fitted"].c_str(), "%lf,%lf,fit%lf", &fx, &fy, &fs), 3) << r["fitted"];
    ASSERT_EQ(std::sscanf(r["quick_zoomed"].c_str(), "%lf,%lf,%lf", &zx, &zy, &zs), 3) << r["quick_zoomed"];
    EXPECT_GT(zs, fs);
    EXPECT_NEAR((200 - fx) / fs, (200 - zx) / zs, 1.0);
    EXPECT_NEAR((300 - fy) / fs, (300 - zy) / zs, 1.0);
    EXPECT_NE(r["generation_after"], r["generation_before"]);
}

// Issue 34, defect 9: a broken starting scene leaves the keys working and nothing edited.
TEST_F(ViewerWindow, BrokenStartingSceneKeepsTheKeys) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    const fs::path broken = dir / "broken.json";
    std::ofstream(broken) << "{ \"cameras\": [ }";
    auto r = drive(dir, "broken_start", 0, broken);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["help"], "1");
    EXPECT_EQ(r["dirty"], "0");
    EXPECT_EQ(r["title"].find("(edited)"), std::string::npos) << r["title"];
    EXPECT_EQ(r["exit_status"], "0");
}

// Missing item 1, with real input: a click selects the sphere under the pointer, Delete
// removes it, Ctrl+Z brings it back, Ctrl+D duplicates it, M moves it with the pointer and a
// click places it (not the camera), Esc clears the selection.
TEST_F(ViewerWindow, ClickSelectsDeleteUndoDuplicateAndMove) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "select_edit", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    const kr::Scene scene = kr::load_scene_file(kr::test::brief_scene_file(3)).scene;
    int sphere01 = -1;
    for (size_t i = 0; i < scene.primitives.size(); ++i)
        if (scene.primitives[i].id == "sphere 01") sphere01 = int(i);
    EXPECT_EQ(r["selected"], std::to_string(sphere01));
    const int n = std::stoi(r["primitives_before"]);
    EXPECT_EQ(r["primitives_deleted"], std::to_string(n - 1));
    EXPECT_EQ(r["primitives_duplicated"], std::to_string(n + 1));
    EXPECT_EQ(r["selected_copy"], std::to_string(n));  // the copy, last in the list
    EXPECT_EQ(r["selected_after_move"], r["selected_again"]);
    EXPECT_NE(r["generation_after"], r["generation_before_move"]);  // the move changed the image
}

// Issue 47 B0, with real input on scene 3: a click on the far wall selects it, and the wall
// shows as selected on the image (its outline is off the image: a tint over the pixels that
// see it, as sphere_coverage finds them, and nowhere else); a left drag from it orbits and
// moves the view, not the wall; M moves it, Esc puts it back (the scene saved then has the
// wall where it was and the orbited camera); M and a click place it, Ctrl+Z undoes that
// (the saved state again); Esc then clears the selection (the window stays).
TEST_F(ViewerWindow, WallSelectionShowsAndADragFromItOrbits) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    const fs::path copy = dir / "scene3.json";
    fs::copy_file(scene(3), copy);
    auto r = drive(dir, "wall_select", 3, copy);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    const kr::viewer::ViewerModel m = kr::test::brief_model(3);
    const kr::Scene& s = m.scene();
    ASSERT_NE(r["selected"], "none");
    const int wall = std::stoi(r["selected"]);
    EXPECT_EQ(s.primitives[size_t(wall)].id, "far wall");
    EXPECT_EQ(r["camera_moved"], "1");
    EXPECT_EQ(r["selected_after_drag"], r["selected"]);
    EXPECT_EQ(r["selected_after_cancel"], r["selected"]);
    const kr::Scene saved = kr::load_scene_file(copy).scene;
    auto centre = [&](const kr::Scene& sc) { return sc.shapes[size_t(sc.primitives[size_t(wall)].shape)].centre; };
    EXPECT_EQ(centre(saved), centre(s));  // neither the drag nor the cancelled move moved it
    EXPECT_NE(saved.cameras[size_t(saved.camera)].position, m.camera().position);  // the drag orbited
    EXPECT_EQ(r["dirty_after_place"], "1");
    EXPECT_EQ(r["running_after_esc"], "1");
    // The tint: over the cells that see the wall (4x4 image pixels each, as the window draws
    // them), the window's pixels are blended with orange (255, 160, 0) at alpha 72/255;
    // elsewhere they stay. Cells whose neighbours all agree (the edges left out).
    ImagePlacement placed;
    ASSERT_TRUE(image_placement(r["image"], placed));
    const double left = placed.left, top = placed.top, scale = placed.scale;
    const kr::Rgb8Image before = kr::read_ppm(dir / "unselected.ppm"), after = kr::read_ppm(dir / "selected.ppm");
    ASSERT_EQ(before.width, after.width);
    const kr::Shape& ws = s.shapes[size_t(s.primitives[size_t(wall)].shape)];
    const int cols = 128, rows = 128;
    const auto cells = kr::viewer::sphere_coverage(*m.prepared(), ws.centre, ws.radius, cols, rows);
    auto at = [&](const kr::Rgb8Image& img, int x, int y, int k) { return int(img.bytes[(size_t(y) * img.width + size_t(x)) * 3 + k]); };
    int tinted = 0, tinted_ok = 0, plain = 0, plain_ok = 0;
    for (int cy = 1; cy + 1 < rows; ++cy)
        for (int cx = 1; cx + 1 < cols; ++cx) {
            const unsigned char c = cells[size_t(cy * cols + cx)];
            bool uniform = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) uniform &= cells[size_t((cy + dy) * cols + cx + dx)] == c;
            if (!uniform) continue;
            const int x = int(left + (cx + 0.5) * 4 * scale), y = int(top + (cy + 0.5) * 4 * scale);
            if (x < 0 || y < 0 || x >= before.width || y >= before.height) continue;
            // Tinted: the pixel blended with orange at alpha 72/255 (within rounding); else as it was.
            int off_tint = 0, off_plain = 0;
            constexpr int kOrange[3] = {255, 160, 0};
            for (int k = 0; k < 3; ++k) {
                const double blended = at(before, x, y, k) + 72.0 / 255 * (kOrange[k] - at(before, x, y, k));
                off_tint = std::max(off_tint, int(std::lround(std::abs(at(after, x, y, k) - blended))));
                off_plain = std::max(off_plain, std::abs(at(after, x, y, k) - at(before, x, y, k)));
            }
            if (c) tinted++, tinted_ok += off_tint <= 3;
            else plain++, plain_ok += off_plain <= 1;
        }
    EXPECT_GT(tinted, 1000);
    EXPECT_EQ(tinted_ok, tinted);
    EXPECT_GT(plain, 1000);
    EXPECT_EQ(plain_ok, plain);
}

// Issue 47 B2, with real input: the same 12-step 120-pixel left drag (an orbit about the far
// wall, stopped at surfaces) and right drag (a pan) from the file's view, with a frame after
// each move, with the moves sent at once, and with them all queued for one frame, end on the
// same camera, to the last digit the status line gives.
TEST_F(ViewerWindow, SameGestureSameCameraWhateverTheFrames) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "same_gesture", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    for (const std::string b : {"1", "3"}) {
        SCOPED_TRACE("button " + b);
        const std::string paced = r["camera_" + b + "_paced"];
        ASSERT_FALSE(paced.empty());
        EXPECT_NE(paced, r["camera_home"]);
        EXPECT_EQ(r["camera_" + b + "_burst"], paced);
        EXPECT_EQ(r["camera_" + b + "_stopped"], paced);
    }
}

// Shift+click and Shift+wheel go by their own events' modifiers: sent behind a backlog of
// keys (the key queue hands ImGui Shift's press frames after the click and the wheel reach
// it), the click still locks the probe and selects nothing, and the wheel dollies (a camera
// edit) without zooming the image.
TEST_F(ViewerWindow, ShiftClickAndShiftWheelBehindQueuedKeys) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "modifier_backlog", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_NE(r["probe"], "none");
    EXPECT_EQ(r["selected"], "none");
    EXPECT_NE(r["image_after_wheel"].find(",fit"), std::string::npos) << r["image_after_wheel"];
    EXPECT_EQ(r["dirty_after_wheel"], "1");
}

// The command line's edits apply in an interactive run as in a scripted one (they were
// taken and ignored): --select selects sphere 01 of scene 3, --region sets the region.
TEST_F(ViewerWindow, StartEditsApplyInAnInteractiveRun) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "start_edits", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    const kr::Scene three = kr::load_scene_file(kr::test::brief_scene_file(3)).scene;
    ASSERT_NE(r["selected"], "none");
    EXPECT_EQ(three.primitives[size_t(std::stoi(r["selected"]))].id, "sphere 01");
    EXPECT_EQ(r["region"], "100,120,300,260");
}

// Missing item 1, the picture: sphere 01 of scene 3 selected (a click on it) and dragged by
// (-60, -40) image pixels. The window's pixels are the CPU-computed image: the headless
// render of the saved (moved) scene, with the selection's outline (sphere_outline of the
// moved sphere, orange) over it: away from the outline within 1/255, on it orange.
TEST_F(ViewerWindow, SelectionOutlineAndMovedSphereArePixelExact) {
    const fs::path shot = dir / "shot.ppm", window = dir / "window.ppm", saved = dir / "moved.json";
    const fs::path moved = dir / "moved.ppm", before = dir / "before.ppm";
    const ViewRun v = keithray("view '" + scene(3) + "' --spp 2 --frames 2 --select 344,410 --move-selection -60,-40 "
                               "--screenshot '" + shot.string() + "' --window-shot '" + window.string() +
                                   "' --save-scene '" + saved.string() + "' --timeout 300",
                               true);
    ASSERT_EQ(v.status, 0) << v.out << v.err;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(v.out, m, std::regex("at ([0-9.]+) screen pixels each, at window pixel ([0-9.]+),([0-9.]+)")))
        << v.out;
    ASSERT_EQ(std::stod(m[1]), 1);  // 1:1 in a 1280x1024 screen
    const int wx = int(std::stod(m[2])), wy = int(std::stod(m[3]));
    ASSERT_TRUE(std::regex_search(v.out, m, std::regex("selected: ([0-9]+)"))) << v.out;
    const int selected = std::stoi(m[1]);
    for (const auto& [file, out] : {std::pair{saved.string(), moved}, std::pair{scene(3), before}}) {
        const ViewRun r = keithray("render '" + file + "' --spp 2 -q -o '" + out.string() + "'", false);
        ASSERT_EQ(r.status, 0) << r.err;
    }
    const kr::Scene original = kr::load_scene_file(scene(3)).scene, edited = kr::load_scene_file(saved).scene;
    ASSERT_EQ(original.primitives[size_t(selected)].id, "sphere 01");
    const kr::RenderScene prepared = kr::prepare_scene(edited);
    const kr::Shape& was = original.shapes[size_t(original.primitives[size_t(selected)].shape)];
    const kr::Shape& now = edited.shapes[size_t(edited.primitives[size_t(selected)].shape)];
    // The sphere followed the pointer: its centre's image point moved by the drag.
    const auto c0 = kr::viewer::project_sphere(prepared.camera, was.centre, was.radius);
    const auto c1 = kr::viewer::project_sphere(prepared.camera, now.centre, now.radius);
    ASSERT_TRUE(c0 && c1);
    EXPECT_NEAR((c1->fx - c0->fx) * 512, -60, 1e-6);
    EXPECT_NEAR((c1->fy - c0->fy) * 512, -40, 1e-6);
    const kr::Rgb8Image s = kr::read_ppm(shot), w = kr::read_ppm(window), h = kr::read_ppm(moved), b = kr::read_ppm(before);
    ASSERT_EQ(s.width, 512);
    ASSERT_EQ(h.width, 512);
    // The display shader's image is the moved scene's render, and not the original's.
    EXPECT_LE(max_channel_difference(s, h), 1);
    EXPECT_GT(max_channel_difference(s, b), 50);
    // The outline as drawn: 64 points around the silhouette, a 2-pixel orange line.
    const auto outline = kr::viewer::sphere_outline(prepared.camera, now.centre, now.radius, 64);
    ASSERT_EQ(outline.size(), 64u);
    auto distance_to_outline = [&](double x, double y) {
        double best = 1e9;
        for (size_t i = 0; i < outline.size(); ++i) {
            const auto [ax, ay] = outline[i];
            const auto [bx, by] = outline[(i + 1) % outline.size()];
            const double px = ax * 512, py = ay * 512, qx = bx * 512 - px, qy = by * 512 - py;
            const double t = std::clamp(((x - px) * qx + (y - py) * qy) / (qx * qx + qy * qy), 0.0, 1.0);
            best = std::min(best, std::hypot(x - px - t * qx, y - py - t * qy));
        }
        return best;
    };
    auto window_pixel = [&](int x, int y, int k) { return int(w.bytes[(size_t(wy + y) * w.width + size_t(wx + x)) * 3 + k]); };
    int worst_off = 0, off = 0, on = 0, orange = 0;
    for (int y = 0; y < 512; ++y)
        for (int x = 0; x < 512; ++x) {
            const double d = distance_to_outline(x + 0.5, y + 0.5);
            if (d > 3) {
                ++off;
                for (int k = 0; k < 3; ++k)
                    worst_off = std::max(worst_off, std::abs(window_pixel(x, y, k) - int(h.bytes[(size_t(y) * 512 + x) * 3 + k])));
            } else if (d < 0.5) {
                ++on;
                orange += std::abs(window_pixel(x, y, 0) - 255) <= 24 && std::abs(window_pixel(x, y, 1) - 160) <= 24 &&
                          window_pixel(x, y, 2) <= 24;
            }
        }
    EXPECT_GT(off, 200000);
    EXPECT_LE(worst_off, 1);
    ASSERT_GT(on, 100);
    EXPECT_GE(orange, on * 9 / 10) << orange << " of " << on << " pixels on the outline are orange";
}

// Missing item 2, with real input: Ctrl+2 stores the orbited view as a camera of the file's
// list, Home resets the view, Shift+2 recalls the bookmark, Ctrl+S saves both: the saved
// file's active camera has the bookmark's view, and the scene block's camera is the file's.
TEST_F(ViewerWindow, BookmarkStoredRecalledAndSaved) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    const fs::path copy = dir / "scene3.json";
    fs::copy_file(kr::test::brief_scene_file(3), copy);
    auto r = drive(dir, "bookmarks", 3, copy);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    const kr::Scene file = kr::load_scene_file(kr::test::brief_scene_file(3)).scene;
    const kr::Scene saved = kr::load_scene_file(copy).scene;
    ASSERT_EQ(saved.cameras.size(), file.cameras.size() + 1);
    const int mark = kr::viewer::find_bookmark(saved, 2);
    ASSERT_GE(mark, 0);
    const kr::Camera& active = saved.cameras[size_t(saved.camera)];
    const kr::Camera& loaded = file.cameras[size_t(file.camera)];
    EXPECT_EQ(active.id, loaded.id);
    EXPECT_NE(active.position, loaded.position);  // the orbited view, recalled
    EXPECT_EQ(active.position, saved.cameras[size_t(mark)].position);
    EXPECT_EQ(active.target, saved.cameras[size_t(mark)].target);
}

// Ctrl+S released Ctrl first: the chord saves, and its S, still held alone, is no camera
// key (it used to dolly the camera once, leaving the saved scene edited).
TEST_F(ViewerWindow, ChordKeyHeldAfterCtrlIsReleasedDoesNotMoveTheCamera) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    const fs::path copy = dir / "scene3.json";
    fs::copy_file(kr::test::brief_scene_file(3), copy);
    auto r = drive(dir, "chord_release_ctrl_first", 3, copy);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["generation_after"], r["generation_edited"]);
    EXPECT_EQ(r["dirty_after"], "0");
    EXPECT_EQ(kr::load_scene_file(copy).scene.renderer.samples, 4);  // the saved target
}

// Missing item 4 with real input: V six times from the render reaches the albedo view, then
// normal and depth. What X shows of the window (tests/x_window_shot.py) is, over the image,
// the picture of render's EXR layers of the same scene and spp, exactly, except under the
// view's label (the image's top 28 rows); the status bar reads the layer of the pixel under
// the pointer.
TEST_F(ViewerWindow, VReachesTheFeatureViewsAndTheWindowShowsTheLayers) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    if (std::system("command -v python3 >/dev/null 2>&1") != 0) GTEST_SKIP() << "python3 takes the X screenshot";
    auto r = drive(dir, "feature_views", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["generation_after"], r["generation_before"]);  // a view is no edit
    const ViewRun render = keithray("render '" + scene(3) + "' --spp 2 --denoise on -q -o '" + (dir / "r.exr").string() + "'", false);
    ASSERT_EQ(render.status, 0) << render.err;
    const ExpectedViews e = expected_views(dir / "r.exr");
    for (const std::string view : {"albedo", "normal", "depth"}) {
        double left = 0, top = 0, scale = 0;
        ASSERT_EQ(std::sscanf(r["image_" + view].c_str(), "%lf,%lf,fit%lf", &left, &top, &scale), 3) << r["image_" + view];
        ASSERT_EQ(scale, 1) << "the 512x512 image fits the window at 1:1";
        const kr::Rgb8Image w = kr::read_ppm(dir / ("window_" + view + ".ppm"));
        const kr::Rgb8Image& want = view == "albedo" ? e.albedo : view == "normal" ? e.normal : e.depth;
        ASSERT_GE(w.width, int(left) + want.width);
        ASSERT_GE(w.height, int(top) + want.height);
        int wrong = 0;
        for (int y = 28; y < want.height; ++y)
            for (int x = 0; x < want.width; ++x)
                for (int k = 0; k < 3; ++k)
                    wrong += w.bytes[3 * ((size_t(top) + size_t(y)) * size_t(w.width) + size_t(left) + size_t(x)) + size_t(k)] !=
                             want.bytes[3 * (size_t(y) * size_t(want.width) + size_t(x)) + size_t(k)];
        EXPECT_EQ(wrong, 0) << view;
        // The pointer's pixel, (250, 330) in the window, as the status bar reads it.
        const size_t px = size_t(250 - int(left)), py = size_t(330 - int(top));
        const size_t i = py * size_t(want.width) + px;
        char text[96];
        if (view == "albedo")
            std::snprintf(text, sizeof text, "albedo_%.3f_%.3f_%.3f", e.exr.albedo[3 * i], e.exr.albedo[3 * i + 1], e.exr.albedo[3 * i + 2]);
        else if (view == "normal")
            std::snprintf(text, sizeof text, "normal_%+.3f_%+.3f_%+.3f", e.exr.normal[3 * i], e.exr.normal[3 * i + 1], e.exr.normal[3 * i + 2]);
        else std::snprintf(text, sizeof text, "depth_%.4g", double(e.exr.depth[i]));
        EXPECT_EQ(r["feature_" + view], text);
    }
}

// Missing item 2, the render region with real input: B, then a left drag over the image sets
// the region to the image pixels under the drag (not an orbit: no edit), Shift+B clears it.
TEST_F(ViewerWindow, RegionDrawnWithBAndADragClearedWithShiftB) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "region", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["region"], "100,120,300,260");
    EXPECT_EQ(r["generation_region"], r["generation_before"]);
    EXPECT_EQ(r["region_cleared"], "none");
}

// A press, a move and a release sent at once (one frame may see them all): the region runs
// from the press's position to the release's, as the X events had them, not from where a
// later frame found the pointer.
TEST_F(ViewerWindow, RegionDrawnInOneQuickDragRunsFromThePressToTheRelease) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "region_fast", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["region"], "100,120,300,260");
}

// The render region's picture (scripted --region, the B key's box): inside it the window
// shows the headless render of the same passes (within 1/255), outside nothing refined
// (black: the region was set before the first full pass).
TEST_F(ViewerWindow, RegionShowsOnlyItsPixelsRendered) {
    const fs::path shot = dir / "shot.ppm";
    const ViewRun v = view_and_render(3, 2, "--region 100,120 300,260 --screenshot '" + shot.string() + "'");
    ASSERT_EQ(v.status, 0) << v.out << v.err;
    const kr::Rgb8Image s = kr::read_ppm(shot), h = kr::read_ppm(dir / "headless.ppm");
    ASSERT_EQ(s.width, 512);
    ASSERT_EQ(h.width, 512);
    int worst_in = 0, lit_out = 0;
    for (int y = 0; y < 512; ++y)
        for (int x = 0; x < 512; ++x) {
            const bool in = x >= 100 && x < 300 && y >= 120 && y < 260;
            for (int k = 0; k < 3; ++k) {
                const size_t i = (size_t(y) * 512 + size_t(x)) * 3 + size_t(k);
                if (in) worst_in = std::max(worst_in, std::abs(int(s.bytes[i]) - int(h.bytes[i])));
                else lit_out += s.bytes[i] != 0;
            }
        }
    EXPECT_LE(worst_in, 1);
    EXPECT_EQ(lit_out, 0);
}

// The viewer applies render's memory estimate before it allocates a render state: a scene
// too large for the machine is an error in the window (and a scripted run's exit 1), never
// an abort of the viewer.
TEST_F(ViewerWindow, RenderTooLargeForMemoryIsAnErrorNotAnAbort) {
    std::string text = kr::test::read_file(scene(1));
    const size_t at = text.find("\"dimensions\"");
    ASSERT_NE(at, std::string::npos);
    text.replace(at, text.find(']', at) + 1 - at, "\"dimensions\": [32768, 32768]");
    std::ofstream(dir / "huge.json") << text;
    const ViewRun v = keithray("view '" + (dir / "huge.json").string() + "' --frames 1 --screenshot '" +
                                   (dir / "x.ppm").string() + "' --timeout 120",
                               true);
    EXPECT_EQ(v.status, 1) << v.err;
    EXPECT_NE(v.err.find("not enough memory for the render of a 32768x32768 image"), std::string::npos) << v.err;
    EXPECT_FALSE(fs::exists(dir / "x.ppm"));
}

// A scripted run whose render does not fit the address space is refused before the window
// opens, by the render thread's estimate: one line naming the scene, exit 1, nothing written.
// (Mesa's llvmpipe, the window's GL, ends the process with SIGSEGV where its own allocations
// fail while it compiles the display's shaders: 1024x1024 under ulimit -v 600000 did.)
TEST_F(ViewerWindow, ScriptedRunThatCannotFitIsRefusedBeforeTheWindow) {
#ifdef KR_TEST_SANITIZED
    GTEST_SKIP() << "the sanitizers' runtimes reserve address space beyond any ulimit -v";
#endif
    std::string text = kr::test::read_file(scene(3));
    const size_t at = text.find("\"dimensions\"");
    ASSERT_NE(at, std::string::npos);
    text.replace(at, text.find(']', at) + 1 - at, "\"dimensions\": [1024, 1024]");
    std::ofstream(dir / "big.json") << text;
    // 16 MiB less than the render needs: room to start, load and estimate.
    const uint64_t kib = (kr::render_memory_bytes(1024, 1024, false, true) >> 10) - 16 * 1024;
    const ViewRun v = kr::test::run_command(
        xvfb_run() + "sh -c \"ulimit -v " + std::to_string(kib) + "; exec '" + KEITHRAY_EXE + "' view '" +
            (dir / "big.json").string() + "' --spp 1 --save-image '" + (dir / "out.exr").string() + "' --timeout 120\"",
        dir);
    EXPECT_EQ(v.status, 1) << v.err;
    EXPECT_EQ(v.err.find("window GL"), std::string::npos) << v.err;  // no window was opened
    EXPECT_NE(v.err.find("big.json: not enough memory for the render of a 1024x1024 image"), std::string::npos) << v.err;
    EXPECT_EQ(std::count(v.err.begin(), v.err.end(), '\n'), 1) << v.err;
    EXPECT_FALSE(fs::exists(dir / "out.exr"));
}

// A status file that cannot be written fails the scripted run (a folder: refused before the
// window opens, naming the flag; exit 1).
TEST_F(ViewerWindow, StatusFileThatCannotBeWrittenFailsTheRun) {
    fs::create_directories(dir / "folder");
    const ViewRun v = keithray("view '" + scene(1) + "' --spp 1 --frames 1 --screenshot '" + (dir / "x.ppm").string() +
                                   "' --status-file '" + (dir / "folder").string() + "' --timeout 120",
                               true);
    EXPECT_EQ(v.status, 1) << v.err;
    EXPECT_NE(v.err.find("--status-file"), std::string::npos) << v.err;
}

// Issue 47 C, in a real window with real input: the outliner's rows and a click on the image
// are one selection; one click on a colour recolours the selected sphere alone (a new
// material of its own, saved with Ctrl+S); "." frames the selection and Ctrl+Z undoes it;
// numpad 7 and 1 give the top and front views about the target; a point light's row selects
// the light, which "." (numpad-.) frames; the tabs switch.
TEST_F(ViewerWindow, OutlinerSelectsFramesAndRecolours) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    const fs::path copy = dir / "scene3.json";
    fs::copy_file(scene(3), copy);
    auto r = drive(dir, "outliner", 3, copy);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    const kr::viewer::ViewerModel m = kr::test::brief_model(3);
    const kr::Scene& s = m.scene();
    EXPECT_EQ(r["tab_first"], "object");
    ASSERT_NE(r["selected_on_image"], "none");
    const int sphere = std::stoi(r["selected_on_image"]);
    EXPECT_EQ(s.primitives[size_t(sphere)].id, "sphere 01");
    EXPECT_EQ(r["selected_by_row"], "0");
    EXPECT_EQ(r["selected_by_row_again"], r["selected_on_image"]);
    EXPECT_EQ(r["filtered"], "2");  // "SPHERE 0": sphere 01 and sphere 02
    EXPECT_EQ(r["filtered_more"], "1");  // "SPHERE 02"
    EXPECT_EQ(r["unfiltered"], "1");
    auto vec = [](const std::string& text) {
        kr::Vec3 v;
        EXPECT_EQ(std::sscanf(text.c_str(), "%lf,%lf,%lf", &v.x, &v.y, &v.z), 3) << text;
        return v;
    };
    const kr::Camera& cam = m.camera();
    EXPECT_EQ(vec(r["camera_first"]), cam.position);
    // Framed: looking at sphere 01's centre along the same direction, kFrameFill of the half fov.
    const kr::Shape& ball = s.shapes[size_t(s.primitives[size_t(sphere)].shape)];
    const kr::Camera want = kr::viewer::framed(cam, {ball.centre, ball.radius});
    const kr::Vec3 framed = vec(r["camera_framed"]);
    EXPECT_NEAR(kr::length(framed - want.position), 0, 1e-6);
    EXPECT_EQ(vec(r["camera_undone"]), cam.position);
    const double d = kr::length(cam.target - cam.position);
    EXPECT_NEAR(kr::length(vec(r["camera_top"]) - (cam.target + kr::Vec3(0, d, 0))), 0, 1e-6);
    EXPECT_EQ(vec(r["camera_front"]), cam.position);  // scene 3 looks along +z: its view is the front view
    EXPECT_EQ(r["light_selected"], "0");
    ASSERT_EQ(s.lights[0].type, kr::LightType::point);
    // The selected point light's marker: orange pixels about its image point (inside the area
    // light's white disc, where the render has none), none there before.
    ImagePlacement placed;
    ASSERT_TRUE(image_placement(r["image_light"], placed));
    const auto point = kr::viewer::project_sphere(m.prepared()->camera, s.lights[0].position, 0);
    ASSERT_TRUE(point);
    const int px = int(placed.left + point->fx * s.renderer.width * placed.scale);
    const int py = int(placed.top + point->fy * s.renderer.height * placed.scale);
    auto orange_near = [&](const fs::path& file) {
        const kr::Rgb8Image shot = kr::read_ppm(file);
        int n = 0;
        for (int y = py - 16; y <= py + 16; ++y)
            for (int x = px - 16; x <= px + 16; ++x) {
                const unsigned char* c = &shot.bytes[(size_t(y) * shot.width + size_t(x)) * 3];
                n += c[0] > 200 && c[1] > 110 && c[1] < 210 && c[2] < 80;
            }
        return n;
    };
    EXPECT_EQ(orange_near(dir / "light_before.ppm"), 0);
    EXPECT_GT(orange_near(dir / "light_selected.ppm"), 30);
    // The point light framed: the target on it, the distance kept.
    const kr::Vec3 at_light = vec(r["camera_light"]);
    EXPECT_NEAR(kr::length(at_light - s.lights[0].position), d, 1e-6);
    EXPECT_EQ(r["camera_row"], "1");
    EXPECT_EQ(r["tab_last"], "camera");
    ASSERT_EQ(r["saved"], "1");
    // The saved file: the second camera active (its row); the first where "." left it on the
    // point light; sphere 01 (glass) tinted red; every other object as it was.
    const kr::Scene saved = kr::load_scene_file(copy).scene;
    EXPECT_EQ(saved.camera, 1);
    EXPECT_EQ(saved.cameras[0].position, at_light);
    ASSERT_EQ(saved.primitives.size(), s.primitives.size());
    const kr::Material& red = saved.materials[size_t(saved.primitives[size_t(sphere)].material)];
    ASSERT_EQ(red.type, kr::MaterialType::dielectric);
    EXPECT_EQ(red.rho_t, kr::viewer::kPalette[2].rho);  // a dielectric's tint: what it transmits
    for (size_t p = 0; p < s.primitives.size(); ++p) {
        if (int(p) == sphere) continue;
        const kr::Material& was = s.materials[size_t(s.primitives[p].material)];
        const kr::Material& now = saved.materials[size_t(saved.primitives[p].material)];
        EXPECT_EQ(now.id, was.id) << s.primitives[p].id;
        EXPECT_EQ(now.rho, was.rho) << s.primitives[p].id;
    }
}

// ---- Issue 47 C: files as users expect, and scale ----

namespace {

// Scene 3 as a user's own file (not under scenes/: no automatic reference), at `rel` in dir.
fs::path own_scene(const fs::path& dir, const fs::path& rel) {
    fs::create_directories((dir / rel).parent_path());
    fs::copy_file(kr::test::brief_scene_file(3), dir / rel, fs::copy_options::overwrite_existing);
    return dir / rel;
}

void keep_shot(const fs::path& dir, const char* name) {
    if (const char* keep = std::getenv("KEITHRAY_KEEP_SHOTS"))
        fs::copy_file(dir / name, fs::path(keep) / name, fs::copy_options::overwrite_existing);
}

}  // namespace

// Ctrl+O: the folder browser (KEITHRAY_FILE_CHOOSER=builtin), driven by the keyboard: a
// folder's name enters it, a file's name opens it and it joins the recent files (the bad
// settings file met at the start is said, then replaced by a good one); Ctrl+Shift+S saves as
// into another folder, the file becoming the scene's; Esc closes the dialog, not the viewer.
// The settings file is in the test's folder ($XDG_CONFIG_HOME), never the user's.
TEST_F(ViewerWindow, OpenAndSaveAsBrowseFoldersAndKeepRecentFiles) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    const fs::path scene = own_scene(dir, "mine/a.json");
    own_scene(dir, "mine/sub/b.json");
    const fs::path settings = dir / "config" / "keithray" / "viewer.json";
    fs::create_directories(settings.parent_path());
    std::ofstream(settings) << "{not json";
    auto r = drive(dir, "open_dialog", 3, scene);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["error_start"], "1");  // the bad settings file, said
    EXPECT_EQ(r["folder_start"], fs::weakly_canonical(dir / "mine").string());
    EXPECT_EQ(r["folder_sub"], fs::weakly_canonical(dir / "mine" / "sub").string());
    EXPECT_EQ(r["opened"], "b.json");
    EXPECT_EQ(r["saved_as"], "saved.json");
    EXPECT_EQ(r["dirty_after_save"], "0");
    EXPECT_EQ(r["running_after_esc"], "1");
    ASSERT_TRUE(fs::exists(dir / "mine" / "saved.json"));
    EXPECT_NO_THROW(kr::load_scene_file(dir / "mine" / "saved.json"));
    // The recent scenes, newest first: saved.json, b.json, a.json (the one started with).
    const auto kept = nlohmann::json::parse(kr::test::read_file(settings));
    ASSERT_TRUE(kept["recent_scenes"].is_array());
    ASSERT_GE(kept["recent_scenes"].size(), 3u);
    EXPECT_EQ(fs::path(kept["recent_scenes"][0].get<std::string>()).filename(), "saved.json");
    EXPECT_EQ(fs::path(kept["recent_scenes"][1].get<std::string>()).filename(), "b.json");
    EXPECT_EQ(fs::path(kept["recent_scenes"][2].get<std::string>()).filename(), "a.json");
    keep_shot(dir, "browser.ppm");
}

// What the drop tests drop, in dir: their own scene (mine/a.json, started with), an image
// (mine/ref.ppm), a text file (mine/notes.txt) and a link to a bundled example (example.json).
::testing::AssertionResult drop_files(const fs::path& dir) {
    own_scene(dir, "mine/a.json");
    fs::copy_file(kr::test::brief_reference_file(3), dir / "mine" / "ref.ppm");
    std::ofstream(dir / "mine" / "notes.txt") << "not an image";
    const auto examples = kr::example_scenes();
    if (examples.empty()) return ::testing::AssertionFailure() << "no example scene";
    fs::create_symlink(examples.front(), dir / "example.json");
    return ::testing::AssertionSuccess();
}

// The drop's outcome: the image became image B, the text file was refused with an error, the
// example opened.
void expect_dropped(std::map<std::string, std::string>& r) {
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["b"], "reference");
    EXPECT_EQ(r["error_shown"], "1");
    EXPECT_EQ(r["opened"], "example.json");
}

// A drop by --drop (the drop callback's path; FilesDroppedThroughXdnd... drops for real):
// the image became image B, the text file was refused with an error, the bundled
// example (a link to it) opened read-only: Ctrl+S asks where.
TEST_F(ViewerWindow, DroppedImageIsImageBDroppedSceneOpensOtherFilesAreRefused) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    ASSERT_TRUE(drop_files(dir));
    auto r = drive(dir, "drop", 3, dir / "mine" / "a.json");
    expect_dropped(r);
    EXPECT_EQ(r["asked"], "save-where");
    keep_shot(dir, "drop.ppm");
}

// A real drop: the X drag-and-drop protocol (XDND) as a file manager speaks it
// (tests/x_drop.py), GLFW's drop callback, the same actions: the image is image B, the
// text file refused with an error, the example then opens (image B, chosen by the user,
// stays); with unsaved edits a dropped scene asks first.
TEST_F(ViewerWindow, FilesDroppedThroughXdndOpenAsTheyWouldFromOpen) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    ASSERT_TRUE(drop_files(dir));
    auto r = drive(dir, "xdnd_drop", 3, dir / "mine" / "a.json");
    expect_dropped(r);
    EXPECT_EQ(r["b_after"], "reference");
    // With unsaved edits, a dropped scene asks first; Esc keeps the scene and the edits.
    EXPECT_EQ(r["asked"], "discard");
    EXPECT_EQ(r["kept"], "example.json");
    EXPECT_EQ(r["dirty_kept"], "1");
}

// The platform's chooser in the window: a stand-in zenity on PATH (KEITHRAY_FILE_CHOOSER=zenity)
// that waits for the test's word, then answers a file. Ctrl+O starts it with the scene's
// folder and the scenes' filter; the window stays live while it runs; its answer opens.
TEST_F(ViewerWindow, OpenRunsThePlatformsChooserAndKeepsTheWindowLive) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    const fs::path scene = own_scene(dir, "mine/a.json");
    own_scene(dir, "mine/sub/b.json");
    fs::create_directories(dir / "bin");
    {
        std::ofstream zenity(dir / "bin" / "zenity");
        zenity << "#!/bin/sh\nprintf '%s\\n' \"$@\" > '" << (dir / "zenity.args").string() << "'\n"
               << "while [ ! -e '" << (dir / "go").string() << "' ]; do sleep 0.05; done\n"
               << "echo '" << (dir / "mine" / "sub" / "b.json").string() << "'\n";
    }
    fs::permissions(dir / "bin" / "zenity", fs::perms::owner_all);
    auto r = drive(dir, "chooser", 3, scene);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["live_while_choosing"], "1");
    EXPECT_EQ(r["opened"], "b.json");
    const std::string args = kr::test::read_file(dir / "zenity.args");
    EXPECT_NE(args.find("--file-selection\n"), std::string::npos) << args;
    EXPECT_NE(args.find("--filename=" + (dir / "mine").string() + "/\n"), std::string::npos) << args;
    EXPECT_NE(args.find("--file-filter=Scenes | *.json"), std::string::npos) << args;
}

// tev's exposure keys: E / Shift+E by half a stop, each one undo step; fly mode's E flies
// up and leaves the exposure; Page Up pans out of fly mode.
TEST_F(ViewerWindow, ExposureKeysStepUndoAndLeaveFlyModesE) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    auto r = drive(dir, "exposure_keys", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["after_e"], "0.50");
    EXPECT_EQ(r["after_shift_e"], "-0.50");
    EXPECT_EQ(r["after_undo"], "0.00");
    EXPECT_EQ(r["fly_exposure"], "0.00");
    EXPECT_EQ(r["page_up_exposure"], "0.00");
}

// The UI at the monitor's content scale (Xft.dpi 144: 1.5) times the kept UI scale (1.5):
// the window shots differ (bigger text and widgets); Ctrl+= raises the scale, Ctrl+0 sets
// it back to 1, and the settings file keeps it.
TEST_F(ViewerWindow, UiFollowsTheMonitorsScaleAndTheUiScaleSetting) {
    if (!have_xdotool()) GTEST_SKIP() << "xdotool is not installed (scripts/setup.sh installs it)";
    const fs::path settings = dir / "config" / "keithray" / "viewer.json";
    fs::create_directories(settings.parent_path());
    std::ofstream(settings) << R"({"ui_scale": 1.5})";
    auto r = drive(dir, "ui_scale", 3);
    ASSERT_EQ(r.count("error"), 0u) << r["error"];
    EXPECT_EQ(r["content_scale"], "1.50");
    EXPECT_EQ(r["ui_scale_start"], "1.50");
    EXPECT_EQ(r["ui_scale_after"], "1.75");
    const auto kept = nlohmann::json::parse(kr::test::read_file(settings));
    EXPECT_EQ(kept["ui_scale"].get<double>(), 1.0);
    const kr::ImageFile scaled = kr::read_image_file(dir / "scaled.ppm");
    const kr::ImageFile unscaled = kr::read_image_file(dir / "unscaled.ppm");
    ASSERT_EQ(scaled.rgb8.width, unscaled.rgb8.width);
    // At 2.25 the status bar is taller than at 1.5: the view above it is shorter, and the
    // image fitted in it (as wide: the panel takes its largest share, half the window,
    // at both) sits higher.
    ImagePlacement big_ui, small_ui;
    ASSERT_TRUE(image_placement(r["image_scaled"], big_ui));
    ASSERT_TRUE(image_placement(r["image_unscaled"], small_ui));
    EXPECT_LT(big_ui.top, small_ui.top);
    EXPECT_NE(max_channel_difference(scaled.rgb8, unscaled.rgb8), 0);
    keep_shot(dir, "scaled.ppm");
    keep_shot(dir, "unscaled.ppm");
}
