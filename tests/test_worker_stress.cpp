// Stress for the viewer's render thread (viewer/render_worker.h), meant to run under
// ThreadSanitizer (scripts/check_sanitizers.sh) as well as in the plain build: rapid edits
// while a pass runs, scene reloads of another size mid-render, readers polling frames
// from other threads, and destruction at every stage of a pass. Each test ends by
// checking that the worker reaches a valid final state: the last submitted generation,
// its full size, its target spp, finite pixels.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <thread>
#include <vector>

#include "render/settings.h"
#include "render/render_scene.h"
#include "scene/load.h"
#include "viewer/edit.h"
#include "viewer/model.h"
#include "viewer/render_worker.h"
#include "test_util.h"

namespace fs = std::filesystem;
using namespace kr;
using namespace kr::viewer;
using Clock = std::chrono::steady_clock;

namespace {

// A brief scene at a small size, so that passes are short even under a sanitizer but
// still span many rows (the stop flag is checked per row).
std::shared_ptr<const RenderScene> small_scene(int n, int width, int height) {
    Scene authored = load_scene_file(test::brief_scene_file(n)).scene;
    authored.renderer.width = width;
    authored.renderer.height = height;
    return std::make_shared<const RenderScene>(prepare_scene(authored));
}

// Waits for a finished frame of `generation` (and of `target_spp`, when given: a job
// resubmitted under the same generation with a new target may still publish the old
// job's finished frame first); null if none comes before the deadline.
std::shared_ptr<const Snapshot> wait_finished(const RenderWorker& worker, uint64_t generation,
                                              int target_spp = 0,
                                              std::chrono::seconds limit = std::chrono::seconds(300)) {
    auto wanted = [&](const std::shared_ptr<const Snapshot>& f) {
        return f && f->generation == generation && f->finished &&
               (target_spp == 0 || f->max_passes == target_spp);
    };
    const auto deadline = Clock::now() + limit;
    std::shared_ptr<const Snapshot> f = worker.latest();
    while (!wanted(f) && Clock::now() < deadline)
        f = worker.wait_newer(f ? f->serial : 0, std::chrono::milliseconds(200));
    return wanted(f) ? f : nullptr;
}

void expect_valid_final(const Snapshot& f, uint64_t generation, int width, int height, int spp) {
    EXPECT_EQ(f.generation, generation);
    EXPECT_TRUE(f.finished);
    EXPECT_EQ(f.scale, 1);
    EXPECT_EQ(f.spp, spp);
    ASSERT_EQ(f.radiance.width, width);
    ASSERT_EQ(f.radiance.height, height);
    ASSERT_EQ(f.radiance.pixels.size(), size_t(width) * size_t(height));
    double sum = 0;
    for (const Color& c : f.radiance.pixels)
        for (int k = 0; k < 3; ++k) {
            ASSERT_TRUE(std::isfinite(c[k]));
            ASSERT_GE(c[k], 0.0);
            sum += c[k];
        }
    EXPECT_GT(sum, 0.0);  // a lit scene, not an empty buffer
}

// Reads every published frame from another thread while the test edits: frames are
// immutable once published, so reading them races with nothing.
class FrameReader {
public:
    explicit FrameReader(const RenderWorker& worker)
        : thread_([this, &worker] {
              uint64_t serial = 0;
              while (!quit_.load()) {
                  const auto f = worker.wait_newer(serial, std::chrono::milliseconds(20));
                  if (!f) continue;
                  serial = f->serial;
                  double sum = 0;
                  for (const Color& c : f->radiance.pixels) sum += c[0] + c[1] + c[2];
                  checksum_ += sum;
                  frames_.fetch_add(1);
              }
          }) {}
    ~FrameReader() {
        quit_.store(true);
        thread_.join();
    }
    int frames() const { return frames_.load(); }

private:
    std::atomic<bool> quit_{false};
    std::atomic<int> frames_{0};
    double checksum_ = 0;
    std::thread thread_;  // last: starts after the members it uses
};

}  // namespace

// Hundreds of edits, each restarting the render mid-pass, interleaved with pause and
// unlimited toggles and frame polling from two other threads; then one last edit must
// render to its target like any other.
TEST(WorkerStress, RapidEditsDuringRendering) {
    const int w = 64, h = 48;
    const auto scene = small_scene(8, w, h);
    const RenderSettings base = RenderSettings::from_scene(scene->renderer);
    std::atomic<int> published{0};
    RenderWorker worker([&] { published.fetch_add(1); });
    FrameReader reader(worker);
    std::thread poller([&] {
        for (int i = 0; i < 300; ++i) {
            if (const auto f = worker.latest()) EXPECT_EQ(f->radiance.pixels.size(), size_t(f->radiance.width) * f->radiance.height);
            std::this_thread::yield();
        }
    });

    uint64_t generation = 0;
    for (int i = 0; i < 200; ++i) {
        RenderSettings s = base;
        s.max_depth = i % 4;
        s.integrator = i % 3 == 0 ? Integrator::wrt : Integrator::pt;
        s.seed = uint64_t(i);
        s.target_spp = 1 + i % 3;
        worker.submit({++generation, scene, s, StopRule{s.target_spp}});
        if (i % 7 == 0) worker.set_paused(i % 14 == 0);
        if (i % 5 == 0) worker.set_stop_rule(StopRule{i % 10 == 0 ? kUnlimitedPasses : s.target_spp});
        // Back to back, or long enough for a pass to be under way when the next edit stops it.
        if (i % 3 != 0) std::this_thread::sleep_for(std::chrono::microseconds(200 * (i % 11)));
    }
    poller.join();
    worker.set_paused(false);
    worker.set_stop_rule(StopRule{1});
    RenderSettings last = base;
    last.target_spp = 2;
    last.max_depth = 2;
    worker.submit({++generation, scene, last, StopRule{last.target_spp}});
    const auto f = wait_finished(worker, generation);
    ASSERT_TRUE(f) << "no finished frame for the last edit";
    expect_valid_final(*f, generation, w, h, 2);
    EXPECT_GT(published.load(), 0);
    EXPECT_GT(reader.frames(), 0);
}

// Edits from two threads at once (the API takes any caller): the worker ends on whichever
// submit came last, whole.
TEST(WorkerStress, ConcurrentSubmitters) {
    const auto a = small_scene(2, 16, 12), b = small_scene(4, 20, 10);
    RenderWorker worker;
    std::atomic<uint64_t> next{1};
    auto submitter = [&](std::shared_ptr<const RenderScene> scene) {
        RenderSettings s = RenderSettings::from_scene(scene->renderer);
        s.target_spp = 1;
        for (int i = 0; i < 100; ++i) worker.submit({next.fetch_add(1), scene, s, StopRule{s.target_spp}});
    };
    std::thread t1(submitter, a), t2(submitter, b);
    t1.join();
    t2.join();
    RenderSettings s = RenderSettings::from_scene(b->renderer);
    s.target_spp = 2;
    const uint64_t last = next.fetch_add(1);
    worker.submit({last, b, s, StopRule{s.target_spp}});
    const auto f = wait_finished(worker, last);
    ASSERT_TRUE(f);
    expect_valid_final(*f, last, 20, 10, 2);
}

// The viewer's own path: the model reloads files of other sizes and edits the camera while
// the worker renders the previous prepared scene. The old RenderScene stays alive (shared)
// for the pass in flight; the final frame has the last scene's size.
TEST(WorkerStress, SceneReloadWhileRendering) {
    ViewerModel model;
    model.load(test::brief_scene_file(3));
    RenderWorker worker;
    auto submit = [&] {
        RenderSettings s = model.settings().render;
        s.target_spp = 1;
        worker.submit({model.generation(), model.prepared(), s, StopRule{s.target_spp}});
    };
    const int scenes[] = {3, 5, 2, 7, 8, 1, 4, 6};
    int w = 0, h = 0;
    for (int round = 0; round < 3; ++round)
        for (int n : scenes) {
            model.load(test::brief_scene_file(n));
            w = 24 + 4 * n + round, h = 16 + 2 * n;
            ASSERT_TRUE(model.edit(Edit::renderer, [&](Scene& sc, ViewerSettings& vs) {
                sc.renderer.width = w;
                sc.renderer.height = h;
                vs.render.max_depth = std::min(vs.render.max_depth, 3);
            }));
            submit();
            std::this_thread::sleep_for(std::chrono::milliseconds(1 + n % 3));
            ASSERT_TRUE(model.edit(Edit::camera, [&](Scene& sc, ViewerSettings&) {
                sc.cameras[size_t(sc.camera)].fov *= 0.99;
            }));
            submit();
        }
    // Ends on scene 6, whose file the model loaded last. The same generation as the last
    // 1-spp job, so that job's finished frame may come first: wait for the 2-spp one.
    RenderSettings s = model.settings().render;
    s.target_spp = 2;
    worker.submit({model.generation(), model.prepared(), s, StopRule{s.target_spp}});
    const auto f = wait_finished(worker, model.generation(), 2);
    ASSERT_TRUE(f);
    expect_valid_final(*f, model.generation(), w, h, 2);
}

// Destroying the worker at any point (idle, mid-preview, mid-full-pass, with an edit
// pending, paused, unlimited) stops the pass at its next row and joins promptly.
TEST(WorkerStress, DestructionMidPass) {
    const auto scene = small_scene(6, 64, 48);  // path traced glass: passes that take a while
    RenderSettings s = RenderSettings::from_scene(scene->renderer);
    s.target_spp = 1000;
    for (int i = 0; i < 24; ++i) {
        std::atomic<int> published{0};
        auto worker = std::make_unique<RenderWorker>([&] { published.fetch_add(1); });
        if (i % 6 != 0) worker->submit({1, scene, s, StopRule{s.target_spp}});
        if (i % 4 == 1) worker->set_stop_rule(StopRule{kUnlimitedPasses});
        if (i % 8 == 3) worker->set_paused(true);
        if (i % 3 == 2) {
            // Until a frame is out: the next pass is a later preview or a full pass.
            const auto deadline = Clock::now() + std::chrono::seconds(60);
            while (published.load() == 0 && Clock::now() < deadline && i % 8 != 3)
                std::this_thread::sleep_for(std::chrono::milliseconds(1));
        } else {
            std::this_thread::sleep_for(std::chrono::microseconds(300 * i));
        }
        if (i % 5 == 4) worker->submit({2, scene, s, StopRule{s.target_spp}});  // an edit pending at destruction
        const auto start = Clock::now();
        worker.reset();
        // One row of a 64-pixel-wide image, not a whole pass: generous for a sanitizer.
        EXPECT_LT(std::chrono::duration<double>(Clock::now() - start).count(), 20.0) << "iteration " << i;
    }
}
