#include "app/view_ranks.h"

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <new>
#include <optional>
#include <type_traits>

#include <unistd.h>

#include "core/memory.h"
#include "render/progressive.h"
#include "render/render_scene.h"
#include "scene/load.h"
#include "scene/save.h"

namespace kr {

namespace {

// The commands, each one broadcast: its kind, then its fields' bytes (the ranks run the same
// build on machines of one byte order).
enum Command : char { kJob = 'J', kPass = 'P', kEnd = 'E' };

// Why a rank could not take a job, as bits that any_flags combines.
enum JobFailure : int { kNoMemory = 1, kUnreadable = 2 };

template <class T>
void put(std::string& out, const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

// Reads the fields of a command in order.
class Fields {
public:
    explicit Fields(const std::string& bytes) : bytes_(bytes) {}
    template <class T>
    T take() {
        static_assert(std::is_trivially_copyable_v<T>);
        T value;
        std::memcpy(&value, bytes_.data() + at_, sizeof value);
        at_ += sizeof value;
        return value;
    }
    std::string_view rest() const { return std::string_view(bytes_).substr(at_); }

private:
    const std::string& bytes_;
    size_t at_ = 1;  // after the kind
};

// Open MPI's mpirun ends a job whose rank died (or that it was told to stop) by sending
// every other rank SIGCONT, then SIGTERM a second later, then SIGKILL: the SIGCONT from the
// launcher is the first and surest word that the job is ending.
std::atomic<bool> g_launcher_ending{false};
static_assert(std::atomic<bool>::is_always_lock_free, "set by a signal handler");

void on_continue(int, siginfo_t* info, void*) {
    if (info && info->si_pid == ::getppid()) g_launcher_ending.store(true);
}

}  // namespace

ViewRanks::ViewRanks(const Cluster& cluster) : cluster_(cluster), dealt_(cluster.deal_rows()) {
    struct sigaction action {};
    action.sa_sigaction = on_continue;
    action.sa_flags = SA_SIGINFO | SA_RESTART;
    sigemptyset(&action.sa_mask);
    ::sigaction(SIGCONT, &action, nullptr);
}

std::string ViewRanks::lost() const {
    if (std::string failure = Cluster::failure(); !failure.empty()) return failure;
    if (g_launcher_ending.load()) return "mpirun is ending it: a rank died, or mpirun was told to stop";
    return "";
}

void ViewRanks::start_job(const Scene& scene, const RenderSettings& settings, bool halves) {
    width_ = scene.renderer.width;
    height_ = scene.renderer.height;
    std::string command(1, kJob);
    put(command, settings);
    put(command, uint8_t(halves));
    command += scene_to_json(scene);
    cluster_.broadcast_waiting(command);
}

std::string ViewRanks::begin_pass(const StopRule& rule, const std::optional<viewer::PixelBox>& region) {
    std::string command(1, kPass);
    put(command, rule);
    put(command, uint8_t(region.has_value()));
    put(command, region.value_or(viewer::PixelBox{}));
    cluster_.broadcast_waiting(command);
    const int failed = cluster_.any_flags(0);
    const std::string image = std::to_string(width_) + "x" + std::to_string(height_) + " image";
    if (failed & kNoMemory) return "not enough memory on a rank of the MPI job for the render of a " + image;
    if (failed & kUnreadable) return "a rank of the MPI job could not read the scene sent to it (its standard error says why)";
    return "";
}

void ViewRanks::end_pass(RenderState& state, uint64_t& rays, uint64_t& nonfinite) {
    cluster_.gather_state(state, rays, nonfinite);
}

void ViewRanks::finish() {
    if (finished_) return;
    finished_ = true;
    std::string command(1, kEnd);
    cluster_.broadcast_waiting(command);
}

int serve_view_passes(const Cluster& cluster) {
    viewer::RegionHooks region;
    const std::unique_ptr<PassHooks> dealt = cluster.deal_rows();
    viewer::RegionOverShare hooks(region, *dealt);
    // The job: its scene (the previous one's BVH serves again where no sphere moved), its
    // settings and this rank's rows of its state.
    std::unique_ptr<const RenderScene> scene;
    RenderSettings settings;
    RenderState state;
    std::optional<ProgressiveDriver> driver;
    int failure = 0;
    for (;;) {
        std::string command;
        cluster.broadcast_waiting(command);
        Fields fields(command);
        if (command.empty() || command[0] == kEnd) return 0;
        if (command[0] == kJob) {
            driver.reset();
            failure = 0;
            settings = fields.take<RenderSettings>();
            const bool halves = fields.take<uint8_t>() != 0;
            try {
                const LoadedScene loaded = parse_scene(fields.rest(), "view");
                scene = std::make_unique<const RenderScene>(prepare_scene(loaded.scene, nullptr, scene.get()));
                const int w = loaded.scene.renderer.width, h = loaded.scene.renderer.height;
                std::vector<int> held = cluster.held_rows(h);
                const size_t rows = held.empty() ? size_t(h) : held.size();
                // Its rows' state and guard buffers, and their halves (render_state.h).
                const uint64_t bytes = render_state_bytes(w, rows, halves);
                if (std::string shortfall = memory_shortfall(bytes, "the render of a " + std::to_string(w) + "x" +
                                                                        std::to_string(h) + " image");
                    !shortfall.empty()) {
                    std::fprintf(stderr, "error: rank %d: %s\n", cluster.rank(), shortfall.c_str());
                    failure = kNoMemory;
                    continue;
                }
                state.reset(w, h, std::move(held));
                if (halves) state.track_halves();
                driver.emplace(*scene, settings, state, StopRule{}, &hooks);
            } catch (const std::bad_alloc&) {
                failure = kNoMemory;
            } catch (const std::exception& e) {  // SceneError; a camera prepare_scene refuses
                std::fprintf(stderr, "error: rank %d: %s\n", cluster.rank(), e.what());
                failure = kUnreadable;
            }
        } else if (command[0] == kPass) {
            const StopRule rule = fields.take<StopRule>();
            const bool has_region = fields.take<uint8_t>() != 0;
            const viewer::PixelBox box = fields.take<viewer::PixelBox>();
            if (cluster.any_flags(failure)) {  // every rank drops the job
                driver.reset();
                continue;
            }
            region.region = has_region ? std::optional(box) : std::nullopt;
            driver->pass(rule);
            uint64_t rays = 0, nonfinite = 0;
            cluster.gather_state(state, rays, nonfinite);
        }
    }
}

}  // namespace kr
