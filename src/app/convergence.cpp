// `keithray bench --convergence`: error against a converged reference as samples and seconds
// grow, per configuration (integrator / light sampling / estimator), side by side in one run.
// Writes a CSV, one log-log plot per scene and a markdown table of time to given errors.
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <omp.h>
#include <unistd.h>

#include "app/bench.h"
#include "app/plot.h"
#include "app/progress.h"
#include "core/args.h"
#include "core/hash.h"
#include "core/image_io.h"
#include "render/progressive.h"
#include "scene/load.h"
#include "scene/scene_list.h"

namespace fs = std::filesystem;

namespace kr {

namespace {

// CPU time of the whole process (every thread), in seconds.
double cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double now_seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// One configuration: how samples are drawn and which integrator uses them.
struct Config {
    Integrator integrator = Integrator::pt;
    LightSampling light = LightSampling::area;
    Estimator estimator = Estimator::uniform;
    Allocation allocation = Allocation::uniform;

    // INTEGRATOR/LIGHT/ESTIMATOR, with /adaptive appended for adaptive allocation.
    std::string name() const {
        return std::string(integrator_names.name(integrator)) + "/" + std::string(light_sampling_names.name(light)) +
               "/" + std::string(estimator_names.name(estimator)) +
               (allocation == Allocation::uniform ? "" : "/" + std::string(allocation_names.name(allocation)));
    }
    // Configurations with the same key converge to the same image: WRT and PT differ, and
    // the brief's light estimator is brighter near lights than the exact ones (docs/fidelity.md).
    // Naive PT finds lights only by hitting them: the exact PT image.
    std::string expectation() const {
        return std::string(integrator == Integrator::wrt ? "wrt" : "pt") +
               (is_brief(light) && integrator != Integrator::pt_naive ? "-brief" : "-exact");
    }
};

Config parse_config(const std::string& text) {
    std::vector<std::string> parts;
    std::stringstream ss(text);
    for (std::string part; std::getline(ss, part, '/');) parts.push_back(part);
    if (parts.size() != 3 && parts.size() != 4)
        throw UsageError{"--configs expects INTEGRATOR/LIGHT/ESTIMATOR[/ALLOCATION] items (e.g. pt/cone/sobol or "
                         "pt/brief/sobol/adaptive), got \"" + text + "\""};
    Config c;
    c.integrator = parse_name("--configs integrator", parts[0], integrator_names);
    c.light = parse_name("--configs light sampling", parts[1], light_sampling_names);
    c.estimator = parse_name("--configs estimator", parts[2], estimator_names);
    if (parts.size() == 4) c.allocation = parse_name("--configs allocation", parts[3], allocation_names);
    return c;
}

// The defaults of `keithray render`, named as a configuration.
Config default_config(Integrator integrator) {
    const RenderSettings d;
    return {integrator, d.light_sampling, d.estimator, d.allocation};
}

// The baselines first: for the exact image the brief's stated one (uniform area light
// sampling, uniform random primary samples), for the brief's image the brief's own estimator
// (uniform over the facing hemisphere's area); then the alternatives for the scene's own
// integrator.
std::vector<Config> default_configs(Integrator file_integrator) {
    std::vector<Config> list;
    if (file_integrator == Integrator::wrt) {
        for (Estimator e : {Estimator::uniform, Estimator::stratified, Estimator::sobol})
            list.push_back({Integrator::wrt, LightSampling::area, e});
        list.push_back({Integrator::wrt, LightSampling::area, Estimator::sobol, Allocation::adaptive});
        return list;
    }
    list = {{Integrator::pt, LightSampling::area, Estimator::uniform},
            {Integrator::pt, LightSampling::brief_area, Estimator::uniform},
            {Integrator::pt, LightSampling::area, Estimator::stratified},
            {Integrator::pt, LightSampling::cone, Estimator::uniform},
            {Integrator::pt, LightSampling::cone, Estimator::sobol},
            {Integrator::pt, LightSampling::cone, Estimator::sobol, Allocation::adaptive},
            {Integrator::pt, LightSampling::brief, Estimator::stratified},
            {Integrator::pt, LightSampling::brief, Estimator::sobol},
            {Integrator::pt, LightSampling::brief, Estimator::sobol, Allocation::adaptive},
            {Integrator::pt_naive, LightSampling::cone, Estimator::sobol},
            {Integrator::wrt, LightSampling::cone, Estimator::sobol}};
    return list;
}

struct Options {
    std::vector<fs::path> scenes;
    std::vector<Config> configs;  // empty: default_configs per scene
    double scale = 0.25;
    int spp = 0;              // 0: the file's
    int reference_factor = 4; // reference spp = factor x the configs' spp
    fs::path reference_file;  // a given reference image instead of rendering one
    fs::path out_dir = "res/output/bench";
    int threads = 0;
};

constexpr const char* kUsage = R"(Usage:
  keithray bench --convergence [SCENE.json ...] [--configs LIST] [--scale F] [--spp N]
                 [--reference-factor K] [--reference IMAGE] [--out DIR] [--threads N]

Renders each scene (default: the bundled scenes) with each configuration, side by
side, at F times the file's resolution (default 0.25), checking the error after 1, 2, 4,
... samples per pixel up to N (default: the file's sample count). Configurations are
INTEGRATOR/LIGHT/ESTIMATOR[/ALLOCATION] items separated by commas, e.g.
pt/area/uniform,pt/cone/sobol/adaptive (integrators wrt, pt, pt-naive; light sampling
brief, brief-area, cone, area; estimators uniform, stratified, sobol; allocation uniform,
the default when left out, or adaptive). Each configuration's speed-up is measured
against the first one listed that converges to the same image: by default pt/area/uniform for the exact
image (the brief's stated baseline) and pt/brief-area/uniform for the brief's (the brief's
own estimator).

The error of each configuration is measured against a converged render of the image it
converges to (the brief's light estimator and WRT converge to their own images), rendered
with Sobol samples at K times N spp (default K = 4) and cached under DIR/cache. The
reference's own remaining variance is subtracted from the squared error. --reference uses
a given image instead (an 8-bit PPM or PNG such as a bundled reference: PSNR only).

Times are CPU seconds of all threads together, each configuration rendering one pass in
turn: other processes on shared cores neither inflate them nor favour one configuration.
Writes DIR/convergence.csv (scene, config, spp, CPU seconds, RMSE, relative RMSE, PSNR),
DIR/SCENE.png (relative RMSE, or 8-bit RMSE, against CPU seconds, log-log) and
DIR/convergence.md (time to reach given errors, and the speed-up over the baseline).
)";

Options parse(int argc, char** argv) {
    Options o;
    for (ArgCursor args(argc, argv); args.next();) {
        const std::string& arg = args.arg();
        auto value = [&] { return args.value(); };
        if (arg == "--convergence") continue;
        else if (arg == "--configs") {
            for (const std::string& item : split_list(value())) o.configs.push_back(parse_config(item));
        } else if (arg == "--scale") o.scale = parse_number(arg, value(), 1e-3, 4.0);
        else if (arg == "--spp") o.spp = int(parse_integer(arg, value(), 1, 1 << 24));
        else if (arg == "--reference-factor") o.reference_factor = int(parse_integer(arg, value(), 1, 1024));
        else if (arg == "--reference") o.reference_file = value();
        else if (arg == "--out") o.out_dir = value();
        else if (arg == "--threads") o.threads = int(parse_integer(arg, value(), 1, 4096));
        else if (arg == "-h" || arg == "--help") throw UsageError{""};
        else if (!arg.empty() && arg[0] == '-') throw UsageError{"unknown option " + arg};
        else o.scenes.emplace_back(arg);
    }
    if (!o.reference_file.empty() && o.scenes.size() != 1)
        throw UsageError{"--reference needs exactly one scene file"};
    return o;
}

// A converged image: per-pixel mean radiance and the variance of its luminance mean
// (zero for a given 8-bit image, which has only its tone-mapped form).
struct Reference {
    int width = 0, height = 0;
    bool has_radiance = false;
    Image radiance;
    std::vector<double> luminance_variance;
    Rgb8Image display;  // sigmoid tone map, as the product writes it
};

std::string hex(uint64_t v) {
    char buf[24];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
    return buf;
}

std::string read_text(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// Cache format: a text line "keithray-reference 2 W H", then W*H x (r, g, b, variance) doubles.
bool load_cached(const fs::path& file, Reference& ref) {
    std::ifstream in(file, std::ios::binary);
    std::string magic;
    int version = 0, w = 0, h = 0;
    if (!(in >> magic >> version >> w >> h) || magic != "keithray-reference" || version != 2 || w != ref.width ||
        h != ref.height)
        return false;
    in.get();
    std::vector<double> data(size_t(w) * h * 4);
    if (!in.read(reinterpret_cast<char*>(data.data()), std::streamsize(data.size() * sizeof(double)))) return false;
    ref.radiance = Image(w, h);
    ref.luminance_variance.resize(size_t(w) * h);
    for (size_t i = 0; i < ref.luminance_variance.size(); ++i) {
        ref.radiance.pixels[i] = Color(data[4 * i], data[4 * i + 1], data[4 * i + 2]);
        ref.luminance_variance[i] = data[4 * i + 3];
    }
    return true;
}

void save_cached(const fs::path& file, const Reference& ref) {
    std::string bytes = "keithray-reference 2 " + std::to_string(ref.width) + " " + std::to_string(ref.height) + "\n";
    std::vector<double> data;
    for (size_t i = 0; i < ref.luminance_variance.size(); ++i) {
        const Color& c = ref.radiance.pixels[i];
        data.insert(data.end(), {c.x, c.y, c.z, ref.luminance_variance[i]});
    }
    bytes.append(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(double));
    write_file_atomic(file, bytes);
}

// What one configuration has measured so far.
struct Series {
    Config config;
    RenderState state;
    RenderSettings settings;
    double seconds = 0;
    struct Point {
        int spp;
        double seconds, rmse, relative_rmse, psnr;
    };
    std::vector<Point> points;
    // The error the table and plot use: relative RMSE of luminance, or with an 8-bit
    // reference, the RMSE of the 8-bit image in levels.
    double error(const Point& p, bool radiance) const { return radiance ? p.relative_rmse : 255 * std::pow(10.0, -p.psnr / 20); }
};

Series::Point measure(const Series& s, const Reference& ref) {
    Series::Point p{s.state.passes, s.seconds, NAN, NAN, 0};
    const Image radiance = s.state.radiance();
    if (ref.has_radiance) {
        // Squared luminance error minus the reference's own variance (its expected share).
        double sq = 0, ref_var = 0, signal = 0;
        for (size_t i = 0; i < radiance.pixels.size(); ++i) {
            const double l = luminance(radiance.pixels[i]), lr = luminance(ref.radiance.pixels[i]);
            sq += (l - lr) * (l - lr);
            ref_var += ref.luminance_variance[i];
            signal += lr * lr;
        }
        const double mse = std::max(0.0, sq - ref_var) / double(radiance.pixels.size());
        p.rmse = std::sqrt(mse);
        p.relative_rmse = signal > 0 ? std::sqrt(mse * radiance.pixels.size() / signal) : NAN;
    }
    p.psnr = psnr(tonemap(radiance, kDefaultToneMap), ref.display);
    return p;
}

// Seconds at which the series first reaches `target` error, interpolated in log-log
// between checkpoints; negative if never. `at_first` is set when already met at 1 spp.
double time_to_error(const Series& s, double target, bool radiance, bool& at_first) {
    at_first = false;
    for (size_t k = 0; k < s.points.size(); ++k) {
        const double e = s.error(s.points[k], radiance);
        if (!(e <= target)) continue;
        if (k == 0) {
            at_first = true;
            return s.points[0].seconds;
        }
        const double e0 = s.error(s.points[k - 1], radiance), t0 = s.points[k - 1].seconds, t1 = s.points[k].seconds;
        if (!(e0 > e) || t0 <= 0) return t1;
        const double f = std::log(e0 / target) / std::log(e0 / e);
        return std::exp(std::log(t0) + f * std::log(t1 / t0));
    }
    return -1;
}

std::string fmt(const char* format, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

struct SceneResult {
    std::string markdown;
    std::string csv;
};

struct Bench {
    const Options& o;
    bool show_progress = ::isatty(STDERR_FILENO);
    double start = now_seconds();
    double last_draw = -1;

    void progress(double fraction, const std::string& what) {
        if (!show_progress || now_seconds() - last_draw < 0.1) return;
        draw_progress(fraction, what, now_seconds() - start);
        last_draw = now_seconds();
    }

    Reference render_reference(const fs::path& file, const RenderScene& scene, const Config& c, int width, int height,
                               int spp, const std::string& label) {
        Reference ref;
        ref.width = width, ref.height = height;
        RenderSettings settings = RenderSettings::from_scene(scene.renderer);
        settings.integrator = c.integrator == Integrator::wrt ? Integrator::wrt : Integrator::pt;
        settings.light_sampling = c.expectation().ends_with("-brief") ? LightSampling::brief : LightSampling::cone;
        settings.estimator = Estimator::sobol;
        settings.allocation = Allocation::uniform;  // unbiased: the sample counts never depend on the samples
        // kReferenceVersion changes whenever the renderer's converged image does (e.g. the
        // pixel grid's half-pixel shift): an older cache then misses instead of skewing errors.
        constexpr int kReferenceVersion = 2;
        const std::string key = file.stem().string() + "-" + c.expectation() + "-" + std::to_string(width) + "x" +
                                std::to_string(height) + "-" + std::to_string(spp) + "spp-" + hex(fnv1a(read_text(file))) +
                                "-v" + std::to_string(kReferenceVersion);
        const fs::path cache = o.out_dir / "cache" / (key + ".ref");
        ref.has_radiance = true;
        if (!load_cached(cache, ref)) {
            // Two independent halves (different seeds). The variance of their average is
            // estimated from their difference, E[(A - B)^2] / 4: unlike the per-sample variance
            // over N, this holds for Sobol samples too, which converge faster than 1/N.
            RenderState halves[2] = {RenderState(width, height), RenderState(width, height)};
            const int half_spp = std::max(1, spp / 2);
            settings.target_spp = half_spp;
            for (int h = 0; h < 2; ++h) {
                settings.seed = 0x5eed + h;  // independent of the configurations' seed 0
                for (int pass = 0; pass < half_spp; ++pass) {
                    render_pass(scene, settings, halves[h]);
                    progress((h * half_spp + pass + 1) / (2.0 * half_spp),
                             label + " reference " + std::to_string(h * half_spp + pass + 1) + "/" +
                                 std::to_string(2 * half_spp) + " spp");
                }
            }
            const Image a = halves[0].radiance(), b = halves[1].radiance();
            ref.radiance = Image(width, height);
            ref.luminance_variance.resize(a.pixels.size());
            for (size_t i = 0; i < a.pixels.size(); ++i) {
                ref.radiance.pixels[i] = 0.5 * (a.pixels[i] + b.pixels[i]);
                const double d = luminance(a.pixels[i]) - luminance(b.pixels[i]);
                ref.luminance_variance[i] = 0.25 * d * d;
            }
            save_cached(cache, ref);
        }
        ref.display = tonemap(ref.radiance, kDefaultToneMap);
        return ref;
    }

    SceneResult run_scene(const fs::path& file, int scene_number, int scene_count) {
        const RenderScene scene = prepare_scene(load_scene_file(file).scene);
        const RenderSettings file_settings = RenderSettings::from_scene(scene.renderer);
        const int width = std::max(1, int(std::lround(scene.renderer.width * o.scale)));
        const int height = std::max(1, int(std::lround(scene.renderer.height * o.scale)));
        const int spp = o.spp > 0 ? o.spp : file_settings.target_spp;
        const std::string label = "[" + std::to_string(scene_number) + "/" + std::to_string(scene_count) + "] " +
                                  file.stem().string();

        std::vector<Series> series;
        for (const Config& c : o.configs.empty() ? default_configs(file_settings.integrator) : o.configs) {
            Series s;
            s.config = c;
            s.settings = file_settings;
            s.settings.integrator = c.integrator;
            s.settings.light_sampling = c.light;
            s.settings.estimator = c.estimator;
            s.settings.allocation = c.allocation;
            s.settings.target_spp = spp;
            s.state.reset(width, height);
            series.push_back(std::move(s));
        }

        // One reference per image the configurations converge to (or the given image).
        std::map<std::string, Reference> references;
        for (const Series& s : series) {
            const std::string key = o.reference_file.empty() ? s.config.expectation() : "given";
            if (references.count(key)) continue;
            if (!o.reference_file.empty()) {
                Reference ref;
                ref.display = read_image(o.reference_file);
                if (ref.display.width != width || ref.display.height != height)
                    throw std::runtime_error(o.reference_file.string() + " is " + std::to_string(ref.display.width) +
                                             "x" + std::to_string(ref.display.height) + ", the renders " +
                                             std::to_string(width) + "x" + std::to_string(height) +
                                             " (choose --scale to match)");
                references[key] = std::move(ref);
            } else {
                references[key] = render_reference(file, scene, s.config, width, height, spp * o.reference_factor, label);
            }
        }

        // Side by side, pass by pass: each configuration renders one pass in turn, so load
        // from other processes falls on all of them alike; and their time is the CPU time of
        // this process (all threads), which other processes on shared cores do not inflate.
        std::vector<int> checkpoints;
        for (int k = 1; k < spp; k *= 2) checkpoints.push_back(k);
        checkpoints.push_back(spp);
        size_t next_checkpoint = 0;
        for (int pass = 1; pass <= spp; ++pass) {
            for (Series& s : series) {
                const double t0 = cpu_seconds();
                plan_pass(s.state, s.settings);
                render_pass(scene, s.settings, s.state);
                s.seconds += cpu_seconds() - t0;
                if (pass == checkpoints[next_checkpoint]) {
                    const std::string key = o.reference_file.empty() ? s.config.expectation() : "given";
                    s.points.push_back(measure(s, references.at(key)));
                }
            }
            if (pass == checkpoints[next_checkpoint]) ++next_checkpoint;
            progress(double(pass) / spp, label + " " + std::to_string(pass) + "/" + std::to_string(spp) + " spp, " +
                                             std::to_string(series.size()) + " configurations");
        }
        return report(file, series, spp, width, height);
    }

    SceneResult report(const fs::path& file, const std::vector<Series>& series, int spp, int width, int height) {
        const bool radiance = o.reference_file.empty();
        const std::string stem = file.stem().string();
        SceneResult r;
        for (const Series& s : series)
            for (const Series::Point& p : s.points)
                r.csv += stem + "," + s.config.name() + "," + std::to_string(p.spp) + "," + fmt("%.4f", p.seconds) + "," +
                         fmt("%.6g", p.rmse) + "," + fmt("%.6g", p.relative_rmse) + "," + fmt("%.3f", p.psnr) + "\n";

        PlotSpec plot;
        plot.title = stem + " (" + std::to_string(width) + "x" + std::to_string(height) + ")";
        plot.x_label = "CPU seconds (" + std::to_string(omp_get_max_threads()) + (omp_get_max_threads() > 1 ? " threads together)" : " thread)");
        plot.y_label = radiance ? "relative RMSE of luminance" : "RMSE of the 8-bit image (levels)";
        for (const Series& s : series) {
            PlotSeries line;
            line.name = s.config.name();
            for (const Series::Point& p : s.points) {
                line.x.push_back(p.seconds);
                line.y.push_back(s.error(p, radiance));
            }
            plot.series.push_back(line);
        }
        write_png(o.out_dir / (stem + ".png"), plot_loglog(plot));

        // Time for each configuration to reach, at full spp, the error of its baseline: the
        // first configuration converging to the same image (with a given 8-bit reference, the
        // first of all). Then the times to fixed error levels.
        auto baseline_of = [&](const Series& s) -> const Series& {
            for (const Series& b : series)
                if (!radiance || b.config.expectation() == s.config.expectation()) return b;
            return s;
        };
        const std::vector<double> levels = radiance ? std::vector<double>{0.1, 0.05, 0.02, 0.01}
                                                    : std::vector<double>{8, 4, 2, 1};
        const Config def = default_config(series.front().settings.integrator == Integrator::wrt ? Integrator::wrt
                                                                                                : Integrator::pt);
        std::string& md = r.markdown;
        md += "### " + stem + "\n\n" + std::to_string(width) + "x" + std::to_string(height) + ", up to " +
              std::to_string(spp) + " spp, " + std::to_string(omp_get_max_threads()) +
              " threads, seconds of CPU time (all threads); error: " +
              (radiance ? "relative RMSE of luminance against the converged image of each configuration"
                        : "RMSE (8-bit levels) against " + o.reference_file.filename().string()) +
              ". Speed-up: the baseline's seconds at " + std::to_string(spp) +
              " spp over the seconds this configuration needs to reach the baseline's error there.\n\n";
        md += "| configuration | final error | PSNR (dB) | seconds | baseline | s to baseline's error | speed-up |";
        for (double level : levels) md += " s to " + fmt(radiance ? "%g" : "%g levels", level) + " |";
        md += "\n|---|---|---|---|---|---|---|";
        for (size_t i = 0; i < levels.size(); ++i) md += "---|";
        md += "\n";
        auto time_cell = [&](const Series& s, double target) {
            bool at_first = false;
            const double t = time_to_error(s, target, radiance, at_first);
            return t < 0 ? std::string("-") : (at_first ? "<= " : "") + fmt("%.3g", t);
        };
        for (const Series& s : series) {
            const Series& baseline = baseline_of(s);
            const double baseline_error = baseline.error(baseline.points.back(), radiance);
            const Series::Point& last = s.points.back();
            bool at_first = false;
            const double t = time_to_error(s, baseline_error, radiance, at_first);
            const bool is_default = s.config.name() == def.name();
            md += "| " + s.config.name() + (is_default ? " (default)" : "") + " | " +
                  fmt("%.4g", s.error(last, radiance)) + " | " + fmt("%.2f", last.psnr) + " | " +
                  fmt("%.2f", last.seconds) + " | " + baseline.config.name() + " | " + time_cell(s, baseline_error) +
                  " | " + (t > 0 ? fmt("%.2fx", baseline.points.back().seconds / t) : std::string("-")) + " |";
            for (double level : levels) md.append(" ").append(time_cell(s, level)).append(" |");
            md += "\n";
        }
        md += "\n";
        return r;
    }
};

}  // namespace

const char* convergence_usage() { return kUsage; }

int bench_convergence(int argc, char** argv) {
    Options o;
    try {
        o = parse(argc, argv);
    } catch (const UsageError& e) {
        return report_usage(e, kUsage);
    }
    if (o.threads > 0) omp_set_num_threads(o.threads);
    const std::vector<fs::path> scenes = o.scenes.empty() ? default_scenes() : o.scenes;
    Bench bench{o};
    std::string csv = "scene,config,spp,cpu_seconds,rmse,relative_rmse,psnr\n";
    std::string md = "# Convergence (keithray bench --convergence)\n\n";
    for (size_t i = 0; i < scenes.size(); ++i) {
        SceneResult r;
        try {
            r = bench.run_scene(scenes[i], int(i + 1), int(scenes.size()));
        } catch (const SceneError& e) {
            std::fprintf(stderr, "%serror: %s\n", bench.show_progress ? "\n" : "", e.what());
            return 1;
        } catch (const std::exception& e) {
            std::fprintf(stderr, "%serror: %s: %s\n", bench.show_progress ? "\n" : "", scenes[i].string().c_str(), e.what());
            return 1;
        }
        if (bench.show_progress) std::fprintf(stderr, "\n");
        std::printf("%s", r.markdown.c_str());
        std::fflush(stdout);
        csv += r.csv;
        md += r.markdown;
        // Written after every scene, so an interrupted run keeps what it measured; the table
        // and its Markdown always agree.
        try {
            write_files_atomic({{o.out_dir / "convergence.csv", csv}, {o.out_dir / "convergence.md", md}});
        } catch (const std::exception& e) {
            std::fprintf(stderr, "error: %s\n", e.what());
            return 1;
        }
    }
    std::printf("Wrote %s, %s and one PNG plot per scene.\n", (o.out_dir / "convergence.csv").string().c_str(),
                (o.out_dir / "convergence.md").string().c_str());
    return 0;
}

}  // namespace kr
