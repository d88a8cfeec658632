// The viewer's behaviour a new user meets first, without a window: a click is not a drag,
// key motion per second, the target spp keeps the samples, the status bar's state, typed
// values apply once, undo/redo, reset view, the reload choice, the Open list, the camera
// inside a sphere. The same rules drive the window (tests/test_viewer_window.cpp).
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "render/camera.h"
#include "scene/load.h"
#include "scene/save.h"
#include "scene/scene_list.h"
#include "viewer/files.h"
#include "viewer/model.h"
#include "viewer/navigation.h"
#include "viewer/render_worker.h"
#include "viewer/scene_edit.h"
#include "viewer/status.h"
#include "viewer/ui_context.h"
#include "test_util.h"

namespace fs = std::filesystem;
using namespace kr;
using namespace kr::viewer;

namespace {

void move_camera_x(ViewerModel& m, double x, const char* group = "") {
    ASSERT_TRUE(m.edit(Edit::camera, [&](Scene& s, ViewerSettings&) { s.cameras[size_t(s.camera)].position.x = x; },
                       nullptr, "camera position", group));
}

double yaw_degrees(const Camera& c) {
    const Vec3 o = c.position - c.target;
    return std::atan2(o.x, o.z) * 180 / kPi;
}

}  // namespace

// Defect 1: a press and release with a pixel of jitter, or a pointer that jumps between
// events, never orbits.
TEST(DragGesture, JitterBelowTheThresholdIsAClick) {
    Camera cam = test::brief_model(3).camera();
    DragGesture g;
    g.press(100, 100);
    double dx = 0, dy = 0;
    EXPECT_FALSE(g.move(101, 100, cam, dx, dy));
    EXPECT_FALSE(g.move(100, 101, cam, dx, dy));
    EXPECT_FALSE(g.move(100 + kDragThresholdPixels, 100, cam, dx, dy));
    EXPECT_FALSE(g.dragging);
    g.release();
    EXPECT_FALSE(g.move(300, 300, cam, dx, dy));  // released: moving is not dragging
}

TEST(DragGesture, OffsetIsFromWhereTheDragStartedNotThePreviousEvent) {
    Camera cam = test::brief_model(3).camera();
    DragGesture g;
    g.press(100, 100);
    double dx = 1, dy = 1;
    // A pointer that jumps 200 pixels between events starts the drag there: no offset yet.
    ASSERT_TRUE(g.move(300, 100, cam, dx, dy));
    EXPECT_EQ(dx, 0);
    EXPECT_EQ(dy, 0);
    Camera moved = cam;
    moved.position.x += 5;  // the camera during the drag; the drag keeps its start camera
    ASSERT_TRUE(g.move(310, 96, moved, dx, dy));
    EXPECT_EQ(dx, 10);
    EXPECT_EQ(dy, -4);
    EXPECT_EQ(g.start_camera.position, cam.position);
    // The same position reported again is the same offset: events do not accumulate.
    ASSERT_TRUE(g.move(310, 96, moved, dx, dy));
    EXPECT_EQ(dx, 10);
    Camera a = g.start_camera, b = g.start_camera;
    orbit_drag(a, dx, dy);
    orbit_drag(b, dx, dy);
    EXPECT_EQ(a.position, b.position);
}

// Defect 10: held keys move at a rate per second, whatever the frame rate.
TEST(KeyMotion, SameMotionAtAnyFrameRate) {
    const Camera start = test::brief_model(3).camera();
    KeyMotion keys;
    keys.orbit_x = 1;
    auto held = [&](int frames, double seconds) {
        Camera c = start;
        for (int i = 0; i < frames; ++i) apply_key_motion(c, keys, seconds / frames, 512);
        return c;
    };
    const Camera at30 = held(15, 0.5), at120 = held(60, 0.5), at60 = held(30, 0.5);
    EXPECT_NEAR(length(at30.position - at120.position), 0, 1e-9);
    EXPECT_NEAR(length(at60.position - at120.position), 0, 1e-9);
    // Half a second turns kKeyOrbitDegreesPerSecond / 2 (30 degrees), not 52.
    double turned = yaw_degrees(at60) - yaw_degrees(start);
    turned = std::remainder(turned, 360.0);
    EXPECT_NEAR(std::abs(turned), kKeyOrbitDegreesPerSecond * 0.5, 1e-9);
}

// Defect 10: a camera orbited into a wall sphere is named.
TEST(CameraInside, NamesTheSphereAroundTheCamera) {
    for (int n = 1; n <= 8; ++n) {
        const ViewerModel m = test::brief_model(n);
        EXPECT_FALSE(sphere_containing(m.scene(), m.camera().position)) << "scene " << n;
    }
    const ViewerModel m = test::brief_model(3);
    const Primitive& p = m.scene().primitives[0];
    const Shape& s = m.scene().shapes[size_t(p.shape)];
    const auto inside = sphere_containing(m.scene(), s.centre);
    ASSERT_TRUE(inside);
    EXPECT_EQ(*inside, s.id);
}

// Defect 2: a new target keeps the samples; only the stratified estimator, whose strata
// depend on the target, restarts.
TEST(TargetSpp, ChangingTheTargetKeepsTheImage) {
    ViewerModel m = test::brief_model(3);
    const uint64_t g = m.generation();
    const auto prepared = m.prepared();
    ASSERT_TRUE(m.set_target_spp(65));
    EXPECT_EQ(m.generation(), g);
    EXPECT_EQ(m.prepared(), prepared);
    EXPECT_EQ(m.settings().render.target_spp, 65);
    EXPECT_EQ(m.scene_for_saving().renderer.samples, 65);
    ASSERT_TRUE(m.set_target_spp(4));
    EXPECT_EQ(m.generation(), g);
    ASSERT_TRUE(m.edit(Edit::renderer, [](Scene&, ViewerSettings& s) { s.render.estimator = Estimator::stratified; }));
    const uint64_t g2 = m.generation();
    ASSERT_TRUE(m.set_target_spp(16));
    EXPECT_EQ(m.generation(), g2 + 1);
}

TEST(TargetSpp, WorkerContinuesFromTheSamplesTaken) {
    Scene authored = load_scene_file(test::brief_scene_file(2)).scene;
    authored.renderer.width = 20;
    authored.renderer.height = 16;
    auto scene = std::make_shared<const RenderScene>(prepare_scene(authored));
    RenderSettings settings = RenderSettings::from_scene(scene->renderer);
    settings.target_spp = 2;
    RenderWorker worker;
    worker.submit({1, scene, settings, StopRule{settings.target_spp}});
    auto wait_for = [&](auto done) {
        std::shared_ptr<const Snapshot> f = worker.latest();
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
        while (!(f && done(*f)) && std::chrono::steady_clock::now() < deadline)
            f = worker.wait_newer(f ? f->serial : 0, std::chrono::milliseconds(500));
        return f;
    };
    const auto first = wait_for([](const Snapshot& s) { return s.finished; });
    ASSERT_TRUE(first && first->spp == 2);
    worker.set_stop_rule(StopRule{4});
    // Every frame after the raise is a full-resolution continuation: 3, then 4 passes.
    int last_spp = 2;
    std::shared_ptr<const Snapshot> f = first;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (!(f->finished && f->spp == 4) && std::chrono::steady_clock::now() < deadline) {
        f = worker.wait_newer(f->serial, std::chrono::milliseconds(500));
        EXPECT_EQ(f->scale, 1);
        EXPECT_EQ(f->generation, 1u);
        EXPECT_GE(f->spp, last_spp);
        last_spp = f->spp;
    }
    ASSERT_TRUE(f->finished);
    EXPECT_EQ(f->spp, 4);
    EXPECT_EQ(f->max_passes, 4);
    // The same image as four plain passes: the two first were kept, not re-rendered.
    RenderState plain(20, 16);
    for (int i = 0; i < 4; ++i) render_pass(*scene, settings, plain);
    const Image expected = plain.radiance();
    for (size_t i = 0; i < expected.pixels.size(); ++i)
        for (int k = 0; k < 3; ++k)
            ASSERT_NEAR(f->radiance.pixels[i][k], expected.pixels[i][k], 1e-12 * (1 + expected.pixels[i][k]));
    // A target below the count taken: nothing more is rendered.
    worker.set_stop_rule(StopRule{3});
    const auto more = worker.wait_newer(f->serial, std::chrono::milliseconds(300));
    EXPECT_EQ(more->serial, f->serial);
}

// Defect 3: the status bar's state and progress.
TEST(RunStatus, StateProgressAndTargetChanges) {
    ViewerSettings s;
    s.render.target_spp = 64;
    EXPECT_EQ(run_status(nullptr, s, false).state, RunState::starting);
    EXPECT_EQ(run_status(nullptr, s, true).state, RunState::error);
    // No frame of this view yet, an earlier view's on screen: the camera moves.
    EXPECT_EQ(run_status(nullptr, s, false, true).state, RunState::moving);
    EXPECT_EQ(run_status(nullptr, s, true, true).state, RunState::error);
    Snapshot f;
    f.spp = 16;
    f.full_seconds = 8;  // the passes' own time: 0.5 s a pass
    f.seconds = 8.2;     // wall time since the edit: 0.5125 s a pass, what the ETA goes by
    f.rays = 16000000;
    f.relative_error = 0.04;
    RunStatus st = run_status(&f, s, false);
    EXPECT_EQ(st.state, RunState::rendering);
    EXPECT_DOUBLE_EQ(st.progress, 0.25);
    EXPECT_DOUBLE_EQ(st.eta, 48 * 8.2 / 16);
    EXPECT_DOUBLE_EQ(st.elapsed, 8.2);
    EXPECT_DOUBLE_EQ(st.mrays_per_second, 2);  // the engine's: rays over the passes' time
    EXPECT_DOUBLE_EQ(st.noise, 0.04);
    s.paused = true;
    EXPECT_EQ(run_status(&f, s, false).state, RunState::paused);
    s.paused = false;
    // Done at 64; a raised target (65) renders on; a lowered one (below 116 done) is done.
    f.spp = 64;
    f.finished = true;
    f.stopped_by = StopReason::passes;
    EXPECT_EQ(run_status(&f, s, false).state, RunState::done);
    s.render.target_spp = 65;
    EXPECT_EQ(run_status(&f, s, false).state, RunState::rendering);
    f.spp = 116;
    f.finished = false;
    f.stopped_by.reset();
    s.render.target_spp = 64;
    EXPECT_EQ(run_status(&f, s, false).state, RunState::done);
    s.unlimited = true;
    EXPECT_EQ(run_status(&f, s, false).state, RunState::rendering);
    // The noise rule: 4% now, 2% wanted: four times the passes, 1/4 of the way.
    s.stop.noise = 0.02;
    st = run_status(&f, s, false);
    EXPECT_EQ(st.rule, "noise");
    EXPECT_DOUBLE_EQ(st.progress, 0.25);
    EXPECT_EQ(window_title("assignment_03.json", run_status(&f, s, false), true),
              "keithray - assignment_03.json (edited) - 116 spp (unlimited) - rendering");
}

// Defect 4: a typed value is applied once, on Enter or focus loss; a refused one names the
// field and keeps the previous value.
TEST(TypedValue, AppliedOnceWhenTheFieldIsLeft) {
    ViewerModel m = test::brief_model(3);
    TypedFields typed;
    const uint64_t g = m.generation();
    for (double keystroke : {-2.0, -20.0}) typed.hold(7, &keystroke, 1);  // "-2", then "-20"
    EXPECT_TRUE(typed.holding(7));
    EXPECT_EQ(m.generation(), g);  // nothing applied while typing
    const auto value = typed.take(7);
    ASSERT_TRUE(value);
    EXPECT_EQ((*value)[0], -20);
    EXPECT_FALSE(typed.take(7));
    move_camera_x(m, (*value)[0]);
    EXPECT_EQ(m.generation(), g + 1);  // one restart, for the value typed
    EXPECT_EQ(m.camera().position.x, -20);
}

TEST(TypedValue, RefusedEditNamesTheFieldAndKeepsThePreviousValue) {
    const double fov = -20;
    const auto why = check_typed_value("fov (deg)", &fov, 1, 0.5, 179.5);
    ASSERT_TRUE(why);
    EXPECT_EQ(*why, "fov (deg): -20 is below the minimum 0.5; the previous value is kept");
    const double nan = std::nan("");
    EXPECT_TRUE(check_typed_value("eta", &nan, 1, 0.25, 4));
    const double ok[3] = {0, 1, 2};
    EXPECT_FALSE(check_typed_value("position", ok, 3, -10, 10));

    ViewerModel m = test::brief_model(3);
    const Camera before = m.camera();
    std::string error;
    EXPECT_FALSE(m.edit(Edit::camera, [](Scene& s, ViewerSettings&) {
        Camera& c = s.cameras[size_t(s.camera)];
        c.position = c.target;
    }, &error, "camera position"));
    EXPECT_EQ(error.rfind("camera position: ", 0), 0u) << error;
    EXPECT_NE(error.find("previous value is kept"), std::string::npos) << error;
    EXPECT_EQ(error.find("assignment_03.json"), std::string::npos) << error;  // not the file's fault
    EXPECT_EQ(m.camera().position, before.position);
    EXPECT_FALSE(m.dirty());
    EXPECT_FALSE(m.can_undo());
}

// Defect 6: undo and redo of every scene and settings edit; one drag is one step.
TEST(UndoRedo, EditsUndoAndRedoInOrder) {
    ViewerModel m = test::brief_model(3);
    const double x0 = m.camera().position.x;
    const uint64_t g0 = m.generation();
    move_camera_x(m, 1);
    ASSERT_TRUE(m.edit(Edit::tone_map, [](Scene&, ViewerSettings& s) { s.tone.exposure = 1.5; }));
    ASSERT_TRUE(m.set_target_spp(99));
    ASSERT_TRUE(m.edit(Edit::run_control, [](Scene&, ViewerSettings& s) { s.paused = true; }));  // not a step
    EXPECT_TRUE(m.dirty());

    ASSERT_TRUE(m.undo());  // the target
    EXPECT_NE(m.settings().render.target_spp, 99);
    EXPECT_TRUE(m.settings().paused);  // pausing is left alone
    const uint64_t g = m.generation();
    ASSERT_TRUE(m.undo());  // the exposure: display only, the samples stay
    EXPECT_EQ(m.settings().tone.exposure, 0);
    EXPECT_EQ(m.generation(), g);
    ASSERT_TRUE(m.undo());  // the camera: the image restarts
    EXPECT_EQ(m.camera().position.x, x0);
    EXPECT_EQ(m.generation(), g + 1);
    EXPECT_NE(m.prepared()->camera.position.x, 1);
    EXPECT_FALSE(m.can_undo());
    EXPECT_FALSE(m.dirty());  // back to the file's state

    ASSERT_TRUE(m.redo());
    EXPECT_EQ(m.camera().position.x, 1);
    EXPECT_EQ(m.prepared()->camera.position.x, 1);
    ASSERT_TRUE(m.redo());
    EXPECT_EQ(m.settings().tone.exposure, 1.5);
    // A new edit drops the redo steps.
    move_camera_x(m, 2);
    EXPECT_FALSE(m.can_redo());
    EXPECT_GT(m.generation(), g0);
}

TEST(UndoRedo, OneDragIsOneStep) {
    ViewerModel m = test::brief_model(3);
    const double x0 = m.camera().position.x;
    for (int i = 1; i <= 10; ++i) move_camera_x(m, i, "orbit");
    m.seal_undo_step();
    for (int i = 11; i <= 12; ++i) move_camera_x(m, i, "orbit");
    ASSERT_TRUE(m.undo());
    EXPECT_EQ(m.camera().position.x, 10);
    ASSERT_TRUE(m.undo());
    EXPECT_EQ(m.camera().position.x, x0);
    EXPECT_FALSE(m.can_undo());
}

TEST(UndoRedo, ResetViewReturnsToTheFilesCamera) {
    ViewerModel m = test::brief_model(3);
    const Camera file = m.camera();
    ASSERT_TRUE(m.edit(Edit::camera, [](Scene& s, ViewerSettings&) { orbit(s.cameras[size_t(s.camera)], 20, 5); }));
    ASSERT_TRUE(m.edit(Edit::lens, [](Scene& s, ViewerSettings&) { s.cameras[size_t(s.camera)].alpha = 0.3; }));
    ASSERT_TRUE(m.edit(Edit::lens, [](Scene& s, ViewerSettings&) { s.cameras[size_t(s.camera)].type = CameraType::lens; }));
    const uint64_t g = m.generation();
    ASSERT_TRUE(m.reset_view());
    EXPECT_EQ(m.camera().position, file.position);
    EXPECT_EQ(m.camera().target, file.target);
    // Issue 34, defect 7: the view goes back, the lens the user set up stays.
    EXPECT_EQ(m.camera().alpha, 0.3);
    EXPECT_EQ(m.camera().type, CameraType::lens);
    EXPECT_EQ(m.generation(), g + 1);
    ASSERT_TRUE(m.undo());  // and it can be undone
    EXPECT_NE(m.camera().position, file.position);
}

// Defect 5: a change of the file on disk reloads at once only without unsaved edits.
TEST(ReloadChoice, AsksOnlyWithUnsavedEdits) {
    ViewerModel m = test::brief_model(3);
    EXPECT_EQ(m.on_file_changed(), WatchAction::reload);
    ASSERT_TRUE(m.edit(Edit::run_control, [](Scene&, ViewerSettings& s) { s.paused = true; }));
    EXPECT_EQ(m.on_file_changed(), WatchAction::reload);  // pausing is not an edit to keep
    // Issue 34, defect 6: a moved camera alone is the view: reloaded keeping it, never asked.
    move_camera_x(m, 3);
    EXPECT_EQ(m.on_file_changed(), WatchAction::reload_keep_view);
    auto set_depth = [&](int depth) {
        ASSERT_TRUE(m.edit(Edit::renderer, [&](Scene& s, ViewerSettings& st) {
            st.render.max_depth = depth;
            s.renderer.depth = depth;
        }));
    };
    set_depth(3);
    EXPECT_EQ(m.on_file_changed(), WatchAction::ask);
    m.mark_saved();
    EXPECT_EQ(m.on_file_changed(), WatchAction::reload);
    set_depth(4);
    ASSERT_TRUE(m.undo());
    EXPECT_EQ(m.on_file_changed(), WatchAction::reload);  // undone back to the saved state
    ASSERT_TRUE(m.redo());
    EXPECT_EQ(m.on_file_changed(), WatchAction::ask);
    // "Reload": the file's scene, no undo history, nothing unsaved.
    m.load(test::brief_scene_file(3));
    EXPECT_EQ(m.on_file_changed(), WatchAction::reload);
    EXPECT_FALSE(m.can_undo());
}

// "Take the file's changes, keep my view": the file's edit arrives, the camera stays.
TEST(ReloadChoice, TakesTheFilesChangesAndKeepsTheView) {
    const fs::path dir = fs::temp_directory_path() / ("kr-keepview-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path file = dir / "s.json";
    fs::copy_file(test::brief_scene_file(3), file, fs::copy_options::overwrite_existing);
    ViewerModel m;
    m.load(file);
    move_camera_x(m, 2.5);
    // An editor changes the depth in the file.
    Scene edited = load_scene_file(file).scene;
    edited.renderer.depth = 2;
    save_scene_json(edited, file);
    ASSERT_EQ(m.on_file_changed(), WatchAction::reload_keep_view);
    m.load_keeping_view(file);
    EXPECT_EQ(m.scene().renderer.depth, 2);
    EXPECT_EQ(m.camera().position.x, 2.5);
    EXPECT_EQ(m.on_file_changed(), WatchAction::reload_keep_view);  // the view still differs from the file
    ASSERT_TRUE(m.undo());                                          // back to the file's view
    EXPECT_EQ(m.camera().position.x, edited.cameras[size_t(edited.camera)].position.x);
    fs::remove_all(dir);
}

// Issue 34, defect 5: Save As makes the new file the scene's (saved, its output naming the
// same image from there); a copy leaves the scene's file and its unsaved state.
TEST(SaveAs, TheNewFileBecomesTheScenesAndACopyDoesNot) {
    const fs::path dir = fs::temp_directory_path() / ("kr-saveas-" + std::to_string(::getpid()));
    fs::create_directories(dir / "sub");
    ViewerModel m = test::brief_model(3);
    const fs::path source = m.scene().source_file;
    const fs::path output = fs::absolute(m.scene().output_path()).lexically_normal();
    move_camera_x(m, 1);
    m.save_scene_to(dir / "copy.json", false);
    EXPECT_TRUE(m.dirty());
    EXPECT_EQ(m.scene().source_file, source);
    EXPECT_TRUE(fs::exists(dir / "copy.json"));
    m.save_scene_to(dir / "sub" / "as.json", true);
    EXPECT_FALSE(m.dirty());
    EXPECT_EQ(m.scene().source_file, dir / "sub" / "as.json");
    EXPECT_EQ(fs::absolute(m.scene().output_path()).lexically_normal(), output);
    // Undo goes back to the camera before, still with the new file's output path.
    ASSERT_TRUE(m.undo());
    EXPECT_EQ(fs::absolute(m.scene().output_path()).lexically_normal(), output);
    EXPECT_EQ(load_scene_file(dir / "sub" / "as.json").scene.cameras[0].position.x, 1);
    fs::remove_all(dir);
}

// Issue 34, defect 9: settings given before a scene (the command line's, or with a broken
// starting scene) are no edit: nothing to undo, nothing unsaved.
TEST(BrokenStart, NoEditAndNoUndoWithoutAScene) {
    ViewerModel m;
    ASSERT_TRUE(m.edit(Edit::run_control, [](Scene&, ViewerSettings& s) { s.unlimited = true; }));
    EXPECT_FALSE(m.dirty());
    EXPECT_FALSE(m.can_undo());
    EXPECT_TRUE(m.settings().unlimited);
}

// Defect 7: the display settings come from the scene file and go back into it.
TEST(DisplaySettings, ModelTakesAndSavesTheDisplayBlock) {
    Scene scene = load_scene_file(test::brief_scene_file(3)).scene;
    scene.display.tonemap = ToneMap::linear;
    scene.display.exposure = -1.5;
    ViewerModel m;
    m.set_scene(scene);
    EXPECT_EQ(m.settings().tone.tonemap, ToneMap::linear);
    EXPECT_EQ(m.settings().tone.exposure, -1.5);
    ASSERT_TRUE(m.edit(Edit::tone_map, [](Scene&, ViewerSettings& s) { s.tone = {ToneMap::sigmoid, 2.25}; }));
    EXPECT_EQ(m.scene_for_saving().display.tonemap, ToneMap::sigmoid);
    EXPECT_EQ(m.scene_for_saving().display.exposure, 2.25);
    EXPECT_EQ(m.settings().tone.exposure_scale(), std::exp2(2.25));
    // Command-line overrides win over the file.
    RenderOptions o;
    o.exposure = 1;
    ViewerModel n;
    n.set_overrides(o);
    n.set_scene(scene);
    EXPECT_EQ(n.settings().tone.exposure, 1);
    EXPECT_EQ(n.settings().tone.tonemap, ToneMap::linear);
}

// Defect 9: one entry per scene file, however its folder is spelled.
TEST(SceneChoices, EachFileOnceWithItsFolderWhenNamesClash) {
    const fs::path dir = fs::temp_directory_path() / ("keithray_choices_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir / "a");
    fs::create_directories(dir / "b");
    for (const char* f : {"a/one.json", "a/two.json", "b/one.json"}) std::ofstream(dir / f) << "{}";
    fs::create_directory_symlink(dir / "a", dir / "link");
    const auto choices = scene_choices({dir / "a", dir / "b" / ".." / "a", dir / "link", dir / "b"});
    ASSERT_EQ(choices.size(), 3u);
    EXPECT_EQ(choices[0].path.filename(), "one.json");
    EXPECT_EQ(choices[1].label, "two.json");
    EXPECT_NE(choices[0].label.find((dir / "a").string()), std::string::npos) << choices[0].label;
    EXPECT_NE(choices[2].label.find((dir / "b").string()), std::string::npos) << choices[2].label;
    // The brief's scenes listed from the working folder and the install path: once each.
    const auto brief = scene_choices({fs::path(KEITHRAY_RES_DIR) / "scenes", fs::path(KEITHRAY_RES_DIR) / ".." / "res" / "scenes"});
    EXPECT_EQ(brief.size(), scene_choices({fs::path(KEITHRAY_RES_DIR) / "scenes"}).size());
    fs::remove_all(dir);
}

namespace {

// How many of an 8x8 grid of pinhole rays of `camera` hit a surface of `scene`.
int surfaces_seen(Scene scene, const Camera& camera) {
    scene.cameras[size_t(scene.camera)] = camera;
    const RenderScene prepared = prepare_scene(scene);
    int hits = 0;
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) hits += surface_point(prepared, (x + 0.5) / 8, (y + 0.5) / 8).has_value();
    return hits;
}

}  // namespace

// Issue 34, defect 1: the first orbit (a 120-pixel left drag, either way, about the target
// or about the surface under the pointer, the pointer reported in steps or in one jump)
// leaves the camera outside every sphere, moved, and with surfaces to see, in every brief scene.
TEST(FirstOrbit, LeavesSomethingToSeeInEveryBriefScene) {
    for (int n = 1; n <= 8; ++n) {
        const ViewerModel m = test::brief_model(n);
        const Scene& scene = m.scene();
        const Camera start = m.camera();
        const int seen_at_start = surfaces_seen(scene, start);
        std::vector<Vec3> pivots{start.target};
        if (const auto p = surface_point(*m.prepared(), 0.3, 0.45)) pivots.push_back(*p);
        for (const Vec3& pivot : pivots)
            for (const double dx : {120.0, -120.0})
                for (const int steps : {1, 12}) {
                    Camera cam = start;
                    for (int i = 1; i <= steps; ++i) cam = orbit_step(scene, start, pivot, dx * i / steps, 0, true);
                    SCOPED_TRACE("scene " + std::to_string(n) + " dx " + std::to_string(dx) + " steps " + std::to_string(steps));
                    EXPECT_FALSE(sphere_containing(scene, cam.position));
                    EXPECT_GT(length(cam.position - start.position), 0.01);
                    // At least half of what the file's camera sees (scenes 4 and 5 are open).
                    EXPECT_GE(2 * surfaces_seen(scene, cam), seen_at_start);
                }
    }
}

// Without stopping, the default scene's first orbit goes through the right wall (the defect);
// with it the camera slides along the wall, still looking at the target.
TEST(FirstOrbit, StopsAtTheWallAndKeepsLookingAtTheTarget) {
    const ViewerModel m = test::brief_model(3);
    const Camera start = m.camera();
    const Camera through = orbit_step(m.scene(), start, start.target, 120, 0, false);
    ASSERT_TRUE(sphere_containing(m.scene(), through.position));
    const Camera kept = orbit_step(m.scene(), start, start.target, 120, 0, true);
    EXPECT_FALSE(sphere_containing(m.scene(), kept.position));
    EXPECT_EQ(kept.target, start.target);
    // The same direction from the target as the free orbit, only nearer.
    const Vec3 a = (through.position - start.target) / length(through.position - start.target);
    const Vec3 b = (kept.position - start.target) / length(kept.position - start.target);
    EXPECT_NEAR(dot(a, b), 1, 1e-9);
}

// Orbiting about a picked point keeps that point where it is in the image.
TEST(FirstOrbit, PickedPivotStaysUnderThePointer) {
    const ViewerModel m = test::brief_model(3);
    const auto p = surface_point(*m.prepared(), 0.3, 0.45);
    ASSERT_TRUE(p);
    Camera cam = m.camera();
    orbit_drag(cam, 30, 10, *p);
    Scene scene = m.scene();
    scene.cameras[size_t(scene.camera)] = cam;
    const RenderScene prepared = prepare_scene(scene);
    // The pivot projects to the same image point: its direction from the camera is the ray's there.
    const CameraRay ray = prepared.camera.generate(0.3, 0.45, 0.5, 0.5);
    const Vec3 to_p = (*p - cam.position) / length(*p - cam.position);
    EXPECT_NEAR(dot(ray.direction, to_p), 1, 1e-9);
}

// Holding W (dolly in) for 3 s, or flying forward, stops at the surface in the way; fly
// mode's keys move position and target together at the speed setting.
TEST(FlyMode, KeysStopAtSurfacesAndFollowTheSpeed) {
    const ViewerModel m = test::brief_model(3);
    const Scene& scene = m.scene();
    for (const bool fly_mode : {false, true}) {
        NavigationSettings nav;
        nav.fly = fly_mode;
        nav.speed = 4;
        KeyMotion keys;
        keys.dolly = -1;  // W
        Camera cam = m.camera();
        for (int i = 0; i < 180; ++i) {
            const Camera before = cam;
            apply_key_motion(cam, keys, 1.0 / 60, 512, nav);
            keep_outside(scene, before, cam);
        }
        EXPECT_FALSE(sphere_containing(scene, cam.position)) << fly_mode;
        EXPECT_GE(surfaces_seen(scene, cam), 32) << fly_mode;
    }
    NavigationSettings nav;
    nav.fly = true;
    KeyMotion keys;
    keys.pan_x = -1;  // D: to the right
    const Camera start = m.camera();
    Camera slow = start, fast = start;
    apply_key_motion(slow, keys, 0.1, 512, nav);
    nav.speed = 2;
    apply_key_motion(fast, keys, 0.1, 512, nav);
    EXPECT_NEAR(length(fast.position - start.position), 2 * length(slow.position - start.position), 1e-9);
    EXPECT_GT(slow.position.x, start.position.x);  // +x is the right of the file's camera
    EXPECT_EQ(slow.target - slow.position, start.target - start.position);
}

// Issue 34, defect 4: a message expires (the status sooner than an error), and an error
// stays while there is no scene to show (it is the state then).
TEST(Messages, ExpireAndClear) {
    Messages msg;
    const auto t0 = UiClock::now();
    msg.show_status("saved x", t0);
    msg.show_error("bad value", t0);
    EXPECT_FALSE(msg.expire(t0 + std::chrono::seconds(1)));
    EXPECT_TRUE(msg.expire(t0 + std::chrono::seconds(int(Messages::kStatusSeconds) + 1)));
    EXPECT_TRUE(msg.status.empty());
    EXPECT_EQ(msg.error, "bad value");
    msg.error_sticks = true;
    EXPECT_FALSE(msg.expire(t0 + std::chrono::seconds(int(Messages::kErrorSeconds) + 1)));
    msg.error_sticks = false;
    EXPECT_TRUE(msg.expire(t0 + std::chrono::seconds(int(Messages::kErrorSeconds) + 1)));
    EXPECT_TRUE(msg.error.empty());
    msg.show_status("kept your edits", t0);
    msg.clear();  // a scene opened or reloaded
    EXPECT_TRUE(msg.status.empty());
}

// Missing item 1: every light of the file can be turned on and off, scene 3's point light
// (not in its scene block) included; the scene still prepares, and with the light.
TEST(SceneEdit, LightsOnAndOff) {
    ViewerModel m = test::brief_model(3);
    const Scene& s = m.scene();
    ASSERT_GT(s.lights.size(), s.active_lights.size());
    const size_t point_lights = test::lights_of(*m.prepared(), LightType::point).size();
    int off = -1;
    for (int i = 0; i < int(s.lights.size()); ++i)
        if (std::find(s.active_lights.begin(), s.active_lights.end(), i) == s.active_lights.end()) off = i;
    ASSERT_GE(off, 0);
    ASSERT_EQ(s.lights[size_t(off)].type, LightType::point);
    ASSERT_TRUE(m.edit(Edit::light, [&](Scene& sc, ViewerSettings&) { set_light_on(sc, off, true); }));
    EXPECT_EQ(test::lights_of(*m.prepared(), LightType::point).size(), point_lights + 1);
    ASSERT_TRUE(m.edit(Edit::light, [&](Scene& sc, ViewerSettings&) { set_light_on(sc, off, false); }));
    EXPECT_EQ(test::lights_of(*m.prepared(), LightType::point).size(), point_lights);
    // Every light off, one at a time: the scene still prepares.
    for (int i = 0; i < int(s.lights.size()); ++i) {
        ViewerModel each = test::brief_model(3);
        EXPECT_TRUE(each.edit(Edit::light, [&](Scene& sc, ViewerSettings&) { set_light_on(sc, i, false); })) << i;
    }
}

// Missing item 5: the example scenes ship in res/scenes/examples, which the Open list shows;
// each loads and prepares; many_spheres is scene 3 with a second area light, a purple
// Fresnel sphere and the lens camera active; furnace is a diffuse sphere inside a spherical
// area light that holds the camera.
TEST(ExampleScenes, ShippedListedAndWhatTheBriefSays) {
    std::vector<std::string> names;
    for (const fs::path& p : example_scenes()) {
        names.push_back(p.stem().string());
        ViewerModel m;
        ASSERT_NO_THROW(m.load(p)) << p;
        EXPECT_TRUE(m.has_scene()) << p;
    }
    for (const char* want : {"many_spheres", "furnace", "gallery_100"})
        EXPECT_NE(std::find(names.begin(), names.end(), want), names.end()) << want;
    const fs::path dir = example_scenes().front().parent_path();
    const Scene many = load_scene_file(dir / "many_spheres.json").scene;
    const Scene three = load_scene_file(test::brief_scene_file(3)).scene;
    EXPECT_EQ(many.cameras[size_t(many.camera)].type, CameraType::lens);
    EXPECT_EQ(many.active_lights.size(), three.active_lights.size() + 1);
    EXPECT_EQ(many.primitives.size(), three.primitives.size() + 2);
    bool purple_fresnel = false;
    for (const Primitive& p : many.primitives) {
        const Material& mat = many.materials[size_t(p.material)];
        purple_fresnel |= mat.type == MaterialType::dielectric && mat.rho_t.z > mat.rho_t.y && mat.rho_t.x > mat.rho_t.y;
    }
    EXPECT_TRUE(purple_fresnel);
    const Scene furnace = load_scene_file(dir / "furnace.json").scene;
    ASSERT_EQ(furnace.active_lights.size(), 1u);
    const Light& sky = furnace.lights[size_t(furnace.active_lights[0])];
    ASSERT_EQ(sky.type, LightType::area);
    const Shape& shell = furnace.shapes[size_t(sky.shape)];
    const auto inside = sphere_containing(furnace, furnace.cameras[size_t(furnace.camera)].position);
    ASSERT_TRUE(inside);
    EXPECT_EQ(*inside, shell.id);
}

namespace {

int primitive_named(const Scene& s, const std::string& id) {
    for (size_t i = 0; i < s.primitives.size(); ++i)
        if (s.primitives[i].id == id) return int(i);
    return -1;
}

}  // namespace

// Missing item 1: a click picks the primitive under the pointer; the highlight circle is
// where the sphere shows; a drag moves it in the view plane (or along one axis) under the pointer.
TEST(SceneEdit, PickProjectAndDrag) {
    const ViewerModel m = test::brief_model(3);
    const Scene& s = m.scene();
    const CameraModel& cam = m.prepared()->camera;
    const int ball = primitive_named(s, "sphere 01");
    ASSERT_GE(ball, 0);
    const Shape& shape = s.shapes[size_t(s.primitives[size_t(ball)].shape)];
    const auto c = project_sphere(cam, shape.centre, shape.radius);
    ASSERT_TRUE(c);
    // The ray through the projected centre goes through the centre; a click there picks it.
    const CameraRay ray = cam.generate(c->fx, c->fy, 0.5, 0.5);
    EXPECT_NEAR(dot(ray.direction, (shape.centre - cam.position) / length(shape.centre - cam.position)), 1, 1e-12);
    EXPECT_EQ(pick_primitive(s, cam, c->fx, c->fy), ball);
    const double aspect = cam.aspect;
    // The outline: just inside each of its points the click picks the sphere, just outside not.
    const auto outline = sphere_outline(cam, shape.centre, shape.radius, 24);
    ASSERT_EQ(outline.size(), 24u);
    for (const auto& point : outline) {
        const double ox = point.first, oy = point.second;  // named, not bound: lambdas capture them
        auto at = [&](double k) { return pick_primitive(s, cam, c->fx + k * (ox - c->fx), c->fy + k * (oy - c->fy)); };
        EXPECT_EQ(at(0.98), ball);
        EXPECT_NE(at(1.02), ball);
    }
    // A drag of 40 pixels right at 512 pixels high moves the centre's image point 40 pixels.
    const Vec3 moved = shape.centre + drag_offset(cam, shape.centre, 40, -10, 512, -1);
    const auto c2 = project_sphere(cam, moved, shape.radius);
    ASSERT_TRUE(c2);
    EXPECT_NEAR((c2->fx - c->fx) * 512 * aspect, 40, 1e-6);
    EXPECT_NEAR((c2->fy - c->fy) * 512, -10, 1e-6);
    // Locked to y: only y changes.
    const Vec3 up = drag_offset(cam, shape.centre, 40, -10, 512, 1);
    EXPECT_EQ(up.x, 0);
    EXPECT_EQ(up.z, 0);
    EXPECT_GT(up.y, 0);
}

// Duplicate, delete, add, new material, make emissive: each one undoable step; the edited
// scene saves and loads back to what was shown, and prepares.
TEST(SceneEdit, DuplicateDeleteAddMaterialEmissiveUndoAndSave) {
    ViewerModel m = test::brief_model(3);
    const Scene before = m.scene();
    const int ball = primitive_named(before, "sphere 01");
    int copy = -1;
    ASSERT_TRUE(m.edit(Edit::object, [&](Scene& s, ViewerSettings&) { copy = duplicate_primitive(s, ball, Vec3(0, 0, 2)); }));
    EXPECT_EQ(m.scene().primitives.size(), before.primitives.size() + 1);
    EXPECT_EQ(m.prepared()->spheres.size(), m.scene().primitives.size());
    const Shape& moved = m.scene().shapes[size_t(m.scene().primitives[size_t(copy)].shape)];
    EXPECT_EQ(moved.centre, before.shapes[size_t(before.primitives[size_t(ball)].shape)].centre + Vec3(0, 0, 2));
    ASSERT_TRUE(m.edit(Edit::object, [&](Scene& s, ViewerSettings&) { new_material_for(s, copy); }));
    ASSERT_TRUE(m.edit(Edit::object, [&](Scene& s, ViewerSettings&) { set_emissive(s, copy, true, Color(3)); }));
    EXPECT_EQ(test::lights_of(*m.prepared(), LightType::area).size(), 2u);
    int added = -1;
    ASSERT_TRUE(m.edit(Edit::object, [&](Scene& s, ViewerSettings&) { added = add_sphere(s, Vec3(0, -4, 3), 0.7); }));
    ASSERT_TRUE(m.edit(Edit::object, [&](Scene& s, ViewerSettings&) { own_shape(s, added).radius = 0.9; }));
    ASSERT_TRUE(m.edit(Edit::object, [&](Scene& s, ViewerSettings&) { delete_primitive(s, ball); }));
    EXPECT_EQ(primitive_named(m.scene(), "sphere 01"), -1);
    // Saved and loaded: the same scene block.
    const fs::path file = fs::temp_directory_path() / ("kr-edit-" + std::to_string(::getpid()) + ".json");
    save_scene_json(m.scene_for_saving(), file);
    const Scene back = load_scene_file(file).scene;
    EXPECT_EQ(scene_to_json(back), scene_to_json(scene_moved_to(m.scene_for_saving(), file)));
    EXPECT_EQ(back.primitives.size(), before.primitives.size() + 1);
    fs::remove(file);
    // Six steps back: the file's scene.
    for (int i = 0; i < 6; ++i) ASSERT_TRUE(m.undo()) << i;
    EXPECT_EQ(scene_to_json(m.scene()), scene_to_json(before));
    EXPECT_FALSE(m.dirty());
}

// Issue 34, defect 2: the render resolution is set in the viewer (a scale of the file's, or
// the window's size with the camera's aspect following), an undoable edit that restarts the
// image; the reference's figures apply only to the file's view and resolution.
TEST(Resolution, ScaleOfTheFilesOrTheWindowsSize) {
    ViewerModel m = test::brief_model(3);
    EXPECT_TRUE(m.view_as_loaded());
    const auto [w, h] = m.file_resolution();
    const uint64_t g = m.generation();
    ASSERT_TRUE(m.set_resolution(w / 2, h / 2, false));
    EXPECT_EQ(m.scene().renderer.width, w / 2);
    EXPECT_EQ(m.prepared()->renderer.width, w / 2);  // what the render thread renders
    EXPECT_EQ(m.generation(), g + 1);
    EXPECT_FALSE(m.view_as_loaded());
    ASSERT_TRUE(m.set_resolution(880, 650, true));
    EXPECT_DOUBLE_EQ(m.camera().aspect, 880.0 / 650);
    ASSERT_TRUE(m.undo());
    ASSERT_TRUE(m.undo());
    EXPECT_EQ(m.scene().renderer.width, w);
    EXPECT_TRUE(m.view_as_loaded());
    move_camera_x(m, 1);
    EXPECT_FALSE(m.view_as_loaded());
}

// Missing item 2: camera bookmarks are cameras of the file's list ("bookmark N"), outside
// the scene block: storing one keeps the image and is undoable, recalling puts its view on
// the active camera (the lens stays), and they survive a save and load.
TEST(Bookmarks, StoreRecallUndoAndSaveWithTheCameras) {
    ViewerModel m = test::brief_model(3);
    const Scene before = m.scene();
    const Camera file_camera = m.camera();
    EXPECT_EQ(find_bookmark(m.scene(), 2), -1);
    Scene unmarked = before;
    EXPECT_FALSE(recall_bookmark(unmarked, 2));
    move_camera_x(m, 3);
    const Camera moved = m.camera();
    const uint64_t generation = m.generation();
    ASSERT_TRUE(m.edit(Edit::bookmark, [](Scene& s, ViewerSettings&) { store_bookmark(s, 2); }));
    EXPECT_EQ(m.generation(), generation);  // the image keeps its samples
    ASSERT_EQ(m.scene().cameras.size(), before.cameras.size() + 1);
    EXPECT_EQ(m.scene().cameras[size_t(find_bookmark(m.scene(), 2))].id, "bookmark 2");
    EXPECT_TRUE(m.dirty());
    // Storing again replaces it.
    ASSERT_TRUE(m.edit(Edit::bookmark, [](Scene& s, ViewerSettings&) { store_bookmark(s, 2); }));
    EXPECT_EQ(m.scene().cameras.size(), before.cameras.size() + 1);
    // Back to the file's view, a lens opened, then the bookmark recalled: its view, our lens.
    ASSERT_TRUE(m.reset_view());
    ASSERT_TRUE(m.edit(Edit::lens, [](Scene& s, ViewerSettings&) {
        s.cameras[size_t(s.camera)].type = CameraType::lens;
        s.cameras[size_t(s.camera)].alpha = 0.2;
    }));
    ASSERT_TRUE(m.edit(Edit::camera, [](Scene& s, ViewerSettings&) { EXPECT_TRUE(recall_bookmark(s, 2)); }));
    EXPECT_EQ(m.camera().position, moved.position);
    EXPECT_EQ(m.camera().target, moved.target);
    EXPECT_EQ(m.camera().type, CameraType::lens);
    EXPECT_EQ(m.camera().alpha, 0.2);
    // Saved and loaded: the bookmark is in the cameras list, the scene block's camera unchanged.
    const fs::path file = fs::temp_directory_path() / ("kr-bookmark-" + std::to_string(::getpid()) + ".json");
    save_scene_json(m.scene_for_saving(), file);
    Scene back = load_scene_file(file).scene;
    fs::remove(file);
    ASSERT_GE(find_bookmark(back, 2), 0);
    EXPECT_EQ(back.cameras[size_t(back.camera)].id, file_camera.id);
    EXPECT_EQ(back.cameras[size_t(find_bookmark(back, 2))].position, moved.position);
    ASSERT_TRUE(recall_bookmark(back, 2));
    EXPECT_EQ(back.cameras[size_t(back.camera)].position, moved.position);
    // Undone step by step: the file's scene, no bookmark.
    while (m.can_undo()) ASSERT_TRUE(m.undo());
    EXPECT_EQ(scene_to_json(m.scene()), scene_to_json(before));
    EXPECT_EQ(find_bookmark(m.scene(), 2), -1);
}

// Missing item 3: a light's power is shown as a colour (largest component 1) times a
// strength; joining them gives the file's power back.
TEST(LightColour, PowerIsColourTimesStrength) {
    for (const Color power : {Color(12, 6, 3), Color(0.5), Color(0, 2, 0), Color(0)}) {
        const ColourStrength cs = split_power(power);
        EXPECT_DOUBLE_EQ(std::max({cs.colour.x, cs.colour.y, cs.colour.z}), 1.0);
        const Color back = join_power(cs);
        EXPECT_NEAR(back.x, power.x, 1e-12);
        EXPECT_NEAR(back.y, power.y, 1e-12);
        EXPECT_NEAR(back.z, power.z, 1e-12);
    }
    EXPECT_EQ(split_power(Color(12, 6, 3)).strength, 12);
    EXPECT_EQ(split_power(Color(12, 6, 3)).colour, Color(1, 0.5, 0.25));
    // A new strength keeps the colour: twice the strength, twice the power.
    ColourStrength cs = split_power(Color(12, 6, 3));
    cs.strength *= 2;
    EXPECT_EQ(join_power(cs), Color(24, 12, 6));
}
