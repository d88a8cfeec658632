// The earlier view's picture carried across a camera move (viewer/reproject.h), model level:
// the projection inverts the pixels' centre rays; the same view gives its picture back on its
// diffuse, inner pixels and nothing elsewhere; after an orbit each pixel takes the picture at
// the surface point it sees, never one the earlier view did not see; the blend fades the prior
// out by the target; and the render thread's first full frame after an orbit is better for it.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <random>

#include "render/progressive.h"
#include "render/trace.h"
#include "scene/load.h"
#include "test_util.h"
#include "viewer/navigation.h"
#include "viewer/render_worker.h"
#include "viewer/reproject.h"
#include "viewer/status.h"

namespace {

using namespace kr;
using namespace kr::viewer;

constexpr int kW = 96, kH = 72;

Scene small_scene3() {
    Scene scene = load_scene_file(kr::test::brief_scene_file(3)).scene;
    scene.renderer.width = kW;
    scene.renderer.height = kH;
    return scene;
}

// Pixel (x, y)'s centre ray's surface point, from its hit distance.
Vec3 centre_point(const ViewHits& v, int x, int y) {
    const Vec2 film = raster_to_camera(x + 0.5, y + 0.5, v.width, v.height);
    const CameraRay cr = v.camera.generate(film.x, film.y, 0.5, 0.5);
    return cr.origin + cr.direction * double(v.distance[size_t(y) * size_t(v.width) + size_t(x)]);
}

bool diffuse(const RenderScene& s, int sphere) {
    return s.materials[size_t(s.sphere_material[size_t(sphere)])].type == MaterialType::diffuse;
}

TEST(Reproject, ProjectionInvertsThePixelsCentreRays) {
    const RenderScene rs = prepare_scene(small_scene3());
    ASSERT_TRUE(reprojectable(rs));
    const ViewHits v = view_hits(rs, kW, kH);
    int checked = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            if (v.sphere[size_t(y) * kW + size_t(x)] < 0) continue;
            const auto at = project_to_pixel(v.camera, kW, kH, centre_point(v, x, y));
            ASSERT_TRUE(at.has_value());
            EXPECT_NEAR(at->x, x, 1e-4);
            EXPECT_NEAR(at->y, y, 1e-4);
            ++checked;
        }
    EXPECT_EQ(checked, kW * kH);  // scene 3 is a closed room
    // Behind the camera: nowhere.
    EXPECT_FALSE(project_to_pixel(v.camera, kW, kH, v.camera.position - v.camera.forward).has_value());
}

TEST(Reproject, TheSameViewGivesItsPictureBackOnItsDiffuseInnerPixelsOnly) {
    const RenderScene rs = prepare_scene(small_scene3());
    ViewHistory history;
    history.hits = view_hits(rs, kW, kH);
    history.picture = Image(kW, kH);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    for (Color& c : history.picture.pixels) c = Color(u(rng), u(rng), u(rng));
    history.samples.assign(size_t(kW) * kH, 7);
    const Reprojection r = reproject(rs, history.hits, history);
    int taken = 0, glossy = 0, edges = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const size_t i = size_t(y) * kW + size_t(x);
            const int s = history.hits.sphere[i];
            bool inner = true;
            for (const auto& [dx, dy] : {std::pair{-1, 0}, std::pair{1, 0}, std::pair{0, -1}, std::pair{0, 1}}) {
                const int nx = x + dx, ny = y + dy;
                if (nx >= 0 && ny >= 0 && nx < kW && ny < kH) inner &= history.hits.sphere[size_t(ny) * kW + size_t(nx)] == s;
            }
            if (!diffuse(rs, s)) {
                ++glossy;
                EXPECT_EQ(r.weight[i], 0.0f) << x << "," << y;
            } else if (!inner) {
                ++edges;
                EXPECT_EQ(r.weight[i], 0.0f) << x << "," << y;
            } else {
                ++taken;
                ASSERT_EQ(r.weight[i], 7.0f) << x << "," << y;
                EXPECT_NEAR(r.colour.pixels[i].x, history.picture.pixels[i].x, 1e-6);
                EXPECT_NEAR(r.colour.pixels[i].y, history.picture.pixels[i].y, 1e-6);
                EXPECT_NEAR(r.colour.pixels[i].z, history.picture.pixels[i].z, 1e-6);
            }
        }
    EXPECT_GT(taken, kW * kH / 2);
    EXPECT_GT(glossy, 100);  // the glossy and the glass ball
    EXPECT_GT(edges, 50);
}

TEST(Reproject, AfterAnOrbitEachPixelTakesTheSurfacePointItSeesAndOnlyOneSeenBefore) {
    Scene scene = small_scene3();
    const RenderScene before = prepare_scene(scene);
    // The earlier view's picture: each pixel's surface point, as a colour.
    ViewHistory history;
    history.hits = view_hits(before, kW, kH);
    history.picture = Image(kW, kH);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const Vec3 p = centre_point(history.hits, x, y);
            history.picture.at(x, y) = Color(p.x, p.y, p.z);
        }
    history.samples.assign(size_t(kW) * kH, 16);
    orbit(scene.cameras[size_t(scene.camera)], 12, 4);
    const RenderScene after = prepare_scene(scene);
    ASSERT_TRUE(same_world(before, after));
    const ViewHits now = view_hits(after, kW, kH);
    const Reprojection r = reproject(after, now, history);
    int taken = 0, diffuse_pixels = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const size_t i = size_t(y) * kW + size_t(x);
            diffuse_pixels += diffuse(after, now.sphere[i]);
            if (r.weight[i] == 0) continue;
            ++taken;
            const Vec3 p = centre_point(now, x, y);
            // Within a pixel's footprint at that distance of the point it sees.
            const double footprint = double(now.distance[i]) * 2 * now.camera.tan_half_fov / kH;
            EXPECT_LT(length(Vec3(r.colour.pixels[i].x, r.colour.pixels[i].y, r.colour.pixels[i].z) - p), footprint)
                << x << "," << y;
            // And the earlier view saw that point: nothing lies between its eye and it.
            Ray ray;
            ray.o = before.camera.position;
            ray.d = normalize(p - ray.o);
            Hit hit;
            ASSERT_TRUE(before.intersects(ray, hit));
            EXPECT_NEAR(hit.t, length(p - ray.o), 1e-3 * length(p - ray.o)) << x << "," << y;
        }
    EXPECT_GT(taken, diffuse_pixels / 2);
}

TEST(Reproject, TheBlendFadesThePriorToNothingByTheTarget) {
    Reprojection prior;
    prior.colour = Image(1, 1);
    prior.colour.pixels[0] = Color(1.0);
    prior.weight = {8};
    auto blended = [&](int spp, int end) {
        Image shown(1, 1);  // the view's own image: black
        blend_history(shown, prior, spp, end);
        return shown.pixels[0].x;
    };
    EXPECT_DOUBLE_EQ(blended(0, 16), 1.0);              // no sample yet: the prior
    EXPECT_DOUBLE_EQ(blended(8, 16), 4.0 / 12);         // worth 8 * (1 - 8/16) = 4 against 8
    EXPECT_DOUBLE_EQ(blended(16, 16), 0.0);             // at the target: the view's own
    EXPECT_DOUBLE_EQ(blended(16, 0), 4.0 / 20);         // no target: gone by 4 x 8 samples
    EXPECT_DOUBLE_EQ(blended(32, 0), 0.0);
    EXPECT_DOUBLE_EQ(blended(8, 1000), 8 * (1 - 8 / 32.0) / (8 + 8 * (1 - 8 / 32.0)));  // the sooner end
    prior.weight = {0};
    EXPECT_DOUBLE_EQ(blended(0, 16), 0.0);  // a pixel that takes nothing
}

// Where it matters: a 2-spp frame of the orbited view (as the render thread makes it) blended
// with the earlier view's 32-spp frame carried across is closer to the settled image of the new
// view than the 2-spp frame alone: by 1.0 dB at 96 px, where a third of the pixels (the
// silhouettes, the glossy and the glass ball, what the earlier view did not see) take nothing
// and hold most of the error (with the settled image itself there, 1.4 dB). The renders are
// the same at every run: more than half a decibel.
TEST(Reproject, AnOrbitsFirstFrameIsBetterForTheEarlierPicture) {
    Scene scene = small_scene3();
    RenderJob before, after;
    before.scene = std::make_shared<const RenderScene>(prepare_scene(scene));
    orbit(scene.cameras[size_t(scene.camera)], 10, 0);
    after.scene = std::make_shared<const RenderScene>(prepare_scene(scene));
    before.settings = after.settings = RenderSettings::from_scene(scene.renderer);
    // A job's full-resolution frame at `spp` samples, as the render thread makes it.
    auto frame_at = [](const RenderJob& job, int spp) {
        RenderState state(kW, kH);
        StopRule rule;
        rule.max_passes = spp;
        render_until(*job.scene, job.settings, state, rule);
        DisplayFeatures features;
        features.reset(kW, kH);
        features.refine_to(job, kDisplayFeatureSamples);
        DenoiseWorkspace workspace;
        Snapshot frame;
        make_full_frame(job, state, &features, workspace, frame);
        frame.spp = spp;
        return frame;
    };
    const Snapshot earlier = frame_at(before, 32);
    ViewHistory history;
    history.hits = view_hits(*before.scene, kW, kH);
    history.picture = earlier.denoised;
    history.samples = earlier.sample_count;
    const Reprojection prior = reproject(*after.scene, view_hits(*after.scene, kW, kH), history);

    RenderSettings settled_settings = after.settings;
    settled_settings.seed += 7919;
    RenderState settled(kW, kH);
    StopRule settle_rule;
    settle_rule.max_passes = 256;
    render_until(*after.scene, settled_settings, settled, settle_rule);
    const Rgb8Image reference = tonemap(settled.radiance(), scene.display.tonemap, scene.display.exposure_scale());
    auto shown_psnr = [&](const Snapshot& f) {
        return psnr(displayed_picture(f, DenoiseView::on, kW, kH, scene.display), reference);
    };
    Snapshot frame = frame_at(after, 2);
    const double alone = shown_psnr(frame);
    EXPECT_GT(blend_history(frame.denoised, prior, 2, 64), size_t(kW * kH / 2));
    const double with_prior = shown_psnr(frame);
    EXPECT_GT(with_prior, alone + 0.5) << "with the earlier picture " << with_prior << " dB, alone " << alone;
}

// The render thread carries the picture across camera moves only: after a job that reached
// its target, an orbit's frames take the earlier picture until the last (the finished frame is
// the engine's own); a thread with no earlier picture, a material edit, a lens camera or a
// render region take none.
TEST(Reproject, TheRenderThreadCarriesThePictureAcrossCameraMovesOnly) {
    Scene scene = small_scene3();
    const RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    const auto before = std::make_shared<const RenderScene>(prepare_scene(scene));
    Scene orbited = scene;
    orbit(orbited.cameras[size_t(orbited.camera)], 10, 0);
    const auto after = std::make_shared<const RenderScene>(prepare_scene(orbited));
    Scene recoloured = orbited;
    recoloured.materials[0].rho = Color(0.2, 0.3, 0.4);
    const auto other_world = std::make_shared<const RenderScene>(prepare_scene(recoloured));
    Scene through_lens = orbited;
    through_lens.cameras[size_t(through_lens.camera)].alpha = 0.2;
    through_lens.cameras[size_t(through_lens.camera)].type = CameraType::lens;
    const auto lens = std::make_shared<const RenderScene>(prepare_scene(through_lens));

    // Every full frame of a job to `target`, in order, the last finished.
    auto full_frames = [](RenderWorker& worker, uint64_t generation, std::shared_ptr<const RenderScene> s,
                          const RenderSettings& settings, int target) {
        StopRule rule;
        rule.max_passes = target;
        worker.submit({generation, std::move(s), settings, rule, nullptr, {}});
        std::vector<std::shared_ptr<const Snapshot>> frames;
        std::shared_ptr<const Snapshot> f;
        while (frames.empty() || !frames.back()->finished) {
            f = worker.wait_newer(f ? f->serial : 0, std::chrono::milliseconds(1000));
            if (f && f->generation == generation && f->scale == 1 && (frames.empty() || frames.back() != f))
                frames.push_back(f);
        }
        return frames;
    };
    auto carried = [](const std::vector<std::shared_ptr<const Snapshot>>& frames) {
        size_t most = 0;
        for (const auto& f : frames) most = std::max(most, f->carried_pixels);
        return most;
    };
    // A frame at every balanced count (no interval, no cost share), so the frames' order does not
    // depend on the machine's speed, and every prior dearer than the budget (here any).
    const auto every_count_prior_late = [] {
        FrameSchedule schedule;
        schedule.age_fraction = schedule.min_interval = schedule.max_interval = 0;
        schedule.cost_share = std::numeric_limits<double>::infinity();
        schedule.prior_budget = 0;
        return schedule;
    };
    // The prior always made before the first full frame, whatever it costs on this machine.
    FrameSchedule prior_first;
    prior_first.prior_budget = std::numeric_limits<double>::infinity();
    {
        RenderWorker worker;
        worker.set_schedule(prior_first);
        EXPECT_EQ(carried(full_frames(worker, 1, before, settings, 32)), 0u);  // nothing earlier
        const auto frames = full_frames(worker, 2, after, settings, 64);
        EXPECT_GT(frames.front()->carried_pixels, size_t(kW * kH / 2));
        EXPECT_EQ(frames.back()->carried_pixels, 0u);  // the finished frame
        EXPECT_EQ(carried(full_frames(worker, 3, other_world, settings, 16)), 0u);
    }
    {
        // A prior dearer than the budget (here any) waits for the first full frame: that frame
        // comes without the earlier picture and the next one carries it.
        const FrameSchedule prior_late = every_count_prior_late();
        // Every frame as it is published (the callback runs on the render thread right after it).
        std::mutex mutex;
        std::vector<std::shared_ptr<const Snapshot>> published;
        RenderWorker* self = nullptr;
        RenderWorker worker([&] {
            std::lock_guard lock(mutex);
            if (self) published.push_back(self->latest());
        });
        {
            std::lock_guard lock(mutex);
            self = &worker;
        }
        worker.set_schedule(prior_late);
        full_frames(worker, 1, before, settings, 32);
        const auto polled = full_frames(worker, 2, after, settings, 64);
        std::vector<std::shared_ptr<const Snapshot>> frames;
        {
            std::lock_guard lock(mutex);
            for (const auto& f : published)
                if (f && f->generation == 2 && f->scale == 1) frames.push_back(f);
        }
        ASSERT_GE(frames.size(), 3u);
        EXPECT_EQ(frames[0]->carried_pixels, 0u);
        EXPECT_GT(frames[1]->carried_pixels, size_t(kW * kH / 2));
        EXPECT_EQ(polled.back()->carried_pixels, 0u);  // the finished frame
    }
    {
        // An edit that comes right after such a first frame (submitted as it is published):
        // the earlier picture (32 spp) still becomes the history, and the next move carries it
        // on to 16 spp and beyond (a history of the interrupted view's 2 spp would fade out by 8).
        Scene further_scene = orbited;
        orbit(further_scene.cameras[size_t(further_scene.camera)], 10, 0);
        const auto further = std::make_shared<const RenderScene>(prepare_scene(further_scene));
        const FrameSchedule every = every_count_prior_late();
        std::mutex mutex;
        std::vector<std::shared_ptr<const Snapshot>> published;
        RenderWorker* self = nullptr;
        bool armed = false;
        RenderWorker worker([&] {
            std::lock_guard lock(mutex);
            if (!self) return;
            const auto f = self->latest();
            published.push_back(f);
            if (armed && f && f->generation == 2 && f->scale == 1) {
                armed = false;
                FrameSchedule now = every;
                now.prior_budget = std::numeric_limits<double>::infinity();
                self->set_schedule(now);
                StopRule rule;
                rule.max_passes = 64;
                self->submit({3, further, settings, rule, nullptr, {}});
            }
        });
        {
            std::lock_guard lock(mutex);
            self = &worker;
        }
        worker.set_schedule(every);
        full_frames(worker, 1, before, settings, 32);
        {
            std::lock_guard lock(mutex);
            armed = true;
        }
        StopRule open_ended;
        open_ended.max_passes = kUnlimitedPasses;
        worker.submit({2, after, settings, open_ended, nullptr, {}});
        std::shared_ptr<const Snapshot> f;
        for (int waits = 0; waits < 600 && !(f && f->generation == 3 && f->finished); ++waits)
            f = worker.wait_newer(f ? f->serial : 0, std::chrono::milliseconds(1000));
        ASSERT_TRUE(f && f->generation == 3 && f->finished);
        std::lock_guard lock(mutex);
        size_t second = 0, at16 = 0;
        bool saw16 = false;
        for (const auto& g : published) {
            if (!g || g->scale != 1) continue;
            if (g->generation == 2) {
                ++second;
                EXPECT_EQ(g->carried_pixels, 0u);
            }
            if (g->generation == 3 && g->spp == 16) saw16 = true, at16 = g->carried_pixels;
        }
        EXPECT_EQ(second, 1u);
        ASSERT_TRUE(saw16);
        EXPECT_GT(at16, size_t(kW * kH / 2));
    }
    {
        RenderWorker worker;
        full_frames(worker, 1, before, settings, 32);
        EXPECT_EQ(carried(full_frames(worker, 2, lens, settings, 16)), 0u);
    }
    {
        RenderWorker worker;
        full_frames(worker, 1, before, settings, 32);
        worker.set_region(PixelBox{10, 10, 50, 40});
        EXPECT_EQ(carried(full_frames(worker, 2, after, settings, 16)), 0u);
    }
}

}  // namespace
