// keithray: the command-line program. Its usage, --version, the man page and completion's
// sources, and the dispatch to each command: render (app/render_command.h), view, psnr and
// compare (app/compare.h), bench (app/bench.h).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <unistd.h>

#include "app/bench.h"
#include "app/cluster.h"
#include "app/command.h"
#include "app/compare.h"
#include "app/docs.h"
#include "app/render_command.h"
#include "app/view_ranks.h"
#include "app/viewer_module.h"
#include "core/data_dir.h"
#include "core/file_write.h"
#include "core/memory.h"
#include "core/module.h"
#include "core/text.h"
#include "render/accel.h"
#include "render/trace.h"
#include "viewer/compare_view.h"
#include "viewer/view_options.h"

namespace fs = std::filesystem;
using namespace kr;

namespace {

// The viewer's GOMP_SPINCOUNT unless the environment sets the waiting (run_viewer_with_short_spins).
constexpr const char* kViewerSpinCount = "10000";

constexpr const char* kTitle = "keithray: a progressive ray tracer for sphere scenes\n\n";

constexpr const char* kSynopsis = R"(Usage:
  keithray render [SCENE.json ...] [options]
  keithray psnr IMAGE REFERENCE            PSNR in dB of two 8-bit images (PPM or PNG);
                                            RMSE and relative MSE of two HDR ones (EXR, PFM)
  keithray compare TEST REFERENCE [options] pass/fail check for CI, thresholds or a
                                            statistical test ('keithray compare --help')
  keithray bench --throughput|--stress ...  speed figures ('keithray bench --help')
  keithray view [SCENE.json] [options]      interactive viewer (GLFW window; see
                                            'keithray view --help' and docs/viewer.md)
  keithray --help | --version
)";

// keithray's --help: the commands, then render's options.
std::string usage() { return kTitle + std::string(kSynopsis) + render_options_help(); }

// Where a module (core/module.h) is, for --version; not loaded here.
std::string module_place(const std::string& name) {
    const fs::path path = module_path(name);
    std::error_code ec;
    return "module " + path.string() + (fs::is_regular_file(path, ec) ? "" : ", missing");
}

// `keithray --version`: what this build and this CPU run.
int print_version() {
    std::printf("keithray %s\n", KEITHRAY_VERSION);
    std::printf("build: %s, %s\n", KEITHRAY_BUILD_TYPE, KEITHRAY_COMPILER);
    const LaneKernels kernels = cpu_lane_kernels(LaneChoice::best);
    const std::string name(lane_kernels_names.name(kernels));
    if (kernels == LaneKernels::one_path)
        std::printf("SIMD kernels on this CPU: none, one path at a time (%s)\n",
                    cpu_lane_kernels(LaneChoice::any) == LaneKernels::x86_64 ? "the CPU lacks AVX2 and FMA"
                                                                        : "not built for this CPU");
    else {
        // The sixteen lanes' sphere limits are measured per kind of CPU (accel.h).
        const int lanes = lane_count(kernels);
        const std::string limits = lanes == 16 ? ", up to " + std::to_string(lane_tree_limits().beside_embree) +
                                                     " spheres beside Embree's tree and " +
                                                     std::to_string(lane_tree_limits().own) + " down our own"
                                               : "";
        std::printf("SIMD kernels on this CPU: %s (%s paths at a time in single precision%s; x86-64-v3 lanes, "
                    "four in double, where a scene's sizes or gaps need it)\n",
                    name.c_str(), lanes == 16 ? "sixteen" : lanes == 8 ? "eight" : "four", limits.c_str());
    }
#ifdef KEITHRAY_HAVE_EMBREE
    std::printf("Embree: yes (%s): scenes of more than 32 spheres (%s)\n", KEITHRAY_EMBREE_VERSION,
                module_place("embree").c_str());
#else
    std::printf("Embree: no: every scene uses keithray's own BVH\n");
#endif
    if (KEITHRAY_MPI_BUILT)
        std::printf("MPI: yes (Open MPI): mpirun -np N keithray render | view (%s)\n", module_place("mpi").c_str());
    else
        std::printf("MPI: no: one process per render\n");
    std::printf("viewer: yes (keithray view: GLFW and Dear ImGui; render --gl: OSMesa) (%s)\n",
                module_place("viewer").c_str());
    const std::optional<DataDir>& data = data_dir();
    if (data)
        std::printf("bundled scenes: %s (%s)\n", data->path.string().c_str(), data->installed ? "installed" : "build tree");
    else
        std::printf("bundled scenes: none found (looked in %s)\n", data_dir_places().c_str());
    return 0;
}

// The commands as their help texts describe them: the man page and the completion's source.
std::vector<CommandHelp> command_helps() {
    const auto names = [](const auto& table) {
        std::vector<std::string> out;
        for (const std::string_view n : table.names) out.emplace_back(n);
        return out;
    };
    return {
        {"render", "render scenes headless into image files", render_options_help(), "scene",
         {{"--kernels", names(lane_choice_names)}}},
        {"view", "the interactive viewer", viewer::view_usage(), "scene",
         {{"--view", names(viewer::view_mode_names)}, {"--error", names(viewer::error_metric_names)}}},
        {"compare", "pass/fail check of a render against a reference, for CI", compare_usage(), "image", {}},
        {"psnr", "PSNR (8-bit) or RMSE and relative MSE (HDR) of two images", psnr_usage(), "image", {}},
        {"bench", "speed and convergence figures", std::string(bench_usage()) + "\n" + convergence_usage(), "scene",
         {{"--kernels", names(lane_choice_names)}}},
    };
}

// The hidden `keithray --help-man` and `keithray --completion bash`, which CMake runs at
// build time.
int print_docs(const std::string& command, int argc, char** argv) {
    const std::vector<CommandHelp> commands = command_helps();
    if (command == "--help-man") {
        const std::string description =
            std::string("keithray renders scenes of spheres described in JSON with a Whitted-style ray tracer ") +
            "or a progressive path tracer, on all CPU cores, headless or in an interactive viewer.\n" +
            render_intro();
        std::fputs(man_page(KEITHRAY_VERSION, kSynopsis, description.substr(0, description.find("\nOptions:")),
                            commands).c_str(), stdout);
        return 0;
    }
    if (argc != 3 || std::string(argv[2]) != "bash") {
        std::fprintf(stderr, "error: --completion expects the shell: bash\n");
        return 2;
    }
    std::fputs(bash_completion(commands, {"--help", "--version", "-V"}).c_str(), stdout);
    return 0;
}


// `keithray view`; under mpirun, rank 0 opens the window and drives the other ranks, which
// serve its passes with no window (app/view_ranks.h). Run plainly it never touches MPI.
int run_view(int argc, char** argv) {
    std::optional<Cluster> joined;
    try {
        joined.emplace(argc, argv, true);  // the viewer's render thread calls MPI
    } catch (const std::runtime_error& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
    if (joined->distributed() && !joined->leader()) return serve_view_passes(*joined);
    // The window's libraries are loaded here, by the process that opens it.
    const ViewerModule* module = nullptr;
    try {
        module = &viewer_module();
    } catch (const std::runtime_error& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        if (joined->distributed()) joined->abort(1);  // the other ranks wait for rank 0's commands
        return 1;
    }
    if (!joined->distributed()) {
        const int status = module->run_viewer(argc, argv, nullptr);
        return stdout_written() ? status : 1;
    }
    int status = 1;
    {
        ViewRanks ranks(*joined);  // its end ends the other ranks' loops
        // mpirun ends the job with SIGTERM when a rank dies: the window says so before it ends.
        StopOnSignal stop_on_signal(true);
        status = module->run_viewer(argc, argv, &ranks);
    }
    return stdout_written() ? status : 1;
}

// The viewer's OpenMP team waits between its parallel regions (a pass's, a frame's) while the
// render thread does serial work, the window draws and other programs run. libgomp's default
// spins 300,000 times there (about 3 ms), holding a core the niced render thread's other
// half, the window or another job needs: with one other job on a 2-core machine the frames
// after an orbit came 3 to 8 times later (docs/viewer.md, "The render pipeline, measured").
// A short spin (GOMP_SPINCOUNT=10000, about 0.1 ms) keeps the quiet figures. libgomp reads
// the variable before main, so `view` runs itself again with it set, unless the user set it
// or OMP_WAIT_POLICY, or valgrind runs it (an exec would leave valgrind).
void run_viewer_with_short_spins(char** argv) {
    if (std::getenv("GOMP_SPINCOUNT") || std::getenv("OMP_WAIT_POLICY")) return;
    if (const char* preload = std::getenv("LD_PRELOAD"); preload && std::strstr(preload, "vgpreload")) return;
    if (::setenv("GOMP_SPINCOUNT", kViewerSpinCount, 1) != 0) return;
    ::execv("/proc/self/exe", argv);
    ::unsetenv("GOMP_SPINCOUNT");  // no exec (no /proc): libgomp's default, as read before main
}

}  // namespace

int main(int argc, char** argv) {
    if (argc > 1 && std::string_view(argv[1]) == "view") run_viewer_with_short_spins(argv);
    install_signal_cleanup();  // one handler for every write of the run (core/file_write.h)
    const std::string command = argc > 1 ? argv[1] : "";
    if (command == "--version" || command == "-V") {
        print_version();
        return stdout_written() ? 0 : 1;
    }
    if (command == "--help-man" || command == "--completion") {
        const int status = print_docs(command, argc, argv);
        return stdout_written() ? status : 1;
    }
    if (command == "-h" || command == "--help" || command == "help") {
        std::fputs(usage().c_str(), stdout);
        return stdout_written() ? 0 : 1;
    }
    if (command == "bench") {
        if (!team_started("bench")) return 1;
        try {
            const int status = run_bench(argc, argv);
            return stdout_written() ? status : 1;
        } catch (const std::exception& e) {
            if (!is_out_of_memory(e)) throw;
            std::fprintf(stderr, "error: bench: not enough memory for the benchmark's scenes and images\n");
            return 1;
        }
    }
    if (command == "psnr" || command == "compare") {
        if (!team_started(argc > 2 ? shown_path(argv[2]) : command)) return 1;
        try {
            const int status = command == "psnr" ? run_psnr(argc, argv) : run_compare(argc, argv);
            return stdout_written() ? status : 1;
        } catch (const std::exception& e) {
            if (!is_out_of_memory(e)) throw;
            std::fprintf(stderr, "error: %s: not enough memory for the images %s and %s\n", command.c_str(),
                         argc > 2 ? shown_path(argv[2]).c_str() : "", argc > 3 ? shown_path(argv[3]).c_str() : "");
            return 1;
        }
    }
    if (command == "view") return run_view(argc, argv);
    if (command != "render") {
        std::fprintf(stderr, "%s%s\n%s", command.empty() ? "error: no command given" : "error: unknown command ",
                     command.empty() ? "" : quote_user_text(command, 40).c_str(), usage().c_str());
        return 2;
    }
    return run_render(argc, argv, usage());
}
