// docs/scaling.md's planning costs per rank: what one rank of N spends between passes on its
// own rows (RenderState::plan_pass and the noise rule's check, relative_error and
// update_adaptive, with a RowShare of rank 0 of N), against N, on one thread (CPU seconds,
// medians of ROUNDS; each the second call on its state, as in a render, whose first plan
// allocates the buffers), at 512x512 and 2048x2048. The statistics are made up (9 samples a
// pixel, varying variances): the plan's cost does not depend on the scene. The per-row sums'
// exchange is not timed here (its combine leaves the other rows' sums at zero); the
// exchanged bytes per pass are printed from their sizes.
//   keithray_bench_plan_rows plan [ROUNDS]
// And how evenly rows dealt round-robin share a scene's rendering when ranks get few rows:
// each row's CPU time over PASSES passes after an untimed one (render_pass on that row alone,
// one thread), then
// for N ranks the busiest rank's rows' time against the mean (1 = perfectly even).
//   keithray_bench_plan_rows balance SCENE.json SIZE PASSES N,N,...
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <vector>

#include <sstream>
#include <string>

#include "render/render_pass.h"
#include "render/render_scene.h"
#include "scene/load.h"

using namespace kr;

namespace {

double cpu_seconds() {
    timespec t{};
    ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Rank `index` of `count`, alone: the per-row sums of the other ranks stay zero.
class AloneRows final : public RowShare {
public:
    using RowShare::RowShare;
    void combine(std::vector<double>&, int) const override {}
};

RenderState made_up_state(int size) {
    RenderState s(size, size);
    s.passes = kAllocationWarmup + 1;
    PixelBuffers& px = s.buffers();
    uint32_t h = 12345;
    for (size_t i = 0; i < px.sample_count.size(); ++i) {
        h = h * 1664525u + 1013904223u;  // an LCG: variances from 0 to 2
        const double n = s.passes, mean = 0.5, variance = 2.0 * double(h >> 8) / double(1 << 24);
        px.sample_count[i] = px.sample_index[i] = uint32_t(s.passes);
        px.radiance_sum[i] = Color(n * mean);
        px.luminance_sq_sum[i] = (n - 1) * variance + n * mean * mean;
    }
    return s;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

// Each row's rendering CPU seconds, PASSES passes of one sample a pixel (uniform allocation).
std::vector<double> row_seconds(const std::string& file, int size, int passes) {
    Scene authored = load_scene_file(file).scene;
    authored.renderer.width = authored.renderer.height = size;
    const RenderScene scene = prepare_scene(authored);
    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    settings.allocation = Allocation::uniform;
    RenderState state(size, size);
    render_pass(scene, settings, state);  // untimed: the buffers' first touch (page faults)
    std::vector<double> seconds(size_t(size), 0.0);
    for (int pass = 0; pass < passes; ++pass)
        for (int y = 0; y < size; ++y) {
            state.active_rows.assign(size_t(size), 0);
            state.active_rows[size_t(y)] = 1;
            const double start = cpu_seconds();
            render_pass(scene, settings, state);
            seconds[size_t(y)] += cpu_seconds() - start;
        }
    return seconds;
}

int balance(const std::string& file, int size, int passes, const std::string& counts) {
    const std::vector<double> seconds = row_seconds(file, size, passes);
    double total = 0;
    for (double s : seconds) total += s;
    std::printf("%s at %dx%d, %d passes: %.1f ns a pixel and pass; busiest rank against the mean:\n", file.c_str(),
                size, size, passes, 1e9 * total / (double(size) * size * passes));
    std::stringstream list(counts);
    for (std::string item; std::getline(list, item, ',');) {
        const int count = std::atoi(item.c_str());
        if (count < 1) continue;
        std::vector<double> rank(size_t(count), 0.0);
        const std::vector<int> owner = row_owners(count, size);
        for (int y = 0; y < size; ++y) rank[size_t(owner[size_t(y)])] += seconds[size_t(y)];
        std::printf("  %d ranks (%.2f rows each): %.3f\n", count, double(size) / count,
                    *std::max_element(rank.begin(), rank.end()) / (total / count));
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    const std::string mode = argc > 1 ? argv[1] : "plan";
    if (mode == "balance" && argc == 6) return balance(argv[2], std::atoi(argv[3]), std::atoi(argv[4]), argv[5]);
    if (mode != "plan") {
        std::fprintf(stderr, "usage: keithray_bench_plan_rows plan [ROUNDS] | balance SCENE.json SIZE PASSES N,N,...\n");
        return 2;
    }
    const int rounds = argc > 2 ? std::max(1, std::atoi(argv[2])) : 5;
    RenderSettings settings;
    settings.allocation = Allocation::adaptive;
    std::printf("ranks | size | own rows | plan ms | noise check ms | plan ns per own pixel | guard rows in | row sums in\n");
    for (int size : {512, 2048}) {
        const RenderState made = made_up_state(size);
        for (int count : {1, 2, 4, 16, 64, 256}) {
            const AloneRows share(0, count);
            const RowShare* rows = count > 1 ? &share : nullptr;
            std::vector<double> plan, check;
            for (int round = 0; round < rounds; ++round) {
                // Timed the second time: a render allocates the plan's buffers in its first plan.
                RenderState s = made;
                plan_pass(s, settings, rows);
                (void)update_adaptive(s, 0.01, 16, rows);
                double start = cpu_seconds();
                plan_pass(s, settings, rows);
                plan.push_back(cpu_seconds() - start);
                start = cpu_seconds();
                (void)s.relative_error(rows);
                (void)update_adaptive(s, 0.01, 16, rows);
                check.push_back(cpu_seconds() - start);
            }
            const size_t own = rows_owned(rows, size).size();
            const double own_pixels = double(own) * size;
            // Received a pass, by the rank receiving most: the rows next to its blocks (36
            // bytes a pixel) and the other rows' two plan sums (8 bytes each).
            size_t guard_rows = 0;
            for (int r = 0; r < count; ++r)
                guard_rows = std::max(guard_rows, rows_guarded(r, count, size).size() - rows_owned(r, count, size).size());
            const double guard = double(guard_rows) * size * 36;
            const double sums = double(size - int(own)) * 2 * 8;
            std::printf("%d | %dx%d | %zu | %.3f | %.3f | %.1f | %.1f kB | %.1f kB\n", count, size, size, own,
                        1e3 * median(plan), 1e3 * median(check), 1e9 * median(plan) / own_pixels, guard * 1e-3,
                        sums * 1e-3);
        }
    }
}
