// The viewer's state without any window: the authored scene (what the file says, edited
// by the panels and saved back), the prepared render scene built from it, the render and
// display settings, a generation counter that advances on every edit that changes the
// image, and the undo history. The window and the scripted modes both edit through this
// class, so the reset rule (viewer/edit.h) is applied in one place and unit-tested.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "render/options.h"
#include "render/settings.h"
#include "render/render_scene.h"
#include "render/stop_rule.h"
#include "scene/scene.h"
#include "viewer/edit.h"

namespace kr::viewer {

// The display of the denoiser (render/denoise.h): the raw estimate, the denoised one, or
// the raw left half beside the denoised right half.
enum class DenoiseView { off, on, split };
inline constexpr EnumNames<DenoiseView, 3> denoise_view_names{{"off", "on", "split"}};

struct ViewerSettings {
    RenderSettings render;    // integrator, estimator, light sampling, depth, target spp, seed
    bool unlimited = false;   // keep refining past target_spp
    StopRule stop;            // its time and noise rules (0: off); stop_rule() adds the pass limit
    bool paused = false;
    ToneSettings tone;
    DenoiseView denoise = DenoiseView::on;  // what the image shows (a display setting, as tone)

    // When the estimate stops refining: after target_spp passes (none when unlimited), or
    // by the time or noise rule.
    StopRule stop_rule() const {
        StopRule rule = stop;
        rule.max_passes = unlimited ? kUnlimitedPasses : render.target_spp;
        return rule;
    }
};

// What to do when the watched scene file changes on disk.
enum class WatchAction {
    reload,            // no unsaved edits: load it
    reload_keep_view,  // only the view changed (orbit, pan, ...): load it and keep the view
    ask                // unsaved edits: ask whether to reload (losing them), take the file's
                       // changes and keep the view, or keep the edits
};

class ViewerModel {
public:
    // An empty model: nothing to render until a scene is set.
    ViewerModel() = default;

    // Loads and prepares `file`. On a SceneError (bad file, or a scene prepare_scene
    // refuses) the model keeps its current scene and rethrows.
    void load(const std::filesystem::path& file);
    // Takes a loaded scene and advances the generation. Render settings are reset to the
    // file's renderer block and the tone map to its display block, except the
    // command-line overrides. The undo history starts again; the scene counts as saved.
    void set_scene(Scene scene, std::vector<std::string> warnings = {});

    bool has_scene() const { return prepared_ != nullptr; }
    const Scene& scene() const { return scene_; }
    const std::shared_ptr<const RenderScene>& prepared() const { return prepared_; }
    const ViewerSettings& settings() const { return settings_; }
    const std::vector<std::string>& warnings() const { return warnings_; }
    uint64_t generation() const { return generation_; }
    // The generation before the camera edits that led to this one (the generation itself when
    // the last resetting edit was not a camera edit): frames of the generations from it on
    // show this scene and settings from an earlier view, which the window shows while the
    // user navigates until the current view's frame comes.
    uint64_t view_base_generation() const { return view_base_generation_; }

    // Applies `change` to the authored scene and settings. An edit that changes the image
    // rebuilds the render scene and advances the generation; if the result cannot be
    // prepared, the edit is undone and false is returned with the reason in `error`,
    // naming `field` when given ("camera position: ...; the previous value is kept").
    // Consecutive edits of the same non-empty `group` (one drag, one held key) make one
    // undo step until seal_undo_step() is called. Pausing is not an undoable edit.
    bool edit(Edit kind, const std::function<void(Scene&, ViewerSettings&)>& change,
              std::string* error = nullptr, std::string_view field = {}, std::string_view group = {});
    // Ends the open undo group: the next edit starts a new step.
    void seal_undo_step() { open_group_.clear(); }
    // Takes back the open undo step of `group` as if it never happened (a cancelled move:
    // nothing to redo); false when that group's step is not the open one.
    bool cancel_step(std::string_view group);

    // Undo / redo of scene and settings edits (the pause state stays as it is).
    bool can_undo() const { return !undo_.empty(); }
    bool can_redo() const { return !redo_.empty(); }
    bool undo();
    bool redo();

    // A new target spp. The running estimate keeps its samples and refines on (or stops, if
    // it already has as many): run control. Except with the stratified estimator, whose
    // strata divide each pixel for the target: there the image restarts.
    bool set_target_spp(int spp);

    // The render resolution (a renderer edit: the image restarts). With `fit_camera`, the
    // active camera's aspect becomes width / height, so the picture is not stretched.
    bool set_resolution(int width, int height, bool fit_camera);
    // The active camera's view and the resolution are the file's (what a reference image
    // of the file shows).
    bool view_as_loaded() const;
    // The resolution the file gives.
    std::pair<int, int> file_resolution() const { return file_resolution_; }

    // Puts the active camera's view (position, target, fov, aspect) back as the file has it
    // (an undoable camera edit); its lens (type, focal distance, aperture) stays.
    bool reset_view();

    // Edits not yet saved: the state differs from the one loaded or last saved.
    bool dirty() const { return state_id_ != saved_id_; }
    // After the scene was written to its own file: the current state counts as saved.
    void mark_saved();
    // Writes scene_for_saving() to `file`. `adopt` (Save As): `file` becomes the scene's
    // file (its output rewritten to name the same image from there, in the undo history
    // too) and the state counts as saved; else (a copy) nothing changes here.
    void save_scene_to(const std::filesystem::path& file, bool adopt);
    // The unsaved edits are only of the view: the cameras' position, target, fov and aspect,
    // and which camera is active. The view is not what an editor of the file changes.
    bool only_view_changed() const;
    WatchAction on_file_changed() const {
        return !dirty() ? WatchAction::reload : only_view_changed() ? WatchAction::reload_keep_view : WatchAction::ask;
    }
    // Loads `file` (a reload: the file changed) and puts the current view back over its
    // cameras when it has as many: the file's changes, the user's view (an undoable step).
    void load_keeping_view(const std::filesystem::path& file);

    // The active camera (the scene must have one).
    const Camera& camera() const { return scene_.cameras[size_t(scene_.camera)]; }

    // Click-to-focus: sets the active camera's focal distance to the surface seen at image
    // point (fx, fy) in [0,1)^2. A pinhole camera becomes a thin lens (its aperture, 0 by
    // default, keeps the image unchanged until the aperture is opened). False on a miss.
    bool focus_at(double fx, double fy);

    // The authored scene with its renderer block brought in line with the settings
    // (type, depth, samples) and its display block with the tone map, as it is saved.
    Scene scene_for_saving() const;

    // Settings kept across loads of another file: those given on the command line
    // (render/options.h; the stop rules in it are the caller's).
    void set_overrides(const RenderOptions& overrides) { overrides_ = overrides; }

private:
    // One undo step: the state before it, and whether going back changes the image.
    struct State {
        Scene scene;
        ViewerSettings settings;
        uint64_t id = 0;
        bool resets = false;
    };
    void restore(State& state, std::vector<State>& push_to);

    static constexpr size_t kMaxUndoSteps = 256;

    Scene scene_;
    std::shared_ptr<const RenderScene> prepared_;
    ViewerSettings settings_;
    std::vector<std::string> warnings_;
    uint64_t generation_ = 0;
    uint64_t view_base_generation_ = 0;
    RenderOptions overrides_;

    std::vector<State> undo_, redo_;
    std::string open_group_;  // the group the newest undo step may still absorb
    uint64_t next_state_id_ = 1, state_id_ = 0, saved_id_ = 0;
    std::string saved_json_;             // scene_for_saving() as loaded or last saved, without the view
    std::vector<Camera> file_cameras_;  // as loaded, for reset_view
    int file_camera_ = -1;
    std::pair<int, int> file_resolution_{0, 0};
};

}  // namespace kr::viewer
