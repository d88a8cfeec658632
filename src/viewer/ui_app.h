// The viewer window: GLFW context, display, ImGui panels, input, and the scripted modes
// (--frames/--screenshot/--measure-latency) that the tests and docs/viewer.md use.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "viewer/files.h"
#include "viewer/gl_display.h"
#include "viewer/gl_functions.h"
#include "viewer/model.h"
#include "viewer/render_worker.h"

struct GLFWwindow;

namespace kr::viewer {

struct ViewOptions {
    std::filesystem::path scene;
    ViewerModel::Overrides overrides;
    ToneSettings tone;
    bool unlimited = false;
    double stop_seconds = 0, stop_noise = 0;  // --time, --noise
    // Scripted mode: edits applied at start, then the run ends by itself.
    int frames = 0;  // full-resolution passes to accumulate before the screenshot
    std::optional<std::pair<double, double>> orbit;        // a left drag of (dx, dy) pixels
    std::optional<std::pair<double, double>> click_focus;  // Ctrl+click at image pixel (x, y)
    std::optional<double> aperture;                        // thin lens with this radius
    std::optional<std::filesystem::path> screenshot;       // image region, read back from GL
    std::optional<std::filesystem::path> save_scene;       // edited scene as JSON
    std::optional<std::filesystem::path> window_shot;      // the whole window, panels included
    int measure_latency = 0;  // edits to time, edit to first displayed frame
    double timeout = 600;     // seconds: a scripted run that gets stuck fails
    bool scripted() const { return frames > 0 || screenshot || save_scene || measure_latency > 0; }
};

class ViewerApp {
public:
    explicit ViewerApp(ViewOptions options);
    ~ViewerApp();
    ViewerApp(const ViewerApp&) = delete;
    ViewerApp& operator=(const ViewerApp&) = delete;

    int run();  // the main loop; returns the exit status

private:
    using Clock = std::chrono::steady_clock;
    enum class SaveKind { ppm, png, exr, pfm, scene };

    // Steps of one UI frame.
    void poll_watch();
    void sync_worker();
    void fetch_frame();
    void handle_input();
    void draw_panels();
    PixelRect image_rect() const;
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

    bool edit(Edit kind, const std::function<void(Scene&, ViewerSettings&)>& change);
    void open_scene(const std::filesystem::path& file);
    void request_save(SaveKind kind, const std::filesystem::path& path);
    void save_now(SaveKind kind, const std::filesystem::path& path);
    void reset_save_paths();

    // Scripted mode: true when the run is over (exit status in script_status_).
    bool script_step(const PixelRect& rect);

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
    std::string status_;  // last save message
    bool pick_focus_ = false;
    std::string image_path_, png_path_, hdr_path_, scene_path_;
    std::optional<std::pair<SaveKind, std::filesystem::path>> pending_save_;
    std::vector<std::filesystem::path> scene_list_;

    // UI frame timing for the Stats panel and --measure-latency.
    double ui_fps_ = 0;
    double ui_work_ = 0;                   // seconds of work per UI frame (smoothed)
    std::vector<double> frame_work_;       // seconds, while rendering
    std::vector<double> frame_intervals_;  // seconds, while rendering
    Clock::time_point last_frame_{};

    // Scripted-mode state.
    int script_status_ = 0;
    int latency_edits_done_ = 0;
    std::optional<uint64_t> latency_waiting_for_;  // generation whose first frame is awaited
    Clock::time_point latency_edit_time_{}, latency_next_edit_{};
    std::vector<double> latencies_;  // seconds
    std::vector<int> latency_scales_;
    Clock::time_point script_start_{};
};

}  // namespace kr::viewer
