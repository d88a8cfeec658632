// The helpers of the robustness tests (test_robust_*.cpp): small seeded renders, estimates
// of one ray's radiance, image comparisons, the scenes they stress, and scene text to break.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/image_io.h"
#include "render/camera.h"
#include "render/progressive.h"
#include "render/trace.h"
#include "scene/load.h"
#include "test_util.h"

namespace kr::robust {

namespace fs = std::filesystem;

inline RenderState render(const RenderScene& scene, const RenderSettings& settings, int width, int height, int passes) {
    RenderState state(width, height);
    for (int i = 0; i < passes; ++i) render_pass(scene, settings, state);
    return state;
}

inline RenderSettings settings_for(Integrator integrator, int depth = 6, int spp = 1,
                                   LightSampling ls = LightSampling::cone) {
    RenderSettings s;
    s.integrator = integrator;
    s.max_depth = depth;
    s.target_spp = spp;
    s.light_sampling = ls;
    s.seed = 11;
    return s;
}

inline bool all_finite(const RenderState& state) {
    for (const Color& c : state.radiance_sum())
        if (!is_finite(c)) return false;
    for (double d : state.depth_sum())
        if (!std::isfinite(d)) return false;
    return true;
}

// Mean radiance of n independent samples along one ray.
struct Estimate {
    Color mean;
    double stderr_lum = 0;
    int nonfinite = 0;
};
inline Estimate estimate(const RenderScene& scene, const RenderSettings& settings, const Ray& ray, int n) {
    Estimate e;
    double sum_l = 0, sum_l2 = 0;
    int used = 0;
    for (int i = 0; i < n; ++i) {
        Sampler sampler(Rng::for_sample(settings.seed, 0, uint64_t(i)));
        const SampleResult r = trace_sample(scene, settings, ray, sampler);
        if (!is_finite(r.radiance)) {
            ++e.nonfinite;
            continue;
        }
        e.mean += r.radiance;
        const double l = luminance(r.radiance);
        sum_l += l;
        sum_l2 += l * l;
        ++used;
    }
    e.mean = e.mean / double(std::max(used, 1));
    const double mean_l = sum_l / std::max(used, 1);
    e.stderr_lum = std::sqrt(std::max(0.0, sum_l2 / std::max(used, 1) - mean_l * mean_l) / std::max(used, 1));
    return e;
}

inline Ray ray_towards(Vec3 from, Vec3 to) {
    Ray r;
    r.o = from;
    r.d = normalize(to - from);
    return r;
}

// Relative difference of two radiance images: sum |a - b| / sum (|a| + |b|), per channel.
inline double relative_l1(const Image& a, const Image& b) {
    double diff = 0, total = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            diff += std::abs(a.pixels[i][k] - b.pixels[i][k]);
            total += std::abs(a.pixels[i][k]) + std::abs(b.pixels[i][k]);
        }
    return total > 0 ? diff / total : 0.0;
}

// Per-pixel z-scores of the luminance difference of two independent estimates of one
// image; returns the mean of z^2 (about 1 for unbiased estimates of the same image).
// Per pixel, the squared difference of two independent estimates of the same image over
// their combined variance of the mean (z^2; 1 on average for independent random samples).
inline std::vector<double> pixel_z2(const RenderState& a, const RenderState& b) {
    const Image ia = a.radiance(), ib = b.radiance();
    std::vector<double> z2;
    for (size_t i = 0; i < ia.pixels.size(); ++i) {
        const double se2 = std::pow(a.pixel_standard_error(i), 2) + std::pow(b.pixel_standard_error(i), 2);
        const double d = luminance(ia.pixels[i]) - luminance(ib.pixels[i]);
        // Both pixels noise-free (e.g. a miss): they must agree exactly.
        z2.push_back(se2 > 0 ? d * d / se2 : (d == 0 ? 1.0 : 1e9));
    }
    return z2;
}

inline double mean_z2(const RenderState& a, const RenderState& b) {
    const std::vector<double> z2 = pixel_z2(a, b);
    double sum = 0;
    for (double z : z2) sum += z;
    return sum / double(z2.size());
}

inline size_t state_bytes(const RenderState& s) {
    return s.radiance_sum().capacity() * sizeof(Color) + s.radiance_compensation().capacity() * sizeof(Color) +
           s.radiance_sq_sum().capacity() * sizeof(Color) + s.depth_sum().capacity() * sizeof(double) +
           s.luminance_sq_sum().capacity() * sizeof(double) + s.sample_count().capacity() * sizeof(uint32_t) +
           s.sample_index().capacity() * sizeof(uint32_t) + s.plan.active.capacity();
}

// A small still life: floor, diffuse, mirror and glass balls, a point light and (for the
// path tracer) a spherical area light; every length multiplied by `s`, the point light's
// intensity by s^2 (irradiance I cos / d^2) and area radiance unchanged.
inline test::SceneBuilder still_life(double s) {
    test::SceneBuilder b;
    b.scene.cameras[0].position = Vec3(0, 1.5, -7) * s;
    b.scene.cameras[0].target = Vec3(0, 0.6, 0) * s;
    b.sphere(Vec3(0, -1000, 0) * s, 1000 * s, b.material(MaterialType::diffuse, Color(0.7, 0.7, 0.6)));
    b.sphere(Vec3(-1.3, 0.6, 0) * s, 0.6 * s, b.material(MaterialType::diffuse, Color(0.8, 0.2, 0.2)));
    b.sphere(Vec3(0.2, 0.5, 0.8) * s, 0.5 * s, b.material(MaterialType::specular, Color(0.9)));
    const int glass = b.material(MaterialType::dielectric);
    b.scene.materials[glass].rho_r = b.scene.materials[glass].rho_t = Color(0.95);
    b.sphere(Vec3(1.2, 0.45, -0.6) * s, 0.45 * s, glass);
    b.sphere(Vec3(0.6, 0.12, -1.8) * s, 0.12 * s, b.material(MaterialType::diffuse, Color(0.2, 0.3, 0.9)));
    b.point_light(Vec3(2, 4, -3) * s, Color(40) * (s * s));
    b.emitter(Vec3(-2, 3.5, 1) * s, 0.5 * s, Color(12), b.material(MaterialType::diffuse, Color(0)));
    return b;
}

// A closed room of six wall spheres of radius R whose inner sides are 5 from the origin,
// a diffuse ball and a spherical light.
inline test::SceneBuilder room(double R) {
    test::SceneBuilder b;
    b.scene.cameras[0].position = {0, 0, -4.5};
    b.scene.cameras[0].target = {0, -0.5, 0};
    b.scene.cameras[0].fov = 80;
    const int white = b.material(MaterialType::diffuse, Color(0.75));
    const int red = b.material(MaterialType::diffuse, Color(0.75, 0.2, 0.2));
    const double c = R + 5;
    b.sphere({-c, 0, 0}, R, red);
    b.sphere({c, 0, 0}, R, white);
    b.sphere({0, c, 0}, R, white);
    b.sphere({0, -c, 0}, R, white);
    b.sphere({0, 0, c}, R, white);
    b.sphere({0, 0, -c}, R, white);
    b.sphere({1, -3.5, 1}, 1.5, b.material(MaterialType::specular, Color(0.9)));
    b.sphere({-1.5, -4, -0.5}, 1, white);
    b.emitter({0, 4, 0}, 0.6, Color(15), b.material(MaterialType::diffuse, Color(0)));
    return b;
}

using test::furnace;

// A scratch folder per test.
class TempDir : public test::ScratchDirTest {};

// A valid scene file; `renderer` and `extra` let tests change one thing.
inline std::string scene_json(const std::string& output = "out.ppm", const std::string& dims = "[16, 12]",
                              const std::string& light = R"({"id": "lamp", "type": "point", "position": [0, 3, -3], "power": [50, 50, 50]})",
                              const std::string& material = R"({"id": "white", "type": "diffuse", "rho": [0.8, 0.8, 0.8]})") {
    return R"({
  "cameras": [{"id": "cam", "type": "pinhole", "fov": 45, "aspect": 1.333, "position": [0, 0, -5], "target": [0, 0, 0]}],
  "materials": [)" + material + R"(],
  "shapes": [{"id": "ball", "type": "sphere", "centre": [0, 0, 0], "radius": 1}],
  "lights": [)" + light + R"(],
  "scene": {
    "camera": "cam", "lights": ["lamp"],
    "primitives": [{"id": "ball", "type": "geometric", "shape": "ball", "material": "white"}],
    "renderer": {"type": "WRT", "dimensions": )" + dims + R"(, "samples": 2, "depth": 4, "output": ")" + output + R"("}
  }
})";
}

// The SceneError message of loading `text`, or "" if it loads.
inline std::string load_error(const std::string& text) {
    try {
        parse_scene(text, "hostile.json");
    } catch (const SceneError& e) {
        return e.what();
    }
    return "";
}


}  // namespace kr::robust
