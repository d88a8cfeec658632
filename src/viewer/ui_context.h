// What the window's panels (ui_panels.h), its input handling (ui_input.h) and its scripted
// mode (ui_script.h) work on: the model and the one edit path into it, the message line,
// and the window's state (the frame on screen, the layout, the scene files, the inspect and
// compare tool). ViewerApp (ui_app.h) owns them and hands each frame a PanelContext.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "viewer/compare_view.h"
#include "viewer/convergence_log.h"
#include "viewer/file_browser.h"
#include "viewer/files.h"
#include "viewer/image_view.h"
#include "viewer/inspect.h"
#include "viewer/model.h"
#include "viewer/navigation.h"
#include "viewer/render_worker.h"
#include "viewer/save_dialog.h"
#include "viewer/status.h"

namespace kr::viewer {

using UiClock = std::chrono::steady_clock;

// The status bar's message line. A message belongs to the event that made it: it expires
// (kStatusSeconds, kErrorSeconds), and opening or reloading a scene clears it.
struct Messages {
    static constexpr double kStatusSeconds = 8, kErrorSeconds = 20;
    std::string error;                 // the last refused edit or failed load, red until the next success
    UiClock::time_point error_time{};  // when it was set: flashed at the pointer for a moment
    std::string status;                // the last save or keep message
    UiClock::time_point status_time{};
    bool error_sticks = false;         // there is no scene to show: the error is the state, it stays
    void show_error(std::string message, UiClock::time_point now = UiClock::now()) {
        error = std::move(message);
        error_time = now;
    }
    void show_status(std::string message, UiClock::time_point now = UiClock::now()) {
        status = std::move(message);
        status_time = now;
    }
    void clear() {
        error.clear();
        status.clear();
    }
    // Drops the messages older than their time; true when one went.
    bool expire(UiClock::time_point now) {
        auto old = [&](UiClock::time_point t, double limit) { return std::chrono::duration<double>(now - t).count() > limit; };
        bool gone = false;
        if (!status.empty() && old(status_time, kStatusSeconds)) status.clear(), gone = true;
        if (!error.empty() && !error_sticks && old(error_time, kErrorSeconds)) error.clear(), gone = true;
        return gone;
    }
    // The error is new enough to show at the pointer.
    bool flashing(UiClock::time_point now) const {
        return !error.empty() && std::chrono::duration<double>(now - error_time).count() < 3;
    }
};

// The inspect and compare tool (ui_compare.cpp draws the image and the inspector,
// ui_panel_compare.cpp its panel): zoom and pan, image B, the picture the view shows, the
// figures of A against B, the locked probe and the convergence log.
struct CompareTool {
    ImageView view;
    bool smooth = false;        // linear filtering of a scaled image
    bool zoom_applied = false;  // --zoom waits for the first frame's layout
    Comparison comparison;
    bool reference_automatic = false;  // the brief's reference for this scene, not --reference
    std::string reference_path;        // the panel's field
    ConvergenceLog convergence;
    std::optional<CompareFigures> figures;  // the shown frame (A) against image B
    std::string figures_note;               // why there are no figures
    bool picture_current = false;  // the texture's bytes are the current view's, for the shown frame
    double picture_scale = 0;      // the false-colour map's top value
    std::optional<DepthRange> picture_range;  // the depth view's nearest and farthest hit
    std::string picture_missing;   // a feature view's picture: why there is none
    std::string picture_key;       // what the picture was made from (cleared: make it again)
    double linear_scale = 0;       // tonemap_scale of the shown frame (the inspector)
    std::optional<std::pair<int, int>> locked_probe;
    std::string hover_text;   // the inspector's numbers for the pixel under the pointer (status bar)
    std::string hover_feature;  // ... of which the feature view's layer ("albedo 0.8 0.5 0.5"; empty in other views)
    bool probe_box = false;   // ... also in a box at the pointer (I)
    bool open_panel = false;  // the command line asked for a view or a probe: the panel opens once
};

// The scene file shown and the others on offer.
struct SceneFiles {
    FileWatch watch;
    std::vector<std::filesystem::path> folders;  // listed in `choices` (empty: list again)
    std::vector<SceneChoice> choices;
    std::optional<std::filesystem::path> pending_open;  // an open or reload awaiting the discard question
    bool ask_discard = false;                           // open that question this frame
    // The file dialogs (ui_file_dialog.h): the ImGui browser shown (none: closed), opened
    // this frame, the platform's chooser running, the files dropped on the window.
    std::optional<FileBrowser> browser;
    bool open_browser = false;
    bool focus_name = false;   // give its name field the keyboard again (after Return entered a folder)
    int browser_frames = 0;    // frames its popup has been drawn (the name field has the keyboard from the second)
    std::string browser_name;  // the Save image dialog's format: its extension by default
    std::shared_ptr<ChildChooser> chooser;
    std::vector<std::filesystem::path> drops;
    // The settings file (file_browser.h): the recent files and the UI scale the user chose
    // (times the monitor's content scale); `settings_file` empty: none read or written.
    ViewerSettingsFile settings;
    std::filesystem::path settings_file;
    double ui_scale = 1;
};

// The questions' popup names (ImGui IDs, begun at the top level by ViewerApp::draw_questions).
inline constexpr const char* kQuitQuestion = "Quit?";
inline constexpr const char* kDiscardQuestion = "Unsaved edits";
inline constexpr const char* kOverwriteQuestion = "Overwrite?";
inline constexpr const char* kSaveWhereQuestion = "Save the scene as";

// The Save panel's paths (edited by the user), the save awaiting the overwrite question and
// a denoised image's save awaiting its frame's halves (save_waits_for_halves).
struct SaveTool {
    SavePaths paths;
    std::optional<std::pair<SaveKind, std::filesystem::path>> pending;
    struct Waiting {
        SaveKind kind;
        std::filesystem::path path;
        uint64_t generation = 0;  // the scene's when asked: an edit before the frame cancels it
    };
    std::optional<Waiting> waiting;
    bool ask_overwrite = false;  // open that question this frame
    bool ask_where = false;      // Save of a read-only scene (a bundled one): ask where, this frame
    bool read_only = false;      // the scene's file is not to be written (scene_file_read_only)
};

// The panel's width in window points: the default (labels uncut at the default font), the
// room kept for labels, the grip along its left edge, and the width shown in a window
// `window_width` wide for the one the user chose: at most half the window, at least the minimum.
inline constexpr float kDefaultPanelWidth = 440, kMinPanelWidth = 260, kPanelLabelWidth = 150, kPanelGripWidth = 8;
inline float shown_panel_width(float chosen, float window_width) {
    return std::max(kMinPanelWidth, std::min(chosen, window_width * 0.5f));
}

// The window's state that the panels, the input handling and the scripted mode share.
struct UiState {
    TypedFields typed;                       // numbers being typed into panel fields
    std::shared_ptr<const Snapshot> shown;   // the frame in the texture
    uint64_t shown_serial = 0;
    int framebuffer_width = 0, framebuffer_height = 0;  // this frame's
    float panel_width = kDefaultPanelWidth;  // window points, as the user chose (shown_panel_width)
    bool panel_visible = true, help_visible = false;
    bool pick_focus = false;                 // the next click on the image focuses the lens
    NavigationSettings nav;                  // orbit or fly, speed, stop at surfaces
    std::optional<int> selected;             // the selected primitive (index in Scene::primitives)
    std::optional<int> selected_light;       // else a light with no primitive of its own (a point light), from the outliner
    int panel_tab = 1;                       // the panel's tab (ui_panels.h: PanelTab; Object first)
    bool show_tab = true;                    // bring panel_tab to the front this frame (the first: Object)
    int outliner_shown_line = -1;            // the outliner line last scrolled to (the selection's)
    std::string outliner_filter;             // the outliner lists the rows that match it
    // Named widgets' centres in window points, this frame (the status file's at=, for the
    // window tests that click them).
    struct Mark {
        std::string name;
        float x = 0, y = 0;
    };
    std::vector<Mark> marks;
    std::string status_fields;               // the status bar's fields shown ("state,spp,...": the status file's bar=)
    int axis_lock = -1;                      // moving the selection: along x, y or z only (-1: the view plane)
    // Where the selection is seen (sphere_coverage), for its tint where its outline is off
    // the image; computed again when the generation or the selection changes.
    struct SelectionTint {
        uint64_t generation = 0;
        int primitive = -1, cols = 0, rows = 0;
        std::vector<unsigned char> cells;
        bool any = false;  // some cell sees it
    } selection_tint;
    std::string move_hint;                   // a move (M) is on: what it does, shown on the image
    bool drawing_region = false;             // B: the next left drag draws the render region
    std::optional<PixelBox> region;          // only these image pixels refine (none: all)
    std::optional<PixelBox> region_draft;    // the box being drawn
    std::optional<std::string> inside_sphere;  // the camera is inside this sphere
    double ui_fps = 0, ui_work = 0;          // UI frames per second, seconds of work each (smoothed)
    SceneFiles files;
    CompareTool compare;
    SaveTool save;
};

// What a panel is drawn over: the model, the edit path, the messages and the window's state.
struct PanelContext {
    ViewerModel& model;
    Messages& messages;
    UiState& ui;

    // Applies `change` through ViewerModel::edit (its reset rule); a refusal becomes the
    // error message. `field` names the value in messages; edits of one `group` (a drag, a
    // held key, one field) make one undo step.
    bool edit(Edit kind, const std::function<void(Scene&, ViewerSettings&)>& change, std::string_view field = {},
              std::string_view group = {});
    // The frame on screen when it shows the model's current image, else null.
    const Snapshot* frame() const;
    // ... and only when it is at full resolution.
    const Snapshot* full_frame() const;
    // Whether, with no frame of the current generation, the window shows one of an earlier
    // view of the same scene (the camera moves: ViewerModel::view_base_generation).
    bool shows_earlier_view() const;
    double status_bar_height() const;  // framebuffer pixels
    PixelRect view_area() const;       // the free area left of the panel, above the status bar
    PixelRect image_rect() const;      // where the image is drawn in it (zoom and pan)
    // The selection when it names a primitive of the current scene (an undo may remove it).
    std::optional<int> selection() const;
};

// The selection's edits, each one undoable step (viewer/scene_edit.h).
void duplicate_selection(PanelContext& ctx);  // Ctrl+D: the copy beside it, selected
void delete_selection(PanelContext& ctx);     // Delete
void add_sphere_at_target(PanelContext& ctx); // a sphere at the camera's target, selected

// Opens `file` now (a reload when it is the current one); on failure the last good scene stays.
// `keep_view`: a reload that puts the current view back over the file's cameras.
void open_scene(PanelContext& ctx, const std::filesystem::path& file, bool keep_view = false);
// The same, asking first when there are unsaved edits.
void open_scene_asking(PanelContext& ctx, const std::filesystem::path& file);

// Writes `kind` to `path` (viewer/save_dialog.h), asking first when a file would be
// replaced; the outcome is the status message (ui_panel_save.cpp). A denoised image of a
// render still refining is written with the next frame, which carries the halves
// (SaveTool::waiting, finish_waiting_save).
void request_save(PanelContext& ctx, SaveKind kind, const std::filesystem::path& path);
// Each frame, after the newest frame is fetched: writes the save waiting for the halves once
// the shown frame has them, or drops it, saying so, where the scene changed meanwhile.
void finish_waiting_save(PanelContext& ctx);
// Save: the scene over its own file, without asking (Ctrl+S).
void save_scene_in_place(PanelContext& ctx);
// The overwrite question (request_save asks for it), drawn every frame after the other windows.
// `confirm`: Return was pressed (the save-where question saves).
void overwrite_popup(PanelContext& ctx, bool cancel, bool confirm = false);

}  // namespace kr::viewer
