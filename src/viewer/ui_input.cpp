#include "viewer/ui_input.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "render/trace.h"
#include "viewer/outliner.h"
#include "viewer/scene_edit.h"
#include "viewer/ui_compare.h"
#include "viewer/ui_file_dialog.h"
#include "viewer/ui_panels.h"

#include <GLFW/glfw3.h>  // after ui_compare.h: gl_functions.h includes the GL headers it needs first
#include <imgui.h>
#include <imgui_internal.h>  // ClosePopupToLevel: Esc closes an open drop-down

namespace kr::viewer {

void InputState::note_key(int key, int action, int mods) {
    if (action == GLFW_PRESS && key_presses.size() < 64) {
        key_presses.push_back(key);
        key_mods.push_back(mods);
    }
    const bool chord = mods & (GLFW_MOD_CONTROL | GLFW_MOD_ALT | GLFW_MOD_SUPER);
    if (action == GLFW_PRESS && chord && !held_in_chord(key) && chord_keys.size() < 64) chord_keys.push_back(key);
    // A release (or a plain press, where a release went to another window) ends the chord.
    if (action == GLFW_RELEASE || (action == GLFW_PRESS && !chord)) chord_keys.erase(std::remove(chord_keys.begin(), chord_keys.end(), key), chord_keys.end());
}

void InputState::note_key_event(int key, int action) {
    if (key == GLFW_KEY_LEFT_SHIFT || key == GLFW_KEY_RIGHT_SHIFT) shift_down = action != GLFW_RELEASE;
}

void InputState::note_cursor(double x, double y) {
    cursor = {x, y};
    for (int b = 0; b < 3; ++b)
        if (event_down[b] && !drag_from[b] && std::hypot(x - event_press[b].first, y - event_press[b].second) > kDragThresholdPixels)
            drag_from[b] = cursor;
}

void InputState::note_button(int button, int action, int mods) {
    if (button < 0 || button >= 3) return;
    if (action == GLFW_PRESS) {
        event_down[button] = true;
        event_press[button] = cursor.value_or(Point{0, 0});
        drag_from[button].reset();
    }
    if (action == GLFW_RELEASE) event_down[button] = false;
    // The first press since the last frame is the one ImGui sees as the click.
    if (action == GLFW_PRESS && !press_at[button]) {
        press_at[button] = cursor;
        press_mods[button] = mods;
    }
    if (action == GLFW_PRESS) release_at[button].reset();
    if (action == GLFW_RELEASE) release_at[button] = cursor;
}

void InputState::apply_pointer() {
    ImGuiIO& io = ImGui::GetIO();
    // The backend leaves -FLT_MAX where the window has no focus; held buttons keep the
    // pointer's events coming (the implicit grab) when it leaves the window.
    const bool held = event_down[0] || event_down[1] || event_down[2];
    if (cursor && ImGui::IsMousePosValid(&io.MousePos) && (cursor_inside || held))
        io.MousePos = ImVec2(float(cursor->first), float(cursor->second));
}

void InputState::apply_button_positions() {
    ImGuiIO& io = ImGui::GetIO();
    for (int b = 0; b < 3; ++b) {
        if (io.MouseClicked[b] && press_at[b]) io.MouseClickedPos[b] = ImVec2(float(press_at[b]->first), float(press_at[b]->second));
        if (io.MouseClicked[b]) {
            // The click's modifiers: its press event's, else (no event seen) the frame's.
            const int frame_mods = (io.KeyShift ? GLFW_MOD_SHIFT : 0) | (io.KeyCtrl ? GLFW_MOD_CONTROL : 0) |
                                   (io.KeyAlt ? GLFW_MOD_ALT : 0) | (io.KeySuper ? GLFW_MOD_SUPER : 0);
            clicked_mods[b] = press_at[b] ? press_mods[b] : frame_mods;
        }
        press_at[b].reset();
        released_here[b].reset();
        if (io.MouseReleased[b]) released_here[b] = std::exchange(release_at[b], std::nullopt);
    }
    wheel_shift_here = wheel_at ? wheel_shift : io.KeyShift;
    wheel_here = std::exchange(wheel_at, std::nullopt);
}

bool InputState::held_in_chord(int key) const {
    return std::find(chord_keys.begin(), chord_keys.end(), key) != chord_keys.end();
}

bool InputState::pressed_with_ctrl(int key) const {
    for (size_t i = 0; i < key_presses.size(); ++i)
        if (key_presses[i] == key && (key_mods[i] & GLFW_MOD_CONTROL)) return true;
    return false;
}

int InputState::pressed_bits() const {
    return int(drags[0].pressed) | 2 * int(drags[1].pressed) | 4 * int(drags[2].pressed) | 8 * int(divider_drag);
}

bool InputState::moving() const {
    const ImGuiIO& io = ImGui::GetIO();
    return io.MouseDown[0] || io.MouseDown[1] || io.MouseDown[2] || motion_keys_held;
}

namespace {

// The image pixels covered by the box between two window points, clamped to the image.
PixelBox region_box(double ax, double ay, double bx, double by, const PixelRect& rect, int w, int h) {
    auto px = [&](double x) { return std::clamp(int(std::lround((x - rect.x) / rect.width * w)), 0, w); };
    auto py = [&](double y) { return std::clamp(int(std::lround((y - rect.y) / rect.height * h)), 0, h); };
    return {std::min(px(ax), px(bx)), std::min(py(ay), py(by)), std::max(px(ax), px(bx)), std::max(py(ay), py(by))};
}

constexpr double kExposureKeyStep = 0.5;  // stops per E / Shift+E, as tev's

// "+1.50", "-0.50", "0.00": an exposure in stops.
std::string format_ev(double ev) {
    char buf[32];
    std::snprintf(buf, sizeof buf, ev > 0 ? "+%.2f" : "%.2f", ev == 0 ? 0.0 : ev);
    return buf;
}

constexpr const char* kGrabGroup = "grab";  // the undo step of one move (M)

// What the move does, on the image for as long as it lasts.
void set_move_hint(PanelContext& ctx, const InputState& in) {
    const Scene& s = ctx.model.scene();
    const int axis = in.grab->axis;
    ctx.ui.move_hint = "moving " + s.primitives[size_t(in.grab->primitive)].id +
                       (axis < 0 ? std::string(" (view plane)") : std::string(" (along ") + "xyz"[axis] + ")") +
                       "\nclick / Return: place   Esc / right click: put back   X Y Z: axis";
}

// M: the selection starts following the pointer.
void start_grab(PanelContext& ctx, InputState& in) {
    const auto sel = ctx.selection();
    if (!sel || !ctx.model.prepared()) {
        ctx.messages.show_status("M moves the selection: click a sphere first");
        return;
    }
    const Scene& s = ctx.model.scene();
    const ImGuiIO& io = ImGui::GetIO();
    InputState::Grab g;
    g.primitive = *sel;
    g.start = s.shapes[size_t(s.primitives[size_t(*sel)].shape)].centre;
    g.x = io.MousePos.x * io.DisplayFramebufferScale.x;
    g.y = io.MousePos.y * io.DisplayFramebufferScale.x;
    g.axis = ctx.ui.axis_lock;
    in.grab = g;
    ctx.model.seal_undo_step();  // the move is one undo step of its own
    set_move_hint(ctx, in);
}

// Ends the move: placed where it is (`keep`), or back where it was (its edit undone, no redo left).
void end_grab(PanelContext& ctx, InputState& in, bool keep) {
    if (!in.grab) return;
    if (!keep && in.grab->moved) ctx.model.cancel_step(kGrabGroup);
    ctx.model.seal_undo_step();
    ctx.messages.show_status(keep ? "placed" : "move cancelled: put back");
    in.grab.reset();
    ctx.ui.move_hint.clear();
}

// One frame of the move: the selection at the pointer's offset from where the move began,
// in the view plane at its depth or along the locked axis. Clicks end it; nothing orbits.
void grab_mouse(PanelContext& ctx, InputState& in, const PixelRect& rect) {
    ViewerModel& model = ctx.model;
    InputState::Grab& g = *in.grab;
    if (ctx.selection() != g.primitive || !model.prepared()) {
        in.grab.reset();  // the selection went (undo, delete): nothing to move
        ctx.ui.move_hint.clear();
        return;
    }
    for (int b = 0; b < 3; ++b) in.drags[b].release();  // a click here places, never orbits or selects
    if (ImGui::IsMouseClicked(ImGuiMouseButton_Left)) return end_grab(ctx, in, true);
    if (ImGui::IsMouseClicked(ImGuiMouseButton_Right)) return end_grab(ctx, in, false);
    const ImGuiIO& io = ImGui::GetIO();
    const double to_fb = io.DisplayFramebufferScale.x;
    const double image_scale = rect.width / model.scene().renderer.width;
    const double dx = (io.MousePos.x * to_fb - g.x) / image_scale, dy = (io.MousePos.y * to_fb - g.y) / image_scale;
    const Vec3 to = g.start + drag_offset(model.prepared()->camera, g.start, dx, dy, model.scene().renderer.height, g.axis);
    const Scene& s = model.scene();
    if (s.shapes[size_t(s.primitives[size_t(g.primitive)].shape)].centre == to) return;
    const int p = g.primitive;
    if (ctx.edit(Edit::object, [&](Scene& scene, ViewerSettings&) { own_shape(scene, p).centre = to; }, "move", kGrabGroup))
        g.moved = true;
}

// The keys of a move: X, Y, Z lock an axis (again: the view plane), Return places it.
void grab_keys(PanelContext& ctx, InputState& in) {
    for (const int key : in.key_presses) {
        if (!in.grab) return;
        const int axis = key == GLFW_KEY_X ? 0 : key == GLFW_KEY_Y ? 1 : key == GLFW_KEY_Z ? 2 : -1;
        if (axis >= 0) {
            in.grab->axis = in.grab->axis == axis ? -1 : axis;
            set_move_hint(ctx, in);
        } else if (key == GLFW_KEY_ENTER || key == GLFW_KEY_KP_ENTER) {
            end_grab(ctx, in, true);
        }
    }
}

void handle_mouse(PanelContext& ctx, InputState& in, const PixelRect& rect) {
    if (in.grab) return grab_mouse(ctx, in, rect);
    ViewerModel& model = ctx.model;
    CompareTool& tool = ctx.ui.compare;
    ImGuiIO& io = ImGui::GetIO();
    const double to_fb = io.DisplayFramebufferScale.x;  // window points to framebuffer pixels
    const int w = model.scene().renderer.width, h = model.scene().renderer.height;
    const double image_scale = rect.width / w;
    const double mx = io.MousePos.x * to_fb, my = io.MousePos.y * to_fb;
    const PixelRect area = ctx.view_area();
    auto inside = [&](const PixelRect& r) { return mx >= r.x && my >= r.y && mx < r.x + r.width && my < r.y + r.height; };
    // The wheel zooms about where the pointer was when it turned.
    const double wx = in.wheel_here ? in.wheel_here->first * to_fb : mx, wy = in.wheel_here ? in.wheel_here->second * to_fb : my;
    const bool over_image = inside(area) && inside(rect);
    // A left press and release that never became a drag is a click: it selects the sphere
    // under it, or clears the selection.
    if (ImGui::IsMouseReleased(ImGuiMouseButton_Left) && in.drags[0].pressed && !in.drags[0].dragging)
        select_primitive(ctx, in.press_pick);  // the outliner's selection too
    // Where the pointer is for button b: where it went up on the frame that sees its release.
    auto pointer_of = [&](int b) {
        return in.released_here[b] ? InputState::Point{in.released_here[b]->first * to_fb, in.released_here[b]->second * to_fb}
                                   : InputState::Point{mx, my};
    };
    if (ctx.ui.region_draft && !io.MouseDown[0]) {
        // The drawn box, to where the button went up, becomes the render region (an empty one: none).
        const auto [ux, uy] = pointer_of(0);
        const PixelBox box = region_box(io.MouseClickedPos[0].x * to_fb, io.MouseClickedPos[0].y * to_fb, ux, uy, rect, w, h);
        ctx.ui.region = box.x1 > box.x0 && box.y1 > box.y0 ? std::optional<PixelBox>(box) : std::nullopt;
        ctx.ui.region_draft.reset();
        ctx.ui.drawing_region = false;
    }
    if (!io.MouseDown[0]) in.divider_drag = false;
    // Mouse: only when ImGui does not want it, so a click on a panel never moves the camera.
    if (io.WantCaptureMouse || !over_image) {
        for (int b = 0; b < 3; ++b)
            if (ImGui::IsMouseClicked(b)) in.drags[b].release();  // a press on a panel drags nothing
        if (!io.WantCaptureMouse && inside(area) && !in.wheel_shift_here && io.MouseWheel != 0)
            tool.view.zoom_steps(area, w, h, io.MouseWheel > 0 ? 1 : -1, wx, wy);
    } else if (ctx.ui.drawing_region && (ImGui::IsMouseClicked(ImGuiMouseButton_Left) || ctx.ui.region_draft)) {
        // B, then a left drag: the box from the press to the pointer, in image pixels.
        ctx.ui.region_draft = region_box(io.MouseClickedPos[0].x * to_fb, io.MouseClickedPos[0].y * to_fb, mx, my, rect, w, h);
    } else {
        for (int b = 0; b < 3; ++b)
            if (ImGui::IsMouseClicked(b))
                in.drags[b].press(io.MouseClickedPos[b].x * to_fb, io.MouseClickedPos[b].y * to_fb);
        const bool left_click = ImGui::IsMouseClicked(ImGuiMouseButton_Left);
        const double px = io.MouseClickedPos[0].x * to_fb, py = io.MouseClickedPos[0].y * to_fb;  // the left press
        if (left_click) {
            // The orbit's pivot: the surface under the press, else the target.
            in.pivot = model.camera().target;
            const double fx = (px - rect.x) / rect.width, fy = (py - rect.y) / rect.height;
            if (ctx.ui.nav.orbit_picked && model.prepared())
                if (const auto p = surface_point(*model.prepared(), fx, fy)) in.pivot = *p;
            // The sphere under it: a click selects it (a drag orbits, from the selection too; M moves it).
            in.press_pick = model.prepared() ? pick_primitive(model.scene(), model.prepared()->camera, fx, fy) : std::nullopt;
        }
        const double divider_x = rect.x + tool.comparison.settings.split * rect.width;
        const bool shift_click = left_click && (in.clicked_mods[0] & GLFW_MOD_SHIFT);
        const bool ctrl_click = left_click && (in.clicked_mods[0] & GLFW_MOD_CONTROL);
        if (shift_click) {
            in.drags[0].release();  // Shift+click locks the inspector on a pixel, or frees it
            const std::pair<int, int> pixel{int(std::floor((px - rect.x) / image_scale)),
                                            int(std::floor((py - rect.y) / image_scale))};
            if (tool.locked_probe == pixel) tool.locked_probe.reset();
            else tool.locked_probe = pixel;
        } else if (left_click && tool.comparison.settings.mode == ViewMode::split && std::abs(px - divider_x) <= 6 * to_fb) {
            in.drags[0].release();  // the split view's divider, never an orbit
            in.divider_drag = true;
        } else if (ctrl_click || (left_click && ctx.ui.pick_focus)) {
            in.drags[0].release();  // a focus click, never an orbit
            const Vec2 film = raster_to_camera((px - rect.x) / rect.width * w, (py - rect.y) / rect.height * h, w, h);
            if (!model.focus_at(film.x, film.y)) ctx.messages.show_error("click-to-focus: nothing there to focus on");
            else ctx.messages.show_status(focus_message(model.camera()));
            ctx.ui.pick_focus = false;
        }
        if (ImGui::IsMouseClicked(ImGuiMouseButton_Middle)) {
            // The middle button pans the image, as the wheel zooms it; Shift+middle dollies.
            in.middle_pans = !(in.clicked_mods[2] & GLFW_MOD_SHIFT);
            in.pan_last_x = in.pan_last_y = 0;
        }
        if (io.MouseWheel != 0) {
            // The wheel zooms the image about the pointer (samples kept); Shift+wheel dollies.
            if (!in.wheel_shift_here) tool.view.zoom_steps(area, w, h, io.MouseWheel > 0 ? 1 : -1, wx, wy);
            else
                ctx.edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
                    Camera& cam = s.cameras[size_t(s.camera)];
                    const Camera before = cam;
                    dolly(cam, std::pow(0.9, double(io.MouseWheel) * ctx.ui.nav.speed));
                    if (ctx.ui.nav.stop_at_surfaces) keep_outside(s, before, cam);
                }, "dolly", "wheel");
        }
    }
    if (in.divider_drag) tool.comparison.settings.split = std::clamp((mx - rect.x) / rect.width, 0.0, 1.0);
    // Drags started on the image go on wherever the pointer goes. Each applies its whole
    // offset from where it started (screen pixels, in image pixels here) to the camera as it was then.
    double dx = 0, dy = 0;
    const int active = model.scene().camera;
    auto drag = [&](DragGesture& g) {
        const int b = int(&g - in.drags);
        const auto [x, y] = pointer_of(b);
        // On the frame of its release a drag moves only to where the button went up, if it moved.
        if (!io.MouseDown[b] && (!in.released_here[b] || (x == g.last_x && y == g.last_y))) return false;
        std::optional<InputState::Point> from;
        if (in.drag_from[b]) from = InputState::Point{in.drag_from[b]->first * to_fb, in.drag_from[b]->second * to_fb};
        if (!g.move(x, y, model.camera(), dx, dy, from)) return false;
        dx /= image_scale;
        dy /= image_scale;
        return true;
    };
    const NavigationSettings& nav = ctx.ui.nav;
    // Each drag's camera is a function of its whole offset and the camera where it started,
    // stopped at surfaces on the way from there: the same pointer path gives the same camera
    // whether its moves reached one frame or many.
    if (drag(in.drags[0]))
        ctx.edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
            Camera& cam = s.cameras[size_t(active)];
            if (nav.fly) {
                cam = in.drags[0].start_camera;
                look_drag(cam, dx, dy);
            } else {
                cam = orbit_step(s, in.drags[0].start_camera, in.pivot, dx, dy, nav.stop_at_surfaces);
            }
        }, "orbit", "orbit");
    if (drag(in.drags[1]))
        ctx.edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
            Camera& cam = s.cameras[size_t(active)];
            const Camera start = in.drags[1].start_camera;
            cam = start;
            pan_drag(cam, dx, dy, h);
            if (nav.stop_at_surfaces) keep_outside(s, start, cam);
        }, "pan", "pan");
    if (in.middle_pans) {
        // The image follows the pointer from where the button went down: this frame's part of
        // the drag, in screen pixels, once past the click threshold.
        if (drag(in.drags[2])) {
            const auto [x, y] = pointer_of(2);
            const double tx = x - in.drags[2].press_x, ty = y - in.drags[2].press_y;
            tool.view.pan(area, w, h, tx - in.pan_last_x, ty - in.pan_last_y);
            in.pan_last_x = tx;
            in.pan_last_y = ty;
        }
    } else if (drag(in.drags[2])) {
        ctx.edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
            Camera& cam = s.cameras[size_t(active)];
            const Camera start = in.drags[2].start_camera;
            cam = start;
            dolly(cam, std::exp(dy * 0.005 * nav.speed));
            if (nav.stop_at_surfaces) keep_outside(s, start, cam);
        }, "dolly", "dolly");
    }
    // A button that went up ends its drag, after the drag's last move above.
    for (int b = 0; b < 3; ++b)
        if (!io.MouseDown[b]) in.drags[b].release();
}

// The zoom and compare keys; true when one acted.
bool zoom_keys(PanelContext& ctx, InputState& in) {
    const ViewerModel& model = ctx.model;
    CompareTool& tool = ctx.ui.compare;
    const int w = model.scene().renderer.width, h = model.scene().renderer.height;
    const PixelRect area = ctx.view_area();
    const ImGuiIO& io = ImGui::GetIO();
    // About the pointer when it is over the view, else about the view's centre.
    const double to_fb = io.DisplayFramebufferScale.x;
    double px = io.MousePos.x * to_fb, py = io.MousePos.y * to_fb;
    if (!(px >= area.x && py >= area.y && px < area.x + area.width && py < area.y + area.height)) {
        px = area.x + area.width / 2;
        py = area.y + area.height / 2;
    }
    bool acted = false;
    for (size_t i = 0; i < in.key_presses.size(); ++i) {
        const int key = in.key_presses[i];
        if (in.key_mods[i] & GLFW_MOD_CONTROL) continue;  // a Ctrl chord, not a zoom key
        if ((in.key_mods[i] & GLFW_MOD_SHIFT) && key == GLFW_KEY_1) continue;  // Shift+1 recalls a bookmark
        acted = true;
        if (key == GLFW_KEY_EQUAL || key == GLFW_KEY_KP_ADD) tool.view.zoom_steps(area, w, h, 1, px, py);
        else if (key == GLFW_KEY_MINUS || key == GLFW_KEY_KP_SUBTRACT) tool.view.zoom_steps(area, w, h, -1, px, py);
        else if (key == GLFW_KEY_0 || key == GLFW_KEY_KP_0) tool.view.fit();
        else if (key == GLFW_KEY_1) tool.view.one_to_one(area, w, h);  // (numpad 1: the front view)
        else if (key == GLFW_KEY_V) {
            auto& mode = tool.comparison.settings.mode;
            mode = ViewMode((int(mode) + 1) % int(view_mode_names.names.size()));
        } else if (key == GLFW_KEY_I) {
            tool.probe_box = !tool.probe_box;
        } else if (key == GLFW_KEY_K && ctx.ui.shown && ctx.ui.shown->scale == 1) {
            keep_image_b(ctx, *ctx.ui.shown);
        } else acted = false;
    }
    return acted;
}

// "." or numpad-.: frame the selection; numpad 1 / 3 / 7: the front, right and top views
// (Ctrl: back, left, bottom), as Blender's. Camera edits, each one undo step.
void view_keys(PanelContext& ctx, InputState& in) {
    for (size_t i = 0; i < in.key_presses.size(); ++i) {
        const int key = in.key_presses[i];
        const bool ctrl = in.key_mods[i] & GLFW_MOD_CONTROL;
        std::optional<AxisView> axis;
        if (key == GLFW_KEY_KP_1) axis = ctrl ? AxisView::back : AxisView::front;
        if (key == GLFW_KEY_KP_3) axis = ctrl ? AxisView::left : AxisView::right;
        if (key == GLFW_KEY_KP_7) axis = ctrl ? AxisView::bottom : AxisView::top;
        const bool frame = !ctrl && (key == GLFW_KEY_PERIOD || key == GLFW_KEY_KP_DECIMAL);
        if (!axis && !frame) continue;
        const Scene& scene = ctx.model.scene();
        Camera cam = ctx.model.camera();
        std::string what;
        if (axis) {
            cam = axis_view(cam, *axis);
            what = std::string(axis_view_name(*axis)) + " view";
        } else {
            const auto sel = ctx.selection();
            Selection what_is;  // the selected primitive, else a light selected in the outliner
            what_is.primitive = sel;
            if (!sel) what_is.light = ctx.ui.selected_light;
            const auto ball = selection_ball(scene, what_is);
            if (!ball) {
                ctx.messages.show_status(". frames the selection: select an object (click it, or its outliner row) first");
                continue;
            }
            cam = framed(cam, *ball);
            what = "frame selected";
        }
        ctx.model.seal_undo_step();
        const int active = scene.camera;
        if (ctx.edit(Edit::camera, [&](Scene& s, ViewerSettings&) { s.cameras[size_t(active)] = cam; }, what))
            ctx.messages.show_status(what + " (Ctrl+Z undoes it)");
        ctx.model.seal_undo_step();
    }
}

// The window's own keys, with or without a scene (a broken starting scene must not freeze
// them), in the order they were pressed: taps that reach one frame together (a busy
// machine) act as they would one frame each (F1 then Esc shows and closes the help; Esc
// then F1 asks to quit, then shows the help). F1 and F11 work even while a field has the keyboard.
void window_keys(PanelContext& ctx, InputState& in, WindowRequests& requests) {
    UiState& ui = ctx.ui;
    const ImGuiIO& io = ImGui::GetIO();
    const bool typing = io.WantTextInput || ImGui::IsAnyItemActive();
    for (const int key : in.key_presses) {
        if (key == GLFW_KEY_F11) requests.toggle_fullscreen = !requests.toggle_fullscreen;
        else if (key == GLFW_KEY_F1) ui.help_visible = !ui.help_visible;
        // Return answers an open question, typed into or not (a tap between frames included).
        else if ((key == GLFW_KEY_ENTER || key == GLFW_KEY_KP_ENTER) && ImGui::GetTopMostPopupModal())
            requests.confirm_question = true;
        // Esc in a question's or a dialog's text field cancels it at once, as desktops do.
        else if (key == GLFW_KEY_ESCAPE && typing && ImGui::GetTopMostPopupModal())
            requests.cancel_question = true;
        else if (typing) continue;
        else if (key == GLFW_KEY_ESCAPE) {
            // Esc closes what is open first: a move (put back), the help, the selection, a
            // drop-down or a question (its safe answer); then quits.
            if (in.grab) end_grab(ctx, in, false);
            else if (ui.help_visible) ui.help_visible = false;
            else if (ImGui::IsPopupOpen(nullptr, ImGuiPopupFlags_AnyPopupId) == false && (ui.selected || ui.selected_light))
                select_primitive(ctx, std::nullopt);
            else if (!ImGui::IsPopupOpen(nullptr, ImGuiPopupFlags_AnyPopupId)) requests.quit = true;
            else if (!ImGui::GetTopMostPopupModal()) ImGui::ClosePopupToLevel(0, true);  // a drop-down
            else requests.cancel_question = true;
        } else if (key == GLFW_KEY_TAB) {
            ui.panel_visible = !ui.panel_visible;
        }
    }
}

void handle_keys(PanelContext& ctx, InputState& in, WindowRequests& requests) {
    ViewerModel& model = ctx.model;
    UiState& ui = ctx.ui;
    ImGuiIO& io = ImGui::GetIO();
    const auto now = UiClock::now();
    // A press this frame, whether ImGui saw the key down or it was released before the frame.
    auto pressed = [&](int key) {
        return ImGui::IsKeyPressed(key, false) ||
               std::find(in.key_presses.begin(), in.key_presses.end(), key) != in.key_presses.end();
    };
    // The window keys, in the order they were pressed: taps that reach one frame together
    // (a busy machine) act as they would one frame each (F1 then Esc shows and closes the
    // help; Esc then F1 asks to quit, then shows the help). F1 and F11 work even while a
    // field has the keyboard.
    window_keys(ctx, in, requests);
    if (io.WantTextInput || ImGui::IsAnyItemActive()) {
        in.motion_keys_held = false;
        in.key_orbit.reset();
        return;
    }
    if (in.grab) {
        // A move takes the keys until it ends (Esc: window_keys above).
        grab_keys(ctx, in);
        in.motion_keys_held = false;
        in.key_orbit.reset();
        return;
    }
    bool question = false;
    for (ImWchar c : io.InputQueueCharacters) question |= c == '?';
    if (question) ui.help_visible = !ui.help_visible;
    // Ctrl chords by the modifiers each key event had: a fast chord can start and end between frames.
    auto ctrl_pressed = [&](int key) { return in.pressed_with_ctrl(key) || (io.KeyCtrl && ImGui::IsKeyPressed(key, false)); };
    auto shift_with = [&](int key) {
        for (size_t i = 0; i < in.key_presses.size(); ++i)
            if (in.key_presses[i] == key && (in.key_mods[i] & GLFW_MOD_SHIFT)) return true;
        return io.KeyShift;
    };
    // Files (ui_file_dialog.h): Ctrl+O opens a scene, Ctrl+Shift+S saves the scene as.
    if (ctrl_pressed(GLFW_KEY_O)) {
        open_file_dialog(ctx, FilePurpose::open_scene);
        return;
    }
    if (ctrl_pressed(GLFW_KEY_S) && shift_with(GLFW_KEY_S)) {
        open_file_dialog(ctx, FilePurpose::save_scene);
        return;
    }
    if (ctrl_pressed(GLFW_KEY_S)) {
        save_scene_in_place(ctx);
        return;
    }
    // The UI's size: Ctrl+= / Ctrl+- by a quarter, Ctrl+0 back to 1 (kept in the settings file).
    if (ctrl_pressed(GLFW_KEY_EQUAL) || ctrl_pressed(GLFW_KEY_KP_ADD)) set_ui_scale(ctx, ui.files.ui_scale + 0.25);
    if (ctrl_pressed(GLFW_KEY_MINUS) || ctrl_pressed(GLFW_KEY_KP_SUBTRACT)) set_ui_scale(ctx, ui.files.ui_scale - 0.25);
    if (ctrl_pressed(GLFW_KEY_0) || ctrl_pressed(GLFW_KEY_KP_0)) set_ui_scale(ctx, 1);
    if (ctrl_pressed(GLFW_KEY_D)) {
        duplicate_selection(ctx);
        return;
    }
    if (pressed(GLFW_KEY_DELETE)) delete_selection(ctx);
    if (ctrl_pressed(GLFW_KEY_Z) || ctrl_pressed(GLFW_KEY_Y)) {
        const bool redo = ctrl_pressed(GLFW_KEY_Y) || shift_with(GLFW_KEY_Z);
        if (redo ? model.redo() : model.undo()) ctx.messages.error.clear();
        return;
    }
    // Camera bookmarks: Ctrl+1..9 stores the view, Shift+1..9 recalls it (1 and 0 alone zoom).
    for (size_t i = 0; i < in.key_presses.size(); ++i) {
        const int n = in.key_presses[i] - GLFW_KEY_0, mods = in.key_mods[i];
        if (n < 1 || n > 9 || !(mods & (GLFW_MOD_CONTROL | GLFW_MOD_SHIFT))) continue;
        model.seal_undo_step();
        const std::string name = bookmark_id(n);
        if (mods & GLFW_MOD_CONTROL) {
            if (ctx.edit(Edit::bookmark, [&](Scene& s, ViewerSettings&) { store_bookmark(s, n); }, name))
                ctx.messages.show_status("stored the view as " + name + " (Shift+" + std::to_string(n) + " recalls it)");
        } else if (find_bookmark(model.scene(), n) < 0) {
            ctx.messages.show_status("no " + name + " yet (Ctrl+" + std::to_string(n) + " stores the view)");
        } else {
            ctx.edit(Edit::camera, [&](Scene& s, ViewerSettings&) { recall_bookmark(s, n); }, name);
        }
    }
    view_keys(ctx, in);
    if (pressed(GLFW_KEY_HOME) || pressed(GLFW_KEY_R)) {
        model.seal_undo_step();
        model.reset_view();
    }
    if (pressed(GLFW_KEY_RIGHT_BRACKET) || pressed(GLFW_KEY_LEFT_BRACKET)) {
        const int spp = model.settings().render.target_spp;
        model.seal_undo_step();
        model.set_target_spp(pressed(GLFW_KEY_RIGHT_BRACKET) ? std::min(spp * 2, 1 << 24) : std::max(1, spp / 2));
    }
    if (pressed(GLFW_KEY_M)) {
        start_grab(ctx, in);
        if (in.grab) return;
    }
    // E / Shift+E: the display's exposure up / down by half a stop, as tev's keys (one undo
    // step each, a display edit as the Tone map panel's). In fly mode E flies up instead.
    if (!ui.nav.fly && !io.KeyCtrl)
        for (size_t i = 0; i < in.key_presses.size(); ++i) {
            if (in.key_presses[i] != GLFW_KEY_E) continue;
            const double step = (in.key_mods[i] & GLFW_MOD_SHIFT) ? -kExposureKeyStep : kExposureKeyStep;
            const double ev = std::clamp(model.settings().tone.exposure + step, -kMaxExposureStops, kMaxExposureStops);
            model.seal_undo_step();
            if (ctx.edit(Edit::tone_map, [&](Scene&, ViewerSettings& s) { s.tone.exposure = ev; }, "exposure"))
                ctx.messages.show_status("exposure " + format_ev(ev) + " EV (E / Shift+E; Ctrl+Z undoes)");
        }
    if (pressed(GLFW_KEY_F)) ui.pick_focus = !ui.pick_focus;
    if (pressed(GLFW_KEY_G)) ui.nav.fly = !ui.nav.fly;
    // B: the next left drag draws the render region; Shift+B: the whole image again.
    if (pressed(GLFW_KEY_B)) {
        if (shift_with(GLFW_KEY_B)) ui.region.reset(), ui.drawing_region = false;
        else ui.drawing_region = !ui.drawing_region;
    }
    if (!io.KeyCtrl) zoom_keys(ctx, in);  // (zoom_keys skips presses made with Ctrl)
    if (pressed(GLFW_KEY_SPACE))
        ctx.edit(Edit::run_control, [](Scene&, ViewerSettings& s) { s.paused = !s.paused; });
    if (io.KeyCtrl) {
        in.motion_keys_held = false;
        in.key_orbit.reset();
        return;
    }
    // Held keys move the camera at rates per second: arrows orbit, W/S dolly, A/D and Page Up/Down pan.
    // A chord's key stays no camera key until it is released (Ctrl let go before the S).
    auto held = [&](int key) { return int(ImGui::IsKeyDown(key) && !in.held_in_chord(key)); };
    KeyMotion keys;
    keys.orbit_x = held(GLFW_KEY_RIGHT) - held(GLFW_KEY_LEFT);
    keys.orbit_y = held(GLFW_KEY_DOWN) - held(GLFW_KEY_UP);
    keys.pan_x = held(GLFW_KEY_A) - held(GLFW_KEY_D);
    // Q / E fly down / up in fly mode; out of it, E is the exposure key and Page Up / Page
    // Down pan up / down.
    keys.pan_y = ui.nav.fly ? held(GLFW_KEY_E) - held(GLFW_KEY_Q) : held(GLFW_KEY_PAGE_UP) - held(GLFW_KEY_PAGE_DOWN);
    keys.dolly = held(GLFW_KEY_S) - held(GLFW_KEY_W);
    if (keys.any()) {
        // The time since the previous frame with keys held; a first frame moves one 60 Hz step.
        const double dt = in.motion_keys_held ? std::clamp(std::chrono::duration<double>(now - in.last_motion).count(), 0.0, 0.1) : 1.0 / 60;
        const int h = model.scene().renderer.height;
        const NavigationSettings& nav = ui.nav;
        const int active = model.scene().camera;
        // The arrows orbit about the target as a drag does (KeyOrbitGesture); anything else
        // that moved the camera meanwhile (another key, a drag, undo) starts a new turn from there.
        const bool orbiting = !nav.fly && (keys.orbit_x || keys.orbit_y);
        if (!orbiting || (in.key_orbit && (in.key_orbit->last.position != model.camera().position || in.key_orbit->last.target != model.camera().target))) in.key_orbit.reset();
        if (orbiting && !in.key_orbit) in.key_orbit = InputState::KeyOrbit{KeyOrbitGesture{model.camera()}, model.camera()};
        ctx.edit(Edit::camera, [&](Scene& s, ViewerSettings&) {
            Camera& cam = s.cameras[size_t(active)];
            if (orbiting) cam = in.key_orbit->gesture.hold(s, keys.orbit_x, keys.orbit_y, dt, nav);
            KeyMotion rest = keys;
            if (orbiting) rest.orbit_x = rest.orbit_y = 0;
            if (rest.any()) {
                // Pan, dolly and fly move along straight lines: stopped at the first surface on
                // the way, wherever the frames cut it.
                const Camera before = cam;
                apply_key_motion(cam, rest, dt, h, nav);
                if (nav.stop_at_surfaces) keep_outside(s, before, cam);
            }
        }, "camera keys", "keys");
        if (in.key_orbit) in.key_orbit->last = model.camera();
    } else {
        in.key_orbit.reset();
    }
    in.motion_keys_held = keys.any();
    in.last_motion = now;
}

}  // namespace

WindowRequests handle_input(PanelContext& ctx, InputState& in) {
    WindowRequests requests;
    if (!ctx.model.has_scene()) {
        window_keys(ctx, in, requests);
        in.key_presses.clear();
        in.key_mods.clear();
        return requests;
    }
    handle_mouse(ctx, in, ctx.image_rect());
    handle_keys(ctx, in, requests);
    in.key_presses.clear();
    in.key_mods.clear();
    // One drag, one held key, one move (M) or one field's edit is one undo step: seal it
    // once nothing is held. (A move redraws only as the pointer moves: it is not `moving`.)
    if (!in.moving() && !in.grab && !ImGui::IsAnyItemActive()) ctx.model.seal_undo_step();
    return requests;
}

}  // namespace kr::viewer
