// Issue 47 B1, B4-B6 and C (the outliner, the selection's properties, the views): the panels,
// the status bar and the files, at the model (GL-free).
// A light switched off emits nothing (in the render, in the saved file, in `keithray render`
// of it); a light that cannot be seen says why; an edit that leaves the image as it was keeps
// its samples; colours are written as the decimals the user picked; the status bar's fields
// give way by priority; bundled scenes are never saved over.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <string>

#include "core/data_dir.h"
#include "core/image_hdr.h"
#include "render/progressive.h"
#include "render/render_state.h"
#include "scene/load.h"
#include "scene/save.h"
#include "scene/scene_list.h"
#include "test_util.h"
#include "viewer/compare_view.h"
#include "viewer/edit.h"
#include "viewer/inspect.h"
#include "viewer/model.h"
#include "viewer/outliner.h"
#include "viewer/render_worker.h"
#include "viewer/save_dialog.h"
#include "viewer/scene_edit.h"
#include "viewer/status.h"
#include "viewer/ui_panels.h"  // the panel list and its tabs (a header: no GL)

namespace kr {
namespace {

namespace fs = std::filesystem;
using viewer::Edit;
using viewer::ViewerModel;
using viewer::ViewerSettings;

int light_named(const Scene& s, const std::string& id) {
    for (size_t i = 0; i < s.lights.size(); ++i)
        if (s.lights[i].id == id) return int(i);
    return -1;
}

int primitive_named(const Scene& s, const std::string& id) {
    for (size_t i = 0; i < s.primitives.size(); ++i)
        if (s.primitives[i].id == id) return int(i);
    return -1;
}

// The largest radiance component of `passes` passes of `scene` at its own (small) size.
double brightest(const RenderScene& scene, int passes) {
    RenderSettings settings = RenderSettings::from_scene(scene.renderer);
    settings.target_spp = passes;
    RenderState state(scene.renderer.width, scene.renderer.height);
    const StopRule rule{passes};
    ProgressiveDriver driver(scene, settings, state, rule);
    for (int i = 0; i < passes; ++i) EXPECT_TRUE(driver.pass(rule));
    double most = 0;
    for (const Color& c : state.radiance().pixels) most = std::max({most, c.x, c.y, c.z});
    return most;
}

fs::path temp_path(const std::string& name) {
    return fs::temp_directory_path() / ("kr-panels-" + std::to_string(::getpid()) + "-" + name);
}

// B1: unchecking scene 3's area light turns it off: its sphere neither glows nor lights the
// room (scene 3 has no other light: the image is black), the saved file keeps it off, and
// `keithray render` of that file renders black too. No warning says it "emits anyway".
TEST(LightsPanel, AnAreaLightSwitchedOffEmitsNothingInTheRenderTheFileAndTheCli) {
    ViewerModel m;
    Scene small = test::brief_scene(3, 12);
    small.source_file = test::brief_scene_file(3);
    m.set_scene(small);
    const int area = light_named(m.scene(), "area light");
    ASSERT_GE(area, 0);
    ASSERT_EQ(test::lights_of(*m.prepared(), LightType::area).size(), 1u);
    EXPECT_GT(brightest(*m.prepared(), 2), 0.1);
    ASSERT_TRUE(m.edit(Edit::light, [&](Scene& s, ViewerSettings&) { viewer::set_light_on(s, area, false); }));
    EXPECT_TRUE(m.prepared()->lights.empty());
    for (int l : m.prepared()->sphere_light) EXPECT_EQ(l, -1);
    EXPECT_EQ(brightest(*m.prepared(), 2), 0.0);
    for (const std::string& w : m.warnings()) EXPECT_EQ(w.find("emits anyway"), std::string::npos) << w;
    // Saved: the scene block lists no light, the primitive stays emissive (on again by one
    // checkbox), and the file renders black from the command line.
    const fs::path file = temp_path("off.json");
    const fs::path image = temp_path("off.pfm");
    save_scene_json(m.scene_for_saving(), file);
    const LoadedScene loaded = load_scene_file(file);
    EXPECT_TRUE(loaded.scene.active_lights.empty());
    const int carrier = primitive_named(loaded.scene, "area light");
    ASSERT_GE(carrier, 0);
    EXPECT_EQ(loaded.scene.primitives[size_t(carrier)].type, PrimitiveType::emissive);
    EXPECT_TRUE(prepare_scene(loaded.scene).lights.empty());
    const test::CommandResult r = test::run_command(
        std::string("'") + KEITHRAY_EXE + "' render '" + file.string() + "' --spp 2 -q -o '" + image.string() + "'",
        fs::temp_directory_path());
    ASSERT_EQ(r.status, 0) << r.err;
    const HdrImage pfm = read_hdr(image);
    ASSERT_EQ(pfm.rgb.size(), size_t(3 * 12 * 12));
    EXPECT_EQ(*std::max_element(pfm.rgb.begin(), pfm.rgb.end()), 0.0f);
    fs::remove(file);
    fs::remove(image);
    fs::remove(fs::path(image).replace_filename(image.stem().string() + "-depth.pfm"));
    // On again: it lights the room as before.
    ASSERT_TRUE(m.edit(Edit::light, [&](Scene& s, ViewerSettings&) { viewer::set_light_on(s, area, true); }));
    EXPECT_EQ(test::lights_of(*m.prepared(), LightType::area).size(), 1u);
}

// B1: a light that cannot be seen says why: scene 3's point light sits inside the area
// light's sphere (the camera outside it); a light of power 0 emits nothing; a visible light
// says nothing.
TEST(LightsPanel, ALightThatCannotBeSeenSaysWhy) {
    Scene s = test::brief_scene(3, 8);
    const int point = light_named(s, "point light"), area = light_named(s, "area light");
    ASSERT_GE(point, 0);
    const std::string why = viewer::light_unseen_reason(s, point);
    EXPECT_NE(why.find("inside the sphere of \"area light\""), std::string::npos) << why;
    EXPECT_TRUE(viewer::light_unseen_reason(s, area).empty()) << viewer::light_unseen_reason(s, area);
    // Moved out of the sphere, into the room: seen.
    s.lights[size_t(point)].position = Vec3(0, -1, -3);
    EXPECT_TRUE(viewer::light_unseen_reason(s, point).empty()) << viewer::light_unseen_reason(s, point);
    s.lights[size_t(point)].power = Color(0);
    EXPECT_NE(viewer::light_unseen_reason(s, point).find("power is 0"), std::string::npos);
    // The camera inside the same sphere as the light: it sees what the light lights.
    s.lights[size_t(point)].power = Color(300);
    s.lights[size_t(point)].position = Vec3(0, 1, -1);
    s.cameras[size_t(s.camera)].position = Vec3(0, 1.2, -1.3);
    s.cameras[size_t(s.camera)].target = Vec3(0, 1, 0);
    EXPECT_TRUE(viewer::light_unseen_reason(s, point).empty()) << viewer::light_unseen_reason(s, point);
}

// B5: edits that leave what the render sees as it was keep the samples: "New material" (a
// copy under a new id), click-to-focus with the aperture closed, their undo; a change of the
// new material's colour then restarts.
TEST(ResetRule, AnEditThatLeavesTheImageAsItWasKeepsTheSamples) {
    ViewerModel m = test::brief_model(3);
    const int ball = primitive_named(m.scene(), "sphere 01");
    ASSERT_GE(ball, 0);
    const uint64_t g = m.generation();
    const size_t materials = m.scene().materials.size();
    ASSERT_TRUE(m.edit(Edit::object, [&](Scene& s, ViewerSettings&) { viewer::new_material_for(s, ball); }));
    EXPECT_EQ(m.scene().materials.size(), materials + 1);
    EXPECT_EQ(m.generation(), g);
    EXPECT_TRUE(m.dirty());  // the file changes, the image does not
    const int copy = m.scene().primitives[size_t(ball)].material;
    ASSERT_TRUE(m.edit(Edit::material, [&](Scene& s, ViewerSettings&) { s.materials[size_t(copy)].rho_t = Color(0.5); }));
    EXPECT_EQ(m.generation(), g + 1);
    ASSERT_TRUE(m.undo());
    EXPECT_EQ(m.generation(), g + 2);  // back to the first colour: the image changes again
    ASSERT_TRUE(m.undo());
    EXPECT_EQ(m.generation(), g + 2);  // the new material undone: the same image
    EXPECT_EQ(m.scene().materials.size(), materials);
    // An edit that changes nothing (a drag held still repeats its step each frame) is no
    // undo step and no unsaved edit.
    const bool dirty = m.dirty(), could_undo = m.can_undo();
    ASSERT_TRUE(m.edit(Edit::camera, [](Scene& s, ViewerSettings&) { s.cameras[size_t(s.camera)].fov += 0; }));
    ASSERT_TRUE(m.edit(Edit::object, [&](Scene& s, ViewerSettings&) { viewer::own_shape(s, ball).radius += 0; }));
    EXPECT_EQ(m.generation(), g + 2);
    EXPECT_EQ(m.dirty(), dirty);
    EXPECT_EQ(m.can_undo(), could_undo);
    // The render settings are part of the image: a renderer edit always restarts.
    ASSERT_TRUE(m.edit(Edit::renderer, [](Scene&, ViewerSettings& st) { st.render.seed += 1; }));
    EXPECT_EQ(m.generation(), g + 3);
    // renders_same sees a lens's focal distance only where the lens is open.
    RenderScene a = *m.prepared(), b = a;
    b.camera.focal_distance += 1;
    EXPECT_TRUE(renders_same(a, b));
    a.camera.lens_radius = b.camera.lens_radius = 0.1;
    EXPECT_FALSE(renders_same(a, b));
    b = a;
    b.materials[0].id = "another name";
    EXPECT_TRUE(renders_same(a, b));
    b.materials[0].roughness += 0.1;
    EXPECT_FALSE(renders_same(a, b));
}

// B5: the colour picker holds floats; the scene gets the shortest decimal of the float picked
// (0.9, not 0.8999999761581421), a component left alone keeps its value, and colour x
// strength has no double noise either. The saved JSON says 0.9.
TEST(ColourPicker, WritesTheDecimalPickedNotFloatNoise) {
    EXPECT_EQ(viewer::shortest_decimal(0.9f), 0.9);
    EXPECT_EQ(viewer::shortest_decimal(0.1f), 0.1);
    EXPECT_EQ(viewer::shortest_decimal(1.0f), 1.0);
    const float rgb[3] = {0.9f, float(0.123456789), 0.25f};
    const Color c = viewer::picked_colour(Color(0.5, 0.123456789, 0.25), rgb);
    EXPECT_EQ(c.x, 0.9);
    EXPECT_EQ(c.y, 0.123456789);  // untouched by the picker: as it was
    EXPECT_EQ(c.z, 0.25);
    EXPECT_EQ(viewer::join_power({Color(1, 0.9, 0.7), 30}), Color(30, 27, 21));
    ViewerModel m = test::brief_model(3);
    ASSERT_TRUE(m.edit(Edit::material, [&](Scene& s, ViewerSettings&) { s.materials[0].rho = c; }));
    const std::string json = scene_to_json(m.scene_for_saving());
    EXPECT_NE(json.find("0.9"), std::string::npos);
    EXPECT_EQ(json.find("0.89999"), std::string::npos) << json;
}

// B5: Add sphere at scene 3's target would overlap the area light's sphere: it goes nearer on
// the line of sight, clear of every sphere and light; where the target is free, there.
TEST(AddSphere, NeverInsideAnotherSphereOrOverALight) {
    const Scene s = test::brief_scene(3, 8);
    const Camera& cam = s.cameras[size_t(s.camera)];
    const double radius = 0.05 * length(cam.target - cam.position);
    const viewer::SpherePlace at = viewer::free_sphere_place(s, cam.position, cam.target, radius);
    EXPECT_GE(at.radius, 0.25 * radius);
    for (const Primitive& p : s.primitives) {
        const Shape& shape = s.shapes[size_t(p.shape)];
        EXPECT_GT(length(at.centre - shape.centre), shape.radius + at.radius) << p.id;
    }
    for (const Light& l : s.lights)
        if (l.type == LightType::point) EXPECT_GT(length(at.centre - l.position), at.radius) << l.id;
    // A free target: the sphere goes there, as asked.
    const Vec3 free_target(-2, -1, -6);
    const viewer::SpherePlace there = viewer::free_sphere_place(s, cam.position, free_target, 0.3);
    EXPECT_EQ(there.centre, free_target);
    EXPECT_EQ(there.radius, 0.3);
}

// B5: names as the panels show them: no "sphere 01: sphere sphere 01"; a camera's type
// beside an id that is another type's name; a light's type where its id does not say it.
TEST(PanelLabels, SayEachThingOnce) {
    Scene s = test::brief_scene(3, 8);
    const int ball = primitive_named(s, "sphere 01");
    EXPECT_EQ(viewer::primitive_label(s, ball), "sphere 01");
    EXPECT_EQ(viewer::primitive_label(s, primitive_named(s, "area light")), "area light, emissive");
    s.shapes[size_t(s.primitives[size_t(ball)].shape)].id = "ball";
    EXPECT_EQ(viewer::primitive_label(s, ball), "sphere 01 (shape ball)");
    Light lamp;
    lamp.id = "lamp";
    lamp.type = LightType::area;
    EXPECT_EQ(viewer::light_label(lamp), "lamp (area light)");
    lamp.id = "area light 02";
    EXPECT_EQ(viewer::light_label(lamp), "area light 02");
    // Click-to-focus names the distance, and with the aperture closed, how to see it.
    Camera cam = s.cameras[size_t(s.camera)];
    cam.alpha = 0;
    cam.focal_distance = 12.5;
    EXPECT_NE(viewer::focus_message(cam).find("12.5"), std::string::npos);
    EXPECT_NE(viewer::focus_message(cam).find("open it"), std::string::npos);
}

// B5: equal images say "identical", not "99.00 dB".
TEST(CompareFigures, IdenticalImagesSayIdentical) {
    Rgb8Image a;
    a.width = 2;
    a.height = 1;
    a.bytes = {10, 20, 30, 40, 50, 60};
    const auto same = viewer::compare_figures(a, a);
    ASSERT_TRUE(same);
    EXPECT_TRUE(same->identical);
    EXPECT_EQ(same->rmse, 0);
    EXPECT_EQ(viewer::format_psnr(*same), "identical");
    Rgb8Image b = a;
    b.bytes[0] = 11;
    const auto near = viewer::compare_figures(a, b);
    ASSERT_TRUE(near);
    EXPECT_FALSE(near->identical);
    EXPECT_NE(viewer::format_psnr(*near).find(" dB"), std::string::npos);
}

// B5: the status bar's fields give way by priority: all at the default width; at 640 px the
// rate and the progress bar go (the elapsed time still fits), and the state, spp, noise and
// PSNR stay.
TEST(StatusBar, FieldsGiveWayByPriorityAndTheFiguresStay) {
    // Widths as the default font measures them (7 px a character), as draw_status_bar lays them.
    const std::vector<viewer::StatusField> fields = {{63, 0}, {168, 0}, {142, 2}, {42, 3}, {112, 4}, {126, 1}, {98, 1}};
    const double spacing = 16;
    const std::vector<bool> wide = viewer::fit_status_fields(fields, 1100, spacing);
    EXPECT_EQ(std::count(wide.begin(), wide.end(), true), 7);
    const std::vector<bool> small = viewer::fit_status_fields(fields, 640 - 16, spacing);
    EXPECT_EQ(small, (std::vector<bool>{true, true, false, true, false, true, true}));
    double used = -spacing;
    for (size_t i = 0; i < fields.size(); ++i)
        if (small[i]) used += fields[i].width + spacing;
    EXPECT_LE(used, 640 - 16);
    // Narrower than the essentials: those stay (clipped), the rest go.
    const std::vector<bool> tiny = viewer::fit_status_fields(fields, 100, spacing);
    EXPECT_EQ(tiny, (std::vector<bool>{true, true, false, false, false, false, false}));
}

// B5: a pixel readout of a frame of an earlier view (right after an orbit) gives no figures
// of that view; it says this view's frame is coming.
TEST(PixelReadout, OfAnEarlierViewGivesNoFigures) {
    viewer::PixelProbe p;
    p.x = 3;
    p.y = 4;
    p.samples = 17;
    p.standard_error = 0.01;
    EXPECT_NE(viewer::probe_line(p).find("17 samples"), std::string::npos);
    p.earlier_view = true;
    const std::string line = viewer::probe_line(p);
    EXPECT_EQ(line.find("samples"), std::string::npos) << line;
    EXPECT_EQ(line.find("radiance"), std::string::npos) << line;
    EXPECT_NE(line.find("earlier view"), std::string::npos) << line;
}

// B5: a pause never freezes a preview: paused before the job came, the worker skips the
// previews and publishes one full-resolution frame of one pass, then holds.
TEST(RenderThread, APauseBeforeTheFirstFullFrameStillBringsOne) {
    Scene authored = test::brief_scene(3, 48);
    auto scene = std::make_shared<const RenderScene>(prepare_scene(authored));
    RenderSettings settings = RenderSettings::from_scene(scene->renderer);
    settings.target_spp = 64;
    viewer::RenderWorker worker;
    worker.set_paused(true);
    worker.submit({1, scene, settings, StopRule{settings.target_spp}});
    std::shared_ptr<const viewer::Snapshot> f;
    while (!f) f = worker.wait_newer(0, std::chrono::seconds(10));
    EXPECT_EQ(f->generation, 1u);
    EXPECT_EQ(f->scale, 1);  // full resolution, not a preview
    EXPECT_EQ(f->spp, 1);    // one pass, then the pause holds
    EXPECT_FALSE(f->finished);
    worker.set_paused(false);
    std::shared_ptr<const viewer::Snapshot> later = worker.wait_newer(f->serial, std::chrono::seconds(30));
    ASSERT_TRUE(later);
    EXPECT_GT(later->spp, 1);
}

// B6: the shipped scenes (the brief's and the examples) are never saved over, in a build's
// res/ as in an install: Save asks where, NAME.json in the current folder by default.
TEST(BundledScenes, AreNeverSavedOver) {
    const std::optional<DataDir> data = data_dir();
    ASSERT_TRUE(data);
    EXPECT_TRUE(viewer::scene_file_read_only(test::brief_scene_file(3), data));
    for (const fs::path& example : example_scenes()) EXPECT_TRUE(viewer::scene_file_read_only(example, data)) << example;
    Scene s = test::brief_scene(3, 8);
    s.source_file = test::brief_scene_file(3);
    EXPECT_EQ(viewer::SavePaths::for_scene(s, true).scene, "assignment_03.json");
    const fs::path mine = temp_path("mine.json");
    EXPECT_FALSE(viewer::scene_file_read_only(mine, data));
}

// Issue 47 C: the outliner lists every object, every light (on or off) and every camera; a
// light's row selects the sphere that carries it, a point light itself.
TEST(Outliner, ListsEveryObjectLightAndCamera) {
    const Scene s = test::brief_scene(3, 8);
    const auto rows = viewer::outliner_rows(s);
    auto count = [&](viewer::OutlinerKind k) { return size_t(std::count_if(rows.begin(), rows.end(), [&](auto& r) { return r.kind == k; })); };
    EXPECT_EQ(count(viewer::OutlinerKind::object), s.primitives.size());
    EXPECT_EQ(count(viewer::OutlinerKind::light), s.lights.size());
    EXPECT_EQ(count(viewer::OutlinerKind::camera), s.cameras.size());
    ASSERT_EQ(rows.size(), s.primitives.size() + s.lights.size() + s.cameras.size());
    // Objects first, in the scene's order, each with its material; the active camera marked.
    for (size_t p = 0; p < s.primitives.size(); ++p) {
        EXPECT_EQ(rows[p].index, int(p));
        EXPECT_EQ(rows[p].label, viewer::primitive_label(s, int(p)));
        EXPECT_NE(rows[p].detail.find(s.materials[size_t(s.primitives[p].material)].id), std::string::npos) << rows[p].detail;
    }
    for (const auto& r : rows) {
        if (r.kind == viewer::OutlinerKind::camera) EXPECT_EQ(r.detail == "active", r.index == s.camera);
        const viewer::Selection sel = viewer::row_selection(s, r);
        if (r.kind == viewer::OutlinerKind::object) EXPECT_EQ(sel.primitive, r.index);
        if (r.kind == viewer::OutlinerKind::camera) EXPECT_FALSE(sel.primitive || sel.light);
        if (r.kind == viewer::OutlinerKind::light) {
            const Light& l = s.lights[size_t(r.index)];
            if (l.type == LightType::point) {
                EXPECT_EQ(sel.light, r.index);  // no sphere to click: the light itself
                EXPECT_FALSE(sel.primitive);
            } else {
                ASSERT_TRUE(sel.primitive) << r.label;  // the emissive sphere that carries it
                EXPECT_EQ(s.primitives[size_t(*sel.primitive)].light, r.index);
            }
        }
    }
}

// The outliner's filter: case-insensitive, in the label or the detail, ends' spaces ignored.
TEST(Outliner, FilterMatchesNamesAndDetails) {
    const Scene s = test::brief_scene(3, 8);
    const auto rows = viewer::outliner_rows(s);
    auto matching = [&](std::string_view filter) {
        std::vector<std::string> out;
        for (const auto& r : rows)
            if (viewer::outliner_row_matches(r, filter)) out.push_back(r.label);
        return out;
    };
    EXPECT_EQ(matching("").size(), rows.size());
    EXPECT_EQ(matching("   ").size(), rows.size());
    EXPECT_EQ(matching(" SPHERE 0 "), (std::vector<std::string>{"sphere 01", "sphere 02"}));
    EXPECT_EQ(matching("Fresnel"), (std::vector<std::string>{"sphere 01"}));  // its material
    EXPECT_EQ(matching("off"), (std::vector<std::string>{"point light"}));    // its state
    EXPECT_TRUE(matching("no such thing").empty());
}

// "Frame selected" looks at the selection from the direction the camera looks, at the
// distance where it fills kFrameFill of the half field of view; a render shows it centred
// and whole. A point light keeps the distance; a lens focuses on what it frames.
TEST(FrameSelected, CentresTheSphereAndFitsIt) {
    ViewerModel m = test::brief_model(3);
    const Scene& s = m.scene();
    int sphere = -1;
    for (size_t p = 0; p < s.primitives.size(); ++p)
        if (s.primitives[p].id == "sphere 01") sphere = int(p);
    ASSERT_GE(sphere, 0);
    const auto ball = viewer::selection_ball(s, viewer::Selection{sphere, std::nullopt});
    ASSERT_TRUE(ball);
    const Camera before = m.camera();
    const Camera c = viewer::framed(before, *ball);
    EXPECT_EQ(c.target, ball->centre);
    // Same direction of view.
    const Vec3 d0 = normalize(before.target - before.position), d1 = normalize(c.target - c.position);
    EXPECT_NEAR(dot(d0, d1), 1.0, 1e-12);
    // Its angular radius is kFrameFill of the half field of view (square image: fov both ways).
    const double half = before.fov * 3.14159265358979323846 / 360;
    EXPECT_NEAR(std::asin(ball->radius / length(c.position - ball->centre)), viewer::kFrameFill * half, 1e-12);
    // Undoable camera edit, as the keys make it.
    ASSERT_TRUE(m.edit(Edit::camera, [&](Scene& sc, ViewerSettings&) { sc.cameras[size_t(sc.camera)] = c; }));
    EXPECT_EQ(viewer::pick_primitive(m.scene(), m.prepared()->camera, 0.5, 0.5), sphere);
    // The image's edges see something else: the sphere fits whole.
    for (auto [fx, fy] : {std::pair{0.02, 0.5}, {0.98, 0.5}, {0.5, 0.02}, {0.5, 0.98}})
        EXPECT_NE(viewer::pick_primitive(m.scene(), m.prepared()->camera, fx, fy), sphere) << fx << "," << fy;
    ASSERT_TRUE(m.undo());
    EXPECT_EQ(m.camera().position, before.position);
    EXPECT_EQ(m.camera().target, before.target);
    // A point light: looked at from the same distance.
    Camera lens = before;
    lens.type = CameraType::lens;
    const viewer::Ball point{Vec3(1, 2, 3), 0};
    const Camera p = viewer::framed(lens, point);
    EXPECT_EQ(p.target, point.centre);
    EXPECT_NEAR(length(p.position - p.target), length(before.target - before.position), 1e-9);
    EXPECT_NEAR(p.focal_distance, length(p.position - p.target), 1e-12);
}

// Numpad 1 / 3 / 7 (Ctrl: the other side): along the world axes about the target, at the
// same distance; the top view is a valid camera (the straight-down basis).
TEST(AxisViews, LookAlongTheWorldAxesAboutTheTarget) {
    Camera c;
    c.position = Vec3(3, 4, -12);
    c.target = Vec3(1, 1, 1);
    const double d = length(c.target - c.position);
    const std::pair<viewer::AxisView, Vec3> cases[] = {
        {viewer::AxisView::front, Vec3(0, 0, 1)},  {viewer::AxisView::back, Vec3(0, 0, -1)},
        {viewer::AxisView::right, Vec3(-1, 0, 0)}, {viewer::AxisView::left, Vec3(1, 0, 0)},
        {viewer::AxisView::top, Vec3(0, -1, 0)},   {viewer::AxisView::bottom, Vec3(0, 1, 0)},
    };
    for (const auto& [view, forward] : cases) {
        const Camera v = viewer::axis_view(c, view);
        EXPECT_EQ(v.target, c.target) << viewer::axis_view_name(view);
        EXPECT_NEAR(length(v.target - v.position), d, 1e-12);
        EXPECT_NEAR(dot(normalize(v.target - v.position), forward), 1.0, 1e-12) << viewer::axis_view_name(view);
        const CameraModel model = CameraModel::from(v);
        EXPECT_NEAR(length(model.right), 1.0, 1e-9) << viewer::axis_view_name(view);
    }
}

// Recolouring the selected sphere recolours it alone: a material it shares is copied for it
// (one undo step), one of its own is changed in place; a dielectric's tint is its rhoT.
TEST(SelectionMaterial, RecolourChangesThisSphereOnly) {
    ViewerModel m = test::brief_model(3);
    const Scene& s = m.scene();
    // Two spheres sharing one material: give sphere 01 sphere 02's.
    int a = -1, b = -1;
    for (size_t p = 0; p < s.primitives.size(); ++p) {
        if (s.primitives[p].id == "sphere 02") a = int(p);  // glossy: its tint is rho
        if (s.primitives[p].id == "sphere 01") b = int(p);
    }
    ASSERT_GE(a, 0);
    ASSERT_GE(b, 0);
    ASSERT_TRUE(m.edit(Edit::object, [&](Scene& sc, ViewerSettings&) { sc.primitives[size_t(b)].material = sc.primitives[size_t(a)].material; }));
    m.seal_undo_step();
    const int shared = s.primitives[size_t(a)].material;
    ASSERT_EQ(viewer::material_users(s, shared), 2);
    const Material before = s.materials[size_t(shared)];
    const size_t materials = s.materials.size();
    const Color red = viewer::kPalette[2].rho;
    ASSERT_TRUE(m.edit(Edit::material, [&](Scene& sc, ViewerSettings&) { EXPECT_TRUE(viewer::recolour_primitive(sc, a, red)); }));
    m.seal_undo_step();
    EXPECT_EQ(s.materials.size(), materials + 1);
    const int own = s.primitives[size_t(a)].material;
    EXPECT_NE(own, shared);
    EXPECT_EQ(s.primitives[size_t(b)].material, shared);
    EXPECT_EQ(s.materials[size_t(shared)].rho, before.rho);  // the other sphere keeps its colour
    EXPECT_EQ(s.materials[size_t(own)].rho, red);
    EXPECT_EQ(s.materials[size_t(own)].type, before.type);
    // Again: its own material now, changed in place.
    const Color blue = viewer::kPalette[6].rho;
    ASSERT_TRUE(m.edit(Edit::material, [&](Scene& sc, ViewerSettings&) { viewer::recolour_primitive(sc, a, blue); }));
    m.seal_undo_step();
    EXPECT_EQ(s.materials.size(), materials + 1);
    EXPECT_EQ(s.materials[size_t(own)].rho, blue);
    // One undo step each.
    ASSERT_TRUE(m.undo());
    EXPECT_EQ(s.materials[size_t(s.primitives[size_t(a)].material)].rho, red);
    ASSERT_TRUE(m.undo());
    EXPECT_EQ(s.materials.size(), materials);
    EXPECT_EQ(s.primitives[size_t(a)].material, shared);
    // A dielectric's tint is what it transmits.
    Scene glass = test::brief_scene(3, 8);
    int g = -1;
    for (size_t i = 0; i < glass.materials.size(); ++i)
        if (glass.materials[i].type == MaterialType::dielectric) g = int(i);
    ASSERT_GE(g, 0);
    glass.primitives[size_t(a)].material = g;
    const Color rho_r = glass.materials[size_t(g)].rho_r;
    ASSERT_TRUE(viewer::recolour_primitive(glass, a, red));
    const Material& tinted = glass.materials[size_t(glass.primitives[size_t(a)].material)];
    EXPECT_EQ(tinted.rho_t, red);
    EXPECT_EQ(tinted.rho_r, rho_r);
}

// The panel list's tabs: every panel has a tab or sits above them (the outliner), every tab
// shows a panel, and the list keeps its order within a tab (Selection first in Object).
TEST(PanelTabs, EveryPanelHasATabAndEveryTabPanels) {
    using viewer::PanelTab;
    [[maybe_unused]] constexpr bool always = true, with_scene = false;
    [[maybe_unused]] constexpr PanelTab top = PanelTab::top, scene = PanelTab::scene, object = PanelTab::object,
                                        camera = PanelTab::camera, render = PanelTab::render, compare = PanelTab::compare;
    std::vector<std::pair<std::string, PanelTab>> panels;
#define KR_LIST_PANEL(name, when, tab) panels.emplace_back(#name, tab);
    KR_VIEWER_PANELS(KR_LIST_PANEL)
#undef KR_LIST_PANEL
    ASSERT_EQ(panels.front(), std::make_pair(std::string("outliner"), PanelTab::top));
    for (int t = 0; t < viewer::kPanelTabs; ++t)
        EXPECT_TRUE(std::any_of(panels.begin(), panels.end(), [&](auto& p) { return p.second == PanelTab(t); }))
            << viewer::kPanelTabNames[t];
    auto first_of = [&](PanelTab t) {
        return std::find_if(panels.begin(), panels.end(), [&](auto& p) { return p.second == t; })->first;
    };
    EXPECT_EQ(first_of(PanelTab::object), "selection");
    EXPECT_EQ(first_of(PanelTab::scene), "scene");
    EXPECT_EQ(first_of(PanelTab::camera), "camera");
    EXPECT_EQ(first_of(PanelTab::compare), "compare");
    EXPECT_EQ(viewer::kPanelTabNames[int(PanelTab::object)], "Object");
}

}  // namespace
}  // namespace kr
