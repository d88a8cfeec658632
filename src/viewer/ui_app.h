// The viewer window: GLFW context, display, ImGui panels and input. The scripted modes
// (viewer/script.h), the latency measurement (viewer/latency.h) and the save dialog
// (viewer/save_dialog.h, ui_save.cpp) keep their state and logic in their own files.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "viewer/compare_view.h"
#include "viewer/convergence_log.h"
#include "viewer/files.h"
#include "viewer/gl_display.h"
#include "viewer/image_view.h"
#include "viewer/inspect.h"
#include "viewer/gl_functions.h"
#include "viewer/latency.h"
#include "viewer/model.h"
#include "viewer/navigation.h"
#include "viewer/render_worker.h"
#include "viewer/save_dialog.h"
#include "viewer/script.h"
#include "viewer/status.h"
#include "viewer/view_options.h"

struct GLFWwindow;

namespace kr::viewer {

class ViewerApp {
public:
    explicit ViewerApp(ViewOptions options);
    ~ViewerApp();
    ViewerApp(const ViewerApp&) = delete;
    ViewerApp& operator=(const ViewerApp&) = delete;

    int run();  // the main loop; returns the exit status

private:
    using Clock = std::chrono::steady_clock;

    // Steps of one UI frame.
    bool draw_frame();  // true when a scripted run is over
    void poll_watch();
    void sync_worker();
    bool fetch_frame();
    void handle_input();
    void handle_mouse(const PixelRect& rect);
    void handle_keys();
    void draw_panels();
    void draw_status_bar();
    void draw_help();
    void draw_error_flash();
    void update_title();
    PixelRect view_area() const;   // the free area left of the panel, above the status bar
    PixelRect image_rect() const;  // where the image is drawn in it (zoom and pan)
    bool zoom_keys();              // the zoom keys; true when one acted
    // Inspect and compare (ui_compare.cpp).
    void update_pictures();        // image B, the error or noise map, the figures, the log
    void draw_image(const PixelRect& rect, int fb_w, int fb_h);
    void draw_inspector(const PixelRect& rect);
    void panel_compare();
    void plot_convergence();
    void load_reference(const std::filesystem::path& file, bool automatic);
    std::optional<PixelProbe> probe(int x, int y) const;
    StatsFigures stats_figures() const;
    double status_bar_height() const;  // framebuffer pixels
    bool animating() const;            // something moves without input: redraw at the frame rate
    void request_quit();
    void toggle_fullscreen();
    void show_error(std::string message);
    Rgb8Image read_image_region(const PixelRect& rect) const;

    // Panels.
    void panel_scene();
    void panel_camera();
    void panel_lens();
    void panel_lights();
    void panel_materials();
    void panel_tone_map();
    void panel_renderer();
    void panel_stats();
    void panel_save();
    void overwrite_popup();
    void quit_popup();
    void discard_popup();
    // Panel fields: mouse drags apply live; typed text applies on Enter or focus loss,
    // after check_typed_value. True when `v` was changed and should be applied.
    bool field(const char* label, double* v, int count, float speed, double lo, double hi,
               const char* format = "%.4g");
    bool field_int(const char* label, int& v, int lo, int hi);
    bool edit(Edit kind, const std::function<void(Scene&, ViewerSettings&)>& change,
              std::string_view field = {}, std::string_view group = {});
    // Opens `file` now (a reload when it is the current one); with unsaved edits, asks first.
    void open_scene_asking(const std::filesystem::path& file);
    void open_scene(const std::filesystem::path& file);
    void request_save(SaveKind kind, const std::filesystem::path& path);
    void save_now(SaveKind kind, const std::filesystem::path& path);
    void reset_save_paths();

    // Scripted mode: true when the run is over (exit status in script_status_).
    bool script_step(const PixelRect& rect);
    // --measure-idle, run on every wake-up whether or not a frame is drawn: true when over.
    bool idle_measure_step();
    void write_status_file(const RunStatus& status);

    ViewOptions options_;
    GLFWwindow* window_ = nullptr;
    GlFunctions gl_;
    std::unique_ptr<Display> display_;
    ViewerModel model_;
    std::unique_ptr<RenderWorker> worker_;
    FileWatch watch_;

    uint64_t submitted_generation_ = 0;
    bool submitted_paused_ = false, submitted_unlimited_ = false;
    double submitted_stop_seconds_ = 0, submitted_stop_noise_ = 0;
    std::shared_ptr<const Snapshot> shown_;  // the frame in the texture
    uint64_t shown_serial_ = 0;
    Clock::time_point generation_edited_{};  // when the image last changed by an edit

    std::string error_;   // last load/edit failure, shown in red until the next success
    Clock::time_point error_time_{};  // when it was set: flashed at the pointer for a moment
    std::string status_;  // last save message
    bool pick_focus_ = false;

    // Layout and modes.
    float panel_width_ = 400;  // window points; the user can resize it
    bool panel_visible_ = true, help_visible_ = false, fullscreen_ = false;
    int windowed_x_ = 0, windowed_y_ = 0, windowed_w_ = 0, windowed_h_ = 0;
    std::string title_;
    std::string status_line_;  // last written to --status-file
    bool quit_asked_ = false;  // the quit confirmation popup is wanted
    std::optional<std::filesystem::path> pending_open_;  // open/reload awaiting the discard popup
    bool open_pending_popup_ = false;
    std::optional<std::string> inside_sphere_;  // the camera is inside this sphere
    uint64_t inside_checked_generation_ = 0;

    // Inspect and compare.
    ImageView view_;
    bool zoom_applied_ = false;  // --zoom waits for the first frame's layout
    Comparison compare_;
    bool reference_automatic_ = false;   // the brief's reference for this scene, not --reference
    std::string reference_path_;         // the compare panel's field
    ConvergenceLog convergence_;
    std::optional<CompareFigures> figures_;  // the shown frame (A) against image B
    std::string figures_note_;           // why there are no figures
    Rgb8Image picture_;                  // what draw_bytes shows, as uploaded
    bool picture_current_ = false;       // picture_ is the current mode's, for the shown frame
    double picture_scale_ = 0;           // the false-colour map's top value
    std::string picture_key_;            // what picture_ was made from
    double linear_scale_ = 0;            // tonemap_scale of the shown frame (the inspector)
    std::optional<std::pair<int, int>> locked_probe_;
    bool divider_drag_ = false, middle_pans_ = false;
    bool compare_panel_shown_ = false;   // the panel has been drawn once (the command line opens it)
    double pan_last_x_ = 0, pan_last_y_ = 0;

    // Input.
    DragGesture drags_[3];  // left: orbit, right: pan, middle: dolly (or pan a zoomed image)
    TypedFields typed_;
    Clock::time_point last_motion_{};  // previous frame with motion keys held
    bool motion_keys_held_ = false;
    int settle_frames_ = 0;  // frames still to draw after input, so ImGui settles
    bool input_seen_ = false;   // set by the GLFW callbacks
    int submitted_target_ = 0;
    SavePaths save_paths_;  // the Save panel's fields
    std::optional<std::pair<SaveKind, std::filesystem::path>> pending_save_;
    std::vector<std::filesystem::path> scene_list_;  // the folders listed (empty: list again)
    std::vector<SceneChoice> scene_choices_;

    // UI frame timing for the Stats panel.
    double ui_fps_ = 0;
    double ui_work_ = 0;                   // seconds of work per UI frame (smoothed)
    Clock::time_point last_frame_{};

    // Scripted-mode state (viewer/script.h, viewer/latency.h).
    int script_status_ = 0;
    LatencyMeasure latency_;
    Clock::time_point script_start_{};
    IdleMeasure idle_;

    // Keys pressed since the last frame, as GLFW reported them. ImGui 1.86 (Debian 12) keeps
    // only whether a key is down at each frame, so a press and release between two frames
    // (a short tap on a busy machine) never shows in ImGui::IsKeyPressed.
    std::vector<int> key_presses_;

public:
    void note_input() { input_seen_ = true; }
    void note_key(int key, int action);
    void on_close_request();
};

}  // namespace kr::viewer
