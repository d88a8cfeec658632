// `keithray view`'s command line, GL-free so that the tests read it as the viewer does:
// the flags shared with render (render/options.h) and the viewer's own.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "render/options.h"
#include "viewer/compare_view.h"

namespace kr::viewer {

struct ViewOptions {
    std::filesystem::path scene;
    RenderOptions render;  // the flags render takes too: kept across loads of another file
    bool unlimited = false;
    // Scripted mode: edits applied at start, then the run ends by itself.
    int frames = 0;  // full-resolution passes to accumulate before the screenshot
    std::optional<std::pair<double, double>> orbit;        // a left drag of (dx, dy) pixels
    std::optional<std::pair<double, double>> click_focus;  // Ctrl+click at image pixel (x, y)
    std::optional<std::pair<double, double>> select;        // a click at image pixel (x, y): selects
    std::optional<std::pair<double, double>> move_selection;  // then a drag of it by (dx, dy) image pixels
    std::optional<std::array<int, 4>> region;               // the render region x0,y0,x1,y1 (image pixels)
    std::optional<double> aperture;                        // thin lens with this radius
    std::optional<std::filesystem::path> screenshot;       // image region, read back from GL
    std::optional<std::filesystem::path> save_scene;       // edited scene as JSON
    std::optional<std::filesystem::path> save_image;       // as the Save panel (and render -o) write it
    std::optional<std::filesystem::path> window_shot;      // the whole window, panels included
    int measure_latency = 0;  // edits to time, edit to first displayed frame
    double measure_idle = 0;  // seconds of idle CPU to measure, done and then paused
    std::optional<std::filesystem::path> status_file;  // the status line, rewritten on change
    // Inspect and compare (interactive too).
    std::optional<std::filesystem::path> reference;  // image B; default: the brief's for its scenes
    CompareSettings compare;                          // --view, --split, --error
    double zoom = 0;                                  // 0: fit; else about the image's centre
    std::optional<std::pair<int, int>> probe;         // a locked probe at image pixel (x, y)
    std::optional<std::filesystem::path> stats_json;  // figures written when a scripted run ends
    std::optional<double> ui_scale;  // --ui-scale: the UI's size (times the monitor's scale)
    std::vector<std::filesystem::path> drop;  // --drop: files handled as dropped on the window
    double timeout = 600;     // seconds: a scripted run that gets stuck fails
    bool help = false;        // -h, --help
    // Something a scripted run writes once the render has its passes (or --frames alone).
    bool writes_after_render() const { return frames > 0 || screenshot || save_scene || save_image || stats_json; }
    bool scripted() const { return writes_after_render() || measure_latency > 0 || measure_idle > 0; }
};

// Reads the arguments after "view". Throws UsageError (core/args.h) on bad usage.
// A flag only view takes is one line here, one in view_usage() and a member above.
ViewOptions parse_view_options(int argc, char** argv);

// What makes the files of a run unusable, checked before anything is opened, or "" if
// nothing: a scene or --reference that is not a regular file (the viewer re-reads and
// watches its scene, and opening a FIFO would block before the --timeout clock could end
// the run), or an output (--screenshot, --window-shot, --save-image and its depth file,
// --stats-json, --status-file; --save-scene onto the reference) that would replace an input.
// Also two outputs naming one file (--save-image's depth file included), and an output its
// writer would refuse (a folder, a device, a read-only file).
std::string view_files_problem(const ViewOptions& options);

// What makes the command line's pixels mean nothing in a `width` x `height` image, checked
// once the scene is loaded and before the window opens, or "" if nothing: --select,
// --click-focus or --probe outside it, a --region reaching outside it.
std::string script_problem(const ViewOptions& options, int width, int height);

// `keithray view --help`: the shared flags from their table, then the viewer's own.
std::string view_usage();

}  // namespace kr::viewer
