// keithray: the headless command-line program. A thin loop over the core library.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include <omp.h>
#include <unistd.h>

#include "app/bench.h"
#include "app/progress.h"
#include "core/args.h"
#include "core/image.h"
#include "render/render.h"
#include "scene/load.h"
#include "viewer/files.h"
#include "viewer/gl_offscreen.h"
#include "viewer/viewer.h"

namespace fs = std::filesystem;
using namespace kr;

namespace {

constexpr const char* kUsage = R"(keithray: a progressive ray tracer for sphere scenes

Usage:
  keithray render [SCENE.json ...] [options]
  keithray psnr IMAGE REFERENCE            PSNR in dB of two 8-bit images (PPM or PNG)
  keithray bench --throughput|--stress ...  speed figures ('keithray bench --help')
  keithray view [SCENE.json] [options]      interactive viewer (GLFW window; see
                                            'keithray view --help' and README.md)
  keithray --help

With no SCENE, renders every *.json in res/scenes/. Defaults come from each scene
file's renderer block; the options below override them.

Options:
  --spp N               samples per pixel (default: the file's "samples"; with --time
                        or --noise, an upper bound, unlimited if not given)
  --time SECONDS        render as many passes as fit in SECONDS (checked between passes)
  --noise X             stop when the estimated relative RMS error of the image falls
                        below X (e.g. 0.01); adaptive: passes go to the noisiest pixels
  --integrator NAME     wrt | pt | pt-naive (default: the file's renderer type;
                        pt-naive samples no area light, only point lights)
  --estimator NAME      where samples come from: uniform | stratified | sobol
                        (default: sobol, Owen-scrambled Sobol in every dimension;
                        stratified is the brief's sub-pixel strata; docs/accuracy.md)
  --allocation NAME     how a pass spreads its samples: adaptive | uniform (default:
                        adaptive, each pixel's share in proportion to its estimated
                        noise after 8 passes, the same total; --spp N is then the
                        mean per pixel; stratified always gets uniform)
  --light-sampling NAME spherical lights: brief | brief-area | cone | area (default:
                        brief, the integral of the brief's reference images, importance
                        sampled; brief-area is the brief's own uniform sampling of it;
                        cone and area are exact: docs/fidelity.md, docs/accuracy.md)
  --depth N             maximum ray depth, 0..20 (default: the file's "depth")
  --tonemap NAME        sigmoid | linear (default: the scene's "display" block, else sigmoid)
  --exposure EV         exposure in stops, -10..10: radiance x 2^EV before the tone map
                        (default: the scene's "display" block, else 0)
  --gl                  tone map through the viewer's GLSL display shaders in an
                        offscreen OSMesa framebuffer (no display, no GPU needed)
  --blur R              box blur of radius R pixels on the radiance (default: 0)
  --seed N              random seed (default: 0); same seed, same image
  --threads N           worker threads (default: all cores)
  --kernels NAME        how paths are traced: best | double | any | off (default: best,
                        in SIMD lanes where the CPU has AVX2: eight in single precision
                        where the scene's sizes allow, else four in double; double keeps
                        the four double lanes; docs/performance.md)
  -o OUT.ppm            write OUT.ppm and OUT-depth.ppm instead of the file's "output"
                        (only with a single scene); OUT.png writes PNGs instead
  -q, --quiet           no progress bar
  -h, --help            this text

Output: an 8-bit binary PPM (a PNG if the name ends in .png) and, beside it, the depth map
(1 - d/(1+d)) as NAME-depth.ppm (or .png), each written atomically. One summary line per
scene on stdout: spp, seconds, Mrays/s.
Exit status: 0 on success, 1 if a scene failed to load or render, 2 on bad usage.
)";

struct Options {
    std::vector<fs::path> scenes;
    std::optional<int> spp, depth, threads;
    double time_limit = 0, noise = 0;  // 0: rule off
    std::optional<Integrator> integrator;
    std::optional<Estimator> estimator;
    std::optional<Allocation> allocation;
    std::optional<LightSampling> light_sampling;
    std::optional<ToneMap> tonemap;  // default: the scene's display block
    std::optional<double> exposure;  // EV stops; default: the scene's display block
    int blur = 0;
    uint64_t seed = 0;
    std::optional<fs::path> output;
    bool quiet = false;
    bool gl = false;  // tone map on the viewer's display path (OSMesa)
    PacketIsa kernels = PacketIsa::best;
};

Options parse_options(int argc, char** argv) {
    Options o;
    for (ArgCursor args(argc, argv); args.next();) {
        const std::string& arg = args.arg();
        auto value = [&] { return args.value(); };
        if (arg == "--spp") o.spp = int(parse_integer(arg, value(), 1, 1 << 24));
        else if (arg == "--time") o.time_limit = parse_positive(arg, value());
        else if (arg == "--noise") o.noise = parse_positive(arg, value());
        else if (arg == "--depth") o.depth = int(parse_integer(arg, value(), 0, 1000));
        else if (arg == "--threads") o.threads = int(parse_integer(arg, value(), 1, 4096));
        else if (arg == "--kernels") o.kernels = parse_name(arg, value(), packet_isa_names);
        else if (arg == "--blur") o.blur = int(parse_integer(arg, value(), 0, 4096));
        else if (arg == "--seed") o.seed = uint64_t(parse_integer(arg, value(), 0, (1ll << 62)));
        else if (arg == "--integrator") o.integrator = parse_name(arg, value(), integrator_names);
        else if (arg == "--estimator") o.estimator = parse_name(arg, value(), estimator_names);
        else if (arg == "--allocation") o.allocation = parse_name(arg, value(), allocation_names);
        else if (arg == "--light-sampling") o.light_sampling = parse_name(arg, value(), light_sampling_names);
        else if (arg == "--tonemap") o.tonemap = parse_name(arg, value(), tonemap_names);
        else if (arg == "--exposure") o.exposure = parse_number(arg, value(), -kMaxExposureStops, kMaxExposureStops);
        else if (arg == "-o" || arg == "--output") o.output = value();
        else if (arg == "-q" || arg == "--quiet") o.quiet = true;
        else if (arg == "--gl") o.gl = true;
        else if (!arg.empty() && arg[0] == '-') throw UsageError{"unknown option " + arg};
        else o.scenes.emplace_back(arg);
    }
    if (o.output && o.scenes.size() != 1)
        throw UsageError{"-o needs exactly one scene file (it names a single output)"};
    return o;
}

// Whether writing path `a` would replace the existing file `b`: the same file under another
// name (hard or symbolic links), or the same path once resolved, e.g. "x/../scene.json"
// through a folder x that does not exist yet (write_ppm would create it).
bool same_file(const fs::path& a, const fs::path& b) {
    std::error_code ec;
    if (fs::exists(a, ec) && fs::exists(b, ec) && fs::equivalent(a, b, ec)) return true;
    auto resolved = [](const fs::path& p) {
        std::error_code e;
        const fs::path absolute = fs::absolute(p, e);
        const fs::path canonical = fs::weakly_canonical(absolute, e);
        return e ? absolute.lexically_normal() : canonical;
    };
    return resolved(a) == resolved(b);
}

// Loads, renders and writes one scene. Returns false (after printing why) on failure.
bool render_scene_file(const fs::path& scene_file, const Options& opt) {
    LoadedScene loaded;
    RenderScene scene;
    std::vector<std::string> warnings;
    try {
        loaded = load_scene_file(scene_file);
        warnings = loaded.warnings;
        scene = prepare_scene(loaded.scene, &warnings);
    } catch (const SceneError& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return false;
    }
    for (const std::string& w : warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());

    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    settings.seed = opt.seed;
    if (opt.spp) settings.target_spp = *opt.spp;
    if (opt.integrator) settings.integrator = *opt.integrator;
    if (opt.estimator) settings.estimator = *opt.estimator;
    if (opt.allocation) settings.allocation = *opt.allocation;
    if (opt.light_sampling) settings.light_sampling = *opt.light_sampling;
    if (opt.depth) {
        if (*opt.depth > kMaxDepth)
            std::fprintf(stderr, "warning: --depth %d is above the maximum %d; clamped to %d\n", *opt.depth,
                         kMaxDepth, kMaxDepth);
        settings.max_depth = std::min(*opt.depth, kMaxDepth);
    }

    const fs::path output = opt.output ? *opt.output : loaded.scene.output_path();
    const fs::path depth_output = depth_path_for(output);
    // No input of this command is ever overwritten: not this scene file, nor another one
    // still to be rendered (nor one already rendered).
    for (const fs::path& input : opt.scenes)
        for (const fs::path& written : {output, depth_output})
            if (same_file(written, input)) {
                std::fprintf(stderr, "error: %s: the output %s would overwrite the scene file %s%s; nothing written\n",
                             scene_file.string().c_str(), written.string().c_str(), input.string().c_str(),
                             same_file(input, scene_file) ? " itself" : "");
                return false;
            }

    RenderState state;
    try {
        state.reset(scene.renderer.width, scene.renderer.height);
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "error: %s: not enough memory for the render state of a %dx%d image\n",
                     scene_file.string().c_str(), scene.renderer.width, scene.renderer.height);
        return false;
    }
    const bool show_progress = !opt.quiet && ::isatty(STDERR_FILENO);
    const auto start = std::chrono::steady_clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
    double last_draw = -1;
    StopRule rule;
    rule.seconds = opt.time_limit;
    rule.noise = opt.noise;
    const bool open_ended = opt.time_limit > 0 || opt.noise > 0;
    rule.max_passes = open_ended && !opt.spp ? (1 << 24) : settings.target_spp;
    const StopReason reason = render_until(scene, settings, state, rule, [&](const RenderState& s) {
        if (show_progress && elapsed() - last_draw > 0.1) {
            if (open_ended) {
                std::fprintf(stderr, "\r  %d passes  %s  est. error %.4f   ", s.passes, format_seconds(elapsed()).c_str(),
                             s.relative_error());
                std::fflush(stderr);
            } else {
                draw_progress(double(s.passes) / settings.target_spp,
                              std::to_string(s.passes) + "/" + std::to_string(settings.target_spp) + " spp", elapsed());
            }
            last_draw = elapsed();
        }
        return true;
    });
    const double seconds = elapsed();
    if (open_ended)
        std::fprintf(stderr, "%s%s: stopped by %s after %d passes, estimated relative error %.4f\n",
                     show_progress ? "\n" : "", scene_file.filename().string().c_str(),
                     reason == StopReason::noise ? "--noise" : reason == StopReason::time ? "--time" : "--spp",
                     state.passes, state.relative_error());
    if (show_progress) std::fprintf(stderr, "\n");

    try {
        const Image radiance = box_blur(state.radiance(), opt.blur);
        // The scene's display block, then the command line over it.
        DisplaySettings display = loaded.scene.display;
        if (opt.tonemap) display.tonemap = *opt.tonemap;
        if (opt.exposure) display.exposure = *opt.exposure;
        viewer::write_image(output, opt.gl ? viewer::display_offscreen(radiance, display)
                                           : tonemap(radiance, display.tonemap, display.exposure_scale()));
        viewer::write_image(depth_output, depth_to_rgb8(state.mean_depth(), state.width, state.height));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: %s: %s\n", scene_file.string().c_str(), e.what());
        return false;
    }
    if (state.nonfinite_samples > 0)
        std::fprintf(stderr, "warning: %s: %llu non-finite samples were dropped\n", scene_file.string().c_str(),
                     static_cast<unsigned long long>(state.nonfinite_samples));
    std::printf("%s: %dx%d %s %d spp, %.2f s, %.1f Mrays/s (%.1f M rays) -> %s\n",
                scene_file.filename().string().c_str(), state.width, state.height,
                std::string(integrator_names.name(settings.integrator)).c_str(), state.passes, seconds,
                seconds > 0 ? double(state.rays) / seconds * 1e-6 : 0.0, double(state.rays) * 1e-6,
                output.string().c_str());
    std::fflush(stdout);
    return true;
}

}  // namespace

// Every *.json in res/scenes: looked up from the working directory, then the source tree.
std::vector<fs::path> kr::default_scenes() {
    std::vector<fs::path> dirs{"res/scenes"};
#ifdef KEITHRAY_SCENES_DIR
    dirs.emplace_back(KEITHRAY_SCENES_DIR);
#endif
    for (const fs::path& dir : dirs) {
        std::error_code ec;
        if (!fs::is_directory(dir, ec)) continue;
        std::vector<fs::path> found;
        for (const auto& entry : fs::directory_iterator(dir, ec))
            if (entry.path().extension() == ".json") found.push_back(entry.path());
        std::sort(found.begin(), found.end());
        if (!found.empty()) return found;
    }
    return {};
}

int main(int argc, char** argv) {
    const std::string command = argc > 1 ? argv[1] : "";
    if (command == "-h" || command == "--help" || command == "help") {
        std::fputs(kUsage, stdout);
        return 0;
    }
    if (command == "bench") return run_bench(argc, argv);
    if (command == "psnr") {
        if (argc != 4) {
            std::fprintf(stderr, "error: psnr needs two image files (PPM or PNG)\n");
            return 2;
        }
        try {
            std::printf("%.2f\n", psnr(viewer::read_image(argv[2]), viewer::read_image(argv[3])));
            return 0;
        } catch (const std::exception& e) {
            std::fprintf(stderr, "error: %s\n", e.what());
            return 1;
        }
    }
    if (command == "view") return viewer::run_viewer(argc, argv);
    if (command != "render") {
        std::fprintf(stderr, "%s%s\n%s", command.empty() ? "error: no command given" : "error: unknown command ",
                     command.c_str(), kUsage);
        return 2;
    }
    Options opt;
    try {
        opt = parse_options(argc, argv);
    } catch (const UsageError& e) {
        std::fprintf(stderr, "error: %s\nRun 'keithray --help' for the options.\n", e.message.c_str());
        return 2;
    }
    if (opt.threads) omp_set_num_threads(*opt.threads);
    set_packet_isa(opt.kernels);
    if (opt.scenes.empty()) {
        opt.scenes = default_scenes();
        if (opt.scenes.empty()) {
            std::fprintf(stderr, "error: no scene given and no res/scenes/*.json found\n");
            return 2;
        }
    }
    bool ok = true;
    for (const fs::path& scene : opt.scenes) {
        try {
            ok = render_scene_file(scene, opt) && ok;
        } catch (const std::exception& e) {  // e.g. out of memory tone mapping a huge image
            std::fprintf(stderr, "error: %s: %s\n", scene.string().c_str(), e.what());
            ok = false;
        }
    }
    return ok ? 0 : 1;
}
