#include "viewer/model.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/limits.h"
#include "core/memory.h"
#include "scene/load.h"
#include "scene/save.h"
#include "scene/scene_list.h"
#include "viewer/navigation.h"
#include "viewer/scene_edit.h"

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
    } catch (const std::exception& e) {
        if (!is_out_of_memory(e)) throw;
        throw SceneError(scene.source_file.string(), "", "not enough memory for the prepared scene and its BVH");
    }
}

// The scene as saved, with every camera's view (position, target, fov, aspect) and the
// active camera blanked: what is left is what an edit other than the view changes.
std::string without_view(Scene scene) {
    for (Camera& c : scene.cameras) {
        c.position = Vec3(0, 0, 0);
        c.target = Vec3(0, 0, 1);
        c.fov = 45;
        c.aspect = 1;
    }
    scene.camera = 0;
    return scene_to_json(scene);
}

// Whether two render settings draw the same samples (every member: one that joins
// RenderSettings joins this).
bool same_sampling(const RenderSettings& a, const RenderSettings& b) {
    return a.integrator == b.integrator && a.estimator == b.estimator && a.allocation == b.allocation &&
           a.light_sampling == b.light_sampling && a.max_depth == b.max_depth && a.target_spp == b.target_spp &&
           a.rr_depth == b.rr_depth && a.seed == b.seed && a.kernels == b.kernels;
}

bool same_camera(const Camera& a, const Camera& b) {
    return a.id == b.id && a.type == b.type && a.fov == b.fov && a.aspect == b.aspect && a.distance == b.distance &&
           a.position == b.position && a.target == b.target && a.focal_distance == b.focal_distance && a.alpha == b.alpha;
}

// Whether an edit of `kind` left the authored scene as it was: a camera or lens edit changes
// only the cameras (compared member by member: cheap, as a drag repeats its step each frame);
// any other is compared as saved.
bool unchanged(Edit kind, const Scene& a, const Scene& b) {
    if (kind == Edit::camera || kind == Edit::lens) {
        if (a.camera != b.camera || a.cameras.size() != b.cameras.size()) return false;
        for (size_t i = 0; i < a.cameras.size(); ++i)
            if (!same_camera(a.cameras[i], b.cameras[i])) return false;
        return true;
    }
    return scene_to_json(a) == scene_to_json(b);
}

}  // namespace

void ViewerModel::mark_saved() {
    saved_id_ = state_id_;
    saved_json_ = without_view(scene_for_saving());
}

void ViewerModel::save_scene_to(const std::filesystem::path& file, bool adopt) {
    save_scene_json(scene_for_saving(), file);
    if (!adopt) return;
    auto move = [&](Scene& s) { s = scene_moved_to(s, file); };
    move(scene_);
    for (State& st : undo_) move(st.scene);
    for (State& st : redo_) move(st.scene);
    mark_saved();
}

bool ViewerModel::only_view_changed() const {
    return dirty() && without_view(scene_for_saving()) == saved_json_;
}

void ViewerModel::load_keeping_view(const std::filesystem::path& file) {
    const std::vector<Camera> cameras = scene_.cameras;
    const int active = scene_.camera;
    load(file);
    if (cameras.size() != scene_.cameras.size()) return;
    edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
        for (size_t i = 0; i < cameras.size(); ++i) copy_view(cameras[i], s.cameras[i]);
        s.camera = active;
    }, nullptr, "keep the view");
}

void ViewerModel::load(const std::filesystem::path& file) {
    // The viewer re-reads and watches its scene, and opening a FIFO would block the window:
    // only a regular file (stat never blocks).
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(file, ec);
    if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
        throw SceneError(file.string(), "", "not a regular file (a FIFO, a device or a folder); the viewer reads "
                                            "and watches a regular scene file");
    LoadedScene loaded = load_scene_file(file);
    // A bundled scene of the install tree renders and saves its image into output/ under the
    // current folder (as `keithray render` writes it), never into the install tree.
    if (const auto output = output_outside_install(loaded.scene, data_dir()))
        loaded.scene.renderer.output = std::filesystem::absolute(*output, ec).lexically_normal().string();
    set_scene(std::move(loaded.scene), std::move(loaded.warnings));
}

void ViewerModel::set_scene(Scene scene, std::vector<std::string> warnings) {
    auto prepared = prepare(scene, &warnings, prepared_.get());  // throws before anything changes
    ViewerSettings settings = settings_;
    // The file's renderer and display blocks with the command line over them, as render does.
    settings.render = apply_render_options(overrides_, scene);
    settings.tone = scene.display;
    // The denoise mode is the view's (ViewerSettings::denoise, the one place the window reads):
    // the file's or the command line's when given, else the view as it was (denoised at start).
    if (settings.tone.denoise) settings.denoise = *settings.tone.denoise == Denoise::on ? DenoiseView::on : DenoiseView::off;
    settings.tone.denoise.reset();
    file_cameras_ = scene.cameras;
    file_resolution_ = {scene.renderer.width, scene.renderer.height};
    file_camera_ = scene.camera;
    scene_ = std::move(scene);
    prepared_ = std::move(prepared);
    settings_ = settings;
    warnings_ = std::move(warnings);
    view_base_generation_ = ++generation_;
    undo_.clear();
    redo_.clear();
    open_group_.clear();
    saved_id_ = state_id_ = next_state_id_++;
    saved_json_ = without_view(scene_for_saving());
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
    // An edit of the scene that leaves what the render sees as it was (a new material that is
    // a copy of the old, a focal distance with the aperture closed) keeps the samples: the
    // render scene is taken (its ids are the panels'), the generation stays.
    const bool same_image = resets && prepared_ && prepared && kind != Edit::renderer && kind != Edit::scene &&
                            renders_same(*prepared_, *prepared) && same_sampling(settings.render, settings_.render);
    // Nothing changed at all (a drag held still repeats its step every frame, a step stopped
    // at a surface): no undo step, no unsaved edit, the samples kept.
    if (same_image && unchanged(kind, scene, scene_)) return true;
    if (!prepared_) {
        // No scene yet (the command line's settings before the first load, or a broken
        // starting scene): nothing the user edited, nothing to undo or to save.
        scene_ = std::move(scene);
        settings_ = settings;
        return true;
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
    if (resets && same_image) {
        prepared_ = std::move(prepared);
        warnings_ = std::move(warnings);
    } else if (resets) {
        prepared_ = std::move(prepared);
        warnings_ = std::move(warnings);
        // A camera edit keeps the base of the camera edits before it; any other starts anew.
        const bool navigating = kind == Edit::camera && view_base_generation_ != 0;
        ++generation_;
        if (!navigating) view_base_generation_ = generation_;
    }
    return true;
}

void ViewerModel::restore(State& state, std::vector<State>& push_to) {
    // The state being left goes on the other stack; it resets the image if the step did.
    State here{scene_, settings_, state_id_, state.resets};
    if (state.resets) {
        std::vector<std::string> warnings;
        // Every state on the stacks was prepared once, so this succeeds.
        auto prepared = prepare(state.scene, &warnings, prepared_.get());
        const bool same_image = renders_same(*prepared_, *prepared) && same_sampling(state.settings.render, settings_.render);
        prepared_ = std::move(prepared);
        warnings_ = std::move(warnings);
        if (!same_image) view_base_generation_ = ++generation_;
    }
    const bool paused = settings_.paused;
    scene_ = std::move(state.scene);
    settings_ = state.settings;
    settings_.paused = paused;
    state_id_ = state.id;
    push_to.push_back(std::move(here));
    open_group_.clear();
}

bool ViewerModel::cancel_step(std::string_view group) {
    if (group.empty() || open_group_ != group || undo_.empty()) return false;
    std::vector<State> dropped;
    State state = std::move(undo_.back());
    undo_.pop_back();
    restore(state, dropped);  // the state left is dropped, not kept for redo
    return true;
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

bool ViewerModel::set_resolution(int width, int height, bool fit_camera) {
    width = std::clamp(width, 1, kMaxDimension);
    height = std::clamp(height, 1, kMaxDimension);
    return edit(Edit::renderer, [&](Scene& s, ViewerSettings&) {
        s.renderer.width = width;
        s.renderer.height = height;
        if (fit_camera) s.cameras[size_t(s.camera)].aspect = double(width) / height;
    }, nullptr, "resolution");
}

bool ViewerModel::view_as_loaded() const {
    if (!has_scene() || scene_.camera != file_camera_ || size_t(scene_.camera) >= file_cameras_.size()) return false;
    const Camera& a = camera();
    const Camera& f = file_cameras_[size_t(scene_.camera)];
    return a.position == f.position && a.target == f.target && a.fov == f.fov && a.aspect == f.aspect &&
           std::make_pair(scene_.renderer.width, scene_.renderer.height) == file_resolution_;
}

bool ViewerModel::reset_view() {
    if (!has_scene() || file_camera_ < 0) return false;
    return edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
        // The view only: the lens the user set up (type, focus, aperture) is not the view.
        for (size_t i = 0; i < s.cameras.size() && i < file_cameras_.size(); ++i) copy_view(file_cameras_[i], s.cameras[i]);
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
    // What the window shows, as `render` reads it back: the split view saves denoised, as Save does.
    scene.display.denoise = settings_.denoise != DenoiseView::off ? Denoise::on : Denoise::off;
    return scene;
}

double shortest_decimal(float value) {
    // to_chars without a precision writes the shortest text that parses back to the same float.
    char text[64];
    const auto [end, ec] = std::to_chars(text, text + sizeof text, value);
    if (ec != std::errc()) return double(value);
    double out = double(value);
    std::from_chars(text, end, out);
    return out;
}

Color picked_colour(const Color& before, const float rgb[3]) {
    double out[3] = {before.x, before.y, before.z};
    for (int i = 0; i < 3; ++i)
        if (rgb[i] != float(out[i])) out[i] = shortest_decimal(rgb[i]);
    return Color(out[0], out[1], out[2]);
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
