// Scene loading: the eight reference scenes load with their content, and every kind of
// bad input gives one SceneError naming the file, the JSON pointer and what was expected.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "scene/display_fields.h"
#include "scene/load.h"
#include "scene/save.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace kr {
namespace {

int find_id(const auto& items, const std::string& id) {
    for (size_t i = 0; i < items.size(); ++i)
        if (items[i].id == id) return static_cast<int>(i);
    return -1;
}

TEST(LoadReferenceScenes, AllEightLoadWithoutWarnings) {
    for (int n = 1; n <= 8; ++n) {
        SCOPED_TRACE(n);
        const LoadedScene loaded = load_scene_file(test::brief_scene_file(n));
        const Scene& s = loaded.scene;
        EXPECT_TRUE(loaded.warnings.empty()) << loaded.warnings.front();
        EXPECT_EQ(s.source_file, test::brief_scene_file(n));
        EXPECT_EQ(s.cameras[size_t(s.camera)].id, "pinhole");
        EXPECT_EQ(s.renderer.width, 512);
        EXPECT_EQ(s.renderer.height, 512);
        EXPECT_FALSE(s.primitives.empty());
        const fs::path expected =
            (fs::path(KEITHRAY_RES_DIR) / "output" / ("assignment_0" + std::to_string(n) + ".ppm"))
                .lexically_normal();
        EXPECT_EQ(s.output_path(), expected);
    }
}

TEST(LoadReferenceScenes, Assignment01Content) {
    const Scene s = load_scene_file(test::brief_scene_file(1)).scene;
    EXPECT_EQ(s.cameras.size(), 1u);
    EXPECT_EQ(s.materials.size(), 7u);
    EXPECT_EQ(s.shapes.size(), 7u);
    EXPECT_EQ(s.lights.size(), 1u);
    ASSERT_EQ(s.primitives.size(), 7u);
    EXPECT_EQ(s.renderer.type, RendererType::wrt);
    EXPECT_EQ(s.renderer.samples, 8);
    EXPECT_EQ(s.renderer.depth, 12);
    EXPECT_EQ(s.renderer.output, "../output/assignment_01.ppm");

    const Camera& cam = s.cameras[0];
    EXPECT_EQ(cam.type, CameraType::pinhole);
    EXPECT_DOUBLE_EQ(cam.fov, 45);
    EXPECT_DOUBLE_EQ(cam.distance, 5);
    EXPECT_EQ(cam.position, Vec3(0, 0, -15));

    // sphere 01 is the Fresnel dielectric, rhoR/rhoT mapped to rho_r/rho_t.
    const Primitive& sphere = s.primitives[5];
    EXPECT_EQ(sphere.id, "sphere 01");
    EXPECT_EQ(s.shapes[size_t(sphere.shape)].id, "sphere 01");
    EXPECT_DOUBLE_EQ(s.shapes[size_t(sphere.shape)].radius, 1.5);
    const Material& glass = s.materials[size_t(sphere.material)];
    EXPECT_EQ(glass.type, MaterialType::dielectric);
    EXPECT_DOUBLE_EQ(glass.eta, 1.5);
    EXPECT_EQ(glass.rho_r, Color(0.9));
    EXPECT_EQ(glass.rho_t, Color(0.9));

    ASSERT_EQ(s.active_lights.size(), 1u);
    const Light& light = s.lights[size_t(s.active_lights[0])];
    EXPECT_EQ(light.type, LightType::point);
    EXPECT_EQ(light.position, Vec3(0, 4, -1));
    EXPECT_EQ(light.power, Color(300));
}

TEST(LoadReferenceScenes, Assignment03LensCameraAndAreaLight) {
    const Scene s = load_scene_file(test::brief_scene_file(3)).scene;
    ASSERT_EQ(s.cameras.size(), 2u);
    const int lens = find_id(s.cameras, "lens-based");
    ASSERT_GE(lens, 0);
    EXPECT_EQ(s.cameras[size_t(lens)].type, CameraType::lens);
    EXPECT_DOUBLE_EQ(s.cameras[size_t(lens)].focal_distance, 14.0);
    EXPECT_DOUBLE_EQ(s.cameras[size_t(lens)].alpha, 1.0);
    EXPECT_EQ(s.cameras[size_t(s.camera)].type, CameraType::pinhole);

    EXPECT_EQ(s.renderer.type, RendererType::pt);
    EXPECT_EQ(s.renderer.samples, 128);
    EXPECT_EQ(s.renderer.depth, 6);

    const Material& glossy = s.materials[size_t(find_id(s.materials, "glossy"))];
    EXPECT_EQ(glossy.type, MaterialType::glossy);
    EXPECT_DOUBLE_EQ(glossy.roughness, 0.1);

    ASSERT_EQ(s.active_lights.size(), 1u);
    const Light& area = s.lights[size_t(s.active_lights[0])];
    EXPECT_EQ(area.id, "area light");
    EXPECT_EQ(area.type, LightType::area);
    EXPECT_EQ(s.shapes[size_t(area.shape)].id, "area light");
    EXPECT_EQ(area.power, Color(30));
    EXPECT_EQ(s.primitives[0].type, PrimitiveType::emissive);
    EXPECT_EQ(s.primitives[0].light, s.active_lights[0]);
}

TEST(LoadReferenceScenes, Assignment04RepeatsAPrimitive) {
    const Scene s = load_scene_file(test::brief_scene_file(4)).scene;
    ASSERT_EQ(s.primitives.size(), 5u);
    EXPECT_EQ(s.primitives[1].id, "floor");
    EXPECT_EQ(s.primitives[2].id, "floor");
    EXPECT_EQ(s.primitives[1].shape, s.primitives[2].shape);
    EXPECT_EQ(s.renderer.samples, 4096);
}

TEST(LoadReferenceScenes, Assignment07TwoPointLights) {
    const Scene s = load_scene_file(test::brief_scene_file(7)).scene;
    ASSERT_EQ(s.active_lights.size(), 2u);
    EXPECT_EQ(s.lights[size_t(s.active_lights[0])].power, Color(320, 300, 280));
    EXPECT_EQ(s.lights[size_t(s.active_lights[1])].power, Color(50, 60, 70));
    EXPECT_EQ(s.renderer.samples, 36);
    EXPECT_EQ(s.renderer.type, RendererType::wrt);
}

TEST(LoadReferenceScenes, Assignment08TwoEmissivePrimitives) {
    const Scene s = load_scene_file(test::brief_scene_file(8)).scene;
    std::vector<const Primitive*> emissive;
    for (const Primitive& p : s.primitives)
        if (p.type == PrimitiveType::emissive) emissive.push_back(&p);
    ASSERT_EQ(emissive.size(), 2u);

    EXPECT_EQ(emissive[0]->id, "area light");
    const Light& first = s.lights[size_t(emissive[0]->light)];
    EXPECT_EQ(first.id, "area light");
    EXPECT_EQ(first.power, Color(32, 30, 28));
    EXPECT_EQ(s.shapes[size_t(first.shape)].centre, Vec3(6, 2, -1));

    EXPECT_EQ(emissive[1]->id, "sphere 05");
    const Light& second = s.lights[size_t(emissive[1]->light)];
    EXPECT_EQ(second.id, "area light 02");
    EXPECT_EQ(second.power, Color(5, 6, 7));
    EXPECT_EQ(s.shapes[size_t(emissive[1]->shape)].id, "area light 02");

    ASSERT_EQ(s.active_lights.size(), 2u);
    EXPECT_EQ(s.active_lights[0], emissive[0]->light);
    EXPECT_EQ(s.active_lights[1], emissive[1]->light);
    EXPECT_EQ(s.materials[size_t(emissive[0]->material)].id, "white diffuse");
}

TEST(SceneOutputPath, WithoutSourceFileIsRelativeToCurrentDir) {
    Scene s;
    s.renderer.output = "out/../img.ppm";
    EXPECT_EQ(s.output_path(), fs::path("img.ppm"));
}

// A small valid scene; each bad-input test changes one thing in it.
// Materials: 0 red (used), 1 glass (used), 2 shiny (used), 3 spare (unused).
// Lights: 0 lamp (area, used), 1 bulb (point, unused).
constexpr const char* kBaseScene = R"({
  "cameras": [{"id": "cam", "type": "pinhole", "fov": 45, "aspect": 1,
               "position": [0, 0, -10], "target": [0, 0, 0]}],
  "materials": [
    {"id": "red", "type": "diffuse", "rho": [0.9, 0, 0]},
    {"id": "glass", "type": "fresnel dielectric", "rhoR": [1, 1, 1], "rhoT": [1, 1, 1], "eta": 1.5},
    {"id": "shiny", "type": "glossy reflection", "rho": [0.9, 0.9, 0.9], "roughness": 0.2},
    {"id": "spare", "type": "diffuse", "rho": [0.5, 0.5, 0.5]}
  ],
  "shapes": [
    {"id": "ball", "type": "sphere", "centre": [0, 0, 0], "radius": 1},
    {"id": "lamp", "type": "sphere", "centre": [0, 5, 0], "radius": 0.5}
  ],
  "lights": [
    {"id": "lamp", "type": "area", "shape": "lamp", "power": [10, 10, 10]},
    {"id": "bulb", "type": "point", "position": [0, 4, 0], "power": [100, 100, 100]}
  ],
  "scene": {
    "camera": "cam",
    "lights": ["lamp"],
    "primitives": [
      {"id": "ball", "type": "geometric", "shape": "ball", "material": "red"},
      {"id": "ball", "type": "geometric", "shape": "ball", "material": "glass"},
      {"id": "ball", "type": "geometric", "shape": "ball", "material": "shiny"},
      {"id": "lamp", "type": "emissive", "shape": "lamp", "material": "red", "light": "lamp"}
    ],
    "renderer": {"type": "PT", "dimensions": [64, 48], "samples": 4, "depth": 6,
                 "output": "out.ppm"}
  }
})";

class LoadErrors : public ::testing::Test {
protected:
    void SetUp() override {
        // A fresh folder per test, so messages name a real file and runs do not collide.
        const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
        for (int attempt = 0;; ++attempt) {
            dir_ = fs::temp_directory_path() /
                   ("keithray_test_load_" + std::to_string(stamp) + "_" + std::to_string(attempt));
            if (fs::create_directory(dir_)) break;
        }
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }

    fs::path write(const std::string& text) {
        const fs::path file = dir_ / ("scene_" + std::to_string(count_++) + ".json");
        std::ofstream(file, std::ios::binary) << text;
        return file;
    }

    // Loads `text` and checks the one error it must raise.
    void expect_error(const std::string& text, const std::string& pointer, const std::string& phrase) {
        const fs::path file = write(text);
        try {
            load_scene_file(file);
            ADD_FAILURE() << "no error; expected " << pointer << ": " << phrase;
        } catch (const SceneError& e) {
            const std::string what = e.what();
            EXPECT_EQ(e.file(), file.string());
            EXPECT_EQ(e.json_path(), pointer) << what;
            EXPECT_NE(what.find(file.string()), std::string::npos) << what;
            if (!pointer.empty()) {
                EXPECT_NE(what.find(": " + pointer + ": "), std::string::npos) << what;
            }
            EXPECT_NE(e.message().find(phrase), std::string::npos) << what;
            EXPECT_NE(what.find(phrase), std::string::npos) << what;
        }
    }

    LoadedScene load_ok(const std::string& text) { return load_scene_file(write(text)); }

    fs::path dir_;
    int count_ = 0;
};

TEST_F(LoadErrors, BaseSceneIsValid) {
    const LoadedScene loaded = load_ok(kBaseScene);
    EXPECT_TRUE(loaded.warnings.empty());
    EXPECT_EQ(loaded.scene.primitives.size(), 4u);
    EXPECT_DOUBLE_EQ(loaded.scene.cameras[0].distance, 5);  // optional, defaults to 5
    EXPECT_EQ(loaded.scene.output_path(), (dir_ / "out.ppm").lexically_normal());
}

TEST_F(LoadErrors, MissingFile) {
    const fs::path file = dir_ / "nope.json";
    try {
        load_scene_file(file);
        ADD_FAILURE() << "no error for a missing file";
    } catch (const SceneError& e) {
        EXPECT_EQ(e.json_path(), "");
        EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos);
        EXPECT_NE(e.message().find("cannot open scene file"), std::string::npos) << e.what();
        EXPECT_NE(e.message().find("No such file"), std::string::npos) << e.what();
    }
}

TEST_F(LoadErrors, DirectoryIsNotAFile) {
    try {
        load_scene_file(dir_);
        ADD_FAILURE() << "no error for a directory";
    } catch (const SceneError& e) {
        EXPECT_NE(e.message().find("cannot"), std::string::npos) << e.what();
    }
}

TEST_F(LoadErrors, MalformedJsonNamesLineAndColumn) {
    expect_error("{\n  \"cameras\": [\n    ,\n  ]\n}", "", "malformed JSON at line 3, column 5");
    expect_error("", "", "malformed JSON at line 1");
}

TEST_F(LoadErrors, DuplicateKey) {
    expect_error(test::edit_once(kBaseScene, R"("rho": [0.9, 0, 0]})", R"("rho": [0.9, 0, 0], "rho": [1, 1, 1]})"),
                 "/materials/0/rho", "duplicate key \"rho\"");
}

TEST_F(LoadErrors, NestingTooDeep) {
    const std::string deep = std::string(100, '[') + std::string(100, ']');
    expect_error(deep, "", "nesting deeper than 64");
    // Brackets inside strings do not count.
    std::string text = kBaseScene;
    text = test::edit_once(text, R"("output": "out.ppm")", R"("output": ")" + std::string(100, '[') + R"(.ppm")");
    EXPECT_NO_THROW(load_ok(text));
}

TEST_F(LoadErrors, InfiniteNumber) {
    expect_error(test::edit_once(kBaseScene, R"("radius": 1})", R"("radius": 1e999})"), "/shapes/0/radius",
                 "not a finite number");
    expect_error(test::edit_once(kBaseScene, R"("position": [0, 4, 0])", R"("position": [0, -1e400, 0])"),
                 "/lights/1/position/1", "1e400");
}

TEST_F(LoadErrors, MissingField) {
    expect_error(test::edit_once(kBaseScene, R"(, "radius": 1})", "}"), "/shapes/0", "missing key \"radius\"");
    expect_error(test::edit_once(kBaseScene, R"("lights": ["lamp"],)", ""), "/scene", "missing key \"lights\"");
}

TEST_F(LoadErrors, StringForANumber) {
    expect_error(test::edit_once(kBaseScene, R"("fov": 45)", R"("fov": "45")"), "/cameras/0/fov",
                 "expected a number, got string \"45\"");
}

TEST_F(LoadErrors, NotAVec3) {
    expect_error(test::edit_once(kBaseScene, R"("target": [0, 0, 0])", R"("target": [0, 0])"), "/cameras/0/target",
                 "expected an array of 3 finite numbers, got an array of 2 elements");
}

TEST_F(LoadErrors, UnknownMaterialTypeListsTheValidOnes) {
    expect_error(test::edit_once(kBaseScene, R"("type": "diffuse", "rho": [0.9, 0, 0])",
                      R"("type": "plastic", "rho": [0.9, 0, 0])"),
                 "/materials/0/type",
                 "unknown material type \"plastic\"; expected \"diffuse\", \"specular reflection\", "
                 "\"glossy reflection\", \"fresnel dielectric\" or \"translucent dielectric\"");
}

TEST_F(LoadErrors, UnknownKey) {
    expect_error(test::edit_once(kBaseScene, R"("rho": [0.9, 0, 0]})", R"("colour": [0.9, 0, 0]})"),
                 "/materials/0/colour", "unknown key \"colour\"; expected one of \"id\", \"type\", \"rho\"");
    expect_error(test::edit_once(kBaseScene, R"("cameras": [)", R"("textures": [], "cameras": [)"), "/textures",
                 "unknown key \"textures\"");
    // "light" belongs to emissive primitives only.
    expect_error(test::edit_once(kBaseScene, R"("material": "red"},)", R"("material": "red", "light": "lamp"},)"),
                 "/scene/primitives/0/light", "unknown key \"light\"");
}

// The optional display block: tone map and exposure in stops, read as strictly as the rest.
TEST_F(LoadErrors, DisplayBlockIsOptionalAndStrict) {
    const LoadedScene plain = load_ok(kBaseScene);
    EXPECT_EQ(plain.scene.display.tonemap, ToneMap::sigmoid);
    EXPECT_EQ(plain.scene.display.exposure, 0.0);
    auto with_display = [](const std::string& block) {
        return test::edit_once(kBaseScene, R"("renderer": {)", R"("display": )" + block + R"(, "renderer": {)");
    };
    const LoadedScene loaded = load_ok(with_display(R"({"tonemap": "linear", "exposure": -1.5})"));
    EXPECT_TRUE(loaded.warnings.empty());
    EXPECT_EQ(loaded.scene.display.tonemap, ToneMap::linear);
    EXPECT_EQ(loaded.scene.display.exposure, -1.5);
    EXPECT_EQ(loaded.scene.display.exposure_scale(), std::exp2(-1.5));
    expect_error(with_display(R"({"tonemap": "filmic"})"), "/scene/display/tonemap",
                 "unknown tone map \"filmic\"; expected \"sigmoid\", \"linear\" or \"srgb\"");
    expect_error(with_display(R"({"exposure": 10.5})"), "/scene/display/exposure",
                 "expected a number of stops in [-10, 10], got 10.5");
    expect_error(with_display(R"({"exposure": "bright"})"), "/scene/display/exposure", "expected a number");
    expect_error(with_display(R"({"gamma": 2.2})"), "/scene/display/gamma", "unknown key \"gamma\"");
    expect_error(with_display("3"), "/scene/display", "display settings");
    // The denoise mode: absent unless given ("on" or "off"), then as strict as the tone map.
    EXPECT_FALSE(plain.scene.display.denoise.has_value());
    EXPECT_EQ(load_ok(with_display(R"({"denoise": "on"})")).scene.display.denoise, Denoise::on);
    EXPECT_EQ(load_ok(with_display(R"({"denoise": "off"})")).scene.display.denoise, Denoise::off);
    expect_error(with_display(R"({"denoise": "nlmeans"})"), "/scene/display/denoise",
                 "unknown denoise mode \"nlmeans\"; expected \"off\" or \"on\"");
    expect_error(with_display(R"({"denoise": true})"), "/scene/display/denoise",
                 "expected a denoise mode (a string), got");
}

// The saver writes the display block from the loader's table: each field round-trips, and a
// denoise mode never set is left out (the file then renders as one without it).
TEST_F(LoadErrors, DisplayBlockRoundTripsThroughTheSaver) {
    Scene scene = load_ok(kBaseScene).scene;
    const std::string unset = scene_to_json(scene);
    EXPECT_EQ(unset.find("\"denoise\""), std::string::npos) << unset;
    EXPECT_FALSE(load_ok(unset).scene.display.denoise.has_value());
    for (const Denoise mode : {Denoise::on, Denoise::off}) {
        scene.display = {ToneMap::srgb, -2.25, mode};
        const DisplaySettings back = load_ok(scene_to_json(scene)).scene.display;
        EXPECT_EQ(back.tonemap, ToneMap::srgb);
        EXPECT_EQ(back.exposure, -2.25);
        EXPECT_EQ(back.denoise, mode);
    }
    // Every field of the table is written, and only those.
    const nlohmann::ordered_json saved = nlohmann::ordered_json::parse(scene_to_json(scene));
    const auto& block = saved["scene"]["display"];
    ASSERT_EQ(block.size(), display_fields().size());
    for (const DisplayField& field : display_fields()) EXPECT_TRUE(block.contains(std::string(field.key))) << field.key;
}

TEST_F(LoadErrors, DanglingMaterialId) {
    expect_error(test::edit_once(kBaseScene, R"("material": "glass")", R"("material": "chalk")"),
                 "/scene/primitives/1/material",
                 "no material with id \"chalk\"; expected one of \"red\", \"glass\", \"shiny\", \"spare\"");
}

TEST_F(LoadErrors, DanglingCameraLightAndShapeIds) {
    expect_error(test::edit_once(kBaseScene, R"("camera": "cam")", R"("camera": "eye")"), "/scene/camera",
                 "no camera with id \"eye\"; expected one of \"cam\"");
    expect_error(test::edit_once(kBaseScene, R"("lights": ["lamp"])", R"("lights": ["lamp", "sun"])"), "/scene/lights/1",
                 "no light with id \"sun\"");
    expect_error(test::edit_once(kBaseScene, R"("shape": "lamp", "power")", R"("shape": "moon", "power")"),
                 "/lights/0/shape", "no shape with id \"moon\"");
}

TEST_F(LoadErrors, LightListedTwice) {
    expect_error(test::edit_once(kBaseScene, R"("lights": ["lamp"])", R"("lights": ["lamp", "lamp"])"),
                 "/scene/lights/1", "already listed at /scene/lights/0");
}

TEST_F(LoadErrors, EmissivePrimitiveNeedsAnAreaLight) {
    expect_error(test::edit_once(kBaseScene, R"("light": "lamp")", R"("light": "bulb")"), "/scene/primitives/3/light",
                 "expects an \"area\" light");
}

TEST_F(LoadErrors, NegativeRadius) {
    expect_error(test::edit_once(kBaseScene, R"("radius": 1})", R"("radius": -1})"), "/shapes/0/radius",
                 "expected a radius > 0, got -1");
}

TEST_F(LoadErrors, EtaNotPositive) {
    expect_error(test::edit_once(kBaseScene, R"("eta": 1.5)", R"("eta": 0)"), "/materials/1/eta",
                 "expected a refractive index eta > 0, got 0");
}

TEST_F(LoadErrors, RoughnessOne) {
    expect_error(test::edit_once(kBaseScene, R"("roughness": 0.2)", R"("roughness": 1)"), "/materials/2/roughness",
                 "expected a roughness in [0, 1), got 1");
}

TEST_F(LoadErrors, NegativeReflectance) {
    expect_error(test::edit_once(kBaseScene, R"("rho": [0.9, 0, 0])", R"("rho": [0.9, -0.5, 0])"), "/materials/0/rho/1",
                 "expected a value >= 0, got -0.5");
}

TEST_F(LoadErrors, ZeroDimension) {
    expect_error(test::edit_once(kBaseScene, R"("dimensions": [64, 48])", R"("dimensions": [0, 48])"),
                 "/scene/renderer/dimensions/0", "expected an integer in [1, 32768], got 0");
    expect_error(test::edit_once(kBaseScene, R"("dimensions": [64, 48])", R"("dimensions": [64, 40000])"),
                 "/scene/renderer/dimensions/1", "expected an integer in [1, 32768], got 40000");
}

TEST_F(LoadErrors, ZeroSamples) {
    expect_error(test::edit_once(kBaseScene, R"("samples": 4)", R"("samples": 0)"), "/scene/renderer/samples",
                 "expected an integer in [1, 16777216], got 0");
    expect_error(test::edit_once(kBaseScene, R"("samples": 4)", R"("samples": 2.5)"), "/scene/renderer/samples",
                 "got number 2.5");
}

TEST_F(LoadErrors, UnknownRendererType) {
    expect_error(test::edit_once(kBaseScene, R"("type": "PT")", R"("type": "MLT")"), "/scene/renderer/type",
                 "unknown renderer type \"MLT\"; expected \"WRT\" or \"PT\"");
}

TEST_F(LoadErrors, PositionEqualsTarget) {
    expect_error(test::edit_once(kBaseScene, R"("position": [0, 0, -10])", R"("position": [0, 0, 0])"), "/cameras/0",
                 "camera position equals target");
}

TEST_F(LoadErrors, DuplicateIdInACategory) {
    expect_error(test::edit_once(kBaseScene, R"("id": "spare")", R"("id": "glass")"), "/materials/3/id",
                 "duplicate material id \"glass\": also the id of /materials/1");
}

TEST_F(LoadErrors, TopLevelMustBeAnObjectWithAScene) {
    expect_error("[1, 2]", "", "expected a JSON object at the top level, got an array of 2 elements");
    expect_error(R"({"cameras": []})", "", "missing key \"scene\"");
}

TEST_F(LoadErrors, DepthAboveTwentyIsClampedWithAWarning) {
    const LoadedScene loaded = load_ok(test::edit_once(kBaseScene, R"("depth": 6)", R"("depth": 25)"));
    EXPECT_EQ(loaded.scene.renderer.depth, kMaxDepth);
    ASSERT_EQ(loaded.warnings.size(), 1u);
    EXPECT_NE(loaded.warnings[0].find("/scene/renderer/depth"), std::string::npos) << loaded.warnings[0];
    EXPECT_NE(loaded.warnings[0].find("clamped to 20"), std::string::npos) << loaded.warnings[0];
}

TEST_F(LoadErrors, OutOfRangeInUnreferencedObjectsIsOnlyAWarning) {
    std::string text = test::edit_once(kBaseScene, R"("rho": [0.5, 0.5, 0.5])", R"("rho": [-1, 0.5, 0.5])");
    text = test::edit_once(text, R"("power": [100, 100, 100])", R"("power": [100, -2, 100])");
    const LoadedScene loaded = load_ok(text);
    ASSERT_EQ(loaded.warnings.size(), 2u);
    EXPECT_NE(loaded.warnings[0].find(": /materials/3/rho/0: expected a value >= 0, got -1"), std::string::npos)
        << loaded.warnings[0];
    EXPECT_NE(loaded.warnings[1].find(": /lights/1/power/1: "), std::string::npos) << loaded.warnings[1];
    // Used by a primitive, the same value is an error.
    expect_error(test::edit_once(text, R"("material": "glass")", R"("material": "spare")"), "/materials/3/rho/0",
                 "expected a value >= 0, got -1");
}

TEST_F(LoadErrors, ReflectanceAboveOneIsAWarning) {
    const LoadedScene loaded = load_ok(test::edit_once(kBaseScene, R"("rho": [0.9, 0, 0])", R"("rho": [1.2, 0, 0])"));
    ASSERT_EQ(loaded.warnings.size(), 1u);
    EXPECT_NE(loaded.warnings[0].find("/materials/0/rho/0: "), std::string::npos) << loaded.warnings[0];
    EXPECT_NE(loaded.warnings[0].find("not energy conserving"), std::string::npos) << loaded.warnings[0];
}

TEST_F(LoadErrors, TranslucentDielectricLoads) {
    const LoadedScene loaded =
        load_ok(test::edit_once(kBaseScene, R"("type": "fresnel dielectric", "rhoR": [1, 1, 1], "rhoT": [1, 1, 1], "eta": 1.5})",
                     R"("type": "translucent dielectric", "rhoR": [1, 1, 1], "rhoT": [0.8, 0.8, 0.8], "eta": 1.33, "roughness": 0.3})"));
    const Material& m = loaded.scene.materials[1];
    EXPECT_EQ(m.type, MaterialType::translucent);
    EXPECT_DOUBLE_EQ(m.eta, 1.33);
    EXPECT_DOUBLE_EQ(m.roughness, 0.3);
    EXPECT_EQ(m.rho_t, Color(0.8));
    // Its roughness is required and range checked like a glossy one.
    expect_error(test::edit_once(kBaseScene, R"("type": "fresnel dielectric")", R"("type": "translucent dielectric")"),
                 "/materials/1", "missing key \"roughness\"");
}

// The loader reads each material type's parameters from material_params (scene.h): every
// parameter of the table is required, and a number outside its range is refused in its words.
TEST_F(LoadErrors, MaterialParametersFollowTheTable) {
    const std::string glass = R"({"id": "glass", "type": "fresnel dielectric", "rhoR": [1, 1, 1], "rhoT": [1, 1, 1], "eta": 1.5})";
    for (const MaterialType type : {MaterialType::diffuse, MaterialType::specular, MaterialType::glossy,
                                    MaterialType::dielectric, MaterialType::translucent}) {
        const auto params = material_params(type);
        ASSERT_FALSE(params.empty());
        for (size_t missing = 0; missing < params.size(); ++missing) {
            std::string m = R"({"id": "glass", "type": ")" + std::string(material_type_names.name(type)) + "\"";
            for (size_t k = 0; k < params.size(); ++k)
                if (k != missing)
                    m += ", \"" + std::string(params[k].name) + "\": " + (params[k].colour ? "[0.5, 0.5, 0.5]" : "0.5");
            m += "}";
            expect_error(test::edit_once(kBaseScene, glass, m), "/materials/1",
                         "missing key \"" + std::string(params[missing].name) + "\"");
        }
        for (const MaterialParam& param : params) {
            if (param.colour) continue;
            std::string m = R"({"id": "glass", "type": ")" + std::string(material_type_names.name(type)) + "\"";
            for (const MaterialParam& k : params)
                m += ", \"" + std::string(k.name) + "\": " + (k.colour ? "[0.5, 0.5, 0.5]" : &k == &param ? "-1" : "0.5");
            m += "}";
            expect_error(test::edit_once(kBaseScene, glass, m), "/materials/1/" + std::string(param.name),
                         "expected " + std::string(param.expected) + ", got -1");
        }
    }
}

// A light field's value in the file, by its kind (kBaseScene's shapes: "ball", "lamp").
std::string light_field_text(const LightParam& param) {
    switch (param.kind) {
    case LightFieldKind::vector: return "[0, 4, 0]";
    case LightFieldKind::colour: return "[100, 100, 100]";
    case LightFieldKind::shape: return "\"lamp\"";
    }
    return "null";
}

// Light 1 of kBaseScene ("bulb", on in the scene block) as a light of `type` with its fields
// but `missing`, and `bad` (a key's value text) in place of one field's value.
std::string scene_with_light(LightType type, std::string_view missing = {}, std::string_view bad_key = {},
                             std::string_view bad = {}) {
    std::string l = R"({"id": "bulb", "type": ")" + std::string(light_type_names.name(type)) + "\"";
    for (const LightParam& param : light_params(type))
        if (param.name != missing)
            l += ", \"" + std::string(param.name) + "\": " + (param.name == bad_key ? std::string(bad) : light_field_text(param));
    l += "}";
    const std::string s = test::edit_once(kBaseScene, R"({"id": "bulb", "type": "point", "position": [0, 4, 0], "power": [100, 100, 100]})", l);
    return test::edit_once(s, R"("lights": ["lamp"],)", R"("lights": ["lamp", "bulb"],)");
}

TEST_F(LoadErrors, LightFieldsFollowTheTable) {
    for (size_t t = 0; t < light_type_names.names.size(); ++t) {
        const LightType type = LightType(t);
        SCOPED_TRACE(std::string(light_type_names.name(type)));
        const auto params = light_params(type);
        ASSERT_FALSE(params.empty());
        // Every field there: it loads, each value where its row puts it.
        const LoadedScene loaded = load_ok(scene_with_light(type));
        const Light& light = loaded.scene.lights[1];
        EXPECT_EQ(light.type, type);
        for (const LightParam& param : params) {
            if (param.kind == LightFieldKind::shape) EXPECT_EQ(light.*param.shape, 1);
            else EXPECT_EQ(light.*param.value, param.kind == LightFieldKind::vector ? Vec3(0, 4, 0) : Color(100));
        }
        for (const LightParam& param : params) {
            const std::string name(param.name);
            expect_error(scene_with_light(type, name), "/lights/1",
                         "missing key \"" + name + "\"; expected " + std::string(param.expected));
            // A value of the wrong kind, then (numbers) one out of range.
            switch (param.kind) {
            case LightFieldKind::vector:
            case LightFieldKind::colour:
                expect_error(scene_with_light(type, {}, name, "[1, 2]"), "/lights/1/" + name,
                             "expected an array of 3 finite numbers, got");
                break;
            case LightFieldKind::shape:
                expect_error(scene_with_light(type, {}, name, "\"moon\""), "/lights/1/" + name, "no shape with id \"moon\"");
                break;
            }
            if (param.kind == LightFieldKind::colour)
                expect_error(scene_with_light(type, {}, name, "[1, -1, 1]"), "/lights/1/" + name + "/1",
                             "expected a value >= 0, got -1");
        }
        // An emissive primitive carries a light on a shape, and no other.
        const std::string carried = test::edit_once(scene_with_light(type), R"("light": "lamp")", R"("light": "bulb")");
        if (light_has_shape(type))
            EXPECT_EQ(load_ok(carried).scene.primitives[3].light, 1);
        else
            expect_error(carried, "/scene/primitives/3/light",
                         "light \"bulb\" is a \"" + std::string(light_type_names.name(type)) +
                             "\" light; an emissive primitive expects an \"area\" light");
    }
    expect_error(test::edit_once(kBaseScene, R"(, "light": "lamp")", ""), "/scene/primitives/3",
                 "missing key \"light\"; expected an area light id");
}

// Where each light type is (scene.h's light_anchor), which the viewer's outliner, gizmo and
// placement ask: its anchor field's value, or a shape's index.
TEST(LightAnchor, IsTheRowsAnchorField) {
    for (size_t t = 0; t < light_type_names.names.size(); ++t) {
        Light light;
        light.type = LightType(t);
        light.position = {1, 2, 3};
        light.shape = 4;
        const LightAnchor anchor = light_anchor(light);
        const LightParam* field = nullptr;
        for (const LightParam& param : light_params(light.type))
            if (param.anchor && !field) field = &param;
        if (!field) {
            EXPECT_EQ(anchor.kind, LightAnchor::Kind::none);
        } else if (field->kind == LightFieldKind::shape) {
            EXPECT_EQ(anchor.kind, LightAnchor::Kind::shape);
            EXPECT_EQ(anchor.shape, 4);
        } else {
            EXPECT_EQ(anchor.kind, LightAnchor::Kind::point);
            EXPECT_EQ(anchor.point, light.*field->value);
        }
    }
    Light point;
    point.position = {1, 2, 3};
    EXPECT_EQ(light_anchor(point).kind, LightAnchor::Kind::point);
    EXPECT_EQ(light_anchor(point).point, Vec3(1, 2, 3));
    Light area;
    area.type = LightType::area;
    area.shape = 2;
    EXPECT_EQ(light_anchor(area).kind, LightAnchor::Kind::shape);
    EXPECT_EQ(light_anchor(area).shape, 2);
    EXPECT_TRUE(light_has_shape(kShapeLightType));
}

TEST_F(LoadErrors, LensCameraNeedsFocalDistanceAndAlpha) {
    expect_error(test::edit_once(kBaseScene, R"("type": "pinhole")", R"("type": "lens-based")"), "/cameras/0",
                 "missing key \"focal distance\"");
    expect_error(test::edit_once(kBaseScene, R"("type": "pinhole")",
                      R"("type": "lens-based", "focal distance": -3, "alpha": 0.5)"),
                 "/cameras/0/focal distance", "expected a focal distance > 0, got -3");
}

TEST(ParseScene, FromTextUsesTheNameInMessages) {
    try {
        parse_scene("{}", "virtual/scene.json");
        ADD_FAILURE() << "no error";
    } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()), "virtual/scene.json: missing key \"scene\"; expected the scene block (an object)");
    }
}

}  // namespace
}  // namespace kr
