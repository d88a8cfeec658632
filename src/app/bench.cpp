// `keithray bench --throughput`: ray throughput and render time per scene, medians of
// several runs; `--stress N,...`: cost per ray on generated scenes of N spheres (BVH scaling).
#include "app/bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <omp.h>

#include "core/args.h"
#include "core/file_write.h"
#include "core/memory.h"
#include "core/text.h"
#include "render/progressive.h"
#include "render/trace.h"
#include "scene/json_reader.h"
#include "scene/load.h"
#include "scene/scene_list.h"

namespace fs = std::filesystem;

namespace kr {

namespace {

constexpr const char* kBenchUsage = R"(Usage:
  keithray bench --throughput [SCENE.json ...] [--fraction F] [--runs N] [--threads N] [--linear|--accel NAME]
                 [--kernels best|double|float8|any|off] [--lens R]
  keithray bench --stress N[,N...] [--accel LIST] [--runs N] [--threads N] [--size W] [--cpu-time]
  keithray bench --sweep FROM:TO [--accel LIST] [--runs N] [--threads N] [--size W] [--cpu-time]
  keithray bench --write-stress N OUT.json
  keithray bench --convergence [SCENE.json ...] [options]   (see keithray bench --convergence --help)

--throughput  renders each scene (default: the bundled scenes) at F times its own
              sample count (default F = 1/32, at least 1 spp), --runs times (default 3),
              and prints the median seconds and Mrays/s (all rays: camera, bounce, shadow),
              the seconds the file's full sample count takes at that speed, and the median
              time of one full-resolution 1-spp pass.
--lens R      also renders each scene through a thin lens of radius R in place of its
              camera (focused on the origin), interleaved with the scene's own camera,
              and prints that row with its speed as a fraction of the other's.
--linear      test every sphere per ray instead of the BVH (the plain path, for comparison).
--kernels     how paths are traced: best (default: in SIMD lanes with the AVX2/FMA
              kernels where the CPU has them, in single precision where the scene's
              sizes allow, sixteen at a time with AVX-512, else eight; else four in
              double; one at a time without AVX2), double (always the four double
              lanes), float8 (the eight float lanes even with AVX-512), any (in lanes
              with the kernels for any x86-64 CPU, SSE2) or off (one at a time), to
              measure what each buys.
              The table's last column says which ran for each scene.
--stress      generated scenes of N random spheres (and a floor and a lamp, two spheres
              more) under a sphere light, path traced at W x W (default 256) with 4 spp:
              ns per ray and ns per ray / log2(N), and how paths were traced: in SIMD
              lanes (single-precision lanes scan the spheres a cluster at a time,
              double lanes walk a tree) or one path at a time. Under auto the lanes
              take up to 1,800 spheres (2,800 on an AMD CPU of family 26:
              `keithray --version` says this CPU's; eight float lanes 768, double
              lanes 128) and Embree one path at a time above; under own, up to
              2,048 (3,000 there; eight float lanes 1,024, double lanes 320) and our
              own tree one path at a time above (never Embree); embree always
              traces one path at a time.
              --runs rounds each render every count once (each BVH in turn); the
              table gives their medians, so that a burst of load on a shared
              machine moves one run of many counts rather than one count's median.
--sweep       --stress at every count from FROM to TO, each about 10 % above the last,
              then per BVH its steps (the largest rise of ns per ray between
              neighbouring counts, and how many rise by more than 15 %) and its band
              (the largest over the smallest ns per ray / log2 N above 64 spheres).
--accel LIST  the BVHs --stress compares, runs interleaved: own, embree, auto (default:
              own,embree where the build has Embree, else own). With --throughput, one
              of them (default auto).
--cpu-time    time --stress and --sweep by the process's CPU time rather than the
              clock: on a machine other programs share, what the renders themselves
              cost (with --threads 1, where no thread waits for work).
--write-stress writes such a scene as a scene file (for the viewer).
)";

}  // namespace

const char* bench_usage() { return kBenchUsage; }

namespace {

double now_seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The CPU time of all the process's threads.
double cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n == 0 ? 0.0 : (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}

struct Timing {
    double seconds = 0;
    uint64_t rays = 0;
};

// Renders `passes` passes into a fresh state, each planned as `keithray render` plans it
// (adaptive allocation, by default); returns wall time (or CPU time, `cpu`) and rays.
Timing time_render(const RenderScene& scene, const RenderSettings& settings, int width, int height, int passes,
                   bool cpu = false) {
    const auto clock = cpu ? cpu_seconds : now_seconds;
    RenderState state(width, height);
    const double start = clock();
    for (int i = 0; i < passes; ++i) {
        plan_pass(state, settings);
        render_pass(scene, settings, state);
    }
    return {clock() - start, state.rays};
}

// N random spheres of a few diffuse colours in a cube of side 20, on a floor, under one
// sphere light: a scene whose cost is all in ray casting.
// Its JSON text, dumped with `indent` (-1: on one line). The DOMs are freed without allocating
// however the function is left (scene/json_reader.h: nlohmann's destructor allocates).
std::string stress_scene_json(int n, uint64_t seed, int indent = -1) {
    using nlohmann::json;
    json j;
    const ReleasedOnExit<json> freed{j};
    j["cameras"] = json::array({{{"id", "camera"}, {"type", "pinhole"}, {"fov", 45}, {"aspect", 1.0},
                                 {"distance", 5.0}, {"position", {0, 4, -45}}, {"target", {0, 0, 0}}}});
    j["materials"] = json::array({{{"id", "red"}, {"type", "diffuse"}, {"rho", {0.8, 0.3, 0.3}}},
                                  {{"id", "green"}, {"type", "diffuse"}, {"rho", {0.3, 0.8, 0.3}}},
                                  {{"id", "blue"}, {"type", "diffuse"}, {"rho", {0.3, 0.3, 0.8}}},
                                  {{"id", "grey"}, {"type", "diffuse"}, {"rho", {0.7, 0.7, 0.7}}}});
    json shapes = json::array(), primitives = json::array();
    const ReleasedOnExit<json> freed_shapes{shapes}, freed_primitives{primitives};
    Rng rng(seed, 17);
    // Radii so the spheres fill about a tenth of the cube whatever N is.
    const double mean_radius = 20.0 * std::cbrt(0.1 * 3.0 / (4.0 * kPi * n));
    for (int i = 0; i < n; ++i) {
        std::string id = std::to_string(i);
        id.insert(id.begin(), 's');  // (not "s" + ...: GCC 12 warns falsely about that)
        shapes.push_back({{"id", id}, {"type", "sphere"},
                          {"centre", {20 * rng.next() - 10, 20 * rng.next() - 10, 20 * rng.next() - 10}},
                          {"radius", mean_radius * (0.5 + rng.next())}});
        static const char* kColours[] = {"red", "green", "blue"};
        primitives.push_back({{"id", "p" + id}, {"type", "geometric"}, {"shape", id},
                              {"material", kColours[i % 3]}});
    }
    shapes.push_back({{"id", "floor"}, {"type", "sphere"}, {"centre", {0, -1011, 0}}, {"radius", 1000}});
    shapes.push_back({{"id", "lamp"}, {"type", "sphere"}, {"centre", {10, 30, -20}}, {"radius", 6}});
    primitives.push_back({{"id", "floor"}, {"type", "geometric"}, {"shape", "floor"}, {"material", "grey"}});
    primitives.push_back({{"id", "lamp"}, {"type", "emissive"}, {"shape", "lamp"}, {"material", "grey"},
                          {"light", "lamp"}});
    j["shapes"] = std::move(shapes);
    j["lights"] = json::array({{{"id", "lamp"}, {"type", "area"}, {"shape", "lamp"}, {"power", {8, 8, 8}}}});
    j["scene"] = {{"camera", "camera"},
                  {"lights", {"lamp"}},
                  {"primitives", std::move(primitives)},
                  {"renderer", {{"type", "PT"}, {"dimensions", {512, 512}}, {"samples", 64}, {"depth", 4},
                                {"output", "stress_" + std::to_string(n) + ".ppm"}}}};
    return j.dump(indent);
}

struct BenchOptions {
    bool throughput = false, linear = false;
    std::vector<int> stress;
    bool sweep = false, cpu_time = false;
    std::vector<AccelBackend> accel;
    int write_stress = 0;
    fs::path write_path;
    std::vector<fs::path> scenes;
    double fraction = 1.0 / 32;
    int runs = 3, threads = 0, size = 256;
    double lens = 0;
    LaneChoice kernels = LaneChoice::best;
};

BenchOptions parse(int argc, char** argv) {
    BenchOptions o;
    for (ArgCursor args(argc, argv); args.next();) {
        const std::string& arg = args.arg();
        auto value = [&] { return args.value(); };
        if (arg == "--throughput") o.throughput = true;
        else if (arg == "--linear") o.linear = true;
        else if (arg == "--cpu-time") o.cpu_time = true;
        else if (arg == "--fraction") o.fraction = parse_number(arg, value(), 1e-6, 1.0);
        else if (arg == "--runs") o.runs = int(parse_number(arg, value(), 1, 1000));
        else if (arg == "--threads") o.threads = int(parse_number(arg, value(), 1, 4096));
        else if (arg == "--size") o.size = int(parse_number(arg, value(), 1, 8192));
        else if (arg == "--kernels") o.kernels = parse_name(arg, value(), lane_choice_names);
        else if (arg == "--lens") o.lens = parse_number(arg, value(), 1e-9, 1e9);
        else if (arg == "--stress") {
            for (const std::string& item : split_list(value()))
                o.stress.push_back(int(parse_number("--stress", item, 1, 1e7)));
        } else if (arg == "--sweep") {
            const std::string range = value();
            const size_t colon = range.find(':');
            if (colon == std::string::npos)
                throw UsageError{"--sweep: expected FROM:TO (sphere counts), got " + quote_user_text(range, 40)};
            const int from = int(parse_number("--sweep", range.substr(0, colon), 1, 1e7));
            const int to = int(parse_number("--sweep", range.substr(colon + 1), 1, 1e7));
            if (to < from) throw UsageError{"--sweep: TO is below FROM in " + quote_user_text(range, 40)};
            for (int n = from; n <= to; n = std::max(n + 1, int(std::lround(n * 1.1)))) o.stress.push_back(n);
            if (o.stress.back() != to) o.stress.push_back(to);
            o.sweep = true;
        } else if (arg == "--accel") {
            for (const std::string& item : split_list(value())) {
                const AccelBackend backend = parse_name(arg, item, accel_backend_names);
                if (backend == AccelBackend::embree && !embree_available())
                    throw UsageError{"--accel embree: this build has no Embree (install libembree-dev)"};
                o.accel.push_back(backend);
            }
        } else if (arg == "--write-stress") {
            o.write_stress = int(parse_number(arg, value(), 1, 1e7));
            o.write_path = value();
        } else if (arg == "-h" || arg == "--help") throw UsageError{""};
        else if (!arg.empty() && arg[0] == '-') throw unknown_option(arg);
        else o.scenes.emplace_back(arg);
    }
    if (!o.throughput && o.stress.empty() && o.write_stress == 0)
        throw UsageError{"choose --throughput, --stress, --sweep, --write-stress or --convergence"};
    if (o.throughput && o.accel.size() > 1) throw UsageError{"--throughput takes one --accel"};
    if (o.accel.empty()) {
        if (o.throughput) o.accel = {AccelBackend::automatic};
        else o.accel = embree_available() ? std::vector{AccelBackend::own, AccelBackend::embree}
                                          : std::vector{AccelBackend::own};
    }
    return o;
}

int bench_throughput(const BenchOptions& o) {
    std::vector<fs::path> scenes = o.scenes.empty() ? default_scenes() : o.scenes;
    std::printf("| scene | renderer | spp run | median s | Mrays/s | est. s at file spp | 1-spp pass ms | paths |\n");
    std::printf("|---|---|---|---|---|---|---|---|\n");
    double total_estimate = 0;
    for (const fs::path& file : scenes) {
        RenderScene scene;
        try {
            scene = prepare_scene(load_scene_file(file).scene);
        } catch (const SceneError& e) {
            std::fprintf(stderr, "error: %s\n", e.what());
            return 1;
        }
        scene.linear_scan = o.linear;
        if (o.accel.front() != AccelBackend::automatic) {  // prepare_scene built the automatic one
            scene.accel_backend = o.accel.front();
            scene.build_accel();
        }
        RenderSettings settings = RenderSettings::from_scene(scene.renderer);
        settings.kernels = o.kernels;
        const int spp = std::max(1, int(std::lround(settings.target_spp * o.fraction)));
        const int w = scene.renderer.width, h = scene.renderer.height;
        // The scene's own camera, and with --lens the same view through a thin lens, their
        // runs interleaved.
        std::vector<RenderScene> cameras{scene};
        if (o.lens > 0) {
            cameras.push_back(scene);
            cameras.back().camera.lens_radius = o.lens;
            cameras.back().camera.focal_distance = std::max(length(scene.camera.position), 1e-3);
        }
        std::vector<std::vector<double>> seconds(cameras.size()), mrays(cameras.size()), pass_ms(cameras.size());
        for (int run = 0; run < o.runs; ++run)
            for (size_t c = 0; c < cameras.size(); ++c) {
                const Timing t = time_render(cameras[c], settings, w, h, spp);
                seconds[c].push_back(t.seconds);
                mrays[c].push_back(t.seconds > 0 ? t.rays / t.seconds * 1e-6 : 0);
                // A lone first pass, as the viewer's first full-resolution refinement.
                pass_ms[c].push_back(time_render(cameras[c], settings, w, h, 1).seconds * 1e3);
            }
        for (size_t c = 0; c < cameras.size(); ++c) {
            const double s = median(seconds[c]), estimate = s * settings.target_spp / spp;
            if (c == 0) total_estimate += estimate;
            std::string name = file.stem().string();
            if (c == 1)
                name += " (lens " + std::to_string(o.lens).substr(0, 6) + ": " +
                        std::to_string(int(std::lround(100 * median(mrays[1]) / std::max(median(mrays[0]), 1e-9)))) +
                        " % of its Mrays/s)";
            std::printf("| %s | %s | %d of %d | %.2f | %.1f | %.0f | %.1f | %s |\n", name.c_str(),
                        std::string(integrator_names.name(settings.integrator)).c_str(), spp, settings.target_spp, s,
                        median(mrays[c]), estimate, median(pass_ms[c]),
                        std::string(lane_kernels_names.name(lane_kernels(cameras[c], settings))).c_str());
        }
        std::fflush(stdout);
    }
    std::printf("\nAll scenes at their own sample counts: %.0f s estimated (%d threads, %s, --kernels %s).\n",
                total_estimate, omp_get_max_threads(),
                o.linear ? "linear scan" : ("BVH " + std::string(accel_backend_names.name(o.accel.front()))).c_str(),
                std::string(lane_choice_names.name(o.kernels)).c_str());
    return 0;
}

// --sweep's summary of one BVH's ns per ray at the sweep's counts.
void print_sweep_summary(const char* bvh, const std::vector<int>& counts, const std::vector<double>& ns) {
    double largest = 0, band_lo = kInfinity, band_hi = 0;
    size_t at = 0;
    int steps = 0;
    for (size_t i = 1; i < counts.size(); ++i) {
        const double rise = ns[i] / ns[i - 1];
        if (rise > 1.15) ++steps;
        if (rise > largest) largest = rise, at = i;
    }
    for (size_t i = 0; i < counts.size(); ++i)
        if (counts[i] > 64) {
            const double per_log = ns[i] / std::log2(double(counts[i]) + 1);
            band_lo = std::min(band_lo, per_log);
            band_hi = std::max(band_hi, per_log);
        }
    std::printf("| %s | %+.0f %% | %d to %d | %d | ", bvh, 100 * (largest - 1), at ? counts[at - 1] : 0,
                at ? counts[at] : 0, steps);
    if (band_hi > 0) std::printf("%.2f to %.2f | %.2fx |\n", band_lo, band_hi, band_hi / band_lo);
    else std::printf("- | - |\n");
}

// One generated scene's figures under each BVH of --stress, gathered over the rounds.
struct StressCount {
    double prepare_ms = 0;
    std::vector<double> build_ms;
    std::vector<std::vector<double>> seconds, ns;  // per BVH, one per round
    struct Built {
        std::string bvh, nodes, depth, paths;  // the table's columns that describe what ran
    };
    std::vector<Built> built;  // per BVH
};

int bench_stress(const BenchOptions& o) {
    const size_t bvhs = o.accel.size();
    std::vector<StressCount> counts(o.stress.size());
    // Rounds: every count once a round, each BVH in turn on copies of one prepared scene, so
    // that the ratios come from the same moments of a shared machine and a burst of load lands
    // in one run of many counts (which their medians drop) rather than in every run of one.
    for (int run = 0; run < o.runs; ++run)
        for (size_t c = 0; c < o.stress.size(); ++c) {
            const int n = o.stress[c];
            StressCount& count = counts[c];
            const double prepare_start = now_seconds();
            const RenderScene prepared = prepare_scene(parse_scene(stress_scene_json(n, 1), "stress.json").scene);
            if (run == 0) {
                count.prepare_ms = (now_seconds() - prepare_start) * 1e3;
                count.build_ms.resize(bvhs);
                count.seconds.resize(bvhs);
                count.ns.resize(bvhs);
                count.built.resize(bvhs);
            }
            RenderSettings settings = RenderSettings::from_scene(prepared.renderer);
            settings.target_spp = 4;
            settings.kernels = o.kernels;
            for (size_t k = 0; k < bvhs; ++k) {
                RenderScene scene = prepared;
                scene.linear_scan = o.linear;
                scene.accel_backend = o.accel[k];
                const double build_start = now_seconds();
                scene.build_accel();
                if (run == 0) count.build_ms[k] = (now_seconds() - build_start) * 1e3;
                const Timing t = time_render(scene, settings, o.size, o.size, 4, o.cpu_time);
                count.seconds[k].push_back(t.seconds);
                // Per-ray cost on all threads together, as a user sees it.
                count.ns[k].push_back(t.rays ? t.seconds / double(t.rays) * 1e9 : 0);
                if (run > 0) continue;
                const SphereBvh& bvh = scene.bvh;
                const bool own = bvh.backend() == AccelBackend::own;
                // How the SIMD lanes cast rays: the clusters a scan tests, or their tree.
                const char* lanes = bvh.one_leaf() ? "" : !bvh.lane_tree().clusters.empty() ? ", scan"
                                                      : !bvh.lane_tree().nodes.empty()     ? ", tree"
                                                                                           : "";
                count.built[k] = {o.linear ? "linear" : std::string(accel_backend_names.name(bvh.backend())),
                                  own ? std::to_string(bvh.node_count()) : "-", own ? std::to_string(bvh.depth()) : "-",
                                  std::string(lane_kernels_names.name(lane_kernels(scene, settings))) + lanes};
            }
        }
    std::vector<std::vector<double>> sweep(bvhs);  // ns per ray, per BVH, per count
    std::printf("| spheres | BVH | nodes | depth | prepare ms | build ms | median s | Mrays/s | ns/ray | ns/ray / log2 N | paths |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (size_t c = 0; c < o.stress.size(); ++c) {
        const int n = o.stress[c];
        const StressCount& count = counts[c];
        for (size_t k = 0; k < bvhs; ++k) {
            const double ns_ray = median(count.ns[k]);
            sweep[k].push_back(ns_ray);
            const StressCount::Built& b = count.built[k];
            std::printf("| %d | %s | %s | %s | %.0f | %.0f | %.2f | %.1f | %.1f | %.2f | %s |\n", n, b.bvh.c_str(),
                        b.nodes.c_str(), b.depth.c_str(), count.prepare_ms, count.build_ms[k], median(count.seconds[k]),
                        ns_ray > 0 ? 1e3 / ns_ray : 0, ns_ray, ns_ray / std::log2(double(n) + 1), b.paths.c_str());
        }
    }
    std::fflush(stdout);
    if (o.sweep) {
        std::printf("\nSweep of %zu counts, %d to %d (%d threads, %d runs, %d x %d at 4 spp, %s time):\n\n",
                    o.stress.size(), o.stress.front(), o.stress.back(), omp_get_max_threads(), o.runs, o.size, o.size,
                    o.cpu_time ? "CPU" : "wall");
        std::printf("| --accel | largest step | between | steps over 15 %% | ns/ray / log2 N above 64 | band |\n");
        std::printf("|---|---|---|---|---|---|\n");
        for (size_t k = 0; k < o.accel.size(); ++k)
            print_sweep_summary(std::string(accel_backend_names.name(o.accel[k])).c_str(), o.stress, sweep[k]);
    }
    return 0;
}

}  // namespace

int run_bench(int argc, char** argv) {
    for (int i = 2; i < argc; ++i)
        if (std::string(argv[i]) == "--convergence") return bench_convergence(argc, argv);
    BenchOptions o;
    try {
        o = parse(argc, argv);
    } catch (const UsageError& e) {
        return report_usage(e, kBenchUsage);
    }
    if (o.threads > 0) omp_set_num_threads(o.threads);
    // Embree's module, asked for by name: loaded before anything is measured.
    if (std::find(o.accel.begin(), o.accel.end(), AccelBackend::embree) != o.accel.end()) try {
            embree_module();
        } catch (const std::runtime_error& e) {
            std::fprintf(stderr, "error: bench --accel embree: %s\n", e.what());
            return 1;
        }
    if (o.write_stress > 0) {
        std::error_code ec;
        if (fs::exists(o.write_path, ec)) {
            std::fprintf(stderr, "error: %s exists; not overwriting it\n", o.write_path.string().c_str());
            return 1;
        }
        try {
            write_file_atomic(o.write_path, stress_scene_json(o.write_stress, 1, 1) + "\n");
        } catch (const std::exception& e) {
            if (is_out_of_memory(e))
                std::fprintf(stderr, "error: %s: not enough memory for a scene of %d spheres\n",
                             show_user_text(o.write_path.string()).c_str(), o.write_stress);
            else
                std::fprintf(stderr, "error: %s\n", e.what());
            return 1;
        }
        std::printf("wrote %s (%d spheres)\n", o.write_path.string().c_str(), o.write_stress);
    }
    int status = 0;
    if (o.throughput) status = bench_throughput(o);
    if (status == 0 && !o.stress.empty()) status = bench_stress(o);
    return status;
}

}  // namespace kr
