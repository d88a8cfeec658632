// The viewer's GL-free parts: the reset rule and generation counter, navigation,
// click-to-focus, exact accumulation, the render thread's determinism, the file watch.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "render/camera.h"
#include "render/outputs.h"
#include "render/progressive.h"
#include "scene/load.h"
#include "test_util.h"
#include "viewer/edit.h"
#include "viewer/files.h"
#include "viewer/inspect.h"
#include "viewer/model.h"
#include "viewer/navigation.h"
#include "viewer/render_worker.h"
#include "viewer/reproject.h"
#include "viewer/scene_edit.h"
#include "viewer/status.h"

namespace fs = std::filesystem;
using namespace kr;
using namespace kr::viewer;

TEST(ResetRule, ImageEditsResetDisplayEditsDoNot) {
    for (Edit e : {Edit::camera, Edit::lens, Edit::light, Edit::material, Edit::renderer, Edit::scene})
        EXPECT_TRUE(edit_resets(e)) << int(e);
    EXPECT_FALSE(edit_resets(Edit::tone_map));
    EXPECT_FALSE(edit_resets(Edit::run_control));
}

TEST(ResetRule, GenerationAdvancesOnlyOnImageEdits) {
    ViewerModel m = test::brief_model(3);
    const uint64_t g0 = m.generation();
    auto scene_before = m.prepared();

    // Tone map: same generation, same prepared scene (the render keeps its samples).
    ASSERT_TRUE(m.edit(Edit::tone_map, [](Scene&, ViewerSettings& s) {
        s.tone.tonemap = ToneMap::linear;
        s.tone.exposure = 2;
    }));
    EXPECT_EQ(m.generation(), g0);
    EXPECT_EQ(m.prepared(), scene_before);
    EXPECT_EQ(m.settings().tone.tonemap, ToneMap::linear);
    ASSERT_TRUE(m.edit(Edit::run_control, [](Scene&, ViewerSettings& s) { s.paused = true; }));
    EXPECT_EQ(m.generation(), g0);

    uint64_t g = g0;
    auto expect_reset = [&](Edit kind, auto change) {
        ASSERT_TRUE(m.edit(kind, change));
        EXPECT_EQ(m.generation(), g + 1) << int(kind);
        EXPECT_NE(m.prepared(), scene_before) << int(kind);  // rebuilt from the authored scene
        g = m.generation();
        scene_before = m.prepared();
    };
    expect_reset(Edit::camera, [](Scene& s, ViewerSettings&) { s.cameras[size_t(s.camera)].fov = 50; });
    EXPECT_NEAR(m.prepared()->camera.tan_half_fov, std::tan(25 * kPi / 180), 1e-15);
    expect_reset(Edit::lens, [](Scene& s, ViewerSettings&) {
        s.cameras[size_t(s.camera)].type = CameraType::lens;
        s.cameras[size_t(s.camera)].alpha = 0.5;
    });
    EXPECT_EQ(m.prepared()->camera.lens_radius, 0.5);
    expect_reset(Edit::light, [](Scene& s, ViewerSettings&) { s.lights[size_t(s.active_lights[0])].power = Color(3); });
    EXPECT_EQ(test::lights_of(*m.prepared(), LightType::area)[0].power, Color(3));
    expect_reset(Edit::material, [](Scene& s, ViewerSettings&) { s.materials[0].rho = Color(0.1); });
    expect_reset(Edit::renderer, [](Scene&, ViewerSettings& s) { s.render.max_depth = 2; });
    EXPECT_EQ(m.settings().render.max_depth, 2);
    // Tone map and pause survived every reset.
    EXPECT_EQ(m.settings().tone.exposure, 2);
    EXPECT_TRUE(m.settings().paused);
}

// Rebuilding the BVH after every edit made it most of an edit's latency in a large scene: an
// edit that moves no sphere keeps it, one that moves a sphere builds it again.
// While the user navigates, frames of the earlier views of the same scene may be shown (the
// picture follows the hand): the view base is the generation before a run of camera edits;
// any other resetting edit, a load or an undo starts a new base.
TEST(ResetRule, CameraEditsKeepTheViewBaseOthersMoveIt) {
    ViewerModel m = test::brief_model(3);
    const uint64_t base = m.generation();
    EXPECT_EQ(m.view_base_generation(), base);
    for (int i = 0; i < 3; ++i)
        ASSERT_TRUE(m.edit(Edit::camera, [](Scene& s, ViewerSettings&) { s.cameras[size_t(s.camera)].position.x += 0.1; }));
    EXPECT_EQ(m.generation(), base + 3);
    EXPECT_EQ(m.view_base_generation(), base);
    ASSERT_TRUE(m.edit(Edit::material, [](Scene& s, ViewerSettings&) { s.materials[0].rho = Color(0.3); }));
    EXPECT_EQ(m.view_base_generation(), m.generation());
    ASSERT_TRUE(m.edit(Edit::camera, [](Scene& s, ViewerSettings&) { s.cameras[size_t(s.camera)].position.x += 0.1; }));
    EXPECT_EQ(m.view_base_generation(), m.generation() - 1);
    ASSERT_TRUE(m.undo());
    EXPECT_EQ(m.view_base_generation(), m.generation());
}

TEST(ResetRule, EditsThatMoveNoSphereKeepTheBvh) {
    test::SceneBuilder b;
    const int m = b.material(MaterialType::diffuse);
    for (int i = 0; i < 40; ++i) b.sphere({double(i % 7) - 3, double(i / 7) - 3, 0}, 0.3, m);
    const int lamp = b.emitter({0, 8, -4}, 2, Color(4), m);
    ViewerModel model;
    model.set_scene(b.scene, {});
    ASSERT_TRUE(model.has_scene());
    EXPECT_EQ(model.prepared()->bvh.backend(), embree_available() ? AccelBackend::embree : AccelBackend::own);
    auto before = model.prepared();
    const auto kept = [&](Edit kind, auto change) {
        EXPECT_TRUE(model.edit(kind, change));
        const bool same = model.prepared()->bvh.same_build(before->bvh);
        before = model.prepared();
        return same;
    };
    EXPECT_TRUE(kept(Edit::camera, [](Scene& s, ViewerSettings&) { s.cameras[size_t(s.camera)].fov = 30; }));
    EXPECT_TRUE(kept(Edit::material, [](Scene& s, ViewerSettings&) { s.materials[0].rho = Color(0.2); }));
    EXPECT_TRUE(kept(Edit::light, [](Scene& s, ViewerSettings&) { s.lights[0].power = Color(9); }));
    EXPECT_TRUE(kept(Edit::renderer, [](Scene&, ViewerSettings& s) { s.render.max_depth = 3; }));
    // The lamp's radius is a sphere's: a new BVH, which finds the lamp's new surface.
    EXPECT_FALSE(kept(Edit::light, [&](Scene& s, ViewerSettings&) { s.shapes[size_t(lamp)].radius = 3; }));
    Ray up;
    up.o = {0, 4, -4};  // under the lamp, above the balls
    up.d = {0, 1, 0};
    Hit hit;
    ASSERT_TRUE(model.prepared()->intersects(up, hit));
    EXPECT_EQ(hit.sphere, test::lights_of(*model.prepared(), LightType::area)[0].sphere);
    EXPECT_NEAR(hit.t, 1.0, 1e-12);  // radius 3, not 2
    // A reload of the same file keeps it too.
    EXPECT_TRUE(kept(Edit::scene, [](Scene&, ViewerSettings&) {}));
}

// Authored and prepared stay apart: an edit the renderer cannot take is undone whole.
TEST(ResetRule, InvalidEditIsRejectedAndUndone) {
    ViewerModel m = test::brief_model(3);
    const uint64_t g = m.generation();
    const Camera before = m.camera();
    std::string error;
    EXPECT_FALSE(m.edit(Edit::camera, [](Scene& s, ViewerSettings&) {
        Camera& c = s.cameras[size_t(s.camera)];
        c.position = c.target;
    }, &error));
    EXPECT_NE(error.find("position equals target"), std::string::npos) << error;
    EXPECT_EQ(m.generation(), g);
    EXPECT_EQ(m.camera().position, before.position);
}

TEST(ResetRule, SavedSceneCarriesRendererSettings) {
    ViewerModel m = test::brief_model(3);
    ASSERT_TRUE(m.edit(Edit::renderer, [](Scene&, ViewerSettings& s) {
        s.render.integrator = Integrator::wrt;
        s.render.max_depth = 3;
        s.render.target_spp = 7;
    }));
    const Scene saved = m.scene_for_saving();
    EXPECT_EQ(saved.renderer.type, RendererType::wrt);
    EXPECT_EQ(saved.renderer.depth, 3);
    EXPECT_EQ(saved.renderer.samples, 7);
}

// The display block's denoise mode is the view's: the file's when it has one (the command
// line's over it), the view as it was when it has none; the saved scene records what the
// window shows (the split view saves denoised, as Save does).
TEST(ResetRule, DenoiseModeComesFromTheFileAndIsSaved) {
    ViewerModel m = test::brief_model(3);  // the brief's scene has no denoise field
    EXPECT_EQ(m.settings().denoise, DenoiseView::on);
    EXPECT_EQ(m.scene_for_saving().display.denoise, Denoise::on);
    ASSERT_TRUE(m.edit(Edit::tone_map, [](Scene&, ViewerSettings& s) { s.denoise = DenoiseView::split; }));
    EXPECT_EQ(m.scene_for_saving().display.denoise, Denoise::on);
    ASSERT_TRUE(m.edit(Edit::tone_map, [](Scene&, ViewerSettings& s) { s.denoise = DenoiseView::off; }));
    EXPECT_TRUE(m.dirty());
    Scene saved = m.scene_for_saving();
    EXPECT_EQ(saved.display.denoise, Denoise::off);

    ViewerModel back;  // starts denoised, as the window does
    back.set_scene(saved);
    EXPECT_EQ(back.settings().denoise, DenoiseView::off);
    EXPECT_FALSE(back.settings().tone.denoise.has_value());  // one place holds the mode: the view
    saved.display.denoise = Denoise::on;
    back.set_scene(saved);
    EXPECT_EQ(back.settings().denoise, DenoiseView::on);
    // Without the field the view stays as it is.
    ASSERT_TRUE(back.edit(Edit::tone_map, [](Scene&, ViewerSettings& s) { s.denoise = DenoiseView::split; }));
    saved.display.denoise.reset();
    back.set_scene(saved);
    EXPECT_EQ(back.settings().denoise, DenoiseView::split);
    // The command line's --denoise over the file's.
    ViewerModel flagged;
    RenderOptions flags;
    flags.denoise = Denoise::off;
    flagged.set_overrides(flags);
    saved.display.denoise = Denoise::on;
    flagged.set_scene(saved);
    EXPECT_EQ(flagged.settings().denoise, DenoiseView::off);
}

TEST(Navigation, OrbitKeepsDistanceAndTarget) {
    Camera c;
    c.position = {0, 0, -15};
    c.target = {1, 2, 3};
    const double r = length(c.position - c.target);
    orbit(c, 30, 20);
    EXPECT_NEAR(length(c.position - c.target), r, 1e-12);
    EXPECT_EQ(c.target, Vec3(1, 2, 3));
    // Pitch stops short of the pole, so the camera frame stays defined.
    orbit(c, 0, 500);
    EXPECT_LT((c.position - c.target).y / r, std::sin(89.5 * kPi / 180));
    EXPECT_NO_THROW(CameraModel::from(c));
}

TEST(Navigation, PanMovesBothDollyKeepsDirection) {
    Camera c;
    c.position = {0, 0, -10};
    c.target = {0, 0, 0};
    pan_drag(c, 10, 0, 100);
    EXPECT_NEAR(c.position.z, -10, 1e-12);
    EXPECT_NEAR(c.position.x, c.target.x, 1e-12);
    EXPECT_NE(c.position.x, 0);
    dolly(c, 0.5);
    EXPECT_NEAR(length(c.position - c.target), 5, 1e-12);
}

// Scene 3: the camera at z = -15 looks down +z; below the area light (which the centre
// ray grazes), the far wall (a radius-500 sphere whose near side is about the plane z = 5)
// is about 20 away along the view axis.
TEST(ClickToFocus, DistanceAlongViewAxis) {
    const RenderScene scene = prepare_scene(load_scene_file(test::brief_scene_file(3)).scene);
    const auto d = focus_distance(scene, 0.5, 0.6);
    ASSERT_TRUE(d.has_value());
    EXPECT_NEAR(*d, 20, 0.01);
    // Along forward (the camera's focal-plane convention), not along the slanted ray.
    const CameraRay r = scene.camera.generate(0.5, 0.6, 0.5, 0.5);
    Ray ray;
    ray.o = r.origin;
    ray.d = r.direction;
    Hit hit;
    ASSERT_TRUE(scene.intersects(ray, hit));
    EXPECT_NEAR(*d, hit.t * dot(r.direction, scene.camera.forward), 1e-12);
    EXPECT_LT(*d, hit.t);
}

TEST(ClickToFocus, ModelSetsFocalDistanceAndMakesALens) {
    ViewerModel m = test::brief_model(3);
    const uint64_t g = m.generation();
    ASSERT_TRUE(m.focus_at(0.5, 0.6));
    EXPECT_EQ(m.camera().type, CameraType::lens);
    EXPECT_NEAR(m.camera().focal_distance, 20, 0.01);
    // Scene 3's camera has no aperture: every distance is sharp, the image is the same, so the
    // samples stay (issue 47 B5), and the click says how to see the focus.
    EXPECT_EQ(m.camera().alpha, 0);
    EXPECT_EQ(m.generation(), g);
    EXPECT_NE(focus_message(m.camera()).find("the aperture is 0"), std::string::npos);
    ASSERT_TRUE(m.edit(Edit::lens, [](Scene& s, ViewerSettings&) { s.cameras[size_t(s.camera)].alpha = 0.2; }));
    EXPECT_EQ(m.generation(), g + 1);
    EXPECT_EQ(focus_message(m.camera()).find("aperture"), std::string::npos);
    // The pixel of the glass ball's centre (2, -3.5, -1), radius 1.5, focuses on its near
    // surface: (|c - o| - r) along that ray, times the ray's cosine to the axis.
    const CameraModel& cam = m.prepared()->camera;
    const double fx = 0.5 + 2.0 / 14.0 / (2 * cam.tan_half_fov), fy = 0.5 + 3.5 / 14.0 / (2 * cam.tan_half_fov);
    ASSERT_TRUE(m.focus_at(fx, fy));
    const double to_centre = length(Vec3(2, -3.5, -1) - Vec3(0, 0, -15));
    EXPECT_NEAR(m.camera().focal_distance, (to_centre - 1.5) * 14.0 / to_centre, 1e-9);
}

// 10^6 samples of radiance (0.1, 0.3, 0.7) (not representable) into one pixel: the camera
// inside an emitter with depth 0 sees exactly that in every sample, 64 samples a pass. The
// plain double sum drifts by about 1e-11 relative; the mean, from the compensated sums, must
// stay within 1e-12. In double: the single-precision lanes would hand in float(0.1).
TEST(Accumulation, NoDriftAfterAMillionSamples) {
    test::SceneBuilder b;
    b.scene.renderer.width = b.scene.renderer.height = 1;
    const Color radiance(0.1, 0.3, 0.7);
    b.emitter({0, 0, 0}, 100, radiance, b.material(MaterialType::diffuse));
    const RenderScene scene = b.build();
    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    settings.max_depth = 0;
    settings.target_spp = 1;
    settings.kernels = LaneChoice::double_lanes;
    RenderState state(1, 1);
    state.plan.pass_samples = {uint8_t(kMaxPassSamples)};
    for (int i = 0; i < 1000000 / kMaxPassSamples; ++i) ASSERT_TRUE(render_pass(scene, settings, state));
    ASSERT_EQ(state.sample_count()[0], 1000000u);
    const Color mean = state.radiance().pixels[0];
    const Color plain = state.radiance_sum()[0] / 1e6;
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(mean[k], radiance[k], 1e-12 * radiance[k]);
        EXPECT_GT(std::abs(plain[k] - radiance[k]), 1e-13 * radiance[k]);  // what the correction is for
    }
}

// render_pass's two ways of adding samples to their pixels (SSE2, and AVX2 where the CPU has
// it) give the same sums bit for bit, over samples of every size, repeated pixels, samples
// that are NaN or infinite, and one that would overflow its pixel's sum (all dropped); a
// pixel's samples one after another or between other pixels'.
TEST(Accumulation, Avx2SumsAreSse2sBitForBit) {
    if (!accumulation_isa_available(AccumulationIsa::avx2)) GTEST_SKIP() << "this CPU has no AVX2";
    const size_t pixels = 7;
    std::vector<size_t> where;
    std::vector<SampleResult> results;
    Rng rng(42, 7);
    for (int k = 0; k < 4000; ++k) {
        SampleResult r;
        const double scale = std::pow(10.0, 12 * rng.next() - 6);
        r.radiance = Color(scale * rng.next(), scale * rng.next(), scale * rng.next() * (rng.next() < 0.1 ? 0 : 1));
        r.primary_distance = rng.next() < 0.2 ? kMissDepth : 10 * rng.next();
        r.rays = 1 + uint64_t(rng.next() * 5);
        if (k % 97 == 5) r.radiance.y = std::nan("");
        if (k % 89 == 7) r.radiance.z = kInfinity;
        if (k == 3000) r.radiance.x = 1e308;  // pixel 3000 % 7's sum, then this one, overflows
        // Runs of one pixel's samples, as a planned pass gives them, between single ones.
        where.push_back(k > 0 && rng.next() < 0.6 ? where.back() : size_t(k) % pixels);
        results.push_back(r);
    }
    where[3001] = where[3000];
    results[3001].radiance.x = 1e308;
    RenderState a(int(pixels), 1), b(int(pixels), 1);
    uint64_t dropped_a = 0, dropped_b = 0;
    for (size_t first = 0; first < results.size(); first += kSampleBatch) {
        const int n = int(std::min<size_t>(kSampleBatch, results.size() - first));
        accumulate_samples(a.buffers(), &where[first], &results[first], n, AccumulationIsa::sse2, dropped_a);
        accumulate_samples(b.buffers(), &where[first], &results[first], n, AccumulationIsa::avx2, dropped_b);
    }
    EXPECT_EQ(dropped_a, dropped_b);
    EXPECT_GT(dropped_a, 80u);  // the NaN, infinite and overflowing samples
    const auto same_bits = [](const auto& x, const auto& y) {
        return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0;
    };
    const PixelBuffers &pa = a.buffers(), &pb = b.buffers();
    EXPECT_TRUE(same_bits(pa.radiance_sum, pb.radiance_sum));
    EXPECT_TRUE(same_bits(pa.radiance_compensation, pb.radiance_compensation));
    EXPECT_TRUE(same_bits(pa.depth_sum, pb.depth_sum));
    EXPECT_TRUE(same_bits(pa.luminance_sq_sum, pb.luminance_sq_sum));
    EXPECT_TRUE(same_bits(pa.radiance_sq_sum, pb.radiance_sq_sum));
    EXPECT_TRUE(same_bits(pa.sample_count, pb.sample_count));
    for (const Color& lost : pa.radiance_compensation) EXPECT_TRUE(is_finite(lost));
}

TEST(RenderThread, PreviewScalesFitTheBudget) {
    EXPECT_EQ(preview_scales(512, 512, 0, 0.02), (std::vector<int>{8, 4, 2}));  // nothing measured yet
    // 1 us per pixel sample: a full pass is 0.26 s; 1/4 is 16 ms.
    EXPECT_EQ(preview_scales(512, 512, 1e-6, 0.02).front(), 4);
    // Cheap scenes skip the preview ladder after its first step.
    EXPECT_EQ(preview_scales(512, 512, 1e-8, 0.02), std::vector<int>{});
    EXPECT_EQ(preview_scales(512, 512, 1e-4, 0.02).front(), 16);
}

// Brief scene n prepared at w x h pixels, for the render thread's tests.
static std::shared_ptr<const RenderScene> small_scene(int n, int w, int h) {
    Scene authored = load_scene_file(test::brief_scene_file(n)).scene;
    authored.renderer.width = w;
    authored.renderer.height = h;
    return std::make_shared<const RenderScene>(prepare_scene(authored));
}

// The worker's published frames are the deterministic estimate: at the target spp they
// equal plain render passes, whatever the thread timing, edits and previews before.
TEST(RenderThread, ReachesTargetWithTheDeterministicImage) {
    const auto scene = small_scene(8, 40, 30);
    RenderSettings settings = RenderSettings::from_scene(scene->renderer);
    settings.target_spp = 3;

    RenderWorker worker;
    worker.submit({1, scene, settings, StopRule{settings.target_spp}});
    RenderSettings other = settings;
    other.max_depth = 1;
    worker.submit({2, scene, other, StopRule{other.target_spp}});  // an edit at once: generation 1 may never show
    worker.submit({3, scene, settings, StopRule{settings.target_spp}});
    std::shared_ptr<const Snapshot> f;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (!(f && f->generation == 3 && f->finished) && std::chrono::steady_clock::now() < deadline)
        f = worker.wait_newer(f ? f->serial : 0, std::chrono::milliseconds(500));
    ASSERT_TRUE(f && f->finished);
    EXPECT_EQ(f->scale, 1);
    EXPECT_EQ(f->spp, 3);

    RenderState plain(40, 30);
    for (int i = 0; i < 3; ++i) render_pass(*scene, settings, plain);
    const Image expected = plain.radiance();
    ASSERT_EQ(f->radiance.pixels.size(), expected.pixels.size());
    // The same driver and passes: the same sums, bit for bit.
    for (size_t i = 0; i < expected.pixels.size(); ++i)
        for (int k = 0; k < 3; ++k) ASSERT_EQ(f->radiance.pixels[i][k], expected.pixels[i][k]) << i;
    // It stops at the target: no newer frame comes.
    const auto more = worker.wait_newer(f->serial, std::chrono::milliseconds(300));
    EXPECT_EQ(more->serial, f->serial);
}

// Missing item 4: the feature views' layers. None by default (the default render makes
// none); asked for once the render is finished, the newest frame comes again with them (the
// denoiser's feature buffers, the same as render/outputs.h feature_buffers), and every frame
// after, previews included (at their resolution and their few samples), has them, with or
// without the denoiser.
TEST(RenderThread, FeatureLayersOnlyWhenAskedAlsoForAFinishedRender) {
    const auto scene = small_scene(8, 40, 30);
    RenderSettings settings = RenderSettings::from_scene(scene->renderer);
    settings.target_spp = 2;
    std::vector<float> albedo, normal;
    feature_buffers(*scene, settings, 40, 30, albedo, normal);
    for (const bool denoise : {true, false}) {
        RenderWorker worker;
        worker.set_denoise(denoise);
        worker.submit({1, scene, settings, StopRule{settings.target_spp}});
        std::shared_ptr<const Snapshot> f;
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
        while (!(f && f->finished) && std::chrono::steady_clock::now() < deadline) {
            f = worker.wait_newer(f ? f->serial : 0, std::chrono::milliseconds(500));
            if (f) EXPECT_FALSE(f->features || !f->hit_depth.empty());
        }
        ASSERT_TRUE(f && f->finished);
        worker.set_features(true);
        const auto again = worker.wait_newer(f->serial, std::chrono::seconds(120));
        ASSERT_GT(again->serial, f->serial);
        ASSERT_TRUE(again->features);
        EXPECT_EQ(again->spp, f->spp);
        EXPECT_EQ(again->radiance.pixels, f->radiance.pixels);
        EXPECT_EQ(again->features->width, 40);
        EXPECT_EQ(again->features->albedo, albedo);
        EXPECT_EQ(again->features->normal, normal);
        EXPECT_EQ(again->hit_depth, hit_depths(f->depth, f->sample_count));
        EXPECT_TRUE(std::any_of(again->hit_depth.begin(), again->hit_depth.end(), [](float d) { return std::isfinite(d); }));

        // A new edit with the views on: every frame carries its own resolution's layers.
        worker.submit({2, scene, settings, StopRule{settings.target_spp}});
        f.reset();
        while (!(f && f->generation == 2 && f->finished) && std::chrono::steady_clock::now() < deadline) {
            f = worker.wait_newer(f ? f->serial : 0, std::chrono::milliseconds(500));
            if (!f || f->generation != 2) continue;
            ASSERT_TRUE(f->features) << f->scale;
            EXPECT_EQ(f->features->width, f->radiance.width);
            EXPECT_EQ(f->features->height, f->radiance.height);
            EXPECT_EQ(f->hit_depth.size(), f->radiance.pixels.size());
            // A full frame's layers are feature_buffers'; a preview's, its own few samples a
            // pixel (kPreviewFeatureSamples) at its resolution.
            std::vector<float> a, n;
            if (f->scale == 1) {
                feature_buffers(*scene, settings, f->radiance.width, f->radiance.height, a, n);
            } else {
                DisplayFeatures preview;
                preview.reset(f->radiance.width, f->radiance.height);
                preview.refine_to(RenderJob{2, scene, settings, StopRule{settings.target_spp}}, kPreviewFeatureSamples);
                a = preview.albedo;
            }
            EXPECT_EQ(f->features->albedo, a) << f->scale;
        }
        ASSERT_TRUE(f && f->finished);
    }
}

// Missing item 2: a render region. Only its pixels refine; their samples and values are the
// plain render's (the same pass plan, the others skipped), the rest keep theirs (none here).
TEST(RenderThread, RegionRefinesOnlyItsPixels) {
    const auto scene = small_scene(8, 40, 30);
    RenderSettings settings = RenderSettings::from_scene(scene->renderer);
    settings.target_spp = 3;
    const PixelBox box{5, 4, 17, 20};
    RenderWorker worker;
    worker.set_region(box);
    worker.submit({1, scene, settings, StopRule{settings.target_spp}});
    std::shared_ptr<const Snapshot> f;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (!(f && f->finished) && std::chrono::steady_clock::now() < deadline)
        f = worker.wait_newer(f ? f->serial : 0, std::chrono::milliseconds(500));
    ASSERT_TRUE(f && f->finished);
    ASSERT_EQ(f->sample_count.size(), 40u * 30u);
    RenderState plain(40, 30);
    for (int i = 0; i < 3; ++i) render_pass(*scene, settings, plain);
    const Image expected = plain.radiance();
    int inside = 0;
    for (int y = 0; y < 30; ++y)
        for (int x = 0; x < 40; ++x) {
            const size_t i = size_t(y) * 40 + size_t(x);
            const bool in = x >= box.x0 && x < box.x1 && y >= box.y0 && y < box.y1;
            inside += in;
            ASSERT_EQ(f->sample_count[i], in ? 3u : 0u) << x << "," << y;
            if (in)
                for (int k = 0; k < 3; ++k) ASSERT_EQ(f->radiance.pixels[i][k], expected.pixels[i][k]) << x << "," << y;
        }
    EXPECT_EQ(inside, 12 * 16);
    // The whole image again: the others refine from the next pass on.
    worker.set_region(std::nullopt);
    StopRule more{6};
    worker.set_stop_rule(more);
    while (!(f && f->finished && f->spp == 6) && std::chrono::steady_clock::now() < deadline)
        f = worker.wait_newer(f ? f->serial : 0, std::chrono::milliseconds(500));
    ASSERT_TRUE(f && f->spp == 6);
    EXPECT_EQ(f->sample_count[0], 3u);
    EXPECT_EQ(f->sample_count[size_t(box.y0) * 40 + size_t(box.x0)], 6u);
}

// The worker's frames until one is finished (at most two minutes, on a loaded machine).
static std::shared_ptr<const Snapshot> finished_frame(const RenderWorker& worker) {
    std::shared_ptr<const Snapshot> f;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (!(f && f->finished) && std::chrono::steady_clock::now() < deadline)
        f = worker.wait_newer(f ? f->serial : 0, std::chrono::milliseconds(500));
    return f;
}

// Past the warm-up (adaptive passes), a region's pass plans only its pixels: the samples of
// a pass are as many as its pixels (not the whole image's, heaped on them), so the region
// reaches its target as its pixels' share of the work.
TEST(RenderThread, ARegionsPassesCostWhatItsPixelsCost) {
    const auto scene = small_scene(3, 48, 40);
    RenderSettings settings = RenderSettings::from_scene(scene->renderer);
    settings.target_spp = 16;  // 8 uniform passes, then 8 planned ones
    const PixelBox box{10, 8, 22, 20};
    RenderWorker worker;
    worker.set_region(box);
    worker.submit({1, scene, settings, StopRule{settings.target_spp}});
    const std::shared_ptr<const Snapshot> f = finished_frame(worker);
    ASSERT_TRUE(f && f->finished);
    ASSERT_EQ(f->spp, 16);
    uint64_t inside = 0, outside = 0;
    for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 48; ++x) {
            const bool in = x >= box.x0 && x < box.x1 && y >= box.y0 && y < box.y1;
            (in ? inside : outside) += f->sample_count[size_t(y) * 48 + size_t(x)];
        }
    EXPECT_EQ(outside, 0u);
    // 16 samples a pixel on average, give or take the planned passes' carried fractions.
    const double mean = double(inside) / (12.0 * 12.0);
    EXPECT_GE(mean, 15.0);
    EXPECT_LE(mean, 17.0);
}

// A region's passes change only its pixels' halves (the final denoiser's guides): the others'
// stay as they were, bit for bit, however many passes go by.
TEST(RenderThread, ARegionsPassesLeaveTheOtherPixelsHalvesAsTheyWere) {
    const auto scene = small_scene(3, 24, 20);
    RenderSettings settings = RenderSettings::from_scene(scene->renderer);
    settings.target_spp = 16;
    RenderState state(24, 20);
    state.track_halves();
    RegionHooks region;
    const StopRule rule{16};
    ProgressiveDriver driver(*scene, settings, state, rule, &region);
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(driver.pass(rule));
    const RenderState::Halves before = state.halves();
    const PixelBox box{4, 5, 13, 11};
    region.region = box;
    for (int i = 0; i < 10; ++i) ASSERT_TRUE(driver.pass(rule));  // planned passes among them
    const RenderState::Halves after = state.halves();
    int changed = 0;
    for (int y = 0; y < 20; ++y)
        for (int x = 0; x < 24; ++x) {
            const size_t i = size_t(y) * 24 + size_t(x);
            const bool in = x >= box.x0 && x < box.x1 && y >= box.y0 && y < box.y1;
            for (int h = 0; h < 2; ++h) {
                if (in) {
                    changed += after.count[h][i] > before.count[h][i];
                    continue;
                }
                ASSERT_EQ(after.count[h][i], before.count[h][i]) << x << "," << y;
                ASSERT_EQ(std::memcmp(&after.mean[h].pixels[i], &before.mean[h].pixels[i], sizeof(Color)), 0) << x << "," << y;
            }
        }
    EXPECT_GE(changed, 2 * 9 * 6 - 4);  // the box's pixels grew both halves
}

// The job the frame tests below make frames of: scene 3 at 48x40, 16 spp.
RenderJob frame_test_job() {
    const auto scene = small_scene(3, 48, 40);
    RenderSettings settings = RenderSettings::from_scene(scene->renderer);
    settings.target_spp = 16;
    return RenderJob{7, scene, settings, StopRule{16}};
}

// An edit stops the frame of the view it replaced (make_full_frame's cancel, the worker's
// stop flag): set before the frame, or before the filter's passes (denoise_atrous), the frame
// is left unfinished; unset, the frame is the one made without it, bit for bit, whole and in a
// region's box.
TEST(RenderThread, AnEditStopsTheFrameOfTheViewItReplaced) {
    const RenderJob job = frame_test_job();
    const auto& scene = job.scene;
    const RenderSettings& settings = job.settings;
    RenderState state(48, 40);
    for (int i = 0; i < 4; ++i) render_pass(*scene, settings, state);
    DisplayFeatures features;
    features.reset(48, 40);
    features.refine_to(job, 2);
    DenoiseWorkspace workspace;
    std::atomic<bool> cancel{false};
    Snapshot plain, kept;
    make_full_frame(job, state, &features, workspace, plain);
    EXPECT_TRUE(make_full_frame(job, state, &features, workspace, kept, nullptr, std::nullopt, &cancel));
    ASSERT_EQ(kept.denoised.pixels.size(), plain.denoised.pixels.size());
    EXPECT_EQ(std::memcmp(kept.denoised.pixels.data(), plain.denoised.pixels.data(),
                          plain.denoised.pixels.size() * sizeof(Color)), 0);
    const PixelBox box{10, 6, 30, 22};
    Snapshot boxed;
    EXPECT_TRUE(make_full_frame(job, state, &features, workspace, boxed, &plain, box, &cancel));
    EXPECT_FALSE(boxed.denoised.pixels.empty());
    cancel = true;
    Snapshot stopped, stopped_box;
    EXPECT_FALSE(make_full_frame(job, state, &features, workspace, stopped, nullptr, std::nullopt, &cancel));
    EXPECT_FALSE(make_full_frame(job, state, &features, workspace, stopped_box, &plain, box, &cancel));
    EXPECT_TRUE(stopped.radiance.pixels.empty());
    // The filter itself: stopped before its first pass, an empty image; the workspace still
    // serves the next frame, which is the same as before.
    RenderEstimates estimates = render_estimates(state, kLayerRadiance | kLayerDepth | kLayerVariance);
    DevelopOptions options;
    options.denoise = Denoise::on;
    options.interactive = true;
    options.sampling = settings;
    options.workspace = &workspace;
    options.cancel = &cancel;
    estimates.albedo = features.albedo;
    estimates.normal = features.normal;
    EXPECT_TRUE(denoised_image(estimates, estimates.radiance, options).pixels.empty());
    cancel = false;
    Snapshot again;
    EXPECT_TRUE(make_full_frame(job, state, &features, workspace, again, nullptr, std::nullopt, &cancel));
    EXPECT_EQ(std::memcmp(again.denoised.pixels.data(), plain.denoised.pixels.data(),
                          plain.denoised.pixels.size() * sizeof(Color)), 0);
    // What a frame of the next view needs first stops too: its feature buffers (refine_to, no
    // sample added, so a later refinement is still that of an uninterrupted one) and its first
    // surfaces for the carried picture (view_hits: no row cast).
    cancel = true;
    DisplayFeatures stopped_features;
    stopped_features.reset(48, 40);
    EXPECT_FALSE(stopped_features.refine_to(job, 2, std::nullopt, &cancel));
    EXPECT_EQ(stopped_features.samples, 0);
    EXPECT_TRUE(std::all_of(stopped_features.counts.begin(), stopped_features.counts.end(),
                            [](uint8_t c) { return c == 0; }));
    const viewer::ViewHits none = view_hits(*scene, 48, 40, settings, &cancel);
    EXPECT_TRUE(std::all_of(none.sphere.begin(), none.sphere.end(), [](int s) { return s < 0; }));
    cancel = false;
    EXPECT_TRUE(stopped_features.refine_to(job, 2, std::nullopt, &cancel));
    EXPECT_EQ(stopped_features.albedo, features.albedo);
    EXPECT_EQ(stopped_features.normal, features.normal);
    const viewer::ViewHits all = view_hits(*scene, 48, 40, settings, &cancel);
    EXPECT_EQ(all.sphere, view_hits(*scene, 48, 40, settings).sphere);
    EXPECT_GT(std::count_if(all.sphere.begin(), all.sphere.end(), [](int s) { return s >= 0; }), 48 * 40 / 2);
}

// A region's full frames denoise its pixels alone, over the previous frame's picture: the
// others keep it bit for bit (their samples did not change), the box's is the estimate's
// (close to the whole image's filter; its edges filtered as the image's borders).
TEST(RenderThread, ARegionsFramesDenoiseItsPixelsOverThePreviousPicture) {
    const RenderJob job = frame_test_job();
    const auto& scene = job.scene;
    const RenderSettings& settings = job.settings;
    RenderState state(48, 40);
    RegionHooks region;
    const StopRule rule{16};
    ProgressiveDriver driver(*scene, settings, state, rule, &region);
    for (int i = 0; i < 4; ++i) ASSERT_TRUE(driver.pass(rule));
    DisplayFeatures features;
    features.reset(48, 40);
    features.refine_to(job, 2);
    DenoiseWorkspace workspace;
    Snapshot first;
    first.generation = job.generation;
    make_full_frame(job, state, &features, workspace, first);
    const PixelBox box{10, 6, 30, 22};
    region.region = box;
    for (int i = 0; i < 8; ++i) ASSERT_TRUE(driver.pass(rule));
    const std::vector<uint32_t>& samples = state.sample_count();
    EXPECT_EQ(denoised_box(box, 48, 40, &first, job.generation, samples), box);
    // Another job's frame, or none, while the other pixels have samples: the whole image.
    EXPECT_EQ(denoised_box(box, 48, 40, &first, job.generation + 1, samples), std::nullopt);
    EXPECT_EQ(denoised_box(box, 48, 40, nullptr, job.generation, samples), std::nullopt);
    // ... but with no sample outside the box (a job started with a region), the box alone.
    std::vector<uint32_t> only_inside(samples.size(), 0);
    only_inside[size_t(box.y0) * 48 + size_t(box.x0)] = 3;
    EXPECT_EQ(denoised_box(box, 48, 40, nullptr, job.generation, only_inside), box);
    EXPECT_EQ(denoised_box(PixelBox{0, 0, 40, 30}, 48, 40, &first, job.generation, samples), std::nullopt);  // most of it
    EXPECT_EQ(denoised_box(PixelBox{-5, -5, 8, 9}, 48, 40, &first, job.generation, samples), (PixelBox{0, 0, 8, 9}));
    Snapshot boxed, whole;
    make_full_frame(job, state, &features, workspace, boxed, &first, box);
    make_full_frame(job, state, &features, workspace, whole);
    double error = 0, signal = 0;
    int changed = 0;
    for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 48; ++x) {
            const size_t i = size_t(y) * 48 + size_t(x);
            const Color a = boxed.denoised.pixels[i], b = first.denoised.pixels[i];
            if (!(x >= box.x0 && x < box.x1 && y >= box.y0 && y < box.y1)) {
                ASSERT_EQ(std::memcmp(&a, &b, sizeof(Color)), 0) << x << "," << y;
                continue;
            }
            changed += std::memcmp(&a, &b, sizeof(Color)) != 0;
            const Color d = a - whole.denoised.pixels[i];
            error += dot(d, d);
            signal += dot(whole.denoised.pixels[i], whole.denoised.pixels[i]);
        }
    EXPECT_GT(changed, 20 * 16 * 9 / 10);
    EXPECT_LT(error, 0.01 * signal);  // within 1 % of the whole image's filter, in energy
}

// The display's feature buffers within a region: its pixels are refined and are the whole
// image's, bit for bit; the others wait until there is no region, and at kFeatureSamples
// every pixel is feature_buffers'.
TEST(RenderThread, DisplayFeaturesRefineARegionFirstAndEndAsSavesOwn) {
    const auto scene = small_scene(8, 30, 24);
    RenderSettings settings = RenderSettings::from_scene(scene->renderer);
    const RenderJob job{1, scene, settings, StopRule{4}};
    SurfaceLayers sums;
    add_surface_samples(*scene, settings, 30, 24, 0, 2, sums);
    std::vector<float> albedo2, normal2;
    feature_buffers_from_sums(sums, 2, albedo2, normal2);
    DisplayFeatures features;
    features.reset(30, 24);
    const PixelBox box{3, 2, 17, 9};
    features.refine_to(job, 1, box);
    features.refine_to(job, 2, box);
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 30; ++x) {
            const size_t i = size_t(y) * 30 + size_t(x);
            const bool in = x >= box.x0 && x < box.x1 && y >= box.y0 && y < box.y1;
            ASSERT_EQ(features.counts[i], in ? 2 : 0) << x << "," << y;
            for (int k = 0; k < 3; ++k) {
                ASSERT_EQ(features.albedo[3 * i + size_t(k)], in ? albedo2[3 * i + size_t(k)] : 0.0f) << x << "," << y;
                ASSERT_EQ(features.normal[3 * i + size_t(k)], in ? normal2[3 * i + size_t(k)] : 0.0f) << x << "," << y;
            }
        }
    EXPECT_EQ(next_display_feature_samples(features), 2);
    features.refine_to(job, 2);  // the region cleared: the other pixels catch up
    EXPECT_EQ(features.albedo, albedo2);
    EXPECT_EQ(features.normal, normal2);
    features.refine_to(job, kFeatureSamples);
    std::vector<float> albedo, normal;
    feature_buffers(*scene, settings, 30, 24, albedo, normal);
    EXPECT_EQ(features.albedo, albedo);
    EXPECT_EQ(features.normal, normal);
}

// A render region's previews sample only the preview pixels over it (the others stay black,
// as in its full frames), and their features and denoised picture are those pixels' alone.
TEST(RenderThread, ARegionsPreviewsSampleOnlyItsPixels) {
    EXPECT_EQ(preview_box(std::nullopt, 40, 30, 2), std::nullopt);
    EXPECT_EQ(preview_box(PixelBox{5, 4, 17, 20}, 40, 30, 2), (PixelBox{2, 2, 9, 10}));
    EXPECT_EQ(preview_box(PixelBox{5, 4, 17, 20}, 40, 30, 4), (PixelBox{1, 1, 5, 6}));  // of 10 x 8 pixels
    EXPECT_EQ(preview_box(PixelBox{-3, -3, 99, 99}, 40, 30, 8), (PixelBox{0, 0, 5, 4}));
    const auto scene = small_scene(8, 40, 30);
    const RenderSettings settings = RenderSettings::from_scene(scene->renderer);
    const RenderJob job{1, scene, settings, StopRule{4}};
    const PixelBox region{5, 4, 17, 20};
    for (const int scale : {4, 2}) {
        SCOPED_TRACE(scale);
        DenoiseWorkspace workspace;
        Snapshot boxed, whole;
        DisplayFeatures kept;
        make_preview_frame(job, scale, true, false, workspace, boxed, &kept, region);
        make_preview_frame(job, scale, true, false, workspace, whole);
        EXPECT_EQ(kept.width, 0);  // a region's preview guides no full frame
        const PixelBox box = *preview_box(region, 40, 30, scale);
        const int pw = boxed.radiance.width;
        size_t lit = 0;
        for (int y = 0; y < boxed.radiance.height; ++y)
            for (int x = 0; x < pw; ++x) {
                const size_t i = size_t(y) * size_t(pw) + size_t(x);
                const bool in = x >= box.x0 && x < box.x1 && y >= box.y0 && y < box.y1;
                const Color c = boxed.radiance.pixels[i];
                if (!in) {
                    ASSERT_EQ(c, Color()) << x << "," << y;
                    ASSERT_EQ(boxed.denoised.pixels[i], Color()) << x << "," << y;
                    continue;
                }
                // The region's samples are the whole preview's (the same samplers).
                ASSERT_EQ(std::memcmp(&c, &whole.radiance.pixels[i], sizeof(Color)), 0) << x << "," << y;
                lit += boxed.denoised.pixels[i][0] > 0;
            }
        EXPECT_GT(lit, size_t((box.x1 - box.x0) * (box.y1 - box.y0) / 2));
    }
}

// The first full frame of an edit takes its 1/2 preview's feature buffers (each pixel the
// preview pixel it lies in, nothing traced), the next one traces every pixel's two camera
// samples over them; a coarser preview, a region or no preview: the first frame traces its own.
TEST(RenderThread, TheFirstFullFrameTakesItsPreviewsFeatures) {
    for (const auto& [w, h] : {std::pair{30, 24}, std::pair{31, 23}}) {
        SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
        const auto scene = small_scene(8, w, h);
        RenderSettings settings = RenderSettings::from_scene(scene->renderer);
        const RenderJob job{1, scene, settings, StopRule{4}};
        DenoiseWorkspace workspace;
        Snapshot frame;
        DisplayFeatures preview;
        make_preview_frame(job, 2, true, false, workspace, frame, &preview);
        ASSERT_EQ(preview.width, (w + 1) / 2);
        ASSERT_EQ(preview.height, (h + 1) / 2);
        ASSERT_EQ(preview.albedo.size(), 3 * size_t(preview.width) * size_t(preview.height));
        ASSERT_TRUE(guides_full_frame(preview, w, h));
        DisplayFeatures features;
        features.reset(w, h);
        display_features_for_frame(features, job, &preview, std::nullopt);
        EXPECT_EQ(features.samples, 0);
        EXPECT_TRUE(features.counts.empty());  // nothing traced
        size_t lit = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                // Pixel x's centre lies in preview pixel x / 2 (the preview spans the same film).
                const int px = int((2 * x + 1) * preview.width / (2 * w)), py = int((2 * y + 1) * preview.height / (2 * h));
                const size_t i = 3 * (size_t(y) * size_t(w) + size_t(x)), j = 3 * (size_t(py) * size_t(preview.width) + size_t(px));
                for (int k = 0; k < 3; ++k) {
                    ASSERT_EQ(features.albedo[i + size_t(k)], preview.albedo[j + size_t(k)]) << x << "," << y;
                    ASSERT_EQ(features.normal[i + size_t(k)], preview.normal[j + size_t(k)]) << x << "," << y;
                }
                lit += features.albedo[i] > 0;
            }
        EXPECT_GT(lit, size_t(w * h / 4));  // the scene's spheres are there
        // The next frame: every pixel's own two camera samples at once (as a frame after a
        // traced first one has them), as refine_to(2) alone gives them.
        display_features_for_frame(features, job, &preview, std::nullopt);
        DisplayFeatures both;
        both.reset(w, h);
        both.refine_to(job, kDisplayFeatureSamples);
        EXPECT_EQ(features.samples, kDisplayFeatureSamples);
        EXPECT_EQ(features.albedo, both.albedo);
        EXPECT_EQ(features.normal, both.normal);
        DisplayFeatures traced;
        traced.reset(w, h);
        traced.refine_to(job, 1);
        // A 1/4 preview guides no full frame; nor does a preview under a region.
        DisplayFeatures coarse;
        make_preview_frame(job, 4, true, false, workspace, frame, &coarse);
        EXPECT_FALSE(guides_full_frame(coarse, w, h));
        DisplayFeatures first;
        first.reset(w, h);
        display_features_for_frame(first, job, &coarse, std::nullopt);
        EXPECT_EQ(first.albedo, traced.albedo);
        DisplayFeatures boxed;
        boxed.reset(w, h);
        display_features_for_frame(boxed, job, &preview, PixelBox{2, 2, 10, 10});
        EXPECT_EQ(boxed.samples, 1);
        EXPECT_EQ(boxed.counts[size_t(3 * w + 3)], 1);
    }
}

// The frame schedule: the first frame, then intervals of half the image's age (at least a
// display refresh, at most a second), never shorter than the frames' cost over their share.
TEST(RenderThread, FrameScheduleFollowsTheImagesAgeAndTheFramesCost) {
    const FrameSchedule s;
    EXPECT_FALSE(s.due(1.0, 0.4, 0.001));  // half of 1 s: 0.5 s
    EXPECT_TRUE(s.due(1.0, 0.5, 0.001));
    EXPECT_TRUE(s.due(0.01, 1.0 / 60, 0.001));  // a young image: one refresh
    EXPECT_FALSE(s.due(0.01, 0.01, 0.001));
    EXPECT_TRUE(s.due(100, 1.0, 0.001));        // an old one: a second
    EXPECT_FALSE(s.due(100, 0.9, 0.001));
    // Frames costing 0.1 s (making and drawing) come at most every 0.4 s (a quarter of the time).
    EXPECT_FALSE(s.due(0.2, 0.35, 0.1));
    EXPECT_TRUE(s.due(0.2, 0.4, 0.1));
    // Early, at a balanced count, where the next one would come later past the interval than
    // now is before it: 0.45 of 0.5 s with the next count 0.2 s away; not with it 0.05 s away,
    // nor before half the interval.
    EXPECT_TRUE(s.due(1.0, 0.45, 0.001, 0.2));
    EXPECT_FALSE(s.due(1.0, 0.45, 0.001, 0.05));
    EXPECT_FALSE(s.due(1.0, 0.24, 0.001, 10));
    EXPECT_TRUE(s.due(1.0, 0.26, 0.001, 10));
    // The counts frames are made at: balanced ones, and after previews none below 4 spp.
    for (const int spp : {1, 2, 4, 8, 16, 24, 64}) EXPECT_TRUE(frame_spp(spp)) << spp;
    for (const int spp : {3, 5, 7, 9, 12, 15, 17, 63}) EXPECT_FALSE(frame_spp(spp)) << spp;
    EXPECT_FALSE(frame_spp(1, 2));
    EXPECT_TRUE(frame_spp(2, 2));
    EXPECT_FALSE(frame_spp(2, 4));
    EXPECT_TRUE(frame_spp(4, 4));
    EXPECT_EQ(next_frame_spp(0, 4), 4);
    EXPECT_EQ(next_frame_spp(0, 2), 2);
    EXPECT_EQ(next_frame_spp(4, 4), 8);
    EXPECT_EQ(next_frame_spp(8, 4), 16);
    EXPECT_EQ(next_frame_spp(13, 4), 16);
    EXPECT_EQ(next_frame_spp(16, 4), 24);
    // The carried picture before the first frame where it costs at most prior_budget: as last
    // measured, else at twice a pass's cost per pixel (a 1920x1080 pass of 60 ms: 0.12 s, after).
    const double hd = 1920.0 * 1080.0;
    EXPECT_FALSE(s.prior_first(0, 0.060 / hd, hd));
    EXPECT_TRUE(s.prior_first(0, 0.045 / hd, hd));
    EXPECT_TRUE(s.prior_first(0.09 / hd, 0.060 / hd, hd));  // measured: 0.09 s
    EXPECT_FALSE(s.prior_first(0.11 / hd, 0.010 / hd, hd));
    EXPECT_TRUE(s.prior_first(0, 0.015 / (512.0 * 512.0), 512.0 * 512.0));
}

// The status bar's elapsed time is the wall time since the edit, not the passes' time alone:
// a job stamped as edited 2 s ago says at least 2 s in its first frame.
TEST(RenderThread, FramesCountWallTimeFromTheEdit) {
    const auto scene = small_scene(3, 24, 20);
    RenderSettings settings = RenderSettings::from_scene(scene->renderer);
    RenderWorker worker;
    RenderJob job{1, scene, settings, StopRule{1}};
    job.edited = std::chrono::steady_clock::now() - std::chrono::seconds(2);
    worker.submit(job);
    const std::shared_ptr<const Snapshot> f = finished_frame(worker);
    ASSERT_TRUE(f && f->finished);
    EXPECT_GE(f->seconds, 2.0);
    EXPECT_LT(f->full_seconds, f->seconds);  // the engine's own clock: its passes alone
    // And the status bar says it.
    ViewerSettings view;
    view.render.target_spp = 1;
    EXPECT_GE(run_status(f.get(), view, false).elapsed, 2.0);
}

TEST(RenderThread, PauseKeepsSamplesAndUnlimitedContinues) {
    Scene authored = load_scene_file(test::brief_scene_file(2)).scene;
    authored.renderer.width = authored.renderer.height = 16;
    auto scene = std::make_shared<const RenderScene>(prepare_scene(authored));
    RenderSettings settings = RenderSettings::from_scene(scene->renderer);
    settings.target_spp = 2;
    RenderWorker worker;
    worker.submit({1, scene, settings, StopRule{settings.target_spp}});
    std::shared_ptr<const Snapshot> f;
    while (!(f && f->finished)) f = worker.wait_newer(f ? f->serial : 0, std::chrono::seconds(10));
    worker.set_paused(true);
    worker.set_stop_rule(StopRule{kUnlimitedPasses});
    // Paused: nothing new (at most the pass that was running when pause came).
    const auto paused_frame = worker.wait_newer(f->serial, std::chrono::milliseconds(200));
    const auto still = worker.wait_newer(paused_frame->serial, std::chrono::milliseconds(300));
    EXPECT_EQ(still->serial, paused_frame->serial);
    worker.set_paused(false);
    const auto resumed = worker.wait_newer(still->serial, std::chrono::seconds(10));
    EXPECT_GT(resumed->spp, 2);  // kept the 2 samples and went on
    EXPECT_EQ(resumed->generation, 1u);
}

// The viewer's stop rules: with no spp cap, the noise rule stops the estimate once its
// estimated relative error is below the target (adaptively), and the time rule after its
// seconds; both like render --noise / --time.
TEST(RenderThread, NoiseAndTimeRulesStopTheEstimate) {
    Scene authored = load_scene_file(test::brief_scene_file(3)).scene;
    authored.renderer.width = authored.renderer.height = 24;
    auto scene = std::make_shared<const RenderScene>(prepare_scene(authored));
    RenderSettings settings = RenderSettings::from_scene(scene->renderer);
    settings.target_spp = 16;
    auto run_until_finished = [&](RenderWorker& worker) {
        std::shared_ptr<const Snapshot> f;
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
        while (!(f && f->finished) && std::chrono::steady_clock::now() < deadline)
            f = worker.wait_newer(f ? f->serial : 0, std::chrono::milliseconds(500));
        return f;
    };
    {
        RenderWorker worker;
        worker.submit({1, scene, settings, StopRule{kUnlimitedPasses, 0, 0.05}});
        const auto f = run_until_finished(worker);
        ASSERT_TRUE(f && f->finished);
        EXPECT_EQ(f->stopped_by, StopReason::noise);
        EXPECT_GT(f->spp, 16);  // past the (ignored) target: the rule decided
        // The whole image is within the target (every pixel within its share implies it).
        EXPECT_LE(f->relative_error, 0.05);
    }
    {
        RenderWorker worker;
        worker.submit({1, scene, settings, StopRule{kUnlimitedPasses, 0.3, 0}});
        const auto f = run_until_finished(worker);
        ASSERT_TRUE(f && f->finished);
        EXPECT_EQ(f->stopped_by, StopReason::time);
        EXPECT_GE(f->full_seconds, 0.3);
        const auto more = worker.wait_newer(f->serial, std::chrono::milliseconds(300));
        EXPECT_EQ(more->serial, f->serial);  // and stays stopped
    }
}

TEST(SceneWatch, BrokenFileKeepsTheLastGoodScene) {
    const fs::path dir = fs::temp_directory_path() / ("keithray_watch_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path file = dir / "scene.json";
    std::stringstream original;
    original << std::ifstream(test::brief_scene_file(2)).rdbuf();
    std::ofstream(file) << original.str();

    ViewerModel m;
    m.load(file);
    FileWatch watch(std::chrono::milliseconds(0));
    watch.watch(file);
    EXPECT_FALSE(watch.changed());
    const uint64_t g = m.generation();
    const Vec3 position = m.camera().position;

    std::ofstream(file) << original.str().substr(0, original.str().size() / 2);  // a half-saved file
    ASSERT_TRUE(watch.changed());
    try {
        m.load(file);
        FAIL() << "a broken file loaded";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("scene.json"), std::string::npos) << e.what();
    }
    EXPECT_EQ(m.generation(), g);
    EXPECT_TRUE(m.has_scene());
    EXPECT_EQ(m.camera().position, position);
    EXPECT_FALSE(watch.changed());  // one change, reported once

    // Fixed in the editor, with the camera moved: the new scene replaces the last good one.
    std::string fixed = original.str();
    const size_t at = fixed.find("[0, 0, -15]");
    ASSERT_NE(at, std::string::npos);
    fixed.replace(at, 11, "[0, 0, -16]");
    std::ofstream(file) << fixed;
    ASSERT_TRUE(watch.changed());
    EXPECT_NO_THROW(m.load(file));
    EXPECT_EQ(m.generation(), g + 1);
    EXPECT_EQ(m.camera().position, Vec3(0, 0, -16));
    fs::remove_all(dir);
}

// Opening a FIFO (from the Open list, a reload, the command line) would block the window
// until something writes it: the model refuses anything but a regular file, by stat alone,
// and keeps the scene it has.
TEST(SceneWatch, FifoSceneIsRefusedWithoutBlocking) {
    const fs::path dir = fs::temp_directory_path() / ("keithray_fifo_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path fifo = dir / "pipe.json";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    ViewerModel m;
    m.load(test::brief_scene_file(2));
    const uint64_t g = m.generation();
    try {
        m.load(fifo);
        ADD_FAILURE() << "a FIFO loaded";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
    }
    EXPECT_EQ(m.generation(), g);
    EXPECT_TRUE(m.has_scene());
    fs::remove_all(dir);
}
