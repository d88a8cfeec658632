#include "viewer/view_options.h"

#include <cmath>
#include <cstdio>
#include <string_view>
#include <vector>

#include "core/file_write.h"
#include "core/image_formats.h"
#include "core/limits.h"
#include "scene/scene_list.h"
#include "viewer/image_view.h"

namespace kr::viewer {

namespace {

constexpr const char* kViewUsageHead = R"(keithray view: the interactive viewer

Usage:
  keithray view [SCENE.json] [options]

Opens SCENE.json (default: the bundled assignment_03.json; a bundled scene of an installed
keithray is read-only: Save asks where to save it, and its image goes to output/ under the
current folder) in a window that refines the image pass by pass. The panels on the right edit camera, lens, lights, materials, tone
map and renderer; any edit that changes the image restarts at once from a
low-resolution preview. The status bar shows the state, spp, progress and noise. The
scene file is watched and reloaded when it changes (asking first if there are unsaved
edits). In the window, F1 or ? lists the keys and mouse controls.

Options (as for render; they stay in force when another scene is opened):
)";

constexpr const char* kViewOnlyOptions = R"(  --unlimited           keep refining past the target spp
  --reference FILE      image B for the compare views and PSNR/RMSE (PPM, PNG, EXR, PFM);
                        default: the brief's reference render for the brief's scenes
  --view MODE           render, reference, split, error, noise, samples, albedo, normal
                        or depth (default render)
  --split F             the split view's divider at fraction F of the image width (0.5)
  --error METRIC        the error view's per-pixel error: absolute or relative
  --zoom Z              show the image at Z screen pixels per pixel (up to 16) about its centre
  --probe X,Y           lock the pixel inspector on image pixel (X, Y)
  --ui-scale S          the panels' and text's size, 0.5 to 3, times the monitor's content
                        scale (default: the UI scale set in the window, kept with the recent
                        files in $XDG_CONFIG_HOME/keithray/viewer.json, else 1)
  --drop FILE           as if FILE were dropped on the window (repeatable): a scene (.json)
                        opens, an image becomes image B; anything else is an error
  -h, --help            this text
Edits made at the start, as the mouse makes them (pixels within the image):
  --aperture A          make the camera a thin lens of aperture radius A
  --orbit DX,DY         a left-button drag of (DX, DY) pixels (orbit)
  --click-focus X,Y     Ctrl+click at image pixel (X, Y): focus there
  --select X,Y          a click at image pixel (X, Y): selects the sphere there
  --move-selection DX,DY  then move it (M) by (DX, DY) image pixels in the view plane
                        (needs --select)
  --region X0,Y0 X1,Y1  refine only the image pixels [X0, X1) x [Y0, Y1) (the B key's box;
                        X0 < X1, Y0 < Y1, whole pixels)
Scripted runs (tests, measurements; the window still opens, e.g. under xvfb-run; each
output its own file):
  --frames N            accumulate N full-resolution passes (at most the target spp)
  --screenshot OUT.ppm  then write the image region as drawn by the display shader (.png: as PNG)
  --save-scene OUT.json then save the edited scene
  --save-image OUT.ppm  then save the image as the Save panel does, which is what
                        'keithray render -o OUT.ppm' writes of the same render: OUT.ppm (or
                        .png) and its depth map OUT-depth.ppm, OUT.exr with every layer, or
                        OUT.pfm and OUT-depth.pfm
  --window-shot OUT.ppm and the whole window, panels included (.png: as PNG)
  --measure-latency N   time N orbit edits from the edit to the first frame on screen
  --measure-idle S      once done, the process's CPU over S seconds with no input; then
                        paused (unlimited), the same again; printed as % of a core
  --status-file FILE    rewrite FILE with the status line (state, spp, target, generation,
                        unsaved edits) whenever it changes: for scripts driving the window
  --stats-json FILE     then write spp, elapsed, Mrays/s, noise, the probe, and PSNR/RMSE
                        against image B when there is one, as JSON
  --timeout S           fail a scripted run after S seconds (default 600)
)";

std::pair<double, double> parse_pair(const std::string& flag, const std::string& text) {
    const size_t comma = text.find(',');
    if (comma == std::string::npos) throw UsageError{flag + " expects X,Y, got " + quote_user_text(text, 40)};
    return {parse_number(flag, text.substr(0, comma), -1e6, 1e6), parse_number(flag, text.substr(comma + 1), -1e6, 1e6)};
}

}  // namespace

ViewOptions parse_view_options(int argc, char** argv) {
    ViewOptions o;
    bool have_scene = false;
    for (ArgCursor args(argc, argv); args.next();) {
        const std::string& arg = args.arg();
        auto value = [&] { return args.value(); };
        if (read_shared_flag(args, o.render)) continue;
        if (arg == "-h" || arg == "--help") o.help = true;
        else if (arg == "--unlimited") o.unlimited = true;
        else if (arg == "--aperture") o.aperture = parse_number(arg, value(), 0, 1e9);
        else if (arg == "--orbit") o.orbit = parse_pair(arg, value());
        else if (arg == "--click-focus") o.click_focus = parse_pair(arg, value());
        else if (arg == "--select") o.select = parse_pair(arg, value());
        else if (arg == "--move-selection") o.move_selection = parse_pair(arg, value());
        else if (arg == "--region") {
            const std::string first = value(), second = value();  // "X0,Y0" then "X1,Y1": two pairs
            const auto a = parse_pair(arg, first), b = parse_pair(arg, second);
            const std::string given = quote_user_text(first + " " + second, 60);
            for (const double v : {a.first, a.second, b.first, b.second})
                if (v != std::floor(v)) throw UsageError{"--region takes whole image pixels, got " + given};
            // The pixels [X0, X1) x [Y0, Y1): none when a side is empty or inverted.
            if (!(a.first < b.first && a.second < b.second))
                throw UsageError{"--region X0,Y0 X1,Y1 refines the pixels [X0, X1) x [Y0, Y1): it needs X0 < X1 and "
                                 "Y0 < Y1, got " + given + ", an empty region"};
            o.region = std::array<int, 4>{int(a.first), int(a.second), int(b.first), int(b.second)};
        }
        else if (arg == "--frames") o.frames = int(parse_integer(arg, value(), 1, kMaxSamples));
        else if (arg == "--screenshot") o.screenshot = value();
        else if (arg == "--save-scene") o.save_scene = value();
        else if (arg == "--save-image") {
            o.save_image = value();
            // Named as the Save panel names it: never a scene file, nor a name of no format.
            if (!format_by_extension(*o.save_image))
                throw UsageError{"--save-image needs a name ending in .ppm, .png, .exr or .pfm, got " +
                                 quote_user_text(o.save_image->string(), 80)};
        }
        else if (arg == "--window-shot") o.window_shot = value();
        else if (arg == "--measure-latency") o.measure_latency = int(parse_integer(arg, value(), 1, 10000));
        else if (arg == "--measure-idle") o.measure_idle = parse_number(arg, value(), 0.1, 3600);
        else if (arg == "--status-file") o.status_file = value();
        else if (arg == "--ui-scale") o.ui_scale = parse_number(arg, value(), 0.5, 3);
        else if (arg == "--drop") o.drop.emplace_back(value());
        else if (arg == "--reference") o.reference = value();
        else if (arg == "--view") o.compare.mode = parse_name(arg, value(), view_mode_names);
        else if (arg == "--split") o.compare.split = parse_number(arg, value(), 0, 1);
        else if (arg == "--error") o.compare.metric = parse_name(arg, value(), error_metric_names);
        else if (arg == "--zoom") o.zoom = parse_number(arg, value(), 0.125, kMaxZoom);
        else if (arg == "--probe") {
            const auto [x, y] = parse_pair(arg, value());
            o.probe = {int(std::floor(x)), int(std::floor(y))};
        } else if (arg == "--stats-json") o.stats_json = value();
        else if (arg == "--timeout") o.timeout = parse_number(arg, value(), 1, 1e7);
        else if (!arg.empty() && arg[0] == '-') throw unknown_option(arg);
        else if (have_scene) throw UsageError{"view opens one scene; got a second: " + quote_user_text(arg)};
        else {
            o.scene = arg;
            have_scene = true;
        }
    }
    // A drag of the selection needs one: without --select it would move nothing.
    if (o.move_selection && !o.select)
        throw UsageError{"--move-selection drags the selection: give --select X,Y too (the sphere to drag)"};
    if (!have_scene && !o.help) {
        // The bundled scene (scene/scene_list.h), read-only where it is installed: the viewer's
        // Save asks where to save it.
        o.scene = default_view_scene();
        if (o.scene.empty())
            throw UsageError{"no scene given and no bundled scenes found (looked in " + data_dir_places() +
                             "); give a SCENE.json to open"};
    }
    return o;
}

std::string view_files_problem(const ViewOptions& o) {
    namespace fs = std::filesystem;
    std::vector<std::pair<const char*, fs::path>> inputs{{"the scene", o.scene}};
    if (o.reference) inputs.push_back({"--reference", *o.reference});
    for (const auto& [what, path] : inputs) {
        std::error_code ec;
        const fs::file_status status = fs::status(path, ec);  // stat: never blocks, not even on a FIFO
        if (!ec && fs::exists(status) && !fs::is_regular_file(status))
            return quoted_path(path) + ": " + what + " is " +
                   (fs::is_directory(status) ? "a folder" : fs::is_fifo(status) ? "a FIFO" : "not a regular file") +
                   "; the viewer reads a regular file";
    }
    // The shots are the 8-bit pictures on screen: PNG or PPM, not the name of a format the
    // viewer does not write (a .jpg, as render refuses it) nor an HDR one. (--save-image's
    // name is checked with the options.)
    for (const auto& [flag, shot] : {std::pair{"--screenshot", o.screenshot}, std::pair{"--window-shot", o.window_shot}}) {
        if (!shot) continue;
        try {
            check_output_extension(*shot);
        } catch (const std::runtime_error& e) {
            return std::string(flag) + " " + e.what();
        }
        if (output_format(*shot).hdr)
            return std::string(flag) + " " + quoted_path(*shot) + ": the shot is an 8-bit picture; give it a name ending in .png or .ppm";
    }
    std::vector<std::pair<const char*, fs::path>> outputs;
    if (o.screenshot) outputs.push_back({"--screenshot", *o.screenshot});
    if (o.window_shot) outputs.push_back({"--window-shot", *o.window_shot});
    if (o.save_image)
        for (const fs::path& file : output_file_paths(*o.save_image)) outputs.push_back({"--save-image", file});
    if (o.stats_json) outputs.push_back({"--stats-json", *o.stats_json});
    if (o.status_file) outputs.push_back({"--status-file", *o.status_file});
    for (const auto& [flag, output] : outputs)
        for (const auto& [what, input] : inputs)
            if (same_file(output, input))
                return std::string(flag) + " " + quoted_path(output) + " would overwrite " + what + " " + quoted_path(input);
    // Saving the edited scene onto its own file is what Save does; onto the reference it is not.
    if (o.save_scene && o.reference && same_file(*o.save_scene, *o.reference))
        return "--save-scene " + quoted_path(*o.save_scene) + " would overwrite --reference " + quoted_path(*o.reference);
    // Two outputs of one run naming one file would both be written, the last one winning.
    if (o.save_scene) outputs.push_back({"--save-scene", *o.save_scene});
    auto named = [&](const std::pair<const char*, fs::path>& output) {
        const bool depth = o.save_image && std::string_view(output.first) == "--save-image" && output.second != *o.save_image;
        return std::string(output.first) + (depth ? "'s depth file " : " ") + quoted_path(output.second);
    };
    for (size_t a = 0; a < outputs.size(); ++a)
        for (size_t b = a + 1; b < outputs.size(); ++b)
            if (same_file(outputs[a].second, outputs[b].second))
                return named(outputs[a]) + " and " + named(outputs[b]) +
                       " are one file: both would be written, the last one winning; give each output its own file";
    // Every output checked as its writer will check it (a folder, a device, a read-only
    // file), before the run rather than at its end.
    for (const auto& output : outputs) try {
            check_output_targets({output.second});
        } catch (const std::runtime_error& e) {
            // The writer's message starts with the file: the flag goes before it.
            const std::string name = named(output);
            return name.substr(0, name.size() - quoted_path(output.second).size()) + e.what();
        }
    return "";
}

std::string script_problem(const ViewOptions& o, int width, int height) {
    const std::string size = std::to_string(width) + "x" + std::to_string(height);
    auto outside = [&](const char* flag, double x, double y) -> std::string {
        if (x >= 0 && x < width && y >= 0 && y < height) return "";
        char at[64];
        std::snprintf(at, sizeof at, "%.10g,%.10g", x, y);
        return std::string(flag) + " " + at + " is outside the " + size + " image (pixels 0 to " +
               std::to_string(width - 1) + " across, 0 to " + std::to_string(height - 1) + " down)";
    };
    if (o.select)
        if (std::string p = outside("--select", o.select->first, o.select->second); !p.empty()) return p;
    if (o.click_focus)
        if (std::string p = outside("--click-focus", o.click_focus->first, o.click_focus->second); !p.empty()) return p;
    if (o.probe)
        if (std::string p = outside("--probe", o.probe->first, o.probe->second); !p.empty()) return p;
    if (const auto& r = o.region; r && ((*r)[0] < 0 || (*r)[1] < 0 || (*r)[2] > width || (*r)[3] > height))
        return "--region " + std::to_string((*r)[0]) + "," + std::to_string((*r)[1]) + " " + std::to_string((*r)[2]) +
               "," + std::to_string((*r)[3]) + " reaches outside the " + size + " image (at most 0,0 " +
               std::to_string(width) + "," + std::to_string(height) + ")";
    return "";
}

std::string view_usage() { return kViewUsageHead + shared_flags_help() + kViewOnlyOptions; }

}  // namespace kr::viewer
