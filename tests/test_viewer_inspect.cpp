// The viewer's inspect and compare tools without a window: the pixel inspector against the
// render state, zoom and pan, image B and its figures, the convergence log, --stats-json.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/args.h"
#include "core/image_compare.h"
#include "core/image_io.h"
#include "render/render_scene.h"
#include "scene/load.h"
#include "test_util.h"
#include "viewer/compare_view.h"
#include "viewer/convergence_log.h"
#include "viewer/image_view.h"
#include "viewer/inspect.h"
#include "viewer/save_dialog.h"
#include "viewer/status.h"
#include "viewer/view_options.h"

namespace fs = std::filesystem;
using namespace kr;
using namespace kr::viewer;

namespace {

// A full-resolution snapshot of `passes` passes of brief scene `n` at size x size, as the
// render thread publishes it, with the state it came from.
struct Rendered {
    RenderState state;
    Snapshot frame;
};
Rendered render_frame(int n, int size, int passes, Allocation allocation = Allocation::adaptive) {
    const RenderScene scene = prepare_scene(test::brief_scene(n, size));
    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    settings.allocation = allocation;
    Rendered r;
    r.state.reset(size, size);
    StopRule rule;
    rule.max_passes = passes;
    EXPECT_EQ(render_until(scene, settings, r.state, rule), StopReason::passes);
    r.frame.radiance = r.state.radiance();
    r.frame.spp = r.state.passes;
    r.frame.relative_error = r.state.relative_error();
    record_pixel_statistics(r.state, r.frame);
    return r;
}

}  // namespace

// Mean radiance, 8-bit value, samples and standard error are the render state's, for every
// tone map (the linear one scaled by the whole image's maximum).
TEST(PixelInspector, NumbersAreTheRenderStates) {
    // Past the adaptive warm-up, so pixels hold different sample counts.
    const Rendered r = render_frame(3, 24, 12);
    const RenderState& totals = r.state;
    const Image mean = totals.radiance();
    for (ToneMap op : {ToneMap::sigmoid, ToneMap::linear, ToneMap::srgb}) {
        ToneSettings tone;
        tone.tonemap = op;
        tone.exposure = 0.5;
        const Rgb8Image shown = tonemap(mean, op, tone.exposure_scale());
        const double linear_scale = tonemap_scale(r.frame.radiance, op, tone.exposure_scale());
        for (const auto& [x, y] : {std::pair{0, 0}, {7, 13}, {23, 23}, {12, 5}}) {
            const auto p = probe_pixel(r.frame, 24, 24, x, y, tone, linear_scale);
            ASSERT_TRUE(p);
            const size_t i = size_t(y) * 24 + size_t(x);
            EXPECT_EQ(p->x, x);
            EXPECT_EQ(p->y, y);
            EXPECT_EQ(p->mean, mean.pixels[i]);
            EXPECT_EQ(p->samples, totals.sample_count()[i]);
            EXPECT_EQ(p->standard_error, float(totals.pixel_standard_error(i)));
            EXPECT_FALSE(p->preview);
            for (int k = 0; k < 3; ++k) EXPECT_EQ(p->displayed[size_t(k)], shown.bytes[3 * i + size_t(k)]) << int(op);
        }
    }
    // The counts differ between pixels (adaptive allocation), so the readout is per pixel.
    const auto [lo, hi] = std::minmax_element(totals.sample_count().begin(), totals.sample_count().end());
    EXPECT_LT(*lo, *hi);
    EXPECT_FALSE(probe_pixel(r.frame, 24, 24, 24, 0, ToneSettings{}, 1));
    EXPECT_FALSE(probe_pixel(r.frame, 24, 24, 0, -1, ToneSettings{}, 1));
}

// The probe's displayed value is image A's pixel: the image the window shows under the
// denoiser's view (raw, denoised, or split at the middle column), as the display draws it;
// its mean stays the raw estimate's.
TEST(PixelInspector, DisplayedValueIsOfTheImageShown) {
    Snapshot frame;
    frame.radiance = Image(4, 2);
    frame.denoised = Image(4, 2);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 4; ++x) {
            frame.radiance.at(x, y) = Color(0.1 * (x + 1), 0.2, 0.05 * (y + 1));
            frame.denoised.at(x, y) = Color(0.9, 0.1 * (x + 1), 0.3);
        }
    const ToneSettings tone;
    for (const DenoiseView view : {DenoiseView::off, DenoiseView::on, DenoiseView::split}) {
        const Rgb8Image shown = displayed_picture(frame, view, 4, 2, tone);
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 4; ++x) {
                const auto p = probe_pixel(frame, 4, 2, x, y, tone, 1, view);
                ASSERT_TRUE(p);
                EXPECT_EQ(p->mean, frame.radiance.at(x, y));
                for (int k = 0; k < 3; ++k)
                    EXPECT_EQ(p->displayed[size_t(k)], shown.bytes[(size_t(y) * 4 + size_t(x)) * 3 + size_t(k)])
                        << int(view) << " " << x << "," << y;
            }
    }
    // The denoised and raw values differ, so the views above tell them apart.
    EXPECT_NE(probe_pixel(frame, 4, 2, 0, 0, tone, 1, DenoiseView::on)->displayed,
              probe_pixel(frame, 4, 2, 0, 0, tone, 1, DenoiseView::off)->displayed);
}

TEST(PixelInspector, PreviewHasNoStatisticsAndCoversBlocks) {
    Snapshot preview;
    preview.scale = 4;
    preview.radiance = Image(4, 4);
    preview.radiance.at(2, 1) = Color(0.5, 1, 2);
    const auto p = probe_pixel(preview, 16, 16, 9, 7, ToneSettings{}, 1);
    ASSERT_TRUE(p);
    EXPECT_TRUE(p->preview);
    EXPECT_EQ(p->mean, Color(0.5, 1, 2));
    EXPECT_EQ(p->samples, 0u);
}

TEST(NoiseView, MapsAreFalseColourOfTheStatistics) {
    const Rendered r = render_frame(3, 16, 12);
    const double se_top = robust_scale(r.frame.standard_error);
    EXPECT_GT(se_top, 0);
    const Rgb8Image noise = standard_error_map(r.frame, se_top);
    const Rgb8Image samples = sample_count_map(r.frame, 64);
    ASSERT_EQ(noise.width, 16);
    ASSERT_EQ(samples.height, 16);
    for (size_t i = 0; i < 256; ++i) {
        const auto n = viridis(r.frame.standard_error[i] / se_top), s = viridis(r.frame.sample_count[i] / 64.0);
        for (size_t k = 0; k < 3; ++k) {
            ASSERT_EQ(noise.bytes[3 * i + k], n[k]);
            ASSERT_EQ(samples.bytes[3 * i + k], s[k]);
        }
    }
    EXPECT_TRUE(standard_error_map(Snapshot{}, 1).bytes.empty());  // a preview: nothing
    // The scale ignores the top 1% and non-finite values.
    std::vector<float> values(1000, 1.0f);
    values[3] = 1e9f;
    values[4] = INFINITY;
    EXPECT_EQ(robust_scale(values), 1.0);
    EXPECT_EQ(robust_scale({}), 0.0);
}

TEST(ImageView, FitPlacesTheImageAsBeforeAndZoomKeepsThePointUnderThePointer) {
    const PixelRect area{0, 0, 880, 650};
    ImageView view;
    // Fit: the free area by any factor (issue 34, defect 2), centred on whole pixels.
    PixelRect r = view.placement(area, 512, 512);
    EXPECT_DOUBLE_EQ(r.height, 650);
    EXPECT_DOUBLE_EQ(r.width, 650);
    EXPECT_EQ(r.x, 115);
    EXPECT_EQ(r.y, 0);
    EXPECT_DOUBLE_EQ(view.placement(area, 200, 100).width, 880);
    // The whole-pixel fit: whole screen pixels when it fits.
    view.whole_pixels = true;
    r = view.placement(area, 512, 512);
    EXPECT_EQ(r.width, 512);
    EXPECT_EQ(r.x, 184);
    EXPECT_EQ(r.y, 69);
    r = view.placement(area, 200, 100);
    EXPECT_EQ(r.width, 800);  // 4x
    r = view.placement(area, 2000, 1000);
    EXPECT_DOUBLE_EQ(r.width, 880);  // shrunk to fit

    // A step in about a pointer keeps the image point under it (to a pixel: corners are whole).
    double ix = 0, iy = 0, jx = 0, jy = 0;
    view.to_image(area, 512, 512, 300, 200, ix, iy);
    view.zoom_steps(area, 512, 512, 1, 300, 200);
    EXPECT_EQ(view.scale(area, 512, 512), 2);
    view.to_image(area, 512, 512, 300, 200, jx, jy);
    EXPECT_NEAR(jx, ix, 0.5);
    EXPECT_NEAR(jy, iy, 0.5);
    view.zoom_steps(area, 512, 512, 2, 300, 200);
    EXPECT_EQ(view.scale(area, 512, 512), 4);
    r = view.placement(area, 512, 512);
    EXPECT_EQ(r.x, std::floor(r.x));
    EXPECT_EQ(r.width, 2048);
    view.zoom_steps(area, 512, 512, 20, 300, 200);
    EXPECT_EQ(view.scale(area, 512, 512), kMaxZoom);
    // Out past the fit scale: fitted again.
    view.zoom_steps(area, 512, 512, -20, 300, 200);
    EXPECT_TRUE(view.fitted());

    // Pan moves a zoomed image with the pointer and keeps some of it in view.
    view.set_zoom(area, 512, 512, 4, 256, 256);
    const PixelRect before = view.placement(area, 512, 512);
    view.pan(area, 512, 512, 40, -8);
    const PixelRect after = view.placement(area, 512, 512);
    EXPECT_EQ(after.x - before.x, 40);
    EXPECT_EQ(after.y - before.y, -8);
    view.pan(area, 512, 512, 1e6, 1e6);
    r = view.placement(area, 512, 512);
    EXPECT_LT(r.x, area.x + area.width);
    EXPECT_LT(r.y, area.y + area.height);
    view.one_to_one(area, 512, 512);
    EXPECT_EQ(view.scale(area, 512, 512), 1);
    view.fit();
    EXPECT_TRUE(view.fitted());
    // A fitted image that shows whole does not pan.
    view.pan(area, 512, 512, 30, 30);
    EXPECT_TRUE(view.fitted());
}

TEST(Compare, FiguresAreThoseOfThePsnrCommand) {
    Rgb8Image a{4, 2, std::vector<uint8_t>(24, 100)}, b = a;
    b.bytes[5] = 130;
    b.bytes[17] = 90;
    const auto f = compare_figures(a, b);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->psnr, psnr(a, b));
    EXPECT_NEAR(f->rmse, rgb8_errors(a, b).rmse, 1e-15);
    EXPECT_EQ(compare_figures(a, a)->rmse, 0);
    EXPECT_NEAR(f->rmse, std::sqrt((30.0 * 30 + 10.0 * 10) / 24) / 255, 1e-12);
    EXPECT_FALSE(compare_figures(a, Rgb8Image{2, 4, std::vector<uint8_t>(24, 100)}));

    // Per pixel: RMS over the channels; relative divides by the reference plus 0.01.
    const std::vector<float> abs = pixel_errors(a, b, ErrorMetric::absolute);
    const std::vector<float> rel = pixel_errors(a, b, ErrorMetric::relative);
    ASSERT_EQ(abs.size(), 8u);
    EXPECT_FLOAT_EQ(abs[1], float(std::sqrt(30.0 * 30 / 3) / 255));
    EXPECT_FLOAT_EQ(rel[1], float(std::sqrt(std::pow(-30 / 255.0 / (130 / 255.0 + 0.01), 2) / 3)));
    EXPECT_EQ(abs[0], 0);
}

TEST(Compare, SlotsKeepSnapshotsAndBPicksThem) {
    Comparison c;
    EXPECT_EQ(c.b(), nullptr);
    Image img(2, 2);
    img.at(1, 1) = Color(1, 2, 3);
    const int s0 = c.keep(img, 16);
    const int s1 = c.keep(img, 32);
    EXPECT_EQ(s0, 0);
    EXPECT_EQ(s1, 1);
    c.settings.b = s1;
    ASSERT_NE(c.b(), nullptr);
    EXPECT_EQ(c.b()->name, "slot 2 (32 spp, raw)");
    EXPECT_TRUE(c.b()->hdr());
    // B tone maps a snapshot as the render is shown.
    ToneSettings tone;
    tone.tonemap = ToneMap::linear;
    EXPECT_EQ(c.b()->display(tone).bytes, tonemap(img, ToneMap::linear).bytes);
    c.drop(s1);
    EXPECT_EQ(c.settings.b, -1);
    // Full: the oldest goes.
    for (int i = 0; i < kSnapshotSlots + 2; ++i) c.keep(img, i);
    int kept = 0;
    for (const auto& slot : c.slots()) kept += slot.has_value();
    EXPECT_EQ(kept, kSnapshotSlots);
}

TEST(Compare, ReferencesLoadByFormatAndTheBriefsIsOffered) {
    const fs::path scenes = fs::path(KEITHRAY_RES_DIR) / "scenes";
    const auto brief = brief_reference_for(scenes / "assignment_05.json");
    ASSERT_TRUE(brief);
    EXPECT_EQ(brief->filename(), "assignment_05.ppm");
    EXPECT_FALSE(brief_reference_for(scenes / "nothing_here.json"));
    EXPECT_FALSE(brief_reference_for("elsewhere/assignment_05.json"));

    const CompareImage ref = load_reference(*brief);
    EXPECT_FALSE(ref.hdr());
    EXPECT_EQ(ref.width(), 512);
    EXPECT_EQ(ref.bytes.bytes, read_image(*brief).bytes);

    const fs::path dir = fs::temp_directory_path() / ("keithray_compare_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path bad = dir / "bad.ppm";
    {
        std::ofstream f(bad, std::ios::binary);
        f << "P6\n2 2\n255\nxx";
    }
    try {
        load_reference(bad);
        ADD_FAILURE() << "a truncated PPM loaded";
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("bad.ppm"), std::string::npos) << e.what();
    }
    fs::remove_all(dir);
}

TEST(ConvergenceLog, OnePointPerFullFrameOfTheGeneration) {
    ConvergenceLog log;
    Snapshot f;
    f.generation = 3;
    f.scale = 4;  // a preview: not a point
    log.record(f, std::nullopt);
    EXPECT_TRUE(log.points().empty());
    f.scale = 1;
    f.spp = 1;
    f.full_seconds = 0.5;
    f.relative_error = INFINITY;
    log.record(f, std::nullopt);
    f.spp = 2;
    f.full_seconds = 1.0;
    f.relative_error = 0.25;
    log.record(f, CompareFigures{30, 0.03});
    log.record(f, CompareFigures{31, 0.028});  // the same frame again: figures updated
    ASSERT_EQ(log.points().size(), 2u);
    EXPECT_EQ(log.points()[1].psnr, 31);
    EXPECT_EQ(log.csv(),
              "seconds,spp,estimated_relative_error,rmse,psnr\n"
              "0.500000,1,,,\n"
              "1.000000,2,0.25,0.028,31\n");
    f.generation = 4;  // an edit: a new log
    log.record(f, std::nullopt);
    EXPECT_EQ(log.points().size(), 1u);
    EXPECT_EQ(log.generation(), 4u);
}

TEST(StatsJson, HoldsWhatTheWindowShows) {
    StatsFigures s;
    s.state = "done";
    s.spp = 8;
    s.target = 8;
    s.elapsed = 1.5;
    s.mrays_per_second = 40;
    s.noise = 0.05;
    s.reference = "assignment_03.ppm";
    s.figures = CompareFigures{25.5, 0.05};
    s.image = "denoised";
    PixelProbe p;
    p.x = 3;
    p.samples = 8;
    p.standard_error = INFINITY;
    s.probe = p;
    const auto j = nlohmann::json::parse(stats_json(s));
    EXPECT_EQ(j["spp"], 8);
    EXPECT_EQ(j["state"], "done");
    EXPECT_EQ(j["noise"], 0.05);
    EXPECT_EQ(j["psnr"], 25.5);
    EXPECT_EQ(j["rmse"], 0.05);
    EXPECT_EQ(j["image"], "denoised");  // image A, of which psnr and rmse are figures
    EXPECT_EQ(j["probe"]["x"], 3);
    EXPECT_TRUE(j["probe"]["standard_error"].is_null());
    s.noise = -1;
    s.figures.reset();
    const auto k = nlohmann::json::parse(stats_json(s));
    EXPECT_TRUE(k["noise"].is_null());
    EXPECT_FALSE(k.contains("psnr"));
}

TEST(ViewOptions, CompareFlags) {
    auto parse = [](std::vector<std::string> args) {
        args.insert(args.begin(), {"keithray", "view"});
        std::vector<char*> argv;
        for (auto& a : args) argv.push_back(a.data());
        return parse_view_options(int(argv.size()), argv.data());
    };
    const ViewOptions o = parse({"s.json", "--view", "error", "--error", "relative", "--split", "0.25", "--zoom", "4",
                                 "--probe", "10,20", "--reference", "r.exr", "--stats-json", "out.json"});
    EXPECT_EQ(o.compare.mode, ViewMode::error);
    EXPECT_EQ(o.compare.metric, ErrorMetric::relative);
    EXPECT_EQ(o.compare.split, 0.25);
    EXPECT_EQ(o.zoom, 4);
    EXPECT_EQ(o.probe, std::make_pair(10, 20));
    EXPECT_EQ(o.reference, fs::path("r.exr"));
    EXPECT_TRUE(o.scripted());
    EXPECT_THROW(parse({"--view", "sideways"}), UsageError);
    EXPECT_EQ(parse({"--save-image", "out.EXR"}).save_image, fs::path("out.EXR"));
    EXPECT_TRUE(parse({"--save-image", "out.pfm"}).scripted());
    EXPECT_THROW(parse({"--save-image", "scene.json"}), UsageError);
    EXPECT_THROW(parse({"--split", "1.5"}), UsageError);
    EXPECT_THROW(parse({"--zoom", "64"}), UsageError);
    EXPECT_THROW(parse({"--probe", "3"}), UsageError);
}

// The Stats panel's "Save convergence CSV" writes the log whole, where the Save panel's
// default path puts it.
TEST(ConvergenceLog, SavedAsCsvBesideTheOutput) {
    const fs::path dir = fs::temp_directory_path() / ("keithray_csv_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    ViewerModel model;
    model.load(fs::path(KEITHRAY_RES_DIR) / "scenes" / "assignment_02.json");
    EXPECT_EQ(fs::path(SavePaths::for_scene(model.scene()).convergence).filename(), "assignment_02-convergence.csv");
    ConvergenceLog log;
    Snapshot f;
    f.spp = 1;
    f.full_seconds = 0.25;
    log.record(f, std::nullopt);
    const fs::path csv = dir / "c.csv";
    EXPECT_NE(save_output(SaveKind::convergence, csv, model, nullptr, log.csv()).find("saved"), std::string::npos);
    std::ifstream in(csv);
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_EQ(text.str(), log.csv());
    // Under a regular file: refused, and nothing written.
    EXPECT_THROW(save_output(SaveKind::convergence, csv / "c.csv", model, nullptr, log.csv()), std::exception);
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 1);  // no temp file left
    fs::remove_all(dir);
}

// A file name that is not UTF-8 (image B's, from the command line) is escaped in the JSON,
// never an exception from the JSON library.
TEST(StatsJson, NameThatIsNotUtf8IsEscaped) {
    StatsFigures s;
    s.state = "done";
    s.reference = std::string("b\xff\xfe.ppm");
    std::string text;
    ASSERT_NO_THROW(text = stats_json(s));
    const auto j = nlohmann::json::parse(text);
    EXPECT_EQ(j["reference"], "b\\xFF\\xFE.ppm");
}

// Missing item 4: the feature views. One name table names every view for --view, the combo,
// the label and the status file; the three new ones are in it, in the order V cycles them.
TEST(FeatureViews, NameTableRoundTripsAndTheFlagReadsIt) {
    ASSERT_EQ(view_mode_names.names.size(), 9u);
    for (size_t i = 0; i < view_mode_names.names.size(); ++i) {
        const std::string name(view_mode_names.names[i]);
        EXPECT_EQ(view_mode_names.parse(name), ViewMode(i)) << name;
        EXPECT_EQ(view_mode_names.name(ViewMode(i)), name);
        const char* argv[] = {"keithray", "view", "s.json", "--view", name.c_str()};
        EXPECT_EQ(parse_view_options(5, const_cast<char**>(argv)).compare.mode, ViewMode(i)) << name;
    }
    EXPECT_EQ(view_mode_names.name(ViewMode::albedo), "albedo");
    EXPECT_EQ(view_mode_names.name(ViewMode::normal), "normal");
    EXPECT_EQ(view_mode_names.name(ViewMode::depth), "depth");
    EXPECT_TRUE(is_feature_view(ViewMode::albedo) && is_feature_view(ViewMode::normal) && is_feature_view(ViewMode::depth));
    EXPECT_FALSE(is_feature_view(ViewMode::render) || is_feature_view(ViewMode::samples));
}

// Each layer value maps to the pixel the view shows: albedo clamped, normal * 0.5 + 0.5, depth
// a grey ramp from the nearest hit (white) to the farthest (kDepthFarGrey), misses black.
TEST(FeatureViews, KnownBuffersMapToTheExpectedPixels) {
    FeatureBuffers f;
    f.width = 3;
    f.height = 1;
    f.albedo = {0.5f, 1.5f, -0.2f, 0, 0, 0, 0.2f, 0.4f, 1.0f};
    f.normal = {0, 1, -1, 0, 0, 0, 0.6f, -0.6f, 0};
    const Rgb8Image a = albedo_picture(f), n = normal_picture(f);
    EXPECT_EQ(a.bytes, (std::vector<uint8_t>{128, 255, 0, 0, 0, 0, 51, 102, 255}));
    EXPECT_EQ(n.bytes, (std::vector<uint8_t>{128, 255, 0, 128, 128, 128, 204, 51, 128}));

    // Means over 4 samples: all hits at 2, at 10 and at 6; one miss (kMissDepth) among hits at
    // 3; no samples.
    const std::vector<double> mean = {2, 10, 6, (1e6 + 3 * 3) / 4.0, 0};
    const std::vector<uint32_t> samples = {4, 4, 4, 4, 0};
    const std::vector<float> d = hit_depths(mean, samples);
    ASSERT_EQ(d.size(), 5u);
    EXPECT_EQ(d[0], 2);
    EXPECT_EQ(d[2], 6);
    EXPECT_TRUE(std::isinf(d[3]));
    EXPECT_TRUE(std::isinf(d[4]));
    const auto range = depth_range(d);
    ASSERT_TRUE(range);
    EXPECT_EQ(range->near, 2);
    EXPECT_EQ(range->far, 10);
    const Rgb8Image g = depth_picture(d, 5, 1, *range);
    const uint8_t mid = quantize_unit(1 - (1 - kDepthFarGrey) * 0.5);  // 6 is halfway: 143
    EXPECT_EQ(mid, 143);
    EXPECT_EQ(g.bytes, (std::vector<uint8_t>{255, 255, 255, 32, 32, 32, mid, mid, mid, 0, 0, 0, 0, 0, 0}));
    EXPECT_FALSE(depth_range({INFINITY, INFINITY}));
}

// A frame's picture at the image's size: a preview's in blocks, as the display shows it; a
// frame without the layer says so, and the inspector reads the layer at the pixel.
TEST(FeatureViews, PreviewPictureInBlocksAndTheInspectorReadsTheLayer) {
    Snapshot frame;
    frame.scale = 2;
    frame.radiance = Image(2, 2);
    auto f = std::make_shared<FeatureBuffers>();
    f->width = f->height = 2;
    f->albedo = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};  // black, red, green, blue
    f->normal = {0, 0, -1, 0, 0, -1, 0, 0, -1, 0, 0, -1};
    frame.features = f;
    frame.hit_depth = {1, 2, 3, INFINITY};

    // The image is 3x3: its last column and row are the preview's second.
    const FeaturePicture a = feature_picture(frame, ViewMode::albedo, 3, 3);
    ASSERT_EQ(a.picture.width, 3);
    ASSERT_EQ(a.picture.height, 3);
    auto at = [](const Rgb8Image& p, int x, int y) {
        const size_t i = 3 * (size_t(y) * size_t(p.width) + size_t(x));
        return std::array<int, 3>{p.bytes[i], p.bytes[i + 1], p.bytes[i + 2]};
    };
    EXPECT_EQ(at(a.picture, 0, 0), (std::array<int, 3>{0, 0, 0}));
    EXPECT_EQ(at(a.picture, 1, 1), (std::array<int, 3>{0, 0, 0}));
    EXPECT_EQ(at(a.picture, 2, 0), (std::array<int, 3>{255, 0, 0}));
    EXPECT_EQ(at(a.picture, 0, 2), (std::array<int, 3>{0, 255, 0}));
    EXPECT_EQ(at(a.picture, 2, 2), (std::array<int, 3>{0, 0, 255}));
    const FeaturePicture d = feature_picture(frame, ViewMode::depth, 3, 3);
    ASSERT_TRUE(d.range);
    EXPECT_EQ(d.range->near, 1);
    EXPECT_EQ(d.range->far, 3);
    EXPECT_EQ(at(d.picture, 2, 0), (std::array<int, 3>{143, 143, 143}));
    EXPECT_EQ(at(d.picture, 2, 2), (std::array<int, 3>{0, 0, 0}));  // no hit

    EXPECT_EQ(feature_readout(frame, ViewMode::albedo, 2, 0), "albedo 1.000 0.000 0.000");
    EXPECT_EQ(feature_readout(frame, ViewMode::normal, 0, 0), "normal +0.000 +0.000 -1.000");
    EXPECT_EQ(feature_readout(frame, ViewMode::depth, 0, 2), "depth 3");
    EXPECT_EQ(feature_readout(frame, ViewMode::depth, 2, 2), "depth: no hit");
    EXPECT_EQ(feature_readout(frame, ViewMode::noise, 0, 0), "");

    // Without the layers: no picture, and why.
    frame.features.reset();
    frame.hit_depth.clear();
    const FeaturePicture none = feature_picture(frame, ViewMode::normal, 3, 3);
    EXPECT_TRUE(none.picture.bytes.empty());
    EXPECT_EQ(none.missing, "no normal in this frame");
    EXPECT_EQ(feature_picture(frame, ViewMode::depth, 3, 3).missing, "no depth in this frame");
    EXPECT_EQ(feature_readout(frame, ViewMode::albedo, 0, 0), "albedo: not available");
}

// Leftover of issue 34: from a fit by any factor, + steps to the smallest zoom level above
// the fit (not to a fixed 2x), and - from there fits again; from a level, + and - step one
// level each way.
TEST(ImageView, PlusFromAnyFitStepsToTheNextLevelAboveIt) {
    struct Case {
        double area_width;  // a square image of 512 in a 560-high area: the fit is area_width / 512
        double next;
    };
    for (const Case c : {Case{307.2, 0.75}, Case{384, 1}, Case{512, 2}, Case{558, 2}, Case{560, 2}}) {
        ImageView view;
        const PixelRect area{0, 0, c.area_width, 560};
        const double fit = view.scale(area, 512, 512);
        view.zoom_steps(area, 512, 512, 1, c.area_width / 2, 280);
        EXPECT_EQ(view.scale(area, 512, 512), c.next) << "fit " << fit;
        view.zoom_steps(area, 512, 512, -1, c.area_width / 2, 280);
        EXPECT_TRUE(view.fitted()) << "fit " << fit;
    }
    // Wider fits: 2.5 -> 3, 3.4 -> 4, 5 -> 6.
    for (const auto& [fit, next] : {std::pair{2.5, 3.0}, std::pair{3.4, 4.0}, std::pair{5.0, 6.0}}) {
        ImageView view;
        const PixelRect area{0, 0, 200 * fit, 200 * fit};
        view.zoom_steps(area, 200, 200, 1, 100 * fit, 100 * fit);
        EXPECT_EQ(view.scale(area, 200, 200), next) << "fit " << fit;
        view.zoom_steps(area, 200, 200, 1, 100 * fit, 100 * fit);
        view.zoom_steps(area, 200, 200, -1, 100 * fit, 100 * fit);
        EXPECT_EQ(view.scale(area, 200, 200), next) << "fit " << fit;
    }
}

// Leftover of issue 34: with a render region the status bar adds the region's own figures,
// the mean samples of its pixels and RenderState::relative_error over them only.
TEST(RegionStatus, TheRegionsOwnSamplesAndNoise) {
    const Rendered r = render_frame(3, 64, 12);  // adaptive: the pixels hold different counts
    const auto whole = region_status(r.frame, {0, 0, 64, 64});
    ASSERT_TRUE(whole);
    EXPECT_NEAR(whole->noise, r.state.relative_error(), 1e-6 * r.state.relative_error());
    double all = 0;
    for (const uint32_t c : r.state.sample_count()) all += c;
    EXPECT_DOUBLE_EQ(whole->samples_per_pixel, all / (64 * 64));

    const PixelBox box{10, 20, 30, 50};
    double samples = 0, error_sq = 0, signal_sq = 0;
    for (int y = box.y0; y < box.y1; ++y)
        for (int x = box.x0; x < box.x1; ++x) {
            const size_t i = size_t(y) * 64 + size_t(x);
            samples += r.state.sample_count()[i];
            error_sq += std::pow(r.state.pixel_standard_error(i), 2);
            signal_sq += std::pow(luminance(r.state.radiance().pixels[i]), 2);
        }
    const auto part = region_status(r.frame, box);
    ASSERT_TRUE(part);
    EXPECT_DOUBLE_EQ(part->samples_per_pixel, samples / (20 * 30));
    EXPECT_NEAR(part->noise, std::sqrt(error_sq / signal_sq), 1e-6 * part->noise);
    EXPECT_GT(std::abs(part->noise - whole->noise), 1e-3 * whole->noise);  // not the whole image's figure

    // Clipped to the image; none outside it or for a preview; unknown below 2 samples.
    EXPECT_DOUBLE_EQ(region_status(r.frame, {-5, -5, 64, 64})->noise, whole->noise);
    EXPECT_FALSE(region_status(r.frame, {70, 0, 80, 10}));
    Snapshot preview = r.frame;
    preview.scale = 2;
    EXPECT_FALSE(region_status(preview, box));
    Snapshot fresh = r.frame;
    fresh.standard_error[size_t(25) * 64 + 15] = INFINITY;
    EXPECT_EQ(region_status(fresh, box)->noise, -1);
}
