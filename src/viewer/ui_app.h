// The viewer window: the GLFW context, the display, the render thread, and the frame loop
// that draws the panel column (ui_panels.h), the status bar and popups (ui_overlays.h), the
// image and the inspector (ui_compare.h), and handles the input (ui_input.h) and the scripted
// runs (ui_script.h). What they share is in ui_context.h.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "viewer/gl_display.h"
#include "viewer/gl_functions.h"
#include "viewer/key_queue.h"
#include "viewer/model.h"
#include "viewer/render_worker.h"
#include "viewer/ui_context.h"
#include "viewer/ui_input.h"
#include "viewer/ui_script.h"
#include "viewer/view_options.h"

struct GLFWwindow;

namespace kr::viewer {

class ViewerApp {
public:
    // With `ranks` (rank 0 of `mpirun -np N keithray view`), full passes are shared with the
    // other ranks, and a stop signal (mpirun ends the job when a rank dies) ends the session.
    explicit ViewerApp(ViewOptions options, SharedPasses* ranks = nullptr);
    ~ViewerApp();
    ViewerApp(const ViewerApp&) = delete;
    ViewerApp& operator=(const ViewerApp&) = delete;

    int run();  // the main loop; returns the exit status

    // The GLFW callbacks.
    void note_input() { input_seen_ = true; }
    void note_key(int key, int action, int mods);
    void queue_key(const KeyEvent& e) {
        input_seen_ = true;
        if (!e.text) input_.note_key_event(e.key, e.action);
        keys_.push(e);
    }
    void note_cursor(double x, double y) { input_seen_ = true; input_.note_cursor(x, y); }
    void note_button(int button, int action, int mods) { input_seen_ = true; input_.note_button(button, action, mods); }
    void note_wheel() { input_seen_ = true; input_.note_wheel(); }
    void note_enter(bool entered) { input_seen_ = true; input_.note_enter(entered); }
    void on_close_request();
    // Files dropped on the window (glfwSetDropCallback): handled at the next frame (ui_file_dialog.h).
    void note_drop(int count, const char** paths);

private:
    // Steps of one UI frame.
    bool draw_frame();  // true when a scripted run is over
    void poll_watch();
    void sync_worker();
    bool fetch_frame();
    void draw_panels();
    void draw_questions(bool cancel, bool confirm);  // the modal questions, last in the frame (cancel: Esc, confirm: Return)
    void update_title();
    void write_status_file(const RunStatus& status);
    bool animating() const;  // something moves without input: redraw at the frame rate
    void request_quit();
    void toggle_fullscreen();
    // The fonts and sizes at the monitor's content scale times the UI scale, when that changed.
    void apply_ui_scale();
    Rgb8Image read_image_region(const PixelRect& rect) const;
    // The MPI job is ending (a stop signal): says so in the window and on standard error, then
    // ends the process with status 1 at once (the render thread may be waiting on a dead rank).
    [[noreturn]] void end_with_the_job();

    ViewOptions options_;
    SharedPasses* ranks_;
    GLFWwindow* window_ = nullptr;
    GlFunctions gl_;
    std::unique_ptr<Display> display_;
    ViewerModel model_;
    std::unique_ptr<RenderWorker> worker_;
    Messages messages_;
    UiState ui_;
    PanelContext ctx_{model_, messages_, ui_};
    InputState input_;
    KeyEventQueue keys_;  // key and text events waiting for ImGui, a frame's worth at a time
    ScriptRun script_;

    // What the render thread was last given.
    struct Submitted {
        uint64_t generation = 0;
        bool paused = false;
        StopRule stop;
        std::optional<PixelBox> region;
        bool denoise = true;
        bool features = false;
        bool halves = false;
    } submitted_;
    DenoiseView shown_view_ = DenoiseView::on;  // the view of the frame in the texture

    // The window.
    bool fullscreen_ = false;
    int windowed_x_ = 0, windowed_y_ = 0, windowed_w_ = 0, windowed_h_ = 0;
    float content_scale_ = 1;  // the monitor's, as GLFW reports it
    float applied_scale_ = 1;  // the scale the fonts and the style are at
    std::string title_;
    std::string status_line_;  // last written to --status-file
    bool failed_ = false;              // a write of --status-file or a render failed: the run exits 1
    bool status_file_failed_ = false;  // said once, not tried again
    bool quit_asked_ = false;  // the quit question is wanted
    bool quit_after_save_ = false;  // "Save and quit" answered: quit once the scene is saved
    uint64_t inside_checked_generation_ = 0;  // ui_.inside_sphere is this generation's
    int settle_frames_ = 0;   // frames still to draw after input, so ImGui settles
    bool input_seen_ = false; // set by the GLFW callbacks
    UiClock::time_point last_frame_{};
};

}  // namespace kr::viewer
