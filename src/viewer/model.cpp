#include "viewer/model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
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
    // The viewer re-reads and watches its scene, and opening a FIFO would block the window:
    // only a regular file (stat never blocks).
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(file, ec);
    if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
        throw SceneError(file.string(), "", "not a regular file (a FIFO, a device or a folder); the viewer reads "
                                            "and watches a regular scene file");
    LoadedScene loaded = load_scene_file(file);
    set_scene(std::move(loaded.scene), std::move(loaded.warnings));
}

void ViewerModel::set_scene(Scene scene, std::vector<std::string> warnings) {
    auto prepared = prepare(scene, &warnings, prepared_.get());  // throws before anything changes
    ViewerSettings settings = settings_;
    // The file's renderer and display blocks with the command line over them, as render does.
    settings.render = apply_render_options(overrides_, scene);
    settings.tone = scene.display;
    file_cameras_ = scene.cameras;
    file_camera_ = scene.camera;
    scene_ = std::move(scene);
    prepared_ = std::move(prepared);
    settings_ = settings;
    warnings_ = std::move(warnings);
    ++generation_;
    undo_.clear();
    redo_.clear();
    open_group_.clear();
    saved_id_ = state_id_ = next_state_id_++;
}

bool ViewerModel::edit(Edit kind, const std::function<void(Scene&, ViewerSettings&)>& change, std::string* error,
                       std::string_view field, std::string_view group) {
    Scene scene = scene_;
    ViewerSettings settings = settings_;
    change(scene, settings);
    const bool resets = edit_resets(kind);
    std::shared_ptr<const RenderScene> prepared = prepared_;
    std::vector<std::string> warnings = warnings_;
    if (resets) {
        warnings.clear();
        try {
            prepared = prepare(scene, &warnings, prepared_.get());
        } catch (const SceneError& e) {
            // A panel edit: the reason, named by the field, not blamed on the file.
            if (error) *error = std::string(field.empty() ? "edit" : field) + ": " + e.message() +
                                "; the previous value is kept";
            return false;
        }
    }
    // Pausing is run control the user toggles, not a change to undo.
    const bool only_pause = !resets && kind == Edit::run_control && settings.paused != settings_.paused;
    if (!only_pause) {
        const bool coalesce = !group.empty() && group == open_group_ && !undo_.empty();
        if (coalesce) {
            undo_.back().resets |= resets;
        } else {
            undo_.push_back({std::move(scene_), settings_, state_id_, resets});
            if (undo_.size() > kMaxUndoSteps) undo_.erase(undo_.begin());
        }
        open_group_ = std::string(group);
        redo_.clear();
        state_id_ = next_state_id_++;
    }
    scene_ = std::move(scene);
    settings_ = settings;
    if (resets) {
        prepared_ = std::move(prepared);
        warnings_ = std::move(warnings);
        ++generation_;
    }
    return true;
}

void ViewerModel::restore(State& state, std::vector<State>& push_to) {
    // The state being left goes on the other stack; it resets the image if the step did.
    State here{scene_, settings_, state_id_, state.resets};
    if (state.resets) {
        std::vector<std::string> warnings;
        // Every state on the stacks was prepared once, so this succeeds.
        prepared_ = prepare(state.scene, &warnings, prepared_.get());
        warnings_ = std::move(warnings);
        ++generation_;
    }
    const bool paused = settings_.paused;
    scene_ = std::move(state.scene);
    settings_ = state.settings;
    settings_.paused = paused;
    state_id_ = state.id;
    push_to.push_back(std::move(here));
    open_group_.clear();
}

bool ViewerModel::undo() {
    if (undo_.empty()) return false;
    State state = std::move(undo_.back());
    undo_.pop_back();
    restore(state, redo_);
    return true;
}

bool ViewerModel::redo() {
    if (redo_.empty()) return false;
    State state = std::move(redo_.back());
    redo_.pop_back();
    restore(state, undo_);
    return true;
}

bool ViewerModel::set_target_spp(int spp) {
    const Edit kind = settings_.render.estimator == Estimator::stratified ? Edit::renderer : Edit::run_control;
    return edit(kind, [&](Scene& s, ViewerSettings& out) {
        out.render.target_spp = std::max(1, spp);
        s.renderer.samples = out.render.target_spp;
    }, nullptr, "target spp");
}

bool ViewerModel::reset_view() {
    if (!has_scene() || file_camera_ < 0) return false;
    return edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
        s.cameras = file_cameras_;
        s.camera = file_camera_;
    }, nullptr, "reset view");
}

bool ViewerModel::focus_at(double fx, double fy) {
    if (!prepared_) return false;
    const std::optional<double> distance = focus_distance(*prepared_, fx, fy);
    if (!distance || !(*distance > 0)) return false;
    return edit(Edit::lens, [&](Scene& scene, ViewerSettings&) {
        Camera& cam = scene.cameras[size_t(scene.camera)];
        cam.type = CameraType::lens;
        cam.focal_distance = *distance;
    }, nullptr, "click-to-focus");
}

Scene ViewerModel::scene_for_saving() const {
    Scene scene = scene_;
    const RenderSettings& r = settings_.render;
    // pt-naive has no file spelling: it is the PT renderer with a command-line option.
    scene.renderer.type = r.integrator == Integrator::wrt ? RendererType::wrt : RendererType::pt;
    scene.renderer.depth = r.max_depth;
    scene.renderer.samples = r.target_spp;
    scene.display = settings_.tone;
    return scene;
}

std::optional<std::string> check_typed_value(std::string_view field, const double* values, int count, double lo,
                                             double hi) {
    for (int i = 0; i < count; ++i) {
        const double v = values[i];
        char text[96];
        if (!std::isfinite(v)) std::snprintf(text, sizeof text, "%g is not a finite number", v);
        else if (v < lo) std::snprintf(text, sizeof text, "%.6g is below the minimum %.6g", v, lo);
        else if (v > hi) std::snprintf(text, sizeof text, "%.6g is above the maximum %.6g", v, hi);
        else continue;
        return std::string(field) + ": " + text + "; the previous value is kept";
    }
    return std::nullopt;
}

}  // namespace kr::viewer
