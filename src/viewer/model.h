// The viewer's state without any window: the authored scene (what the file says, edited
// by the panels and saved back), the prepared render scene built from it, the render and
// display settings, and a generation counter that advances on every edit that changes
// the image. The window and the scripted modes both edit through this class, so the
// reset rule (viewer/edit.h) is applied in one place and unit-tested.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "render/render.h"
#include "render/render_scene.h"
#include "scene/scene.h"
#include "viewer/edit.h"

namespace kr::viewer {

struct ViewerSettings {
    RenderSettings render;    // integrator, estimator, light sampling, depth, target spp, seed
    bool unlimited = false;   // keep refining past target_spp
    double stop_seconds = 0;  // stop after this much render time (0: no limit)
    double stop_noise = 0;    // stop at this estimated relative error, adaptively (0: off)
    bool paused = false;
    ToneSettings tone;
};

class ViewerModel {
public:
    // An empty model: nothing to render until a scene is set.
    ViewerModel() = default;

    // Loads and prepares `file`. On a SceneError (bad file, or a scene prepare_scene
    // refuses) the model keeps its current scene and rethrows.
    void load(const std::filesystem::path& file);
    // Takes a loaded scene and advances the generation. Render settings are reset to the
    // file's renderer block, except the command-line overrides; the tone map is kept.
    void set_scene(Scene scene, std::vector<std::string> warnings = {});

    bool has_scene() const { return prepared_ != nullptr; }
    const Scene& scene() const { return scene_; }
    const std::shared_ptr<const RenderScene>& prepared() const { return prepared_; }
    const ViewerSettings& settings() const { return settings_; }
    const std::vector<std::string>& warnings() const { return warnings_; }
    uint64_t generation() const { return generation_; }

    // Applies `change` to the authored scene and settings. An edit that changes the image
    // rebuilds the render scene and advances the generation; if the result cannot be
    // prepared, the edit is undone and false is returned with the reason in `error`.
    bool edit(Edit kind, const std::function<void(Scene&, ViewerSettings&)>& change,
              std::string* error = nullptr);

    // The active camera (the scene must have one).
    const Camera& camera() const { return scene_.cameras[size_t(scene_.camera)]; }

    // Click-to-focus: sets the active camera's focal distance to the surface seen at image
    // point (fx, fy) in [0,1)^2. A pinhole camera becomes a thin lens (its aperture, 0 by
    // default, keeps the image unchanged until the aperture is opened). False on a miss.
    bool focus_at(double fx, double fy);

    // The authored scene with its renderer block brought in line with the settings
    // (type, depth, samples), as it is saved.
    Scene scene_for_saving() const;

    // Settings kept across loads of another file: those given on the command line.
    struct Overrides {
        std::optional<int> spp, depth;
        std::optional<Integrator> integrator;
        std::optional<Estimator> estimator;
        std::optional<Allocation> allocation;
        std::optional<LightSampling> light_sampling;
        std::optional<uint64_t> seed;
    };
    void set_overrides(const Overrides& overrides) { overrides_ = overrides; }

private:
    Scene scene_;
    std::shared_ptr<const RenderScene> prepared_;
    ViewerSettings settings_;
    std::vector<std::string> warnings_;
    uint64_t generation_ = 0;
    Overrides overrides_;
};

}  // namespace kr::viewer
