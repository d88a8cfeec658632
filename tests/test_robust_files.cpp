// The command line on hostile ground: non-finite samples reported, outputs written
// atomically, the scene file never overwritten, images too large for memory refused, and
// coincident spheres rendered as one.
// One test per row of the matrix in docs/robustness.md; everything is seeded; images are
// small and compared statistically or against analytic values.
#include "robustness_util.h"

namespace fs = std::filesystem;
using namespace kr;
using namespace kr::robust;

// =======================================================================================
// Output files

// The CLI reports dropped non-finite samples.
TEST_F(TempDir, CliReportsNonFiniteSamples) {
    const fs::path scene = write("hot.json", scene_json("hot.ppm", "[16, 12]",
                                                        R"({"id": "lamp", "type": "point", "position": [0, 0, -1.02], "power": [1.7e308, 1.7e308, 1.7e308]})"));
    const test::CommandResult r = cli("render '" + scene.string() + "' -q");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("non-finite samples were dropped"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::exists(dir / "hot.ppm"));
}

// write_ppm replaces the file by a rename: a reader holding the old file keeps reading the
// old bytes whole, and a failed write leaves the target and no temporary behind.
TEST_F(TempDir, OutputIsWrittenAtomically) {
    const fs::path out = dir / "img.ppm";
    Rgb8Image small{2, 1, {1, 2, 3, 4, 5, 6}};
    write_ppm(out, small);
    std::ifstream reader(out, std::ios::binary);
    ASSERT_TRUE(reader);
    Rgb8Image big{64, 64, std::vector<uint8_t>(64 * 64 * 3, 200)};
    write_ppm(out, big);
    std::string old((std::istreambuf_iterator<char>(reader)), std::istreambuf_iterator<char>());
    EXPECT_EQ(old, std::string("P6\n2 1\n255\n\x01\x02\x03\x04\x05\x06"));
    EXPECT_EQ(read_ppm(out).width, 64);
    // Writing onto a directory fails cleanly.
    fs::create_directories(dir / "taken");
    std::ofstream(dir / "taken" / "keep") << "x";
    EXPECT_THROW(write_ppm(dir / "taken", big), std::runtime_error);
    EXPECT_TRUE(fs::exists(dir / "taken" / "keep"));
    for (const auto& e : fs::directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

// No render ever writes over an input scene file: -o naming it, the file's own "output"
// naming it (or its depth map landing on it), or, with several scenes, one scene's output
// naming another input. Each is refused with a clear error before anything is written.
TEST_F(TempDir, SceneFileIsNeverOverwritten) {
    // "output" naming the scene file itself.
    const fs::path self = write("self.ppm", scene_json("self.ppm"));
    const std::string self_text = test::read_file(self);
    test::CommandResult r = cli("render '" + self.string() + "' -q");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("overwrite the scene file"), std::string::npos) << r.err;
    EXPECT_EQ(test::read_file(self), self_text);
    // Its depth map would land on the scene file: out-depth.json.
    const fs::path depth = write("out-depth.json", scene_json("out.json"));
    const std::string depth_text = test::read_file(depth);
    r = cli("render '" + depth.string() + "' -q");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("overwrite"), std::string::npos) << r.err;
    EXPECT_EQ(test::read_file(depth), depth_text);
    EXPECT_FALSE(fs::exists(dir / "out.json"));
    // -o through another path to the same file (a symbolic link).
    fs::create_symlink(self, dir / "link.ppm");
    const fs::path good = write("good.json", scene_json("good.ppm"));
    const std::string good_text = test::read_file(good);
    r = cli("render '" + good.string() + "' -q -o '" + (dir / "sub" / ".." / "good.json").string() + "'");
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(test::read_file(good), good_text);
    // Several scenes: the first one's output is the second scene file.
    const fs::path first = write("first.json", scene_json("second.json"));
    const fs::path second = write("second.json", scene_json("second.ppm"));
    const std::string second_text = test::read_file(second);
    r = cli("render '" + first.string() + "' '" + second.string() + "' -q");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("overwrite"), std::string::npos) << r.err;
    EXPECT_EQ(test::read_file(second), second_text);
    EXPECT_TRUE(fs::exists(dir / "second.ppm"));  // the second scene itself still renders
    for (const auto& e : fs::directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

// Dimensions the loader accepts but memory cannot hold: a clear error naming the size, exit
// status 1, nothing written (run under a 1 GiB address-space limit).
TEST_F(TempDir, DimensionsTooLargeForMemory) {
#ifdef KR_TEST_SANITIZED
    GTEST_SKIP() << "sanitizers reserve terabytes of address space: ulimit -v cannot be used";
#endif
    const fs::path scene = write("huge.json", scene_json("huge.ppm", "[32768, 32768]"));
    const test::CommandResult r = test::run_command(
        "ulimit -v 1048576; '" + std::string(KEITHRAY_EXE) + "' render '" + scene.string() + "' -q --threads 1", dir);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("32768x32768"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("memory"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "huge.ppm"));
}
// =======================================================================================
// Coincident spheres

namespace {

// A ball on a floor under a point light, the ball's primitive repeated `copies` times under
// further shape ids at exactly the same centre and radius (a copy-paste), the last copy with
// material `copy_material`.
std::string copied_ball_json(int copies, const std::string& copy_material = "white") {
    std::string shapes = R"({"id": "floor", "type": "sphere", "centre": [0, -1001, 0], "radius": 1000},
        {"id": "ball", "type": "sphere", "centre": [0, 0, 0], "radius": 1})";
    std::string prims = R"({"id": "floor", "type": "geometric", "shape": "floor", "material": "white"},
        {"id": "ball", "type": "geometric", "shape": "ball", "material": "white"})";
    for (int k = 1; k <= copies; ++k) {
        const std::string id = "ball copy " + std::to_string(k);
        shapes += R"(, {"id": ")" + id + R"(", "type": "sphere", "centre": [0, 0, 0], "radius": 1})";
        prims += R"(, {"id": ")" + id + R"(", "type": "geometric", "shape": ")" + id + R"(", "material": ")" +
                 (k == copies ? copy_material : "white") + R"("})";
    }
    return R"({"cameras": [{"id": "cam", "type": "pinhole", "fov": 40, "aspect": 1, "position": [0, 1, -6], "target": [0, 0, 0]}],
      "materials": [{"id": "white", "type": "diffuse", "rho": [0.8, 0.8, 0.8]},
                    {"id": "red", "type": "diffuse", "rho": [0.8, 0.1, 0.1]}],
      "shapes": [)" + shapes + R"(],
      "lights": [{"id": "lamp", "type": "point", "position": [2, 4, -3], "power": [40, 40, 40]}],
      "scene": {"camera": "cam", "lights": ["lamp"], "primitives": [)" + prims + R"(],
                "renderer": {"type": "PT", "dimensions": [32, 32], "samples": 4, "depth": 3, "output": "out.ppm"}}})";
}

size_t occurrences(const std::string& text, const std::string& what) {
    size_t count = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++count;
    return count;
}

}  // namespace

// The same sphere under two shape ids rendered both surfaces, which shadowed each other at
// random (speckle, 26 to 32 dB against the one-sphere image). The second is left out with one
// warning naming both primitives: the image is the one-sphere image byte for byte.
TEST_F(TempDir, CoincidentSpheresRenderAsOne) {
    const fs::path one = write("one.json", copied_ball_json(0)), two = write("two.json", copied_ball_json(1));
    test::CommandResult r = cli("render '" + one.string() + "' --seed 3 -o '" + (dir / "one.ppm").string() + "' -q");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err, "");
    r = cli("render '" + two.string() + "' --seed 3 -o '" + (dir / "two.ppm").string() + "' -q");
    ASSERT_EQ(r.status, 0) << r.err;
    ASSERT_TRUE(fs::exists(dir / "one.ppm"));
    EXPECT_EQ(test::read_file(dir / "one.ppm"), test::read_file(dir / "two.ppm"));
    EXPECT_EQ(occurrences(r.err, "\n"), 1u) << r.err;  // one line
    EXPECT_EQ(occurrences(r.err, "warning: "), 1u) << r.err;
    EXPECT_NE(r.err.find("/scene/primitives/2: primitive \"ball copy 1\" (shape \"ball copy 1\") is the same sphere as "
                         "primitive \"ball\" (shape \"ball\"); rendered once, as the first"),
              std::string::npos)
        << r.err;

    // Three copies, the last of another material: one warning each, the last saying its
    // material is left out; the image is still the first ball's.
    const Scene three = load_scene_file(write("three.json", copied_ball_json(3, "red"))).scene;
    std::vector<std::string> warnings;
    const RenderScene prepared = prepare_scene(three, &warnings);
    EXPECT_EQ(prepared.spheres.size(), 2u);
    EXPECT_EQ(prepared.materials.size(), 1u);
    ASSERT_EQ(warnings.size(), 3u);
    EXPECT_NE(warnings[2].find("; its material \"red\" is left out"), std::string::npos) << warnings[2];
    EXPECT_EQ(warnings[0].find("left out"), std::string::npos) << warnings[0];
    // Spheres that only nearly coincide (a radius one ulp larger) stay two spheres.
    test::SceneBuilder b;
    const int m = b.material(MaterialType::diffuse);
    b.sphere({0, 0, 0}, 1, m);
    b.sphere({0, 0, 0}, std::nextafter(1.0, 2.0), m);
    warnings.clear();
    EXPECT_EQ(prepare_scene(b.scene, &warnings).spheres.size(), 2u);
    EXPECT_TRUE(warnings.empty());
}
