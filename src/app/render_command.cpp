// `keithray render`: its help text, its options and one scene's render (SceneRender), under
// mpirun one rank's share of it (app/cluster.h).
#include "app/render_command.h"

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <omp.h>
#include <unistd.h>

#include "app/cluster.h"
#include "app/command.h"
#include "app/progress.h"
#include "app/viewer_module.h"
#include "core/args.h"
#include "core/data_dir.h"
#include "core/image.h"
#include "core/limits.h"
#include "core/memory.h"
#include "core/module.h"
#include "core/text.h"
#include "core/file_write.h"
#include "core/image_formats.h"
#include "render/checkpoint.h"
#include "render/options.h"
#include "render/outputs.h"
#include "render/progressive.h"
#include "render/trace.h"
#include "scene/load.h"
#include "scene/scene_list.h"
#include "viewer/view_options.h"

namespace fs = std::filesystem;

namespace kr {

namespace {

// render's own text before its options (the man page's render section starts with it).
constexpr const char* kRenderIntro = R"(
With no SCENE, renders the bundled scenes (the brief's eight, installed with keithray)
into output/ under the current folder. Defaults come from each scene file's renderer
block; the options below override them.

Options:
)";

// The options only render takes; the shared ones (render/options.h) come before them.
constexpr const char* kRenderOnlyOptions = R"(  --gl                  tone map through the viewer's GLSL display shaders in an
                        offscreen OSMesa framebuffer (no display, no GPU needed)
  --blur R              box blur of radius R pixels on the radiance, 0..4096 (default: 0)
  --threads N           worker threads, 1..4096 (default: all cores); a render of at
                        most 16,384 samples (width x height x spp) runs on one, which
                        makes the same image for less CPU
  --kernels NAME        how paths are traced: best | double | float8 | any | off (default:
                        best, in SIMD lanes where the CPU has AVX2: in single precision
                        where the scene's sizes allow, sixteen at a time with AVX-512, else
                        eight; else four in double; double keeps the four double lanes,
                        float8 the eight float ones; docs/performance.md)
  -o OUT.ppm            write OUT.ppm and OUT-depth.ppm instead of the file's "output"
                        (only with a single scene); OUT.png writes PNGs instead;
                        OUT.exr one OpenEXR with the radiance and its layers; OUT.pfm
                        the radiance and OUT-depth.pfm the distances as float PFMs
  --checkpoint FILE     write the render state to FILE (atomically) at most every
                        --every seconds and on SIGINT/SIGTERM, which then end the
                        render without an image (a second signal ends it at once;
                        only with a single scene)
  --every SECONDS       seconds between checkpoints, 0..1e6 (default: 60; 0: every pass)
  --resume FILE         go on from checkpoint FILE: the image is byte for byte the one
                        of an uninterrupted render; refused for another scene, other
                        settings or another size
  -q, --quiet           no progress bar
  -h, --help            this text

With --time or --noise and no --spp, a render stops after at most 65536 passes.

Output: an 8-bit binary PPM (a PNG if the name ends in .png) and, beside it, the depth map
(1 - d/(1+d)) as NAME-depth.ppm (or .png), both replaced together or neither (a
read-only file, a folder or a device as output is refused). NAME.exr holds the mean
radiance (R, G, B, 32-bit float) and the layers depth.Z (primary hit distance, 1e6 where
the ray missed), albedo.R/G/B and normal.X/Y/Z (first non-specular hit of the pixel
centre's ray), samples (per pixel) and variance.R/G/B (of the mean; left out with
--blur); NAME.pfm the radiance and NAME-depth.pfm the distances, both or neither.
One summary line per scene on stdout: spp, seconds, Mrays/s.
Under mpirun (or srun) the ranks share each render and rank 0 writes; the summary adds
each rank's busy time and Mrays/s (docs/cli.md, "Rendering on many machines").
A render whose memory estimate exceeds the machine's (or ulimit -v's) memory is refused;
scene files are at most 64 MiB (docs/cli.md, "Limits").
Exit status: 0 on success, 1 if a scene failed to load, render or be written (or stdout
could not be written), 2 on bad usage.
)";

struct Options {
    std::vector<fs::path> scenes;
    RenderOptions render;  // the flags view takes too: render/options.h
    std::optional<int> threads;
    int team = 1;  // threads for a render above kOneThreadMaxSamples: --threads, else OpenMP's default
    int blur = 0;
    std::optional<fs::path> output;
    bool quiet = false;
    bool gl = false;  // tone map on the viewer's display path (OSMesa)
    LaneChoice kernels = LaneChoice::best;
    std::optional<fs::path> checkpoint, resume;
    double checkpoint_every = 60;
    bool bundled = false;  // no scene given: the bundled scenes, written under ./output/
};

Options parse_options(int argc, char** argv) {
    Options o;
    for (ArgCursor args(argc, argv); args.next();) {
        const std::string& arg = args.arg();
        auto value = [&] { return args.value(); };
        if (read_shared_flag(args, o.render)) continue;
        if (arg == "-h" || arg == "--help") throw UsageError{};
        else if (arg == "--threads") o.threads = int(parse_integer(arg, value(), 1, kMaxThreads));
        else if (arg == "--kernels") o.kernels = parse_name(arg, value(), lane_choice_names);
        else if (arg == "--blur") o.blur = int(parse_integer(arg, value(), 0, kMaxBlur));
        else if (arg == "-o" || arg == "--output") o.output = value();
        else if (arg == "--checkpoint") o.checkpoint = value();
        else if (arg == "--every") o.checkpoint_every = parse_number(arg, value(), 0, kMaxSeconds);
        else if (arg == "--resume") o.resume = value();
        else if (arg == "-q" || arg == "--quiet") o.quiet = true;
        else if (arg == "--gl") o.gl = true;
        else if (!arg.empty() && arg[0] == '-') throw unknown_option(arg);
        else o.scenes.emplace_back(arg);
    }
    if (o.output && o.scenes.size() != 1)
        throw UsageError{"-o needs exactly one scene file (it names a single output)"};
    if ((o.checkpoint || o.resume) && o.scenes.size() != 1)
        throw UsageError{"--checkpoint and --resume need exactly one scene file (a checkpoint holds one render)"};
    if (o.gl && o.output && output_format(*o.output).hdr)
        throw UsageError{"--gl tone maps for an 8-bit output; an .exr or .pfm output is not tone mapped"};
    return o;
}

// A render of at most this many samples (width x height x spp, 64x64 at 4 spp) runs on one
// thread, whose team is then never started: its passes cost a few milliseconds, less than
// another thread costs to start and to wait in (libgomp's idle threads spin about 20 ms of
// CPU after each parallel region unless OMP_WAIT_POLICY=passive, which only the environment
// sets). The image is the same on any number of threads (docs/performance.md, "Start-up").
constexpr uint64_t kOneThreadMaxSamples = 64 * 64 * 4;

// Writes the checkpoint of `state` (gathered at rank 0 first). Returns false after printing
// why where it could not be written; the previous checkpoint then stays as it was.
bool write_checkpoint(const Cluster& cluster, const fs::path& path, const CheckpointKey& key, RenderState& state) {
    uint64_t rays = 0, nonfinite = 0;
    cluster.gather_state(state, rays, nonfinite);
    if (!cluster.leader()) return true;
    // The job's counts in the file; this rank's own stay in the state it goes on with.
    const uint64_t own_rays = state.rays, own_nonfinite = state.nonfinite_samples;
    state.rays = rays;
    state.nonfinite_samples = nonfinite;
    const std::string bytes = encode_checkpoint(key, state);
    state.rays = own_rays;
    state.nonfinite_samples = own_nonfinite;
    try {
        write_file_atomic(path, bytes);
        return true;
    } catch (const std::runtime_error& e) {
        std::fprintf(stderr, "warning: checkpoint not written: %s\n", e.what());
        return false;
    }
}

// The per-rank line of the summary: busy time (CPU seconds in render_pass), its spread, each
// rank's Mrays/s, the exchange between passes (the slowest rank's wall time in it, waiting
// included, and the most bytes a rank received) and the time between passes less the
// exchange (planning and the noise rule, each rank on its own rows).
void print_rank_costs(const std::vector<RankCost>& costs) {
    double total = 0, slowest = 0, combine = 0, between = 0, received = 0;
    for (const RankCost& c : costs) {
        received = std::max(received, c.received_bytes);
        total += c.busy_seconds;
        slowest = std::max(slowest, c.busy_seconds);
        combine = std::max(combine, c.combine_seconds);
        between = std::max(between, c.between_seconds);
    }
    const double mean = total / double(costs.size());
    std::string busy, speed;
    for (const RankCost& c : costs) {
        char buf[64];
        std::snprintf(buf, sizeof buf, " %.2f", c.busy_seconds);
        busy += buf;
        std::snprintf(buf, sizeof buf, " %.2f", c.busy_seconds > 0 ? double(c.rays) / c.busy_seconds * 1e-6 : 0.0);
        speed += buf;
    }
    std::printf("  %zu ranks: busy s%s (slowest %+.1f%% of the mean); Mrays/s per busy s%s; exchange %.3f s "
                "and %.3f MB received after %d passes; between passes %.3f s\n",
                costs.size(), busy.c_str(), mean > 0 ? 100 * (slowest / mean - 1) : 0.0, speed.c_str(), combine,
                received * 1e-6, costs.front().exchanges, between);
}

// One scene's render, in the order its steps run: load, check the outputs, check the memory,
// resume, render with checkpoints, gather and report, write. Each step that fails prints why
// (rank 0) and returns false. `stage` says what the work in progress needs memory for, for
// the caller's message. Under MPI every rank runs it: rank 0 reads the scene and the
// checkpoint and sends their bytes, every rank renders its rows, rank 0 gathers the state
// and writes.
class SceneRender {
public:
    SceneRender(const fs::path& scene_file, const Options& opt, std::string& stage, const Cluster& cluster)
        : scene_file_(scene_file), opt_(opt), stage_(stage), cluster_(cluster), file_(shown_path(scene_file)),
          leader_(cluster.leader()) {}

    bool run() {
        if (!load() || !check_outputs() || !check_memory()) return false;
        start_ = std::chrono::steady_clock::now();
        set_stop_rule();
        if (!resume()) return false;
        if (!start_threads()) return false;
        const StopReason reason = render();
        if (reason == StopReason::cancelled) {
            if (leader_)
                std::fprintf(stderr, "%s%s: stopped by a signal after %d passes; no image written; %s %s\n",
                             show_progress_ ? "\n" : "", file_.c_str(), state_.passes, shown_path(*opt_.checkpoint).c_str(),
                             checkpoint_written_ ? "holds them (go on with --resume)" : "could not be written (above)");
            return false;
        }
        gather();
        if (!leader_) return true;
        report_stop(reason);
        if (!write()) return false;
        report_summary();
        return true;
    }

private:
    double elapsed() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    }

    // Rank 0 reads the file and sends its text; every rank parses and prepares it.
    bool load() {
        std::vector<std::string> warnings;
        try {
            stage_ = "the scene";
            std::string text;
            bool read = true;
            if (leader_) try {
                    text = read_scene_text(scene_file_);
                } catch (const SceneError& e) {
                    std::fprintf(stderr, "error: %s\n", e.what());
                    read = false;
                }
            if (!cluster_.broadcast(read)) return false;
            cluster_.broadcast(text);
            loaded_ = parse_scene(text, scene_file_);
            warnings = loaded_.warnings;
            stage_ = "the prepared scene and its BVH";
            scene_ = prepare_scene(loaded_.scene, &warnings);
        } catch (const SceneError& e) {
            if (leader_) std::fprintf(stderr, "error: %s\n", e.what());
            return false;
        }
        if (leader_)
            for (const std::string& w : warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
        // The file's renderer and display blocks, then the command line over them.
        settings_ = apply_render_options(opt_.render, loaded_.scene);
        settings_.kernels = opt_.kernels;
        // The bundled scenes without a scene argument, and a scene whose output lies in the
        // install tree, write into output/ under the current folder: the install tree is never
        // written (scene/scene_list.h).
        if (opt_.output) output_ = *opt_.output;
        else if (opt_.bundled) output_ = output_in_current_folder(loaded_.scene);
        else output_ = output_outside_install(loaded_.scene, data_dir()).value_or(loaded_.scene.output_path());
        return true;
    }

    // No input of this command is ever overwritten: not this scene file, nor another one
    // still to be rendered (nor one already rendered). The checkpoint, written during the
    // render, never replaces a scene file or an output.
    bool check_outputs() {
        const std::vector<fs::path> outputs = output_file_paths(output_);
        bool overwrites_input = false;
        if (leader_)  // the rank that writes
            for (const fs::path& input : opt_.scenes)
                for (const fs::path& written : outputs)
                    if (!overwrites_input && same_file(written, input)) {
                        std::fprintf(stderr,
                                     "error: %s: the output %s would overwrite the scene file %s%s; nothing written\n",
                                     file_.c_str(), shown_path(written).c_str(), shown_path(input).c_str(),
                                     same_file(input, scene_file_) ? " itself" : "");
                        overwrites_input = true;
                    }
        std::vector<fs::path> kept = opt_.scenes;
        kept.insert(kept.end(), outputs.begin(), outputs.end());
        if (leader_ && opt_.checkpoint)
            for (const fs::path& other : kept)
                if (!overwrites_input && same_file(*opt_.checkpoint, other)) {
                    std::fprintf(stderr, "error: --checkpoint %s would overwrite %s; nothing written\n",
                                 shown_path(*opt_.checkpoint).c_str(), shown_path(other).c_str());
                    overwrites_input = true;
                }
        // Every file written later (the images after the render, the checkpoint during it)
        // checked now, as the writer would: not after hours of rendering.
        if (leader_ && !overwrites_input) try {
                check_output_extension(output_);
                std::vector<fs::path> targets = outputs;
                if (opt_.checkpoint) targets.push_back(*opt_.checkpoint);
                check_output_targets(targets);
            } catch (const std::runtime_error& e) {
                std::fprintf(stderr, "error: %s: %s; nothing rendered\n", file_.c_str(), e.what());
                overwrites_input = true;
            }
        return !cluster_.broadcast(overwrites_input);
    }

    // Refused before allocating when the render cannot fit in the memory the process may use
    // (core/memory.h): better at once than after hours, or by the kernel's OOM killer.
    bool check_memory() {
        const int width = scene_.renderer.width, height = scene_.renderer.height;
        image_ = std::to_string(width) + "x" + std::to_string(height) + " image";
        // Rank 0 holds the whole state and writes the outputs; another rank holds its rows and
        // their neighbours only. Each checks its own machine.
        std::vector<int> held = cluster_.held_rows(height);
        const uint64_t bytes =
            held.empty() ? render_memory_bytes(width, height, opt_.blur > 0, denoise() != Denoise::off)
                         : render_state_bytes(width, held.size()) +
                               (denoise() != Denoise::off ? kHalvesBytesPerPixel * uint64_t(width) * held.size() : 0);
        const std::string shortfall = memory_shortfall(bytes, "the render of a " + image_);
        if (!shortfall.empty())
            std::fprintf(stderr, "error: %s: %s%s\n", file_.c_str(), shortfall.c_str(),
                         cluster_.distributed() ? (" on rank " + std::to_string(cluster_.rank())).c_str() : "");
        if (cluster_.any_flags(!shortfall.empty())) return false;
        stage_ = "the render state of a " + image_;
        state_.reset(width, height, std::move(held));
        show_progress_ = leader_ && !opt_.quiet && ::isatty(STDERR_FILENO);
        return true;
    }

    // --denoise, else the scene's display block, else raw (apply_render_options put the flag over the block).
    Denoise denoise() const { return loaded_.scene.display.denoise.value_or(Denoise::off); }

    void set_stop_rule() {
        rule_ = render_stop_rule(opt_.render, settings_);
        open_ended_ = rule_.open_ended();
        capped_ = open_ended_ && !opt_.render.spp;
        stage_ = "the render's fingerprint (the scene's JSON text)";
        key_ = checkpoint_key(loaded_.scene, scene_, settings_, rule_);
    }

    // --resume: rank 0 reads and decodes the checkpoint and says its verdict; every other
    // rank receives its rows of it.
    bool resume() {
        if (opt_.resume) {
            stage_ = "the checkpoint " + shown_path(*opt_.resume) + " of a " + image_;
            std::string error;
            if (leader_) try {
                    decode_checkpoint(read_checkpoint_file(*opt_.resume, key_), *opt_.resume, key_, state_);
                    // The final denoiser reads the halves of every sample: without them in the
                    // checkpoint it would not make the uninterrupted render's image.
                    if (denoise() != Denoise::off && !state_.tracks_halves() && state_.passes > 0)
                        error = show_user_text(opt_.resume->string()) +
                                ": checkpoint of a render without --denoise: it lacks the two halves "
                                "of the samples that --denoise reads";
                } catch (const std::runtime_error& e) {
                    error = e.what();
                }
            if (cluster_.broadcast(!error.empty())) {
                if (leader_) std::fprintf(stderr, "error: --resume %s; nothing rendered\n", error.c_str());
                return false;
            }
            cluster_.scatter_state(state_);
        }
        rays_before_ = state_.rays;
        return true;
    }

    // One thread for a render of at most kOneThreadMaxSamples (the same choice in every rank:
    // it depends on the scene and the options), else the team, started before the passes.
    bool start_threads() {
        const uint64_t samples = uint64_t(scene_.renderer.width) * uint64_t(scene_.renderer.height) *
                                 uint64_t(std::max(rule_.max_passes, 0));
        const bool one = !open_ended_ && samples <= kOneThreadMaxSamples;
        omp_set_num_threads(one ? 1 : opt_.team);
        return one || !cluster_.any_flags(!team_started(file_));
    }

    // The passes, with the checkpoints, the stop signals and the progress bar between them.
    // With a checkpoint, SIGINT and SIGTERM during the passes end the pass under way, the
    // checkpoint is written and the render stops without an image; once the passes are over a
    // signal ends the run at once (the cleanup handler removes what was being written).
    StopReason render() {
        auto last_checkpoint = std::chrono::steady_clock::now();
        double last_draw = -1;
        StopOnSignal stop_on_signal(opt_.checkpoint.has_value());
        // The final denoiser's two halves of the samples, from here on or from the checkpoint
        // resumed (under MPI each rank keeps its rows', and the gather brings them to rank 0).
        if (denoise() != Denoise::off && !state_.tracks_halves()) state_.track_halves();
        hooks_ = cluster_.deal_rows();
        const RowShare* share = hooks_ ? hooks_->rows() : nullptr;
        // The progress line's estimated error is added up from every rank's rows: every rank
        // takes part where rank 0 shows it.
        const bool estimate_error = cluster_.broadcast(show_progress_) && rule_.noise > 0;
        stage_ = "rendering a " + image_;
        StopReason reason = render_until(scene_, settings_, state_, rule_, [&](const RenderState& s) {
            if (opt_.checkpoint) {
                // One decision for every rank: rank 0's clock, any rank's signal.
                const bool due = leader_ && std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                                                          last_checkpoint).count() >= opt_.checkpoint_every;
                const int flags = cluster_.any_flags((due ? 1 : 0) | (stop_signal() ? 2 : 0));
                if (flags) {
                    checkpoint_written_ = write_checkpoint(cluster_, *opt_.checkpoint, key_, state_);
                    last_checkpoint = std::chrono::steady_clock::now();
                }
                if (flags & 2) return false;
            }
            const double noise = estimate_error ? s.relative_error(share) : 0;
            if (show_progress_ && elapsed() - last_draw > 0.1) {
                // The bar goes towards the rule nearest to ending the render.
                const StopProgress progress = stop_progress(rule_, s.passes, elapsed(), noise);
                char what[96];
                if (open_ended_) std::snprintf(what, sizeof what, "%d passes", s.passes);
                else std::snprintf(what, sizeof what, "%d/%d spp", s.passes, rule_.max_passes);
                if (rule_.noise > 0)
                    std::snprintf(what + std::strlen(what), sizeof what - std::strlen(what), "  est. error %.4f", noise);
                draw_progress(progress.fraction, what, elapsed());
                last_draw = elapsed();
            }
            return true;
        }, hooks_.get());
        // A signal after the last pass's check still stops the render, with its checkpoint.
        stop_on_signal.release();
        if (opt_.checkpoint && reason != StopReason::cancelled && cluster_.any_flags(stop_signal() ? 1 : 0)) {
            checkpoint_written_ = write_checkpoint(cluster_, *opt_.checkpoint, key_, state_);
            reason = StopReason::cancelled;
        }
        return reason;
    }

    // Every rank's costs, and the state gathered at rank 0 with the job's counts.
    void gather() {
        if (cluster_.distributed()) {
            RankCost mine = hooks_ ? Cluster::cost(*hooks_) : RankCost{};
            mine.rays = state_.rays - rays_before_;
            costs_ = cluster_.gather(mine);
        }
        uint64_t total_rays = 0, total_nonfinite = 0;
        cluster_.gather_state(state_, total_rays, total_nonfinite);
        if (!leader_) return;
        state_.rays = total_rays;
        state_.nonfinite_samples = total_nonfinite;
        seconds_ = elapsed();
    }

    void report_stop(StopReason reason) const {
        if (open_ended_) {
            const std::string by = reason == StopReason::passes && capped_
                                       ? "the cap of " + std::to_string(kMaxOpenEndedPasses) + " passes (no --spp)"
                                       : "--" + std::string(stop_reason_names.name(reason));
            std::fprintf(stderr, "%s%s: stopped by %s after %d passes, estimated relative error %.4f\n",
                         show_progress_ ? "\n" : "", shown_path(scene_file_.filename()).c_str(), by.c_str(), state_.passes,
                         state_.relative_error());
        }
        if (show_progress_) std::fprintf(stderr, "\n");
    }

    // Every file of the output, developed and encoded by render/outputs.h, committed
    // together: all replaced, or none.
    bool write() {
        stage_ = "the output images of a " + image_;
        try {
            OutputRequest request;
            request.path = output_;
            request.develop.blur = opt_.blur;
            request.develop.denoise = denoise();
            request.develop.sampling = settings_;
            request.display = loaded_.scene.display;
            if (opt_.gl)
                request.tone_map = [](const Image& radiance, const DisplaySettings& display) {
                    return viewer_module().display_offscreen(radiance, display, nullptr);
                };
            write_files_atomic(output_files(scene_, state_, request));
        } catch (const std::exception& e) {
            if (is_out_of_memory(e)) throw;
            std::fprintf(stderr, "error: %s: %s\n", file_.c_str(), e.what());
            return false;
        }
        return true;
    }

    void report_summary() const {
        if (state_.nonfinite_samples > 0)
            std::fprintf(stderr, "warning: %s: %llu non-finite samples were dropped\n", file_.c_str(),
                         static_cast<unsigned long long>(state_.nonfinite_samples));
        std::printf("%s: %dx%d %s %d spp, %.2f s, %.1f Mrays/s (%.1f M rays) -> %s\n",
                    shown_path(scene_file_.filename()).c_str(), state_.width, state_.height,
                    std::string(integrator_names.name(settings_.integrator)).c_str(), state_.passes, seconds_,
                    seconds_ > 0 ? double(state_.rays - rays_before_) / seconds_ * 1e-6 : 0.0,
                    double(state_.rays) * 1e-6, shown_path(output_).c_str());
        if (!costs_.empty()) print_rank_costs(costs_);
        std::fflush(stdout);
    }

    const fs::path& scene_file_;
    const Options& opt_;
    std::string& stage_;
    const Cluster& cluster_;
    const std::string file_;  // the scene file as messages show it
    const bool leader_;

    LoadedScene loaded_;
    RenderScene scene_;
    RenderSettings settings_;
    fs::path output_;
    std::string image_;  // "WxH image", for messages
    RenderState state_;
    StopRule rule_;
    bool open_ended_ = false, capped_ = false;
    CheckpointKey key_;
    uint64_t rays_before_ = 0;
    bool show_progress_ = false;
    bool checkpoint_written_ = false;  // the last attempt succeeded (rank 0)
    std::chrono::steady_clock::time_point start_;
    std::unique_ptr<PassHooks> hooks_;
    std::vector<RankCost> costs_;
    double seconds_ = 0;
};

bool render_scene_file(const fs::path& scene_file, const Options& opt, std::string& stage, const Cluster& cluster) {
    return SceneRender(scene_file, opt, stage, cluster).run();
}

}  // namespace

const char* render_intro() { return kRenderIntro; }

std::string render_options_help() { return kRenderIntro + shared_flags_help() + kRenderOnlyOptions; }

int run_render(int argc, char** argv, const std::string& help) {
    // Under mpirun or srun, this process is one rank of the job (app/cluster.h); every rank
    // parses the same command line, and rank 0 alone speaks for them.
    std::optional<Cluster> joined;
    try {
        joined.emplace(argc, argv);
    } catch (const std::runtime_error& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
    const Cluster& cluster = *joined;
    Options opt;
    try {
        opt = parse_options(argc, argv);
    } catch (const UsageError& e) {
        if (e.message.empty()) {  // --help
            if (cluster.leader()) std::fputs(help.c_str(), stdout);
            return stdout_written() ? 0 : 1;
        }
        if (cluster.leader()) std::fprintf(stderr, "error: %s\nRun 'keithray --help' for the options.\n", e.message.c_str());
        return 2;
    }
    if (opt.threads) omp_set_num_threads(*opt.threads);
    opt.team = omp_get_max_threads();
    // --gl's OSMesa is loaded before any render, by the rank that writes.
    std::string gl_error;
    if (opt.gl && cluster.leader()) try {
            viewer_module();
        } catch (const std::runtime_error& e) {
            gl_error = e.what();
            std::fprintf(stderr, "error: --gl: %s\n", e.what());
        }
    if (cluster.any_flags(!gl_error.empty())) return 1;
    if (opt.scenes.empty()) {
        // Rank 0's list of the bundled scenes, in every rank.
        std::string names;
        if (cluster.leader())
            for (const fs::path& scene : default_scenes()) names += scene.string() + '\0';
        cluster.broadcast(names);
        for (size_t at = 0, end; (end = names.find('\0', at)) != std::string::npos; at = end + 1)
            opt.scenes.emplace_back(names.substr(at, end - at));
        if (opt.scenes.empty()) {
            if (cluster.leader())
                std::fprintf(stderr, "error: no scene given and no bundled scenes found (looked in %s); give a "
                                     "SCENE.json to render\n", data_dir_places().c_str());
            return 2;
        }
        opt.bundled = true;
        if (cluster.leader())
            std::fprintf(stderr, "keithray: no scene given: rendering the %zu bundled scenes of %s into output/\n",
                         opt.scenes.size(), shown_path(opt.scenes.front().parent_path()).c_str());
    }
    bool ok = true;
    for (const fs::path& scene : opt.scenes) {
        std::string stage;
        try {
            ok = render_scene_file(scene, opt, stage, cluster) && ok;
        } catch (const std::exception& e) {
            if (is_out_of_memory(e))
                std::fprintf(stderr, "error: %s: not enough memory for %s\n", shown_path(scene).c_str(), stage.c_str());
            else
                std::fprintf(stderr, "error: %s: %s\n", shown_path(scene).c_str(), e.what());
            ok = false;
            // The other ranks wait for this one in the next exchange: end the job.
            if (cluster.distributed()) cluster.abort(1);
        }
        if (stop_signal()) break;  // a checkpointed render stopped by a signal: no further scene
    }
    // Every rank exits with the same status.
    ok = cluster.any_flags(!(stdout_written() && ok)) == 0;
    if (stop_signal()) return 128 + stop_signal();
    return ok ? 0 : 1;
}

}  // namespace kr
