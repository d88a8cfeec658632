// HDR output (OpenEXR with the render's layers, PFM), reading it back, and `keithray compare`,
// its statistical test included.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>

#include "core/image_compare.h"
#include "core/image_hdr.h"
#include "render/aov.h"
#include "render/outputs.h"
#include "scene/save.h"
#include "test_util.h"
#include "core/image_io.h"

namespace fs = std::filesystem;
using namespace kr;

namespace {

// An image whose every layer holds distinct values, some of them awkward floats.
HdrImage layered_image(int w, int h) {
    HdrImage img;
    img.width = w;
    img.height = h;
    const size_t n = img.pixel_count();
    for (size_t i = 0; i < n; ++i) {
        const float f = float(i);
        for (int k = 0; k < 3; ++k) {
            img.rgb.push_back(f * 1.25e-3f + float(k) + (i == 3 ? 6.5e4f : 0.0f));
            img.albedo.push_back(0.01f * float(k) + f * 1e-4f);
            img.normal.push_back(k == 2 ? -1.0f : 1.0f / (1.0f + f));
            img.variance.push_back(i == 5 ? std::numeric_limits<float>::infinity() : f * 3e-7f + float(k));
        }
        img.depth.push_back(i % 7 == 0 ? float(kMissDepth) : 0.5f + f);
        img.samples.push_back(uint32_t(i * 3 + 1));
    }
    return img;
}

void expect_same_layers(const HdrImage& a, const HdrImage& b) {
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    EXPECT_EQ(a.rgb, b.rgb);
    EXPECT_EQ(a.depth, b.depth);
    EXPECT_EQ(a.albedo, b.albedo);
    EXPECT_EQ(a.normal, b.normal);
    EXPECT_EQ(a.samples, b.samples);
    EXPECT_EQ(a.variance, b.variance);
}

std::string read_bytes(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}
void write_bytes(const fs::path& p, const std::string& bytes) { std::ofstream(p, std::ios::binary) << bytes; }

// One line naming the file: the house rule for every error.
void expect_one_line_naming(const std::string& err, const std::string& file) {
    EXPECT_NE(err.find(file), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
}

}  // namespace

TEST(HdrFiles, ExrRoundTripsEveryLayerExactly) {
    const HdrImage img = layered_image(7, 5);
    expect_same_layers(decode_exr(encode_exr(img), "mem.exr"), img);
    // The radiance alone: the other layers stay absent.
    const HdrImage plain = hdr_from_radiance(img.radiance());
    const HdrImage back = decode_exr(encode_exr(plain), "mem.exr");
    EXPECT_EQ(back.rgb, img.rgb);
    EXPECT_TRUE(back.depth.empty() && back.variance.empty() && back.samples.empty() && back.albedo.empty());
}

// Another writer's EXR whose data window does not start at (0, 0): its pixels, in order.
TEST(HdrFiles, ExrWithAnOffsetDataWindowReads) {
    const Imath::Box2i display(Imath::V2i(0, 0), Imath::V2i(7, 7)), data(Imath::V2i(2, 3), Imath::V2i(5, 6));
    Imf::Header header(display, data);
    std::vector<float> rgb(4 * 4 * 3);
    for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = float(i) * 0.5f;
    const fs::path file = fs::temp_directory_path() / ("keithray_window_" + std::to_string(::getpid()) + ".exr");
    {
        Imf::FrameBuffer frame;
        for (int k = 0; k < 3; ++k) {
            header.channels().insert(std::string(1, "RGB"[k]), Imf::Channel(Imf::FLOAT));
            frame.insert(std::string(1, "RGB"[k]),
                         Imf::Slice::Make(Imf::FLOAT, rgb.data() + k, data, 3 * sizeof(float), 12 * sizeof(float)));
        }
        Imf::OutputFile out(file.c_str(), header);
        out.setFrameBuffer(frame);
        out.writePixels(4);
    }
    const HdrImage img = read_hdr(file);
    fs::remove(file);
    EXPECT_EQ(img.width, 4);
    EXPECT_EQ(img.height, 4);
    EXPECT_EQ(img.rgb, rgb);
}

TEST(HdrFiles, PfmRoundTripsRadianceAndDepthExactly) {
    const HdrImage img = layered_image(6, 4);
    EXPECT_EQ(decode_pfm(encode_pfm_rgb(img), "mem.pfm").rgb, img.rgb);
    const HdrImage depth = decode_pfm(encode_pfm_gray(img.depth, img.width, img.height), "mem-depth.pfm");
    EXPECT_EQ(depth.depth, img.depth);
    // PFM stores rows bottom first: the first bytes after the header are the last row.
    const std::string bytes = encode_pfm_rgb(img);
    float first = 0;
    std::memcpy(&first, bytes.data() + bytes.size() - img.rgb.size() * sizeof(float), sizeof(float));
    EXPECT_EQ(first, img.rgb[3 * size_t(img.width) * size_t(img.height - 1)]);
}

TEST(HdrFiles, BadExrAndPfmBytesGiveOneLineNamingTheFile) {
    const std::string exr = encode_exr(layered_image(16, 16));
    auto exr_error = [](const std::string& bytes) {
        try {
            decode_exr(bytes, "bad.exr");
        } catch (const std::runtime_error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    for (size_t cut : {size_t(3), size_t(40), exr.size() / 3, exr.size() / 2, exr.size() - 1}) {
        const std::string err = exr_error(exr.substr(0, cut));
        EXPECT_EQ(err.rfind("bad.exr: ", 0), 0u) << "cut at " << cut << ": " << err;
        EXPECT_EQ(err.find('\n'), std::string::npos) << err;
    }
    std::string corrupt = exr;
    std::fill(corrupt.begin() + long(corrupt.size() / 2), corrupt.end(), '\xff');
    EXPECT_EQ(exr_error(corrupt).rfind("bad.exr: ", 0), 0u) << exr_error(corrupt);

    // An EXR without R, G, B (a luminance Y only), and one with a layer missing channels.
    const std::pair<std::vector<const char*>, const char*> channel_cases[] = {
        {{"Y"}, "expected the channels R, G and B"}, {{"R", "G", "B", "variance.R"}, "the variance layer is incomplete"}};
    for (const auto& [names, expected] : channel_cases) {
        Imf::Header header(4, 4);
        std::vector<float> values(16, 1.0f);
        Imf::FrameBuffer frame;
        for (const char* channel : names) {
            header.channels().insert(channel, Imf::Channel(Imf::FLOAT));
            frame.insert(channel, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(values.data()), sizeof(float),
                                             4 * sizeof(float)));
        }
        const fs::path file = fs::temp_directory_path() / ("keithray_channels_" + std::to_string(::getpid()) + ".exr");
        {
            Imf::OutputFile out(file.c_str(), header);
            out.setFrameBuffer(frame);
            out.writePixels(4);
        }
        try {
            read_hdr(file);
            ADD_FAILURE() << "read an EXR with channels " << names.size();
        } catch (const std::runtime_error& e) {
            EXPECT_EQ(std::string(e.what()), file.string() + ": " + expected + (names.size() == 1 ? " of an RGB radiance image" : ""));
        }
        fs::remove(file);
    }

    const std::string pfm = encode_pfm_rgb(layered_image(5, 3));
    auto pfm_error = [](const std::string& bytes) {
        try {
            decode_pfm(bytes, "bad.pfm");
        } catch (const std::runtime_error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    const std::vector<std::string> bad_pfms{
        pfm.substr(0, pfm.size() - 4),               // truncated pixels
        pfm + "xxxx",                                // trailing bytes
        "PF\n5 300\n-1.0\n" + pfm.substr(12),        // header larger than the data
        "PF\n5 3\n1.0\n" + pfm.substr(12),           // big-endian
        "PF\n0 3\n-1.0\n",                           // empty
        "PF\n99999999 99999999\n-1.0\n",             // absurd size
        "PF\nfive 3\n-1.0\n",                        // not a number
        "P6\n5 3\n255\n",                            // not a PFM
    };
    for (const std::string& bytes : bad_pfms) {
        const std::string err = pfm_error(bytes);
        EXPECT_EQ(err.rfind("bad.pfm: ", 0), 0u) << err;
        EXPECT_EQ(err.find('\n'), std::string::npos) << err;
    }
}

TEST(HdrStatistics, NoiselessPixelsAgreeWhenEqualAndDifferWhenNot) {
    HdrImage a = layered_image(16, 16);
    std::fill(a.variance.begin(), a.variance.end(), 0.0f);
    HdrImage b = a;
    EXPECT_TRUE(statistical_compare(a, "a.exr", b, "b.exr", {}).agree);
    // Equal up to float rounding: still the same image.
    b.rgb[100] = std::nextafter(b.rgb[100], 1e9f);
    EXPECT_TRUE(statistical_compare(a, "a.exr", b, "b.exr", {}).agree);
    // A real change of a pixel neither image has noise in, beside a bright one (pixel 3).
    b.rgb[100] *= 1.001f;
    StatisticalResult r = statistical_compare(a, "a.exr", b, "b.exr", {});
    EXPECT_FALSE(r.agree);
    EXPECT_TRUE(std::isinf(r.max_abs_z));
    EXPECT_EQ(r.worst_x, 33 % 16);
    EXPECT_EQ(r.worst_y, 33 / 16);
    b = a;
    a.rgb[7] = b.rgb[7] = 0;  // black in both, then lit in one
    EXPECT_TRUE(statistical_compare(a, "a.exr", b, "b.exr", {}).agree);
    b.rgb[7] = 1e-3f;
    EXPECT_FALSE(statistical_compare(a, "a.exr", b, "b.exr", {}).agree);
}

TEST(HdrStatistics, MissingOrUnknownVarianceNamesTheFile) {
    const HdrImage a = layered_image(8, 8);
    HdrImage no_variance = a;
    no_variance.variance.clear();
    try {
        statistical_compare(a, "a.exr", no_variance, "ref.exr", {});
        ADD_FAILURE() << "compared without a variance layer";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()).rfind("ref.exr: --statistical needs the variance layer", 0), 0u) << e.what();
    }
    // layered_image gives pixel 5 an infinite variance (fewer than two samples).
    HdrImage finite = a;
    for (float& v : finite.variance)
        if (std::isinf(v)) v = 1;
    try {
        statistical_compare(finite, "t.exr", a, "ref.exr", {});
        ADD_FAILURE() << "compared with an unknown variance";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()).rfind("ref.exr: pixel (5, 0) has no variance estimate", 0), 0u) << e.what();
    }
}

// A denoised render's R, G, B are biased; its variance layer belongs to its raw mean
// (raw.R/G/B). The test compares the raw means wherever an image holds them: a filter that
// moved R, G, B far from them (noiseless pixels included) is no change of the render.
TEST(HdrStatistics, DenoisedImagesAreTestedByTheirRawRadiance) {
    HdrImage raw = layered_image(16, 16);
    for (float& v : raw.variance)
        if (std::isinf(v)) v = 1;
    raw.variance[3 * 40] = raw.variance[3 * 40 + 1] = raw.variance[3 * 40 + 2] = 0;  // a noiseless pixel
    HdrImage denoised = raw;
    denoised.raw = raw.rgb;
    for (float& v : denoised.rgb) v = v * 1.5f + 100;  // the filter's bias, far beyond the noise
    EXPECT_EQ(&tested_radiance(denoised), &denoised.raw);
    EXPECT_EQ(&tested_radiance(raw), &raw.rgb);
    for (const auto& [a, b] : {std::pair{&denoised, &raw}, std::pair{&raw, &denoised}, std::pair{&denoised, &denoised}}) {
        const StatisticalResult r = statistical_compare(*a, "a.exr", *b, "b.exr", {});
        EXPECT_TRUE(r.agree);
        EXPECT_EQ(r.max_abs_z, 0);
    }
    // A change of the raw mean is still found, at the pixel that changed.
    HdrImage changed = denoised;
    changed.raw[3 * 40] += 1;
    const StatisticalResult r = statistical_compare(changed, "a.exr", raw, "b.exr", {});
    EXPECT_FALSE(r.agree);
    EXPECT_EQ(r.worst_x, 40 % 16);
    EXPECT_EQ(r.worst_y, 40 / 16);
}

TEST(HdrStatistics, NormalQuantileMatchesKnownValues) {
    EXPECT_NEAR(normal_upper_quantile(0.025), 1.959964, 1e-5);
    EXPECT_NEAR(normal_upper_quantile(1e-4), 3.719016, 1e-5);
    EXPECT_NEAR(normal_upper_quantile(1e-9), 5.997807, 1e-5);
}

// ---- Renders ----

namespace {

HdrImage render_hdr(const Scene& scene, int spp, uint64_t seed, Estimator estimator = Estimator::sobol) {
    const RenderScene prepared = prepare_scene(scene);
    RenderSettings settings = RenderSettings::from_scene(prepared.renderer);
    settings.estimator = estimator;
    settings.seed = seed;
    settings.target_spp = spp;
    RenderState state(prepared.renderer.width, prepared.renderer.height);
    StopRule rule;
    rule.max_passes = spp;
    render_until(prepared, settings, state, rule);
    return hdr_from_developed(develop(prepared, render_estimates(state, kAllLayers), DevelopOptions{}));
}

// The scene's one active light, the camera, a material by name: the three changes.
Scene brighter_light(Scene s) {
    s.lights[size_t(s.active_lights.at(0))].power = s.lights[size_t(s.active_lights.at(0))].power * 1.05;
    return s;
}
Scene camera_shifted_one_pixel(Scene s) {
    Camera& cam = s.cameras[size_t(s.camera)];
    // One pixel at the target's distance: the image plane there is 2 d tan(fov/2) high.
    const double pixel = 2 * length(cam.target - cam.position) * std::tan(cam.fov * kPi / 360) / s.renderer.height;
    cam.position.x += pixel;
    cam.target.x += pixel;
    return s;
}
Scene green_rho_lowered(Scene s) {
    for (Material& m : s.materials)
        if (m.id == "green diffuse") m.rho = m.rho * 0.95;
    return s;
}

}  // namespace

// 50 pairs of renders of one scene with different seeds: the failures must fit the stated
// false-alarm rate (the Sobol samples' variance estimates are conservative, so fewer is fine).
TEST(HdrStatistics, SameSceneDifferentSeedsPassAtTheFalseAlarmRate) {
    const Scene scene = test::brief_scene(3, 32);
    int failures_default = 0, failures_loose = 0;
    constexpr int kPairs = 50;
    for (int pair = 0; pair < kPairs; ++pair) {
        const HdrImage a = render_hdr(scene, 16, uint64_t(2 * pair + 1)), b = render_hdr(scene, 16, uint64_t(2 * pair + 2));
        failures_default += !statistical_compare(a, "a", b, "b", {}).agree;  // alpha 1e-4
        failures_loose += !statistical_compare(a, "a", b, "b", {0.05, 8}).agree;
    }
    // At 1e-4, more than one false alarm in 50 has probability 1.2e-5; at 0.05 (mean 2.5),
    // more than 8 has probability 8e-4.
    std::printf("false alarms in %d pairs: %d at alpha 1e-4, %d at alpha 0.05\n", kPairs, failures_default,
                failures_loose);
    EXPECT_LE(failures_default, 1);
    EXPECT_LE(failures_loose, 8);
}

// Independent (uniform) samples, whose variance estimates are not conservative as Sobol's
// are, spread by the default adaptive allocation: the failures still fit the rate.
TEST(HdrStatistics, IndependentSamplesWithAdaptiveAllocationPassAtTheFalseAlarmRate) {
    const Scene scene = test::brief_scene(3, 32);
    int failures_default = 0, failures_loose = 0;
    constexpr int kPairs = 25;
    for (int pair = 0; pair < kPairs; ++pair) {
        const HdrImage a = render_hdr(scene, 16, uint64_t(2 * pair + 1), Estimator::uniform);
        const HdrImage b = render_hdr(scene, 16, uint64_t(2 * pair + 2), Estimator::uniform);
        failures_default += !statistical_compare(a, "a", b, "b", {}).agree;
        failures_loose += !statistical_compare(a, "a", b, "b", {0.05, 8}).agree;
    }
    std::printf("false alarms in %d pairs: %d at alpha 1e-4, %d at alpha 0.05\n", kPairs, failures_default,
                failures_loose);
    // At 0.05 (mean 1.25), more than 5 has probability 1.2e-3.
    EXPECT_LE(failures_default, 1);
    EXPECT_LE(failures_loose, 5);
}

// Scenes 3 and 6 at 64 spp (at 64x64 pixels, to keep the test short) against a reference
// of 256 spp: a render with another seed agrees; a light 5% brighter, the camera one pixel
// to the side, and the green walls' rho 5% lower each fail.
class HdrChanges : public testing::TestWithParam<int> {};

TEST_P(HdrChanges, EachChangeFailsAndTheSameSceneAgrees) {
    const Scene scene = test::brief_scene(GetParam(), 64);
    // The reference at 256 spp, as README's CI recipe keeps one: its own noise then adds a
    // quarter of the test's to the difference rather than as much again.
    const HdrImage reference = render_hdr(scene, 256, 1);
    const StatisticalResult same = statistical_compare(render_hdr(scene, 64, 2), "test", reference, "ref", {});
    EXPECT_TRUE(same.agree) << "max |z| " << same.max_abs_z << " limit " << same.z_limit << ", chi2 " << same.chi_square;
    const std::pair<const char*, Scene> changes[] = {{"light 5% brighter", brighter_light(scene)},
                                                     {"camera shifted 1 px", camera_shifted_one_pixel(scene)},
                                                     {"green rho 5% lower", green_rho_lowered(scene)}};
    for (const auto& [what, changed] : changes) {
        const StatisticalResult r = statistical_compare(render_hdr(changed, 64, 2), "test", reference, "ref", {});
        std::printf("scene %d, %s: max |z| %.2f (limit %.2f), chi2 %.1f (limit %.1f)\n", GetParam(), what, r.max_abs_z,
                    r.z_limit, r.chi_square, r.chi_square_limit);
        EXPECT_FALSE(r.agree) << what << ": max |z| " << r.max_abs_z << " limit " << r.z_limit;
    }
}

INSTANTIATE_TEST_SUITE_P(Scenes3And6, HdrChanges, testing::Values(3, 6));

// The 8-bit image from the EXR's float radiance is the one from the render's double radiance,
// except where the float's rounding (2^-24) crosses a quantisation step.
TEST(HdrRender, ToneMappedExrRadianceEqualsTheEightBitImage) {
    const Scene scene = test::brief_scene(6, 32);
    const RenderScene prepared = prepare_scene(scene);
    RenderSettings settings = RenderSettings::from_scene(prepared.renderer);
    settings.target_spp = 8;
    RenderState state(32, 32);
    StopRule rule;
    rule.max_passes = 8;
    render_until(prepared, settings, state, rule);
    const Image radiance = state.radiance();
    const HdrImage exr = decode_exr(
        encode_exr(hdr_from_developed(develop(prepared, render_estimates(state, kAllLayers), DevelopOptions{}))), "mem.exr");
    const Rgb8Image direct = tonemap(radiance, ToneMap::sigmoid), from_exr = tonemap(exr.radiance(), ToneMap::sigmoid);
    int steps_crossed = 0;
    for (size_t i = 0; i < direct.bytes.size(); ++i) {
        if (direct.bytes[i] == from_exr.bytes[i]) continue;
        const double v = radiance.pixels[i / 3][int(i % 3)], unit = v / (1 + v);
        EXPECT_NEAR(unit * 255 - std::floor(unit * 255), 0.5, 1e-4) << "byte " << i;
        EXPECT_EQ(std::abs(int(direct.bytes[i]) - int(from_exr.bytes[i])), 1);
        ++steps_crossed;
    }
    EXPECT_LE(steps_crossed, 2);
}

// ---- The command line ----

namespace {

class HdrCli : public test::ScratchDirTest {
protected:
    test::CommandResult run(const std::string& args) {
        return test::run_command("cd '" + dir.string() + "' && '" + KEITHRAY_EXE + "' " + args, dir);
    }

    // A diffuse ball (rho 0.8) under a point light on black, 16x12 pixels, path traced.
    fs::path write_scene(const std::string& name, int width = 16) {
        const fs::path file = dir / name;
        std::ofstream(file) << R"({
  "cameras": [{"id": "cam", "type": "pinhole", "fov": 45, "aspect": 1.333, "position": [0, 0, -5], "target": [0, 0, 0]}],
  "materials": [{"id": "white", "type": "diffuse", "rho": [0.8, 0.8, 0.8]}],
  "shapes": [{"id": "ball", "type": "sphere", "centre": [0, 0, 0], "radius": 1}],
  "lights": [{"id": "lamp", "type": "point", "position": [0, 3, -3], "power": [50, 50, 50]}],
  "scene": {
    "camera": "cam", "lights": ["lamp"],
    "primitives": [{"id": "ball", "type": "geometric", "shape": "ball", "material": "white"}],
    "renderer": {"type": "PT", "dimensions": [)"
                            << width << R"(, 12], "samples": 4, "depth": 3, "output": "out.ppm"}
  }
})";
        return file;
    }
};

}  // namespace

TEST_F(HdrCli, ExrCarriesEveryLayerAndMatchesThePpmAndPfm) {
    write_scene("s.json");
    ASSERT_EQ(run("render s.json -q -o r.exr").status, 0);
    ASSERT_EQ(run("render s.json -q -o r.ppm").status, 0);
    ASSERT_EQ(run("render s.json -q -o r.pfm").status, 0);
    EXPECT_FALSE(fs::exists(dir / "r-depth.exr"));  // the depth is a layer of the EXR
    EXPECT_EQ(run("render s.json -q --gl -o g.exr").status, 2);  // nothing to tone map
    EXPECT_FALSE(fs::exists(dir / "g.exr"));
    const HdrImage exr = read_hdr(dir / "r.exr");
    ASSERT_EQ(exr.width, 16);
    ASSERT_EQ(exr.height, 12);
    ASSERT_EQ(exr.depth.size(), 16u * 12u);
    ASSERT_EQ(exr.albedo.size(), 3u * 16u * 12u);
    ASSERT_EQ(exr.normal.size(), 3u * 16u * 12u);
    ASSERT_EQ(exr.variance.size(), 3u * 16u * 12u);
    ASSERT_EQ(exr.samples.size(), 16u * 12u);
    // Pixel (8, 6) sees the ball's near side, 4 units away, facing the camera; (0, 0) misses.
    const size_t centre = 6 * 16 + 8;
    // The unit ball at the origin: its normal is the hit point, whose distance from the camera
    // at (0, 0, -5) is the depth (the pixel's mean over its samples, the normal its centre's).
    const Vec3 normal{exr.normal[3 * centre], exr.normal[3 * centre + 1], exr.normal[3 * centre + 2]};
    EXPECT_NEAR(length(normal), 1.0, 1e-6);
    EXPECT_LT(normal.z, -0.9);  // towards the camera
    EXPECT_NEAR(exr.depth[centre], length(normal - Vec3(0, 0, -5)), 0.01);
    EXPECT_FLOAT_EQ(exr.albedo[3 * centre], 0.8f);
    EXPECT_EQ(exr.depth[0], float(kMissDepth));
    EXPECT_EQ(exr.albedo[0], 0.0f);
    EXPECT_EQ(exr.normal[0], 0.0f);
    for (uint32_t n : exr.samples) EXPECT_EQ(n, 4u);
    for (float v : exr.variance) EXPECT_TRUE(std::isfinite(v) && v >= 0);
    EXPECT_GT(exr.variance[3 * centre], 0.0f);  // path tracing noise on the lit ball

    // The 8-bit image from the EXR is the PPM of the same render (ties at a step excepted).
    const Rgb8Image ppm = read_ppm(dir / "r.ppm"), from_exr = tonemap(exr.radiance(), ToneMap::sigmoid);
    ASSERT_EQ(ppm.bytes.size(), from_exr.bytes.size());
    for (size_t i = 0; i < ppm.bytes.size(); ++i)
        if (ppm.bytes[i] != from_exr.bytes[i]) {
            const double v = exr.rgb[i], frac = v / (1 + v) * 255 - std::floor(v / (1 + v) * 255);
            EXPECT_NEAR(frac, 0.5, 1e-4) << "byte " << i;
        }
    // The PFMs hold the same floats: radiance and depth.
    EXPECT_EQ(read_hdr(dir / "r.pfm").rgb, exr.rgb);
    EXPECT_EQ(read_hdr(dir / "r-depth.pfm").depth, exr.depth);
    for (const fs::directory_entry& p : fs::directory_iterator(dir))
        EXPECT_EQ(p.path().string().find(".tmp"), std::string::npos) << "temporary file left: " << p.path();
}

TEST_F(HdrCli, ExrOpensInOpenImageIO) {
    if (std::system("command -v oiiotool >/dev/null 2>&1") != 0)
        GTEST_SKIP() << "oiiotool (openimageio-tools) is not installed: the second reader is not checked";
    write_scene("s.json");
    ASSERT_EQ(run("render s.json -q -o r.exr").status, 0);
    const test::CommandResult info = test::run_command("oiiotool --info -v '" + (dir / "r.exr").string() + "'", dir);
    ASSERT_EQ(info.status, 0) << info.err;
    EXPECT_NE(info.out.find("16 x   12"), std::string::npos) << info.out;
    for (const char* channel : {"R (float)", "G (float)", "B (float)", "depth.Z (float)", "albedo.R (float)",
                                "normal.X (float)", "samples (uint)", "variance.B (float)"})
        EXPECT_NE(info.out.find(channel), std::string::npos) << channel << " missing in:\n" << info.out;
}

TEST_F(HdrCli, CompareExitStatusVerdictAndDiffImage) {
    write_scene("s.json");
    ASSERT_EQ(run("render s.json -q --spp 16 --seed 1 -o a.exr").status, 0);
    ASSERT_EQ(run("render s.json -q --spp 16 --seed 2 -o b.exr").status, 0);
    test::CommandResult r = run("compare a.exr b.exr --statistical --diff d.png");
    EXPECT_EQ(r.status, 0) << r.out << r.err;
    EXPECT_EQ(r.out.rfind("agree: a.exr vs b.exr: psnr ", 0), 0u) << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1);
    // The false-colour picture: the image, then the colour bar and its labels below.
    const Rgb8Image diff = read_image(dir / "d.png");
    EXPECT_EQ(diff.width, 160);
    EXPECT_EQ(diff.height, 12 + 34);
    r = run("compare a.exr b.exr --max-rmse 0");
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.out.rfind("DIFFER: ", 0), 0u) << r.out;
    EXPECT_EQ(run("compare a.exr a.exr --max-rmse 0 --max-relmse 0 --min-psnr 99").status, 0);
    r = run("psnr a.exr b.exr");
    EXPECT_EQ(r.status, 0);
    EXPECT_EQ(r.out.rfind("rmse ", 0), 0u) << r.out;
    EXPECT_EQ(run("compare a.exr b.exr").status, 2);  // no criterion
    EXPECT_EQ(run("compare a.exr --statistical").status, 2);
    EXPECT_EQ(run("compare a.exr b.exr --max-rmse 1 --diff ./b.exr").status, 2);  // never over an input
    EXPECT_EQ(run("compare a.exr b.exr --max-rmse 1 --diff d.exr").status, 2);    // 8-bit picture only
    // The statistical test's settings without the test mean nothing: bad usage, naming the flag.
    for (const char* flag : {"--alpha 0.01", "--block 4"}) {
        r = run(std::string("compare a.exr b.exr --max-rmse 1 ") + flag);
        EXPECT_EQ(r.status, 2) << flag;
        EXPECT_EQ(r.err.rfind("error: " + std::string(flag).substr(0, std::string(flag).find(' ')) + " sets the statistical test", 0), 0u)
            << r.err;
    }
    EXPECT_EQ(run("compare a.exr b.exr --statistical --alpha 0.01 --block 4").status, 0);
    EXPECT_GT(read_hdr(dir / "b.exr").rgb.size(), 0u);
}

// A NaN or infinite radiance never passes as data: psnr and compare refuse the file (exit 1,
// one line naming it and the first such pixel), whatever the thresholds; an image of NaNs
// never "agrees" with a black one.
TEST_F(HdrCli, NonFiniteRadianceIsRefusedNeverAgreement) {
    HdrImage black;
    black.width = 4;
    black.height = 3;
    black.rgb.assign(black.pixel_count() * 3, 0.0f);
    HdrImage nan = black, inf = black;
    std::fill(nan.rgb.begin(), nan.rgb.end(), std::numeric_limits<float>::quiet_NaN());
    inf.rgb[3 * 5 + 1] = std::numeric_limits<float>::infinity();  // pixel (1, 1), green
    write_bytes(dir / "black.pfm", encode_pfm_rgb(black));
    write_bytes(dir / "nan.pfm", encode_pfm_rgb(nan));
    write_bytes(dir / "inf.pfm", encode_pfm_rgb(inf));
    const std::pair<std::string, std::string> cases[] = {
        {"compare nan.pfm black.pfm --min-psnr 30", "nan.pfm"},
        {"compare black.pfm nan.pfm --max-rmse 1e30", "nan.pfm"},
        {"compare inf.pfm inf.pfm --max-relmse 1", "inf.pfm"},
        {"psnr nan.pfm black.pfm", "nan.pfm"},
    };
    for (const auto& [args, file] : cases) {
        const test::CommandResult r = run(args);
        EXPECT_EQ(r.status, 1) << args << "\n" << r.out << r.err;
        EXPECT_EQ(r.out.find("agree"), std::string::npos) << args << "\n" << r.out;
        expect_one_line_naming(r.err, file);
        EXPECT_NE(r.err.find("not finite"), std::string::npos) << r.err;
    }
    EXPECT_NE(run("psnr inf.pfm black.pfm").err.find("infinite at pixel (1, 1)"), std::string::npos);
    EXPECT_EQ(run("compare black.pfm black.pfm --min-psnr 30").status, 0);
}

// Means that are finite but beyond a float's range (a point light of 1e45) are written as
// float's largest value, variance included, never as infinity: the EXR and PFM hold finite
// numbers, and `compare --statistical` of the render against itself agrees.
TEST_F(HdrCli, HugeFiniteMeansStayFiniteInTheFiles) {
    std::string text = test::read_file(write_scene("huge.json"));
    const std::string power = "\"power\": [50, 50, 50]";
    text.replace(text.find(power), power.size(), "\"power\": [1e45, 1e45, 1e45]");
    std::ofstream(dir / "huge.json") << text;
    ASSERT_EQ(run("render huge.json -q -o huge.exr").status, 0);
    ASSERT_EQ(run("render huge.json -q -o huge.pfm").status, 0);
    const HdrImage exr = read_hdr(dir / "huge.exr"), pfm = read_hdr(dir / "huge.pfm");
    size_t saturated = 0;
    for (const std::vector<float>* layer : {&exr.rgb, &exr.variance, &exr.depth, &pfm.rgb})
        for (float v : *layer) {
            ASSERT_TRUE(std::isfinite(v));
            saturated += v == std::numeric_limits<float>::max();
        }
    EXPECT_GT(saturated, 0u);  // the test reaches beyond float's range
    const test::CommandResult self = run("compare huge.exr huge.exr --statistical");
    EXPECT_EQ(self.status, 0) << self.out << self.err;
    EXPECT_EQ(run("compare huge.pfm huge.pfm --max-rmse 0").status, 0);
}

// Radiance whose squares overflow a double (an area light of 1e200): the mean is stored as
// float's largest and so is its variance, never infinity, which marks fewer than two
// samples. Every layer of the EXR (raw and denoised included) and of the PFM and its depth
// file is finite, and `compare --statistical` of the render against itself agrees.
TEST_F(HdrCli, VarianceOfRadianceWhoseSquaresOverflowIsStoredAsFloatsLargest) {
    test::SceneBuilder b;
    b.sphere({0, 0, 0}, 1, b.material(MaterialType::diffuse, Color(0.5)));
    b.emitter({0, 3, -2}, 0.5, Color(1e200), b.material(MaterialType::diffuse, Color(0)));
    b.scene.cameras[0].fov = 8;
    b.scene.renderer.type = RendererType::pt;
    b.scene.renderer.samples = 4;
    b.scene.renderer.depth = 2;
    save_scene_json(b.scene, dir / "bright.json");
    ASSERT_EQ(run("render bright.json -q --threads 1 -o bright.exr").status, 0);
    ASSERT_EQ(run("render bright.json -q --threads 1 -o bright.pfm").status, 0);
    const test::CommandResult denoised = run("render bright.json -q --threads 1 --denoise -o denoised.exr");
    ASSERT_EQ(denoised.status, 0) << denoised.err;
    const HdrImage exr = read_hdr(dir / "bright.exr"), pfm = read_hdr(dir / "bright.pfm"),
                   depth = read_hdr(dir / "bright-depth.pfm"), den = read_hdr(dir / "denoised.exr");
    size_t saturated = 0;
    for (const HdrImage* image : {&exr, &den})
        for (uint32_t n : image->samples) ASSERT_GE(n, 2u);
    for (const std::vector<float>* layer :
         {&exr.rgb, &exr.variance, &exr.depth, &exr.albedo, &exr.normal, &den.rgb, &den.raw, &den.variance, &den.albedo,
          &den.normal, &pfm.rgb, &depth.rgb})
        for (float v : *layer) {
            ASSERT_TRUE(std::isfinite(v));
            saturated += v == std::numeric_limits<float>::max();
        }
    size_t saturated_variance = 0;
    for (float v : exr.variance) saturated_variance += v == std::numeric_limits<float>::max();
    EXPECT_GT(saturated_variance, 0u);  // the squares overflowed
    EXPECT_GT(saturated, saturated_variance);
    const test::CommandResult self = run("compare bright.exr bright.exr --statistical");
    EXPECT_EQ(self.status, 0) << self.out << self.err;
    const test::CommandResult raw = run("compare denoised.exr bright.exr --statistical");
    EXPECT_EQ(raw.status, 0) << raw.out << raw.err;
}

// `compare --statistical` of a denoised render tests its raw radiance and says so on the
// verdict line; the thresholds compare what the file shows (R, G, B).
TEST_F(HdrCli, StatisticalCompareOfADenoisedRenderTestsItsRawRadiance) {
    write_scene("s.json");
    ASSERT_EQ(run("render s.json -q --spp 8 --seed 1 --denoise -o d.exr").status, 0);
    ASSERT_EQ(run("render s.json -q --spp 8 --seed 2 -o r.exr").status, 0);
    const HdrImage d = read_hdr(dir / "d.exr");
    ASSERT_EQ(d.raw.size(), d.rgb.size());
    ASSERT_NE(d.raw, d.rgb);  // the filter changed the image
    for (const std::string args : {"compare d.exr r.exr --statistical", "compare r.exr d.exr --statistical"}) {
        const test::CommandResult r = run(args);
        EXPECT_EQ(r.status, 0) << args << "\n" << r.out << r.err;
        EXPECT_EQ(r.out.rfind("agree: ", 0), 0u) << r.out;
        EXPECT_NE(r.out.find("d.exr is denoised: its raw.R/G/B tested"), std::string::npos) << r.out;
        EXPECT_EQ(r.out.find("r.exr is denoised"), std::string::npos) << r.out;
        EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
    }
    const test::CommandResult plain = run("compare r.exr d.exr --max-rmse 1e9");
    EXPECT_EQ(plain.out.find("denoised"), std::string::npos) << plain.out;
}

// The depth layer: a hit farther than the miss value (1e6) keeps its distance; a miss is 1e6.
TEST_F(HdrCli, DepthOfAHitBeyondTheMissValueIsNotAMiss) {
    std::ofstream(dir / "far.json") << R"({
  "cameras": [{"id": "cam", "type": "pinhole", "fov": 30, "aspect": 1, "position": [0, 0, 0], "target": [0, 0, 1]}],
  "materials": [{"id": "white", "type": "diffuse", "rho": [0.8, 0.8, 0.8]}],
  "shapes": [{"id": "ball", "type": "sphere", "centre": [0, 0, 4e6], "radius": 1e6}],
  "lights": [{"id": "lamp", "type": "point", "position": [0, 0, 0], "power": [1, 1, 1]}],
  "scene": {"camera": "cam", "lights": ["lamp"],
    "primitives": [{"id": "ball", "type": "geometric", "shape": "ball", "material": "white"}],
    "renderer": {"type": "WRT", "dimensions": [9, 9], "samples": 1, "depth": 1, "output": "far.exr"}}
})";
    ASSERT_EQ(run("render far.json -q").status, 0);
    const HdrImage image = read_hdr(dir / "far.exr");
    EXPECT_NEAR(image.depth[4 * 9 + 4], 3e6, 1e5);  // the centre pixel hits the ball's near side
    EXPECT_EQ(image.depth[0], 1e6f);               // a corner misses it
}

TEST_F(HdrCli, BadInputsGiveOneLineNamingTheFileAndExitOne) {
    write_scene("s.json");
    write_scene("wide.json", 20);
    ASSERT_EQ(run("render s.json -q -o a.exr").status, 0);
    ASSERT_EQ(run("render wide.json -q -o wide.exr").status, 0);
    ASSERT_EQ(run("render s.json -q -o a.pfm").status, 0);
    ASSERT_EQ(run("render s.json -q --blur 1 -o blurred.exr").status, 0);
    const std::string exr = read_bytes(dir / "a.exr"), pfm = read_bytes(dir / "a.pfm");
    write_bytes(dir / "truncated.exr", exr.substr(0, exr.size() / 2));
    std::string corrupt = exr;
    std::fill(corrupt.begin() + long(corrupt.size() / 2), corrupt.end(), '\x5a');
    write_bytes(dir / "corrupt.exr", corrupt);
    write_bytes(dir / "truncated.pfm", pfm.substr(0, pfm.size() - 10));
    write_bytes(dir / "huge.ppm", "P6\n100000 100000\n255\nabc");
    const std::pair<std::string, std::string> cases[] = {
        {"compare truncated.exr a.exr --max-rmse 1", "truncated.exr"},
        {"compare a.exr corrupt.exr --max-rmse 1", "corrupt.exr"},
        {"compare truncated.pfm a.pfm --max-rmse 1", "truncated.pfm"},
        {"psnr truncated.pfm a.pfm", "truncated.pfm"},
        {"compare a.exr wide.exr --max-rmse 1", "wide.exr"},
        {"compare a.exr a.pfm --statistical", "a.pfm"},
        {"compare blurred.exr a.exr --statistical", "blurred.exr"},
        {"compare a.exr missing.exr --max-rmse 1", "missing.exr"},
        {"psnr huge.ppm a.exr", "huge.ppm"},  // a PPM header far larger than its file
    };
    for (const auto& [args, file] : cases) {
        const test::CommandResult r = run(args);
        EXPECT_EQ(r.status, 1) << args << "\n" << r.out << r.err;
        expect_one_line_naming(r.err, file);
    }
}

// A name of an image format keithray does not write (out.jpg, out.TIFF, out.hdr) is refused
// before the render, one line naming it; nothing is written. Any other name gets a PPM.
TEST_F(HdrCli, OutputNamedForAnotherImageFormatIsRefused) {
    write_scene("s.json");
    for (const std::string name : {"out.jpg", "out.JPEG", "out.TIFF", "out.hdr", "out.webp"}) {
        const test::CommandResult r = run("render s.json -q -o " + name);
        EXPECT_EQ(r.status, 1) << name << "\n" << r.out << r.err;
        expect_one_line_naming(r.err, name);
        EXPECT_NE(r.err.find("nothing rendered"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(dir / name)) << name;
    }
    ASSERT_EQ(run("render s.json -q -o out.image").status, 0);
    EXPECT_EQ(read_bytes(dir / "out.image").substr(0, 3), "P6\n");
}
