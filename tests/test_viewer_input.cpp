// The viewer's input, GL-free (issue 47, defects B0, B2, B3): a gesture's camera depends on
// the input, not on the frames that saw it; a move of the selection is a step of its own that
// Esc takes back; where the selection's outline is off the image its tint shows it; key and
// text events reach the widgets a frame's worth at a time, every press seen as down.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "render/render_scene.h"
#include "test_util.h"
#include "viewer/key_queue.h"
#include "viewer/model.h"
#include "viewer/navigation.h"
#include "viewer/scene_edit.h"

namespace kr::viewer {
namespace {

int primitive_named(const Scene& scene, const std::string& id) {
    for (size_t i = 0; i < scene.primitives.size(); ++i)
        if (scene.primitives[i].id == id) return int(i);
    return -1;
}

// The window's left drag, frame by frame: the drag starts where the pointer's events first
// went past the threshold, and each frame sets the camera from the whole offset
// (orbit_step). `frames` lists the move events (index into `moves`) after which a frame ran.
Camera orbit_by_frames(const Scene& scene, const Camera& start, const Vec3& pivot, double press_x,
                       const std::vector<double>& moves, const std::vector<size_t>& frames) {
    std::optional<std::pair<double, double>> started;
    for (const double x : moves)
        if (!started && std::abs(x - press_x) > kDragThresholdPixels) started = std::pair{x, 100.0};
    DragGesture g;
    g.press(press_x, 100);
    Camera cam = start;
    for (const size_t i : frames) {
        double dx = 0, dy = 0;
        // The events up to move i were seen: the drag's start, if the pointer was past it by then.
        std::optional<std::pair<double, double>> from;
        for (size_t k = 0; k <= i; ++k)
            if (std::abs(moves[k] - press_x) > kDragThresholdPixels) {
                from = std::pair{moves[k], 100.0};
                break;
            }
        if (g.move(moves[i], 100, cam, dx, dy, from)) cam = orbit_step(scene, g.start_camera, pivot, dx, dy, true);
    }
    return cam;
}

}  // namespace

// B2: the identical 12-step 120-pixel drag on scene 3, seen by a frame after every move, after
// every third, or only after the last, ends on the same camera, outside every sphere.
TEST(GestureCamera, SameDragSameCameraWhateverTheFrames) {
    const ViewerModel m = test::brief_model(3);
    const Scene& scene = m.scene();
    const Camera start = m.camera();
    std::vector<double> moves;
    for (int i = 1; i <= 12; ++i) moves.push_back(200 + 10.0 * i);
    for (const Vec3& pivot : {start.target, *surface_point(*m.prepared(), 0.3, 0.45)}) {
        const Camera every = orbit_by_frames(scene, start, pivot, 200, moves, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11});
        const Camera third = orbit_by_frames(scene, start, pivot, 200, moves, {2, 5, 8, 11});
        const Camera last = orbit_by_frames(scene, start, pivot, 200, moves, {11});
        const Camera uneven = orbit_by_frames(scene, start, pivot, 200, moves, {0, 6, 7, 11});
        for (const Camera* c : {&third, &last, &uneven}) {
            EXPECT_EQ(c->position, every.position);
            EXPECT_EQ(c->target, every.target);
        }
        EXPECT_FALSE(sphere_containing(scene, every.position));
        EXPECT_GT(length(every.position - start.position), 0.01);
    }
}

// The orbit's camera is a function of the offset: back to no offset is the start again, and
// a wall's slide is undone by turning back (the camera never ratchets in).
TEST(GestureCamera, TurningBackUndoesTheSlide) {
    const ViewerModel m = test::brief_model(3);
    const Camera start = m.camera();
    const Camera there = orbit_step(m.scene(), start, start.target, 240, 0, true);
    EXPECT_LT(length(there.position - start.target), length(start.position - start.target) - 1);  // slid along the wall
    const Camera back = orbit_step(m.scene(), start, start.target, 0, 0, true);
    EXPECT_EQ(back.position, start.position);
}

// B2, the keys: holding the left arrow for 0.5 s cut into frames of any length ends on the
// same camera (the slide along scene 3's wall included), and holding it back as long brings
// the camera to where it began, its distance to the target with it.
TEST(GestureCamera, HeldArrowSameCameraAtAnyFrameRateAndReversible) {
    const ViewerModel m = test::brief_model(3);
    const Camera start = m.camera();
    NavigationSettings nav;
    auto hold = [&](int orbit_x, const std::vector<double>& frames, KeyOrbitGesture& g) {
        Camera cam = start;
        for (const double dt : frames) cam = g.hold(m.scene(), orbit_x, 0, dt, nav);
        return cam;
    };
    KeyOrbitGesture a{start}, b{start}, c{start};
    const Camera at60 = hold(-1, std::vector<double>(30, 1.0 / 60), a);
    const Camera at7 = hold(-1, {0.1, 0.1, 0.1, 0.1, 0.1}, b);
    const Camera uneven = hold(-1, {0.01, 0.09, 0.25, 0.05, 0.1}, c);
    EXPECT_LT(length(at60.position - at7.position), 1e-9);
    EXPECT_LT(length(at60.position - uneven.position), 1e-9);
    EXPECT_FALSE(sphere_containing(m.scene(), at60.position));
    EXPECT_EQ(at60.target, start.target);
    // Back again, in other frames: the start, at its distance.
    Camera back = start;
    for (int i = 0; i < 5; ++i) back = a.hold(m.scene(), +1, 0, 0.1, nav);
    EXPECT_LT(length(back.position - start.position), 1e-9);
}

// B0: a move (M) is one undo step; Esc takes it back as if it never happened: the scene as
// before, not dirty, nothing to redo.
TEST(SelectionMove, CancelledMoveLeavesNothing) {
    ViewerModel m = test::brief_model(3);
    const int wall = primitive_named(m.scene(), "far wall");
    ASSERT_GE(wall, 0);
    const Vec3 was = m.scene().shapes[size_t(m.scene().primitives[size_t(wall)].shape)].centre;
    m.seal_undo_step();
    for (int i = 1; i <= 3; ++i)
        ASSERT_TRUE(m.edit(Edit::object, [&](Scene& s, ViewerSettings&) { own_shape(s, wall).centre = was + Vec3(i, 0, 0); },
                           nullptr, "move", "grab"));
    EXPECT_TRUE(m.dirty());
    EXPECT_FALSE(m.cancel_step("orbit"));  // not the open step
    ASSERT_TRUE(m.cancel_step("grab"));
    EXPECT_EQ(m.scene().shapes[size_t(m.scene().primitives[size_t(wall)].shape)].centre, was);
    EXPECT_FALSE(m.dirty());
    EXPECT_FALSE(m.can_redo());
    EXPECT_FALSE(m.can_undo());
    EXPECT_FALSE(m.cancel_step("grab"));  // taken back once
    // A placed move is a step Ctrl+Z undoes.
    ASSERT_TRUE(m.edit(Edit::object, [&](Scene& s, ViewerSettings&) { own_shape(s, wall).centre = was + Vec3(5, 0, 0); },
                       nullptr, "move", "grab"));
    m.seal_undo_step();
    EXPECT_FALSE(m.cancel_step("grab"));
    ASSERT_TRUE(m.undo());
    EXPECT_EQ(m.scene().shapes[size_t(m.scene().primitives[size_t(wall)].shape)].centre, was);
}

// B0: scene 3's far wall has no outline on the image (its silhouette is off it): the tint
// covers the cells that see it, as picking sees them; sphere 01's outline is on the image.
TEST(SelectionVisible, WallIsTintedWhereItIsSeen) {
    const ViewerModel m = test::brief_model(3);
    const Scene& s = m.scene();
    const RenderScene& prepared = *m.prepared();
    const int wall = primitive_named(s, "far wall"), ball = primitive_named(s, "sphere 01");
    ASSERT_GE(wall, 0);
    ASSERT_GE(ball, 0);
    const Shape& ws = s.shapes[size_t(s.primitives[size_t(wall)].shape)];
    const Shape& bs = s.shapes[size_t(s.primitives[size_t(ball)].shape)];
    EXPECT_FALSE(outline_on_image(sphere_outline(prepared.camera, ws.centre, ws.radius, 64)));
    EXPECT_TRUE(outline_on_image(sphere_outline(prepared.camera, bs.centre, bs.radius, 64)));
    const int cols = 32, rows = 32;
    const auto cells = sphere_coverage(prepared, ws.centre, ws.radius, cols, rows);
    ASSERT_EQ(cells.size(), size_t(cols * rows));
    int covered = 0, agree = 0;
    for (int y = 0; y < rows; ++y)
        for (int x = 0; x < cols; ++x) {
            const bool c = cells[size_t(y * cols + x)];
            covered += c;
            agree += c == (pick_primitive(s, prepared.camera, (x + 0.5) / cols, (y + 0.5) / rows) == wall);
        }
    EXPECT_GT(covered, cols * rows / 10);  // the far wall fills much of the view
    EXPECT_LT(covered, cols * rows);
    EXPECT_EQ(agree, cols * rows);
}

// B0: a selection behind the camera has no outline on the image and no cell that sees it
// (the window then names it on the image instead).
TEST(SelectionVisible, SphereBehindTheCameraCoversNothing) {
    ViewerModel m = test::brief_model(3);
    ASSERT_TRUE(m.edit(Edit::camera, [](Scene& s, ViewerSettings&) {
        Camera& c = s.cameras[size_t(s.camera)];
        c.target = Vec3(0, 0, -30);  // looking away from the room's inside, at the near wall's gap
    }));
    const Scene& s = m.scene();
    const int ball = primitive_named(s, "sphere 01");
    const Shape& bs = s.shapes[size_t(s.primitives[size_t(ball)].shape)];
    EXPECT_FALSE(outline_on_image(sphere_outline(m.prepared()->camera, bs.centre, bs.radius, 64)));
    const auto cells = sphere_coverage(*m.prepared(), bs.centre, bs.radius, 16, 16);
    EXPECT_EQ(std::count(cells.begin(), cells.end(), 1), 0);
}

namespace {

constexpr int kCtrl = 341, kEnter = 257, kBackspace = 259, kA = 65, kTwo = 50, kDot = 46, kEight = 56, kD = 68;

KeyEvent key(int k, int action, int mods = 0) { return {false, k, 0, action, mods, 0}; }
KeyEvent text(unsigned c) { return {true, 0, 0, 0, 0, c}; }

// Feeds the queue's frames to a model of ImGui 1.86's key state: per frame, which keys were
// down when it started (a press seen) and the text in order.
struct Frames {
    std::vector<std::vector<KeyEvent>> frames;
    explicit Frames(KeyEventQueue& q) {
        while (!q.empty()) frames.push_back(q.take_frame());
    }
    // The frame numbers in which `k` is down at the frame's start with Ctrl down or not.
    std::vector<size_t> down(int k, bool with_ctrl = false) const {
        std::vector<size_t> out;
        bool is_down = false, ctrl = false;
        for (size_t f = 0; f < frames.size(); ++f) {
            for (const KeyEvent& e : frames[f]) {
                if (e.text) continue;
                if (e.key == k && e.action != KeyEventQueue::kRepeat) is_down = e.action == KeyEventQueue::kPress;
                if (e.key == kCtrl) ctrl = e.action != KeyEventQueue::kRelease;
            }
            if (is_down && (!with_ctrl || ctrl)) out.push_back(f);
        }
        return out;
    }
};

}  // namespace

// B3: Ctrl+A pressed and released between two frames is still seen: a frame starts with
// Ctrl and A down; the text typed after it comes in a later frame (ImGui applies a frame's
// text before its keys, so it would go in before the select-all).
TEST(KeyQueue, QuickCtrlAIsSeenAndTextAfterItWaits) {
    KeyEventQueue q;
    for (const KeyEvent& e : {key(kCtrl, 1), key(kA, 1, 2), key(kA, 0, 2), key(kCtrl, 0), key(kD, 1), text('d'), key(kD, 0)})
        q.push(e);
    Frames f(q);
    const auto a = f.down(kA, true);
    ASSERT_EQ(a.size(), 1u);
    size_t text_frame = 99;
    for (size_t i = 0; i < f.frames.size(); ++i)
        for (const KeyEvent& e : f.frames[i])
            if (e.text) text_frame = i;
    EXPECT_GT(text_frame, a[0]);
    // Every event handed over once, in order.
    size_t n = 0;
    for (const auto& fr : f.frames) n += fr.size();
    EXPECT_EQ(n, 7u);
}

// Ctrl+A as xdotool sends it (Ctrl goes up before A) between two frames: a frame starts with
// Ctrl and A down, Ctrl's release waits for the next one (with it in the same frame, ImGui saw
// an A without Ctrl: the outliner's filter lost its select-all after the viewer had idled).
// Likewise a modifier pressed after a key waits: the key is not taken as a chord.
TEST(KeyQueue, AModifierChangeAfterAKeysPressWaitsForTheNextFrame) {
    KeyEventQueue q;
    for (const KeyEvent& e : {key(kCtrl, 1), key(kA, 1, 2), key(kCtrl, 0, 2), key(kA, 0)}) q.push(e);
    Frames f(q);
    EXPECT_EQ(f.down(kA, true).size(), 1u);
    EXPECT_EQ(f.down(kA).size(), 1u);
    KeyEventQueue r;
    for (const KeyEvent& e : {key(kD, 1), key(kCtrl, 1), key(kD, 0, 2), key(kCtrl, 0, 2)}) r.push(e);
    Frames g(r);
    EXPECT_EQ(g.down(kD, true).size(), 0u);  // D was pressed alone
    EXPECT_EQ(g.down(kD).size(), 1u);
}

// B3: "2.8" and Enter, all between two frames: Enter is down at the start of one frame, by
// which all the text has reached the field (it applies "2.8"); its release in a later one.
TEST(KeyQueue, QuickEnterAfterTypingIsSeenWithTheText) {
    KeyEventQueue q;
    for (const int k : {kTwo, kDot, kEight}) {
        q.push(key(k, 1));
        q.push(text(unsigned(k)));
        q.push(key(k, 0));
    }
    q.push(key(kEnter, 1));
    q.push(key(kEnter, 0));
    Frames f(q);
    const auto enter = f.down(kEnter);
    ASSERT_EQ(enter.size(), 1u);
    std::string typed;
    for (size_t i = 0; i <= enter[0]; ++i)
        for (const KeyEvent& e : f.frames[i])
            if (e.text) typed += char(e.codepoint);
    EXPECT_EQ(typed, "2.8");
    // A key pressed and released in one batch is down for a frame: each digit too.
    for (const int k : {kTwo, kDot, kEight}) EXPECT_EQ(f.down(k).size(), 1u) << k;
}

// A key pressed twice, and text after Backspace, wait for the next frame; a frame always
// takes at least one event, so the queue drains.
TEST(KeyQueue, RepeatedKeysAndEditsKeepTheirOrder) {
    KeyEventQueue q;
    for (const KeyEvent& e : {text('a'), key(kBackspace, 1), key(kBackspace, 0), key(kBackspace, 1), key(kBackspace, 0),
                              text('b')})
        q.push(e);
    Frames f(q);
    EXPECT_EQ(f.down(kBackspace).size(), 2u);  // two presses, two frames that see it down
    EXPECT_GE(f.frames.size(), 3u);
    EXPECT_TRUE(f.frames.back().back().text);  // 'b' after both Backspaces
    for (const auto& fr : f.frames) EXPECT_FALSE(fr.empty());
}

}  // namespace kr::viewer
