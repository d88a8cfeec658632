// `keithray view`: option parsing and the top-level error handling.
#include <cstdio>
#include <exception>
#include <string>

#include "core/args.h"
#include "viewer/ui_app.h"
#include "viewer/viewer.h"

namespace kr::viewer {

namespace {

constexpr const char* kViewUsage = R"(keithray view: the interactive viewer

Usage:
  keithray view [SCENE.json] [options]

Opens SCENE.json (default: res/scenes/assignment_03.json) in a window that refines the
image pass by pass. The panels on the right edit camera, lens, lights, materials, tone
map and renderer; any edit that changes the image restarts at once from a
low-resolution preview. The status bar shows the state, spp, progress and noise. The
scene file is watched and reloaded when it changes (asking first if there are unsaved
edits). In the window, F1 or ? lists the keys and mouse controls.

Options:
  --spp N               target samples per pixel (default: the file's "samples")
  --unlimited           keep refining past the target
  --time SECONDS        stop refining after SECONDS of full-resolution rendering
  --noise X             stop at estimated relative error X (adaptive sampling)
  --integrator NAME     wrt | pt | pt-naive      --depth N         0..20
  --estimator NAME      uniform | stratified | sobol
  --allocation NAME     adaptive | uniform (samples per pixel and pass)
  --light-sampling NAME brief | brief-area | cone | area
  --seed N              random seed (default 0)
  --tonemap NAME        sigmoid | linear         --exposure EV     stops, -10..10
                        (default: the scene's "display" block, else sigmoid and 0)
Scripted runs (tests, measurements; the window still opens, e.g. under xvfb-run):
  --aperture A          make the camera a thin lens of aperture radius A
  --orbit DX,DY         a left-button drag of (DX, DY) pixels (orbit)
  --click-focus X,Y     Ctrl+click at image pixel (X, Y): focus there
  --frames N            accumulate N full-resolution passes (at most the target spp)
  --screenshot OUT.ppm  then write the image region as drawn by the display shader (.png: as PNG)
  --save-scene OUT.json then save the edited scene
  --window-shot OUT.ppm and the whole window, panels included (.png: as PNG)
  --measure-latency N   time N orbit edits from the edit to the first frame on screen
  --measure-idle S      once done, the process's CPU over S seconds with no input; then
                        paused (unlimited), the same again; printed as % of a core
  --status-file FILE    rewrite FILE with the status line (state, spp, target, generation,
                        unsaved edits) whenever it changes: for scripts driving the window
  --timeout S           fail a scripted run after S seconds (default 600)
)";

int parse_int(const std::string& flag, const std::string& text, int lo, int hi) {
    const double v = parse_number(flag, text, lo, hi);
    if (v != double(int(v))) throw UsageError{flag + " expects an integer, got " + quote_user_text(text, 40)};
    return int(v);
}

std::pair<double, double> parse_pair(const std::string& flag, const std::string& text) {
    const size_t comma = text.find(',');
    if (comma == std::string::npos) throw UsageError{flag + " expects X,Y, got " + quote_user_text(text, 40)};
    return {parse_number(flag, text.substr(0, comma), -1e6, 1e6), parse_number(flag, text.substr(comma + 1), -1e6, 1e6)};
}

ViewOptions parse(int argc, char** argv, bool& help) {
    ViewOptions o;
    bool have_scene = false;
    for (ArgCursor args(argc, argv); args.next();) {
        const std::string& arg = args.arg();
        auto value = [&] { return args.value(); };
        if (arg == "-h" || arg == "--help") help = true;
        else if (arg == "--spp") o.overrides.spp = parse_int(arg, value(), 1, kMaxSamples);
        else if (arg == "--depth") o.overrides.depth = parse_int(arg, value(), 0, kMaxDepth);
        else if (arg == "--seed") o.overrides.seed = uint64_t(parse_number(arg, value(), 0, 9e15));
        else if (arg == "--integrator") o.overrides.integrator = parse_name(arg, value(), integrator_names);
        else if (arg == "--estimator") o.overrides.estimator = parse_name(arg, value(), estimator_names);
        else if (arg == "--allocation") o.overrides.allocation = parse_name(arg, value(), allocation_names);
        else if (arg == "--light-sampling") o.overrides.light_sampling = parse_name(arg, value(), light_sampling_names);
        else if (arg == "--tonemap") o.overrides.tonemap = parse_name(arg, value(), tonemap_names);
        else if (arg == "--exposure")
            o.overrides.exposure = parse_number(arg, value(), -kMaxExposureStops, kMaxExposureStops);
        else if (arg == "--unlimited") o.unlimited = true;
        else if (arg == "--time") o.stop_seconds = parse_number(arg, value(), 0, kMaxSeconds, true);
        else if (arg == "--noise") o.stop_noise = parse_number(arg, value(), kMinNoise, kMaxNoise);
        else if (arg == "--aperture") o.aperture = parse_number(arg, value(), 0, 1e9);
        else if (arg == "--orbit") o.orbit = parse_pair(arg, value());
        else if (arg == "--click-focus") o.click_focus = parse_pair(arg, value());
        else if (arg == "--frames") o.frames = parse_int(arg, value(), 1, 1 << 24);
        else if (arg == "--screenshot") o.screenshot = value();
        else if (arg == "--save-scene") o.save_scene = value();
        else if (arg == "--window-shot") o.window_shot = value();
        else if (arg == "--measure-latency") o.measure_latency = parse_int(arg, value(), 1, 10000);
        else if (arg == "--measure-idle") o.measure_idle = parse_number(arg, value(), 0.1, 3600);
        else if (arg == "--status-file") o.status_file = value();
        else if (arg == "--timeout") o.timeout = parse_number(arg, value(), 1, 1e7);
        else if (!arg.empty() && arg[0] == '-') throw unknown_option(arg);
        else if (have_scene) throw UsageError{"view opens one scene; got a second: " + quote_user_text(arg)};
        else {
            o.scene = arg;
            have_scene = true;
        }
    }
    if (!have_scene) {
        o.scene = "res/scenes/assignment_03.json";
#ifdef KEITHRAY_SCENES_DIR
        std::error_code ec;
        if (!std::filesystem::exists(o.scene, ec))
            o.scene = std::filesystem::path(KEITHRAY_SCENES_DIR) / "assignment_03.json";
#endif
    }
    return o;
}

}  // namespace

int run_viewer(int argc, char** argv) {
    ViewOptions options;
    bool help = false;
    try {
        options = parse(argc, argv, help);
    } catch (const UsageError& e) {
        std::fprintf(stderr, "error: %s\nRun 'keithray view --help' for the options.\n", e.message.c_str());
        return 2;
    }
    if (help) {
        std::fputs(kViewUsage, stdout);
        return 0;
    }
    try {
        ViewerApp app(std::move(options));
        return app.run();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
}

}  // namespace kr::viewer
