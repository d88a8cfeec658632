// `keithray render --gl`: the viewer's display shaders in an OSMesa framebuffer give the
// CPU tone map's PPM (same seed and spp) within 1/255 per channel, on several scenes and
// every tone map; the depth PPM is untouched.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/image.h"
#include "core/image_io.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace {

int run(const std::string& args) {
    const std::string cmd = std::string("'") + KEITHRAY_EXE + "' " + args + " >/dev/null 2>&1";
    const int raw = std::system(cmd.c_str());
    return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

int max_channel_difference(const kr::Rgb8Image& a, const kr::Rgb8Image& b) {
    int worst = 0;
    for (size_t i = 0; i < a.bytes.size(); ++i) worst = std::max(worst, std::abs(int(a.bytes[i]) - int(b.bytes[i])));
    return worst;
}

class GlDisplay : public testing::TestWithParam<std::tuple<int, std::string>> {
protected:
    fs::path dir;
    void SetUp() override {
        dir = fs::temp_directory_path() / ("keithray_gl_" + std::to_string(std::get<0>(GetParam())) + "_" +
                                           std::get<1>(GetParam()) + "_" + std::to_string(::getpid()));
        fs::remove_all(dir);
        fs::create_directories(dir);
    }
    void TearDown() override { fs::remove_all(dir); }
};

}  // namespace

TEST_P(GlDisplay, MatchesCpuToneMap) {
    const auto [n, tonemap] = GetParam();
    const std::string scene =
        kr::test::brief_scene_file(n).string();
    // The brief's sigmoid at EV 0; the others with an exposure, which the linear map's scale
    // and the sRGB curve take on the CPU and in the shader alike.
    const std::string exposure = tonemap == "sigmoid" ? "" : " --exposure 0.5";
    const std::string common = "render '" + scene + "' --spp 4 --seed 7 -q --tonemap " + tonemap + exposure;
    ASSERT_EQ(run(common + " -o '" + (dir / "cpu.ppm").string() + "'"), 0);
    ASSERT_EQ(run(common + " --gl -o '" + (dir / "gl.ppm").string() + "'"), 0);
    const kr::Rgb8Image cpu = kr::read_ppm(dir / "cpu.ppm"), gl = kr::read_ppm(dir / "gl.ppm");
    ASSERT_EQ(gl.width, cpu.width);
    ASSERT_EQ(gl.height, cpu.height);
    EXPECT_LE(max_channel_difference(cpu, gl), 1);
    // Not a black or constant image that would match trivially.
    int lo = 255, hi = 0;
    for (uint8_t v : gl.bytes) lo = std::min(lo, int(v)), hi = std::max(hi, int(v));
    EXPECT_GT(hi - lo, 100);
    EXPECT_EQ(kr::read_ppm(dir / "cpu-depth.ppm").bytes, kr::read_ppm(dir / "gl-depth.ppm").bytes);
}

// WRT and PT scenes, glass, glossy and a lens-free camera; every tone map.
INSTANTIATE_TEST_SUITE_P(Scenes, GlDisplay,
                         testing::Combine(testing::Values(2, 4, 5, 7, 8), testing::Values(std::string("sigmoid"), std::string("linear"), std::string("srgb"))),
                         [](const auto& info) {
                             return "assignment_0" + std::to_string(std::get<0>(info.param)) + "_" +
                                    std::get<1>(info.param);
                         });
