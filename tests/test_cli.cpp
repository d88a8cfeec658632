// The keithray command line: flags, exit codes, outputs, and error messages.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/image_hdr.h"
#include "core/image_io.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace {

using CliRun = kr::test::CommandResult;
using kr::test::read_file;

class Cli : public kr::test::ScratchDirTest {
protected:

    // A small valid scene: a diffuse ball under a point light, 16x12 pixels.
    fs::path write_scene(const std::string& name, const std::string& material_type = "diffuse",
                         int depth = 4, const std::string& output = "out/render.ppm") {
        const fs::path file = dir / name;
        std::ofstream(file) << R"({
  "cameras": [{"id": "cam", "type": "pinhole", "fov": 45, "aspect": 1.333, "position": [0, 0, -5], "target": [0, 0, 0]}],
  "materials": [{"id": "white", "type": ")" << material_type << R"(", "rho": [0.8, 0.8, 0.8]}],
  "shapes": [{"id": "ball", "type": "sphere", "centre": [0, 0, 0], "radius": 1}],
  "lights": [{"id": "lamp", "type": "point", "position": [0, 3, -3], "power": [50, 50, 50]}],
  "scene": {
    "camera": "cam", "lights": ["lamp"],
    "primitives": [{"id": "ball", "type": "geometric", "shape": "ball", "material": "white"}],
    "renderer": {"type": "WRT", "dimensions": [16, 12], "samples": 2, "depth": )"
                          << depth << R"(, "output": ")" << output << R"("}
  }
})";
        return file;
    }
    // write_scene's scene with a display block `block` (a JSON object's text).
    fs::path write_scene_with_display(const std::string& name, const std::string& block) {
        std::string text = read_file(write_scene(name));
        text.insert(text.find("\"renderer\""), "\"display\": " + block + ", ");
        return write(name, text);
    }
    // The bytes `render SCENE --spp 2 FLAGS -o dir/OUT` writes (a failure is reported here).
    std::string render_bytes(const fs::path& scene, const std::string& flags, const std::string& out) {
        const CliRun r = cli("render '" + scene.string() + "' --spp 2 " + flags + " -q -o '" + (dir / out).string() + "'");
        EXPECT_EQ(r.status, 0) << r.err;
        return read_file(dir / out);
    }
};

}  // namespace

TEST_F(Cli, HelpDocumentsEveryFlag) {
    const CliRun r = cli("--help");
    EXPECT_EQ(r.status, 0);
    for (const char* flag : {"render", "--spp", "--integrator", "wrt", "pt-naive", "--estimator", "uniform",
                             "stratified", "--tonemap", "sigmoid", "linear", "--blur", "--seed", "--threads", "-o",
                             "--light-sampling", "--depth", "psnr", "--checkpoint", "--every", "--resume", "mpirun"})
        EXPECT_NE(r.out.find(flag), std::string::npos) << flag;
}

// `view` runs itself again with a short OpenMP spin (GOMP_SPINCOUNT=10000) unless the
// environment sets the waiting; `render` keeps libgomp's default. libgomp prints what it read
// at each start (OMP_DISPLAY_ENV), so the last count printed is the one the viewer runs with.
TEST_F(Cli, ViewerRunsWithAShortOpenMpSpinUnlessTheEnvironmentSetsOne) {
    const auto spin_counts = [&](const std::string& env, const std::string& args) {
        const CliRun r = kr::test::run_command("env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT OMP_DISPLAY_ENV=verbose " + env +
                                               " '" + KEITHRAY_EXE + "' " + args,
                                           dir);
        EXPECT_EQ(r.status, 0) << r.err;
        std::vector<std::string> counts;
        std::istringstream lines(r.err);
        for (std::string line; std::getline(lines, line);)
            if (const size_t at = line.find("GOMP_SPINCOUNT = '"); at != std::string::npos)
                counts.push_back(line.substr(at + 18, line.find('\'', at + 18) - at - 18));
        return counts;
    };
    const std::vector<std::string> view = spin_counts("", "view --help");
    // LLVM's libomp (the ThreadSanitizer build's) prints no GOMP_SPINCOUNT and ignores it.
    if (view.empty()) GTEST_SKIP() << "the OpenMP runtime is not libgomp";
    ASSERT_EQ(view.size(), 2u);  // read before main, then again after the exec
    EXPECT_NE(view[0], "10000");
    EXPECT_EQ(view[1], "10000");
    const std::vector<std::string> render = spin_counts("", "render --help");
    ASSERT_EQ(render.size(), 1u);
    EXPECT_NE(render[0], "10000");
    EXPECT_EQ(spin_counts("GOMP_SPINCOUNT=5", "view --help"), std::vector<std::string>{"5"});
    EXPECT_EQ(spin_counts("OMP_WAIT_POLICY=passive", "view --help"), std::vector<std::string>{"0"});
}

TEST_F(Cli, RendersImageAndDepthBesideIt) {
    const fs::path scene = write_scene("ok.json");
    const CliRun r = cli("render '" + scene.string() + "' --spp 3 -o '" + (dir / "x.ppm").string() + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    const kr::Rgb8Image img = kr::read_ppm(dir / "x.ppm");
    EXPECT_EQ(img.width, 16);
    EXPECT_EQ(img.height, 12);
    const kr::Rgb8Image depth = kr::read_ppm(dir / "x-depth.ppm");
    EXPECT_EQ(depth.width, 16);
    // The summary line: spp, seconds and Mrays/s.
    EXPECT_NE(r.out.find("3 spp"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("Mrays/s"), std::string::npos) << r.out;
    // The ball is lit: the centre pixel is not black; the corner (a miss) is.
    EXPECT_GT(img.bytes[(6 * 16 + 8) * 3], 0);
    EXPECT_EQ(img.bytes[0], 0);
    // No temporary files are left behind.
    for (const auto& e : fs::directory_iterator(dir)) EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos);
}

TEST_F(Cli, PngOutputByNameAndPsnrReadsBothFormats) {
    const fs::path scene = write_scene("png.json");
    const std::string base = "render '" + scene.string() + "' --spp 2 -q -o '";
    ASSERT_EQ(cli(base + (dir / "x.ppm").string() + "'").status, 0);
    const CliRun r = cli(base + (dir / "x.PNG").string() + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    // A PNG by its signature, the depth map beside it too, and the same pixels as the PPM.
    EXPECT_EQ(read_file(dir / "x.PNG").substr(0, 8), std::string("\x89PNG\r\n\x1a\n"));
    EXPECT_EQ(read_file(dir / "x-depth.PNG").substr(0, 4), std::string("\x89PNG"));
    const CliRun same = cli("psnr '" + (dir / "x.ppm").string() + "' '" + (dir / "x.PNG").string() + "'");
    EXPECT_EQ(same.status, 0) << same.err;
    EXPECT_EQ(same.out, "99.00\n");  // identical images
    const CliRun depth = cli("psnr '" + (dir / "x-depth.PNG").string() + "' '" + (dir / "x.ppm").string() + "'");
    EXPECT_EQ(depth.status, 0) << depth.err;
    EXPECT_LT(std::stod(depth.out), 40.0);  // a different image
    // Images are told apart by content, not name: a PPM called .png still reads.
    fs::copy_file(dir / "x.ppm", dir / "ppm-inside.png");
    const CliRun renamed = cli("psnr '" + (dir / "ppm-inside.png").string() + "' '" + (dir / "x.PNG").string() + "'");
    EXPECT_EQ(renamed.status, 0) << renamed.err;
    EXPECT_EQ(renamed.out, "99.00\n");
    // A file that is neither: one message naming it, exit status 1.
    std::ofstream(dir / "bad.png") << "not an image";
    const CliRun bad = cli("psnr '" + (dir / "bad.png").string() + "' '" + (dir / "x.ppm").string() + "'");
    EXPECT_EQ(bad.status, 1);
    EXPECT_NE(bad.err.find("bad.png"), std::string::npos) << bad.err;
    EXPECT_NE(bad.err.find("not a binary PPM (P6) or PNG"), std::string::npos) << bad.err;
}

TEST_F(Cli, OutputIsRelativeToTheSceneFolder) {
    const fs::path scene = write_scene("rel.json");
    const CliRun r = cli("render '" + scene.string() + "' -q");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(fs::exists(dir / "out" / "render.ppm"));
    EXPECT_TRUE(fs::exists(dir / "out" / "render-depth.ppm"));
}

TEST_F(Cli, SameSeedSameImageAndFlagsOverride) {
    const fs::path scene = write_scene("seed.json");
    const std::string base = "render '" + scene.string() + "' --integrator pt --spp 4 --threads ";
    ASSERT_EQ(cli(base + "1 -o '" + (dir / "a.ppm").string() + "'").status, 0);
    ASSERT_EQ(cli(base + "2 -o '" + (dir / "b.ppm").string() + "'").status, 0);
    ASSERT_EQ(cli(base + "2 --seed 7 -o '" + (dir / "c.ppm").string() + "'").status, 0);
    EXPECT_EQ(read_file(dir / "a.ppm"), read_file(dir / "b.ppm"));
    EXPECT_NE(read_file(dir / "a.ppm"), read_file(dir / "c.ppm"));
    const CliRun linear = cli(base + "2 --tonemap linear --blur 1 --estimator uniform -o '" + (dir / "d.ppm").string() + "'");
    EXPECT_EQ(linear.status, 0) << linear.err;
    // Linear tone mapping scales the brightest channel to 255.
    const kr::Rgb8Image d = kr::read_ppm(dir / "d.ppm");
    EXPECT_EQ(*std::max_element(d.bytes.begin(), d.bytes.end()), 255);
}

// The scene's display block is what `render` writes, and --exposure / --tonemap override it:
// a scene saved from the viewer renders headless to the image the window showed.
TEST_F(Cli, DisplayBlockAppliesAndFlagsOverrideIt) {
    const fs::path plain = write_scene("plain.json");
    const fs::path brighter = write_scene_with_display("brighter.json", R"({"exposure": 1.5})");
    const auto render = [&](const fs::path& scene, const std::string& flags, const std::string& out) {
        return render_bytes(scene, flags, out);
    };
    const std::string base = render(plain, "", "base.ppm");
    const std::string from_file = render(brighter, "", "file.ppm");
    EXPECT_NE(from_file, base);
    EXPECT_EQ(render(plain, "--exposure 1.5", "flag.ppm"), from_file);
    EXPECT_EQ(render(brighter, "--exposure 0", "back.ppm"), base);
    // Exposure EV scales radiance by 2^EV before the sigmoid: the same as the EXR's radiance
    // tone mapped at that scale.
    ASSERT_EQ(cli("render '" + plain.string() + "' --spp 2 -q -o '" + (dir / "r.exr").string() + "'").status, 0);
    const kr::Rgb8Image expected =
        kr::tonemap(kr::read_hdr(dir / "r.exr").radiance(), kr::ToneMap::sigmoid, std::exp2(1.5));
    const kr::Rgb8Image got = kr::read_ppm(dir / "file.ppm");
    ASSERT_EQ(got.bytes.size(), expected.bytes.size());
    int worst = 0;
    for (size_t i = 0; i < got.bytes.size(); ++i) worst = std::max(worst, std::abs(int(got.bytes[i]) - int(expected.bytes[i])));
    EXPECT_LE(worst, 1);  // float radiance in the EXR: at most one step where rounding lands on a boundary
}

// The display block's denoise mode is read by `render` as its tone map is, and --denoise
// overrides it; a file without it renders raw, as before the field existed.
TEST_F(Cli, DisplayBlockDenoiseModeAppliesAndTheFlagOverridesIt) {
    const fs::path plain = write_scene("plain.json");
    const fs::path on = write_scene_with_display("on.json", R"({"denoise": "on"})");
    const fs::path off = write_scene_with_display("off.json", R"({"denoise": "off"})");
    // Path tracing: a noisy estimate, which the denoiser changes.
    const auto render = [&](const fs::path& scene, const std::string& flags, const std::string& out) {
        return render_bytes(scene, "--integrator pt " + flags, out);
    };
    const std::string raw = render(plain, "", "raw.ppm");
    const std::string denoised = render(plain, "--denoise on", "denoised.ppm");
    EXPECT_NE(raw, denoised);
    EXPECT_EQ(render(plain, "--denoise off", "raw2.ppm"), raw);
    EXPECT_EQ(render(on, "", "on.ppm"), denoised);
    EXPECT_EQ(render(off, "", "off.ppm"), raw);
    EXPECT_EQ(render(on, "--denoise off", "on_flag_off.ppm"), raw);
    EXPECT_EQ(render(off, "--denoise on", "off_flag_on.ppm"), denoised);
    // A bad mode is one line naming the file and the JSON path.
    const fs::path bad_scene = write_scene_with_display("bad.json", R"({"denoise": "yes"})");
    const CliRun bad = cli("render '" + bad_scene.string() + "' --spp 1 -q -o '" + (dir / "bad.ppm").string() + "'");
    EXPECT_EQ(bad.status, 1);
    EXPECT_NE(bad.err.find("bad.json"), std::string::npos) << bad.err;
    EXPECT_NE(bad.err.find("/scene/display/denoise"), std::string::npos) << bad.err;
    EXPECT_FALSE(fs::exists(dir / "bad.ppm"));
}

TEST_F(Cli, BadSceneGivesOneMessageAndNoOutput) {
    const fs::path scene = write_scene("bad.json", "plastic");
    const CliRun r = cli("render '" + scene.string() + "' -o '" + (dir / "x.ppm").string() + "'");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("bad.json"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("/materials/0/type"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("\"specular reflection\""), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "x.ppm"));
    EXPECT_FALSE(fs::exists(dir / "x-depth.ppm"));
    EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST_F(Cli, MissingFileAndBadFlags) {
    CliRun r = cli("render '" + (dir / "nope.json").string() + "'");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("nope.json"), std::string::npos);
    EXPECT_NE(r.err.find("cannot open"), std::string::npos);
    r = cli("render --spp 0");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--spp"), std::string::npos);
    r = cli("render --integrator magic");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("\"pt-naive\""), std::string::npos);
    r = cli("render --frobnicate");
    EXPECT_EQ(r.status, 2);
    r = cli("paint");
    EXPECT_EQ(r.status, 2);
}

TEST_F(Cli, DepthAbove20IsClampedWithAWarning) {
    const fs::path scene = write_scene("deep.json", "diffuse", 25);
    const CliRun r = cli("render '" + scene.string() + "' -q");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("clamped to 20"), std::string::npos) << r.err;
}

TEST_F(Cli, NeverOverwritesTheSceneFile) {
    const fs::path scene = write_scene("self.json");
    const std::string before = read_file(scene);
    const CliRun r = cli("render '" + scene.string() + "' -o '" + scene.string() + "'");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("overwrite"), std::string::npos) << r.err;
    EXPECT_EQ(read_file(scene), before);
}

TEST_F(Cli, StopRulesAndTheirErrors) {
    const fs::path scene = write_scene("scene.json");
    CliRun r = cli("render '" + scene.string() + "' --integrator pt --time 0.2 -o '" + (dir / "t.ppm").string() + "'");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("stopped by --time"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::exists(dir / "t.ppm"));
    r = cli("render '" + scene.string() + "' --integrator pt --noise 0.05 --spp 4096 -o '" + (dir / "n.ppm").string() + "'");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("stopped by --noise"), std::string::npos) << r.err;
    for (const char* bad : {"--noise 0", "--noise -1", "--time abc", "--time"}) {
        r = cli("render '" + scene.string() + "' " + bad + " -o '" + (dir / "bad.ppm").string() + "'");
        EXPECT_EQ(r.status, 2) << bad;
        EXPECT_FALSE(fs::exists(dir / "bad.ppm")) << bad;
    }
}

TEST_F(Cli, BenchPrintsFiguresAndRejectsBadUsage) {
    const fs::path scene = write_scene("scene.json");
    CliRun r = cli("bench --throughput '" + scene.string() + "' --runs 1 --fraction 1");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("| scene |"), std::string::npos);
    EXPECT_NE(r.out.find("Mrays/s"), std::string::npos);
    EXPECT_NE(r.out.find("| one path |"), std::string::npos) << r.out;  // Whitted: never in lanes
    // The same scene path traced: the kernels each --kernels names, in the table's last column.
    std::string text = read_file(scene);
    text.replace(text.find("\"WRT\""), 5, "\"PT\"");
    std::ofstream(dir / "pt.json") << text;
    const std::string pt = (dir / "pt.json").string();
    r = cli("bench --throughput '" + pt + "' --runs 1 --fraction 1 --kernels any");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("| x86-64 lanes |"), std::string::npos) << r.out;  // never the v3 ones
    EXPECT_NE(r.out.find("--kernels any)"), std::string::npos) << r.out;
    r = cli("bench --throughput '" + pt + "' --runs 1 --fraction 1 --kernels off");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("| one path |"), std::string::npos) << r.out;
    r = cli("bench --throughput '" + pt + "' --runs 1 --fraction 1 --kernels double");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out.find("float lanes"), std::string::npos) << r.out;
    r = cli("bench --throughput '" + pt + "' --runs 1 --fraction 1");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out.find("| x86-64 lanes |"), std::string::npos) << r.out;
    r = cli("bench --throughput --kernels avx9");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("\"best\", \"double\", \"float8\", \"any\" or \"off\""), std::string::npos) << r.err;
    r = cli("bench --stress 20 --runs 1 --size 16");
    EXPECT_EQ(r.status, 0) << r.err;
    // One row per BVH: ours, and Embree's where the build has it.
    EXPECT_NE(r.out.find("| 20 | own |"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("| 20 | embree |") != std::string::npos, kr::embree_available()) << r.out;
    // --sweep: every count about 10 % above the last (8, 9, 10 here), then each BVH's steps and band.
    r = cli("bench --sweep 8:10 --runs 1 --size 8 --accel own");
    EXPECT_EQ(r.status, 0) << r.err;
    for (const char* row : {"| 8 | own |", "| 9 | own |", "| 10 | own |", "Sweep of 3 counts, 8 to 10", "| own | "})
        EXPECT_NE(r.out.find(row), std::string::npos) << row << "\n" << r.out;
    EXPECT_NE(r.out.find("at 4 spp, wall time)"), std::string::npos) << r.out;
    // --cpu-time: the same, timed by the process's CPU time; two rounds over the counts, one row
    // per count and BVH all the same.
    r = cli("bench --sweep 8:9 --runs 2 --size 8 --accel own --threads 1 --cpu-time");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("| 9 | own |"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("| 9 | own |"), r.out.rfind("| 9 | own |")) << r.out;
    EXPECT_NE(r.out.find("(1 threads, 2 runs, 8 x 8 at 4 spp, CPU time)"), std::string::npos) << r.out;
    r = cli("bench --sweep 10:8");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--sweep: TO is below FROM in \"10:8\""), std::string::npos) << r.err;
    r = cli("bench --stress 20 --runs 1 --size 16 --accel bogus");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--accel expects \"auto\", \"own\" or \"embree\""), std::string::npos) << r.err;
    EXPECT_EQ(cli("bench --throughput --accel own,embree").status, 2);  // one BVH at a time
    EXPECT_EQ(cli("bench --bogus").status, 2);
    EXPECT_EQ(cli("bench").status, 2);
    // --write-stress never overwrites.
    EXPECT_EQ(cli("bench --write-stress 5 '" + scene.string() + "'").status, 1);
    EXPECT_EQ(cli("bench --write-stress 5 '" + (dir / "s.json").string() + "'").status, 0);
    r = cli("render '" + (dir / "s.json").string() + "' --spp 1 -o '" + (dir / "s.ppm").string() + "'");
    EXPECT_EQ(r.status, 0) << r.err;
}

// bench --convergence: CSV rows per configuration and checkpoint, a PNG plot per scene, a
// markdown table with the speed-up column; and its usage errors.
TEST_F(Cli, BenchConvergenceWritesCsvPlotAndTable) {
    const fs::path scene = write_scene("conv.json");
    const fs::path out = dir / "bench";
    CliRun r = cli("bench --convergence '" + scene.string() + "' --scale 1 --spp 4 --reference-factor 2 --configs " +
                   "wrt/area/uniform,wrt/area/sobol --out '" + out.string() + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string csv = read_file(out / "convergence.csv");
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 2 * 3) << csv;  // header, 2 configs x spp 1, 2, 4
    EXPECT_NE(csv.find("conv,wrt/area/sobol,4,"), std::string::npos) << csv;
    const std::string md = read_file(out / "convergence.md");
    EXPECT_NE(md.find("| wrt/area/sobol |"), std::string::npos) << md;
    EXPECT_NE(md.find("speed-up"), std::string::npos);
    const std::string png = read_file(out / "conv.png");
    ASSERT_GT(png.size(), 8u);
    EXPECT_EQ(png.substr(1, 3), "PNG");
    // The reference is cached: a second run renders none and gives the same errors at 4 spp.
    EXPECT_FALSE(fs::is_empty(out / "cache"));
    r = cli("bench --convergence '" + scene.string() + "' --scale 1 --spp 4 --reference-factor 2 --configs " +
            "wrt/area/uniform,wrt/area/sobol --out '" + out.string() + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    auto rows_at_4 = [](const std::string& text) {
        std::string rows;
        std::istringstream in(text);
        for (std::string line; std::getline(in, line);)
            if (line.find(",4,") != std::string::npos) rows += line.substr(line.find(",4,") + 3) + "\n";
        // Drop the seconds column, which differs run to run.
        std::string kept;
        std::istringstream rows_in(rows);
        for (std::string line; std::getline(rows_in, line);) kept += line.substr(line.find(',')) + "\n";
        return kept;
    };
    EXPECT_EQ(rows_at_4(read_file(out / "convergence.csv")), rows_at_4(csv));

    EXPECT_EQ(cli("bench --convergence '" + scene.string() + "' --configs pt/cone").status, 2);
    EXPECT_EQ(cli("bench --convergence '" + scene.string() + "' --configs pt/lamp/sobol").status, 2);
    EXPECT_EQ(cli("bench --convergence '" + scene.string() + "' --scale 0").status, 2);
    EXPECT_EQ(cli("bench --convergence --help").status, 0);
}
