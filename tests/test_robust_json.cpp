// Hostile scene files: NaN and Infinity literals, strings for numbers, huge arrays, deep
// nesting, duplicate and dangling ids, empty scenes, a hundred thousand primitives.
// One test per row of the matrix in docs/robustness.md; everything is seeded; images are
// small and compared statistically or against analytic values.
#include "robustness_util.h"

namespace fs = std::filesystem;
using namespace kr;
using namespace kr::robust;

// =======================================================================================
// JSON

TEST(RobustJson, NanAndInfinityLiteralsAreRefused) {
    const std::string base = scene_json();
    for (const char* literal : {"NaN", "nan", "Infinity", "-Infinity", "inf", "1e999", "-1e400"}) {
        std::string text = base;
        text = test::edit_once(text, "\"radius\": 1", std::string("\"radius\": ") + literal);
        const std::string error = load_error(text);
        EXPECT_NE(error, "") << literal;
        EXPECT_NE(error.find("hostile.json"), std::string::npos) << error;
        const bool names_it = error.find("malformed JSON at line 4") != std::string::npos ||
                              error.find("not a finite number") != std::string::npos;
        EXPECT_TRUE(names_it) << literal << ": " << error;
    }
}

TEST(RobustJson, StringsForNumbers) {
    const std::string base = scene_json();
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"\"radius\": 1", "\"radius\": \"1\""},
        {"[16, 12]", "[\"16\", 12]"},
        {"\"samples\": 2", "\"samples\": \"2\""},
        {"\"depth\": 4", "\"depth\": \"4\""},
        {"\"fov\": 45", "\"fov\": \"45deg\""},
        {"\"power\": [50, 50, 50]", "\"power\": [\"50\", 50, 50]"},
    };
    for (const auto& [from, to] : cases) {
        std::string text = base;
        text = test::edit_once(text, from, to);
        const std::string error = load_error(text);
        EXPECT_NE(error.find("got string"), std::string::npos) << to << ": " << error;
    }
}

// Huge arrays: a million-element vector or primitive list is refused with its size (how long
// that takes is no test's business: RobustJson.HundredThousandPrimitives prints load times).
TEST(RobustJson, HugeArrays) {
    std::string numbers = "[0";
    for (int i = 1; i < 1000000; ++i) numbers += ",0";
    numbers += "]";
    std::string text = scene_json();
    text = test::edit_once(text, "\"centre\": [0, 0, 0]", "\"centre\": " + numbers);
    std::string error = load_error(text);
    EXPECT_NE(error.find("/shapes/0/centre: expected an array of 3 finite numbers, got an array of 1000000 elements"),
              std::string::npos)
        << error.substr(0, 200);
    text = scene_json();
    text = test::edit_once(text, "\"lights\": [\"lamp\"]", "\"lights\": " + numbers);
    error = load_error(text);
    EXPECT_NE(error.find("/scene/lights/0: expected a light id (a string), got number 0"), std::string::npos) << error;
}

// Deep nesting: 10^5 (and 10^6) nested arrays or objects are refused before parsing, with a
// clear error and no stack overflow (nlohmann's DOM is recursive).
TEST(RobustJson, DeepNesting) {
    for (size_t depth : {size_t(100000), size_t(1000000)}) {
        const std::string arrays = std::string(depth, '[') + std::string(depth, ']');
        std::string error = load_error(arrays);
        EXPECT_NE(error.find("nesting deeper than 64 levels at line 1, column 65"), std::string::npos) << error;
        std::string objects;
        for (size_t i = 0; i < depth; ++i) objects += "{\"a\":";
        objects += "0" + std::string(depth, '}');
        error = load_error(objects);
        EXPECT_NE(error.find("nesting deeper than 64 levels"), std::string::npos) << error;
        // Inside a valid scene, unbalanced and never closed.
        std::string text = scene_json();
        text = test::edit_once(text, "\"radius\": 1", "\"radius\": " + std::string(depth, '['));
        error = load_error(text);
        EXPECT_NE(error.find("nesting deeper than 64 levels at line 4"), std::string::npos) << error;
    }
}

// Ids: duplicates within a category are errors, across categories legal; dangling ids are
// errors naming the valid ones (more in test_load.cpp: DuplicateIdInACategory,
// DanglingMaterialId, DanglingCameraLightAndShapeIds).
TEST(RobustJson, DuplicateAndDanglingIds) {
    std::string text = scene_json();
    text = test::edit_once(text, "\"shapes\": [", "\"shapes\": [{\"id\": \"ball\", \"type\": \"sphere\", \"centre\": [1, 0, 0], \"radius\": 1}, ");
    EXPECT_NE(load_error(text).find("/shapes/1/id: duplicate shape id \"ball\""), std::string::npos) << load_error(text);
    text = scene_json();
    text = test::edit_once(text, "\"cameras\": [", "\"cameras\": [{\"id\": \"cam\", \"type\": \"pinhole\", \"fov\": 45, \"aspect\": 1, \"position\": [0, 0, -5], "
                 "\"target\": [0, 0, 0]}, ");
    EXPECT_NE(load_error(text).find("duplicate camera id \"cam\""), std::string::npos) << load_error(text);
    // One id in every category (and repeated primitive ids): legal.
    text = scene_json("out.ppm", "[16, 12]",
                      R"({"id": "ball", "type": "point", "position": [0, 3, -3], "power": [50, 50, 50]})",
                      R"({"id": "ball", "type": "diffuse", "rho": [0.8, 0.8, 0.8]})");
    text = test::edit_once(text, "\"lights\": [\"lamp\"]", "\"lights\": [\"ball\"]");
    text = test::edit_once(text, "\"material\": \"white\"", "\"material\": \"ball\"");
    EXPECT_EQ(load_error(text), "");
    // Dangling: the light the scene lists, and an area light's shape.
    text = scene_json();
    text = test::edit_once(text, "\"lights\": [\"lamp\"]", "\"lights\": [\"sun\"]");
    EXPECT_NE(load_error(text).find("/scene/lights/0: no light with id \"sun\"; expected one of \"lamp\""),
              std::string::npos)
        << load_error(text);
}

// Empty scenes: no primitives and no lights load, render black and finite; an empty file or
// object is a clear error.
TEST(RobustJson, EmptyScene) {
    const std::string empty = R"({
  "cameras": [{"id": "cam", "type": "pinhole", "fov": 45, "aspect": 1, "position": [0, 0, -5], "target": [0, 0, 0]}],
  "scene": {"camera": "cam", "lights": [], "primitives": [],
            "renderer": {"type": "PT", "dimensions": [8, 8], "samples": 1, "depth": 6, "output": "out.ppm"}}
})";
    const LoadedScene loaded = parse_scene(empty, "empty.json");
    const RenderScene scene = prepare_scene(loaded.scene);
    for (Integrator integrator : {Integrator::wrt, Integrator::pt, Integrator::pt_naive}) {
        const RenderState state = render(scene, settings_for(integrator), 8, 8, 2);
        for (const Color& c : state.radiance_sum()) EXPECT_EQ(c, Color());
        for (double d : state.mean_depth()) EXPECT_EQ(d, kMissDepth);
    }
    EXPECT_NE(load_error("").find("malformed JSON"), std::string::npos);
    EXPECT_NE(load_error("{}").find("missing key \"scene\""), std::string::npos);
    EXPECT_NE(load_error("{\"scene\": {}}").find("missing key"), std::string::npos);
    EXPECT_NE(load_error("null").find("expected a JSON object at the top level"), std::string::npos);
}

// 100,000 primitives: the file loads, is prepared and renders a small image in seconds; the
// time is printed for docs/robustness.md. Every primitive is emissive with its own active
// light, the worst case for the loader's and prepare_scene's cross-checks.
TEST(RobustJson, HundredThousandPrimitives) {
    constexpr int kCount = 100000;
    std::string text = R"({"cameras": [{"id": "cam", "type": "pinhole", "fov": 60, "aspect": 1, "position": [0, 0, -80], "target": [0, 0, 0]}],
"materials": [{"id": "m", "type": "diffuse", "rho": [0.7, 0.7, 0.7]}, {"id": "e", "type": "diffuse", "rho": [0, 0, 0]}],
"shapes": [)";
    std::string lights = "\"lights\": [", light_ids = "\"lights\": [", prims = "\"primitives\": [";
    Rng rng(1, 2);
    for (int i = 0; i < kCount; ++i) {
        const std::string id = std::to_string(i);
        char buf[160];
        std::snprintf(buf, sizeof buf, R"({"id": "s%d", "type": "sphere", "centre": [%.4f, %.4f, %.4f], "radius": %.4f})",
                      i, 60 * rng.next() - 30, 60 * rng.next() - 30, 60 * rng.next() - 30, 0.05 + 0.2 * rng.next());
        text += std::string(i ? "," : "") + buf;
        const bool emissive = i % 2 == 0;
        if (emissive) {
            lights += std::string(i ? "," : "") + R"({"id": "l)" + id + R"(", "type": "area", "shape": "s)" + id +
                      R"(", "power": [1, 1, 1]})";
            light_ids += std::string(i ? "," : "") + "\"l" + id + "\"";
            prims += std::string(i ? "," : "") + R"({"id": "p)" + id + R"(", "type": "emissive", "shape": "s)" + id +
                     R"(", "material": "e", "light": "l)" + id + "\"}";
        } else {
            prims += R"(,{"id": "p)" + id + R"(", "type": "geometric", "shape": "s)" + id + R"(", "material": "m"})";
        }
    }
    text += "],\n" + lights + "],\n\"scene\": {\"camera\": \"cam\", " + light_ids + "], " + prims +
            "],\n\"renderer\": {\"type\": \"PT\", \"dimensions\": [32, 32], \"samples\": 1, \"depth\": 4, "
            "\"output\": \"out.ppm\"}}}";
    const auto t0 = std::chrono::steady_clock::now();
    const LoadedScene loaded = parse_scene(text, "many.json");
    const auto t1 = std::chrono::steady_clock::now();
    const RenderScene scene = prepare_scene(loaded.scene);
    const auto t2 = std::chrono::steady_clock::now();
    const RenderState state = render(scene, settings_for(Integrator::pt, 4, 1), 32, 32, 1);
    const auto t3 = std::chrono::steady_clock::now();
    auto sec = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
    EXPECT_EQ(loaded.scene.primitives.size(), size_t(kCount));
    EXPECT_EQ(scene.spheres.size(), size_t(kCount));
    EXPECT_EQ(test::lights_of(scene, LightType::area).size(), size_t(kCount / 2));
    ASSERT_TRUE(all_finite(state));
    EXPECT_EQ(state.nonfinite_samples, 0u);
    double lit = 0;
    for (const Color& c : state.radiance_sum()) lit += c.x;
    EXPECT_GT(lit, 0);
    std::printf("[ timing   ] 100k primitives (50k area lights), %.1f MB of JSON: parse+load %.2f s, "
                "prepare %.2f s, 32x32 PT 1 spp render %.2f s\n",
                text.size() / 1e6, sec(t0, t1), sec(t1, t2), sec(t2, t3));
    // Generous bounds: the quadratic cross-checks this guards against took minutes.
    EXPECT_LT(sec(t0, t1), 30.0);
    EXPECT_LT(sec(t1, t2), 10.0);
}
