// The scene serializer (scene/save.h): every brief scene loads, saves and loads back to an
// equal authored scene, and a saved file renders the same image.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "render/progressive.h"
#include "scene/load.h"
#include "scene/save.h"
#include "test_util.h"

namespace fs = std::filesystem;
using namespace kr;

namespace {

// Field by field, so a failure names what differs.
void expect_equal_scenes(const Scene& a, const Scene& b, bool compare_output = true) {
    ASSERT_EQ(a.cameras.size(), b.cameras.size());
    for (size_t i = 0; i < a.cameras.size(); ++i) {
        const Camera &x = a.cameras[i], &y = b.cameras[i];
        EXPECT_EQ(x.id, y.id);
        EXPECT_EQ(x.type, y.type);
        EXPECT_EQ(x.fov, y.fov);
        EXPECT_EQ(x.aspect, y.aspect);
        EXPECT_EQ(x.distance, y.distance);
        EXPECT_EQ(x.position, y.position);
        EXPECT_EQ(x.target, y.target);
        EXPECT_EQ(x.focal_distance, y.focal_distance);
        EXPECT_EQ(x.alpha, y.alpha);
    }
    ASSERT_EQ(a.materials.size(), b.materials.size());
    for (size_t i = 0; i < a.materials.size(); ++i) {
        const Material &x = a.materials[i], &y = b.materials[i];
        EXPECT_EQ(x.id, y.id);
        EXPECT_EQ(x.type, y.type);
        EXPECT_EQ(x.rho, y.rho);
        EXPECT_EQ(x.rho_r, y.rho_r);
        EXPECT_EQ(x.rho_t, y.rho_t);
        EXPECT_EQ(x.eta, y.eta);
        EXPECT_EQ(x.roughness, y.roughness);
    }
    ASSERT_EQ(a.shapes.size(), b.shapes.size());
    for (size_t i = 0; i < a.shapes.size(); ++i) {
        EXPECT_EQ(a.shapes[i].id, b.shapes[i].id);
        EXPECT_EQ(a.shapes[i].type, b.shapes[i].type);
        EXPECT_EQ(a.shapes[i].centre, b.shapes[i].centre);
        EXPECT_EQ(a.shapes[i].radius, b.shapes[i].radius);
    }
    ASSERT_EQ(a.lights.size(), b.lights.size());
    for (size_t i = 0; i < a.lights.size(); ++i) {
        const Light &x = a.lights[i], &y = b.lights[i];
        EXPECT_EQ(x.id, y.id);
        EXPECT_EQ(x.type, y.type);
        EXPECT_EQ(x.position, y.position);
        EXPECT_EQ(x.power, y.power);
        EXPECT_EQ(x.shape, y.shape);
        // And every field its type's row names (scene.h's light_params), a new type's too.
        for (const LightParam& param : light_params(x.type)) {
            if (param.kind == LightFieldKind::shape) EXPECT_EQ(x.*param.shape, y.*param.shape) << param.name;
            else EXPECT_EQ(x.*param.value, y.*param.value) << param.name;
        }
    }
    EXPECT_EQ(a.camera, b.camera);
    EXPECT_EQ(a.active_lights, b.active_lights);
    ASSERT_EQ(a.primitives.size(), b.primitives.size());
    for (size_t i = 0; i < a.primitives.size(); ++i) {
        const Primitive &x = a.primitives[i], &y = b.primitives[i];
        EXPECT_EQ(x.id, y.id);
        EXPECT_EQ(x.type, y.type);
        EXPECT_EQ(x.shape, y.shape);
        EXPECT_EQ(x.material, y.material);
        EXPECT_EQ(x.light, y.light);
    }
    EXPECT_EQ(a.renderer.type, b.renderer.type);
    EXPECT_EQ(a.renderer.width, b.renderer.width);
    EXPECT_EQ(a.renderer.height, b.renderer.height);
    EXPECT_EQ(a.renderer.samples, b.renderer.samples);
    EXPECT_EQ(a.renderer.depth, b.renderer.depth);
    if (compare_output) EXPECT_EQ(a.renderer.output, b.renderer.output);
    EXPECT_EQ(a.output_path(), b.output_path());
}

class SaveScene : public testing::TestWithParam<int> {
protected:
    fs::path dir;
    void SetUp() override {
        dir = fs::temp_directory_path() / ("keithray_save_" + std::to_string(GetParam()) + "_" + std::to_string(::getpid()));
        fs::remove_all(dir);
        fs::create_directories(dir);
    }
    void TearDown() override { fs::remove_all(dir); }
};

}  // namespace

// load -> text -> load, read as if from the same file: the structs are equal, output included.
TEST_P(SaveScene, TextRoundTripIsExact) {
    const fs::path file = test::brief_scene_file(GetParam());
    const Scene original = load_scene_file(file).scene;
    const LoadedScene again = parse_scene(scene_to_json(original), file);
    expect_equal_scenes(original, again.scene);
    EXPECT_EQ(again.scene.source_file, original.source_file);
}

// load -> save elsewhere -> load: equal, and the output still names the same file.
TEST_P(SaveScene, FileRoundTripKeepsOutputTarget) {
    const Scene original = load_scene_file(test::brief_scene_file(GetParam())).scene;
    const fs::path saved = dir / "nested" / "copy.json";
    save_scene_json(original, saved);
    const Scene again = load_scene_file(saved).scene;
    expect_equal_scenes(original, again, /*compare_output=*/false);
    // And saving the reloaded copy over itself changes nothing.
    save_scene_json(again, saved);
    expect_equal_scenes(again, load_scene_file(saved).scene);
}

// The saved file renders bit for bit the same image (a small crop of the view, 1 spp).
TEST_P(SaveScene, SavedSceneRendersTheSameImage) {
    Scene original = load_scene_file(test::brief_scene_file(GetParam())).scene;
    original.renderer.width = original.renderer.height = 24;
    const fs::path saved = dir / "small.json";
    save_scene_json(original, saved);
    const Scene again = load_scene_file(saved).scene;
    auto render = [](const Scene& s) {
        const RenderScene rs = prepare_scene(s);
        RenderSettings settings = RenderSettings::from_scene(rs.renderer);
        RenderState state(rs.renderer.width, rs.renderer.height);
        render_pass(rs, settings, state);
        return state.radiance_sum();
    };
    const auto a = render(original), b = render(again);
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << "pixel " << i;
}

INSTANTIATE_TEST_SUITE_P(AllScenes, SaveScene, testing::Range(1, 9));

// Every light type's fields (scene.h's light_params) are written in its row's order, after
// its id and type, and load back equal.
TEST(SaveSceneVariants, EveryLightTypeRoundTrips) {
    Scene s;
    Camera cam;
    cam.id = "cam";
    s.cameras = {cam};
    s.camera = 0;
    Material grey;
    grey.id = "grey";
    s.materials = {grey};
    Shape ball;
    ball.id = "ball";
    Shape lamp = ball;
    lamp.id = "lamp";
    lamp.centre = {0, 3, 0};
    s.shapes = {ball, lamp};
    s.primitives = {{"ball", PrimitiveType::geometric, 0, 0, -1}};
    s.renderer.output = "out.ppm";
    for (size_t t = 0; t < light_type_names.names.size(); ++t) {
        Light light;
        light.type = LightType(t);
        light.id = std::string(light_type_names.name(light.type));
        // Values unlike the defaults, so a field not written or not read shows.
        for (const LightParam& param : light_params(light.type)) {
            if (param.kind == LightFieldKind::shape) light.*param.shape = 1;
            else light.*param.value = param.kind == LightFieldKind::vector ? Vec3(1e-7, 2e5, -3) : Color(30, 20, 10.5);
        }
        s.lights.push_back(light);
        s.active_lights.push_back(int(t));
        if (light_has_shape(light.type)) s.primitives.push_back({light.id, PrimitiveType::emissive, 1, 0, int(t)});
    }
    const std::string text = scene_to_json(s);
    const LoadedScene back = parse_scene(text, "");
    EXPECT_TRUE(back.warnings.empty());
    expect_equal_scenes(s, back.scene);
    const nlohmann::ordered_json file = nlohmann::ordered_json::parse(text);
    ASSERT_EQ(file["lights"].size(), s.lights.size());
    for (size_t t = 0; t < s.lights.size(); ++t) {
        std::vector<std::string> keys, expected = {"id", "type"};
        for (const auto& [key, value] : file["lights"][t].items()) keys.push_back(key);
        for (const LightParam& param : light_params(s.lights[t].type)) expected.emplace_back(param.name);
        EXPECT_EQ(keys, expected);
    }
}

// Every camera, material and light variant the format has, used or not, survives.
TEST(SaveSceneVariants, EveryTypeRoundTrips) {
    Scene s;
    Camera pin;
    pin.id = "pin";
    pin.fov = 33.3;
    pin.position = {0.1, 0.2, -7.3};
    Camera lens = pin;
    lens.id = "lens";
    lens.type = CameraType::lens;
    lens.focal_distance = 12.345678901234567;
    lens.alpha = 0.3;
    s.cameras = {pin, lens};
    s.camera = 1;
    for (MaterialType t : {MaterialType::diffuse, MaterialType::specular, MaterialType::glossy,
                           MaterialType::dielectric, MaterialType::translucent}) {
        Material m;
        m.id = std::string(material_type_names.name(t));
        m.type = t;
        // Only the keys the type has are in the file; the others keep their defaults.
        if (t == MaterialType::dielectric || t == MaterialType::translucent) {
            m.rho_r = Color(0.9, 0.8, 0.7);
            m.rho_t = Color(0.6, 0.5, 0.4);
            m.eta = 1.33;
        } else {
            m.rho = Color(0.1, 0.2, 0.3);
        }
        m.roughness = (t == MaterialType::glossy || t == MaterialType::translucent) ? 0.25 : 0.0;
        s.materials.push_back(m);
    }
    Shape ball;
    ball.id = "ball";
    ball.radius = 1.0 / 3.0;
    Shape lamp = ball;
    lamp.id = "lamp";
    lamp.centre = {0, 3, 0};
    s.shapes = {ball, lamp};
    Light point;
    point.id = "point";
    point.position = {1e-7, 2e5, -3};
    point.power = Color(300);
    Light area;
    area.id = "area";
    area.type = LightType::area;
    area.shape = 1;
    area.power = Color(30, 20, 10);
    s.lights = {point, area};
    s.active_lights = {1, 0};
    s.primitives = {{"ball", PrimitiveType::geometric, 0, 4, -1}, {"lamp", PrimitiveType::emissive, 1, 0, 1}};
    s.renderer.type = RendererType::wrt;
    s.renderer.width = 64;
    s.renderer.height = 48;
    s.renderer.samples = 9;
    s.renderer.depth = 20;
    s.renderer.output = "out/a b.ppm";
    const LoadedScene back = parse_scene(scene_to_json(s), "");
    EXPECT_TRUE(back.warnings.empty());
    expect_equal_scenes(s, back.scene);
}
