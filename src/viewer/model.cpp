#include "viewer/model.h"

#include <stdexcept>

#include "scene/load.h"
#include "viewer/navigation.h"

namespace kr::viewer {

namespace {

// prepare_scene throws SceneError; CameraModel::from throws invalid_argument (camera
// position equal to target), which an edit can produce.
// `previous`: the render scene before the edit, whose BVH serves again if no sphere moved.
std::shared_ptr<const RenderScene> prepare(const Scene& scene, std::vector<std::string>* warnings,
                                           const RenderScene* previous) {
    try {
        return std::make_shared<const RenderScene>(prepare_scene(scene, warnings, previous));
    } catch (const std::invalid_argument& e) {
        throw SceneError(scene.source_file.string(), "", e.what());
    }
}

}  // namespace

void ViewerModel::load(const std::filesystem::path& file) {
    LoadedScene loaded = load_scene_file(file);
    set_scene(std::move(loaded.scene), std::move(loaded.warnings));
}

void ViewerModel::set_scene(Scene scene, std::vector<std::string> warnings) {
    auto prepared = prepare(scene, &warnings, prepared_.get());  // throws before anything changes
    ViewerSettings settings = settings_;
    const ToneSettings tone = settings_.tone;
    settings.render = RenderSettings::from_scene(scene.renderer);
    if (overrides_.spp) settings.render.target_spp = *overrides_.spp;
    if (overrides_.depth) settings.render.max_depth = std::min(*overrides_.depth, kMaxDepth);
    if (overrides_.integrator) settings.render.integrator = *overrides_.integrator;
    if (overrides_.estimator) settings.render.estimator = *overrides_.estimator;
    if (overrides_.allocation) settings.render.allocation = *overrides_.allocation;
    if (overrides_.light_sampling) settings.render.light_sampling = *overrides_.light_sampling;
    if (overrides_.seed) settings.render.seed = *overrides_.seed;
    settings.tone = tone;
    scene_ = std::move(scene);
    prepared_ = std::move(prepared);
    settings_ = settings;
    warnings_ = std::move(warnings);
    ++generation_;
}

bool ViewerModel::edit(Edit kind, const std::function<void(Scene&, ViewerSettings&)>& change, std::string* error) {
    if (!edit_resets(kind)) {
        change(scene_, settings_);
        return true;
    }
    Scene scene = scene_;
    ViewerSettings settings = settings_;
    change(scene, settings);
    std::vector<std::string> warnings;
    try {
        prepared_ = prepare(scene, &warnings, prepared_.get());
    } catch (const SceneError& e) {
        if (error) *error = e.what();
        return false;
    }
    scene_ = std::move(scene);
    settings_ = settings;
    warnings_ = std::move(warnings);
    ++generation_;
    return true;
}

bool ViewerModel::focus_at(double fx, double fy) {
    if (!prepared_) return false;
    const std::optional<double> distance = focus_distance(*prepared_, fx, fy);
    if (!distance || !(*distance > 0)) return false;
    return edit(Edit::lens, [&](Scene& scene, ViewerSettings&) {
        Camera& cam = scene.cameras[size_t(scene.camera)];
        cam.type = CameraType::lens;
        cam.focal_distance = *distance;
    });
}

Scene ViewerModel::scene_for_saving() const {
    Scene scene = scene_;
    const RenderSettings& r = settings_.render;
    // pt-naive has no file spelling: it is the PT renderer with a command-line option.
    scene.renderer.type = r.integrator == Integrator::wrt ? RendererType::wrt : RendererType::pt;
    scene.renderer.depth = r.max_depth;
    scene.renderer.samples = r.target_spp;
    return scene;
}

}  // namespace kr::viewer
