// Shared helpers for the test suite.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "render/trace.h"
#include "render/render_scene.h"
#include "scene/load.h"
#include "scene/scene.h"
#include "viewer/model.h"

// KR_TEST_SANITIZED: this build runs under a sanitizer, which reserves terabytes of address
// space, so tests that run the program under `ulimit -v` skip.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define KR_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define KR_TEST_SANITIZED 1
#endif
#endif
// KR_TEST_TSAN: ThreadSanitizer, whose runtime maps files that `ulimit -f` cuts short (it
// dies of SIGBUS), so tests that run the program under a file size limit skip.
#if defined(__SANITIZE_THREAD__)
#define KR_TEST_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define KR_TEST_TSAN 1
#endif
#endif

namespace kr::test {

inline std::string read_file(const std::filesystem::path& p) {
    std::ifstream f(p);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

struct CommandResult {
    int status;  // exit status, -1 if the command did not exit normally
    std::string out, err;
};

// Runs a shell command with stdout and stderr captured in files under `dir`.
inline CommandResult run_command(const std::string& command, const std::filesystem::path& dir) {
    const std::string cmd =
        command + " >'" + (dir / "stdout").string() + "' 2>'" + (dir / "stderr").string() + "'";
    const int raw = std::system(cmd.c_str());
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, read_file(dir / "stdout"), read_file(dir / "stderr")};
}

// A fixture with a scratch folder per test (named after the suite, the test and the process),
// removed after it even where the test took its write permission away. `cli` runs the
// keithray executable there, its output captured.
class ScratchDirTest : public testing::Test {
protected:
    std::filesystem::path dir;

    void SetUp() override {
        const testing::TestInfo* info = testing::UnitTest::GetInstance()->current_test_info();
        std::string name = "keithray_" + std::string(info->test_suite_name()) + "_" + info->name() + "_" +
                           std::to_string(::getpid());
        for (char& c : name)
            if (c == '/') c = '_';
        dir = std::filesystem::temp_directory_path() / name;
        std::filesystem::remove_all(dir);
        std::filesystem::create_directories(dir);
    }
    void TearDown() override {
        std::error_code ec;
        std::filesystem::permissions(dir, std::filesystem::perms::owner_all, std::filesystem::perm_options::add, ec);
        std::filesystem::remove_all(dir, ec);
    }
    std::filesystem::path write(const std::filesystem::path& name, const std::string& text) {
        const std::filesystem::path file = dir / name;
        std::ofstream(file, std::ios::binary) << text;
        return file;
    }
    CommandResult cli(const std::string& args) {
        return run_command(std::string("'") + KEITHRAY_EXE + "' " + args, dir);
    }
};

// The brief's scene `n` (res/scenes/assignment_0n.json) and its reference render.
inline std::filesystem::path brief_scene_file(int n) {
    return std::filesystem::path(KEITHRAY_RES_DIR) / "scenes" / ("assignment_0" + std::to_string(n) + ".json");
}
inline std::filesystem::path brief_reference_file(int n) {
    return std::filesystem::path(KEITHRAY_RES_DIR) / "references" / ("assignment_0" + std::to_string(n) + ".ppm");
}

// `text` with its one occurrence of `from` replaced by `to`; the test fails where `from` is
// not there exactly once.
inline std::string edit_once(std::string text, const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << "no " << from;
    EXPECT_EQ(text.find(from, at + 1), std::string::npos) << "ambiguous " << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

// The viewer's model with the brief's scene `n` loaded.
inline viewer::ViewerModel brief_model(int n) {
    viewer::ViewerModel m;
    m.load(brief_scene_file(n));
    return m;
}

// Scene `n` of the brief at size x size pixels.
inline Scene brief_scene(int n, int size) {
    Scene scene = load_scene_file(brief_scene_file(n)).scene;
    scene.renderer.width = scene.renderer.height = size;
    return scene;
}

// The relative tolerance of a render's analytic value: the rounding of the single-precision
// lanes where they trace the scene (lane_kernels), else double's.
inline double analytic_tolerance(const RenderScene& scene, const RenderSettings& settings) {
    const LaneKernels kernels = lane_kernels(scene, settings);
    return single_precision(kernels) ? 1e-6 : 1e-9;
}

// Upper critical value of the chi-square distribution with `dof` degrees of freedom at
// significance `alpha` (Wilson-Hilferty; accurate to a few percent for dof >= 10).
inline double chi_square_critical(int dof, double z_alpha = 3.719 /* alpha = 1e-4 */) {
    const double k = dof;
    const double a = 2.0 / (9.0 * k);
    return k * std::pow(1.0 - a + z_alpha * std::sqrt(a), 3.0);
}

// Pearson's statistic of observed counts against expected counts (cells with tiny
// expectations merged by the caller).
inline double chi_square(const std::vector<double>& observed, const std::vector<double>& expected) {
    double stat = 0;
    for (size_t i = 0; i < observed.size(); ++i) {
        const double d = observed[i] - expected[i];
        stat += d * d / expected[i];
    }
    return stat;
}

// Minimal scene builder for analytic tests. Everything it adds is referenced.
struct SceneBuilder {
    Scene scene;

    SceneBuilder() {
        Camera cam;
        cam.id = "cam";
        cam.position = {0, 0, -10};
        cam.target = {0, 0, 0};
        scene.cameras.push_back(cam);
        scene.camera = 0;
        scene.renderer.width = 8;
        scene.renderer.height = 8;
        scene.renderer.samples = 16;
        scene.renderer.depth = 6;
        scene.renderer.output = "out.ppm";
    }
    int material(MaterialType type, Color rho = Color(0.8)) {
        Material m;
        m.id = "m" + std::to_string(scene.materials.size());
        m.type = type;
        m.rho = rho;
        scene.materials.push_back(m);
        return int(scene.materials.size()) - 1;
    }
    int sphere(Vec3 centre, double radius, int material) {
        Shape s;
        s.id = "s" + std::to_string(scene.shapes.size());
        s.centre = centre;
        s.radius = radius;
        scene.shapes.push_back(s);
        Primitive p;
        p.id = s.id;
        p.shape = int(scene.shapes.size()) - 1;
        p.material = material;
        scene.primitives.push_back(p);
        return p.shape;
    }
    // An emissive sphere with its area light, active.
    int emitter(Vec3 centre, double radius, Color radiance, int material) {
        const int shape = sphere(centre, radius, material);
        Light l;
        l.type = LightType::area;
        l.shape = shape;
        l.power = radiance;
        scene.primitives.back().type = PrimitiveType::emissive;
        scene.primitives.back().light = active_light(l);
        return shape;
    }
    void point_light(Vec3 position, Color intensity) {
        Light l;
        l.type = LightType::point;
        l.position = position;
        l.power = intensity;
        active_light(l);
    }
    // Adds a light, lists it in the scene block, returns its index.
    int active_light(Light l) {
        l.id = "l" + std::to_string(scene.lights.size());
        scene.lights.push_back(l);
        const int index = int(scene.lights.size()) - 1;
        scene.active_lights.push_back(index);
        return index;
    }
    RenderScene build() const { return prepare_scene(scene); }
};

// The brief's furnace: a unit sphere of material `type` (rho, or rhoR = rhoT = rho) inside a
// black emitting sphere of radius 20 and radiance Le.
inline SceneBuilder furnace(MaterialType type, Color rho, double le) {
    SceneBuilder b;
    const int m = b.material(type, rho);
    b.scene.materials[m].rho_r = rho;
    b.scene.materials[m].rho_t = rho;
    b.sphere({0, 0, 0}, 1, m);
    b.emitter({0, 0, 0}, 20, Color(le), b.material(MaterialType::diffuse, Color(0)));
    return b;
}

// The prepared scene's lights of one type, in their order in scene.lights.
inline std::vector<RenderLight> lights_of(const RenderScene& scene, LightType type) {
    std::vector<RenderLight> out;
    for (const RenderLight& light : scene.lights)
        if (light.type == type) out.push_back(light);
    return out;
}

}  // namespace kr::test
