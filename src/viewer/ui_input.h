// The mouse and the keys on the image, once per frame (the panels take them while the
// pointer is over them): orbit, pan and dolly drags, the wheel, focus and probe clicks, the
// split view's divider, zoom, the camera keys, undo, the window's own keys.
#pragma once

#include <optional>
#include <utility>
#include <vector>

#include "viewer/navigation.h"
#include "viewer/ui_context.h"

namespace kr::viewer {

struct InputState {
    DragGesture drags[3];        // left: orbit (fly: look), right: pan, middle: pan the image (Shift: dolly)
    Vec3 pivot;                  // what the left drag orbits about: the surface under the press, or the target
    std::optional<int> press_pick;   // the primitive under the left press (a click selects it)
    // M: the selection follows the pointer (no button held) until a click or Return places
    // it, or Esc or a right click puts it back. A left drag never moves it: it orbits.
    struct Grab {
        int primitive = -1;
        Vec3 start;                  // its centre when the move began
        double x = 0, y = 0;         // the pointer then, framebuffer pixels
        int axis = -1;               // X, Y or Z pressed: along that world axis only
        bool moved = false;          // an edit was made (Esc undoes it)
    };
    std::optional<Grab> grab;
    bool divider_drag = false;   // the left button holds the split view's divider
    bool middle_pans = false;    // the middle drag pans the image (not Shift+middle: that dollies)
    double pan_last_x = 0, pan_last_y = 0;  // the middle pan so far, framebuffer pixels
    bool motion_keys_held = false;
    UiClock::time_point last_motion{};  // previous frame with motion keys held
    // Keys pressed since the last frame, as GLFW reported them. ImGui 1.86 (Debian 12) keeps
    // only whether a key is down at each frame, so a press and release between two frames
    // (a short tap on a busy machine) never shows in ImGui::IsKeyPressed.
    std::vector<int> key_presses;
    std::vector<int> key_mods;  // each press's modifiers (GLFW_MOD_*), as the event had them
    // Keys pressed with Ctrl, Alt or Super and not yet released: a chord's key (the S of
    // Ctrl+S, the D of Ctrl+D) is no camera key even when the modifier goes up first.
    std::vector<int> chord_keys;
    // Where each button went down and up, by the events: the pointer's last motion before
    // each. ImGui 1.86 reads the pointer at the frame that sees a press or release, which on a
    // busy machine can be after the pointer moved on (a drag, a click's selection or a region
    // would start late, or lose its last move); apply_button_positions gives the frame the
    // events' positions instead.
    using Point = std::pair<double, double>;  // window points
    std::optional<Point> cursor;              // none before the first motion
    bool cursor_inside = false;               // the pointer is over the window (by its enter/leave events)
    std::optional<Point> press_at[3], release_at[3];
    // The modifiers (GLFW_MOD_*) of each button's first press since the last frame, by its
    // event, and of the press this frame sees as a click: Shift+click and Ctrl+click go by the
    // press's own modifiers, not the keys ImGui has been handed by the frame (the key queue
    // can hold a modifier's release, or lag behind a burst of input).
    int press_mods[3] = {0, 0, 0};
    int clicked_mods[3] = {0, 0, 0};
    std::optional<Point> released_here[3];    // where the button this frame sees released went up
    std::optional<Point> wheel_at, wheel_here;  // the pointer at the last wheel event (zoom's centre)
    // Shift held, by the key events (not the keys the queue has handed ImGui yet), and as it
    // was at the last wheel event: Shift+wheel dollies, the wheel zooms.
    bool shift_down = false, wheel_shift = false, wheel_shift_here = false;
    // By the events, not the frames: each button held, where it went down, and where the
    // pointer's motion first went more than kDragThresholdPixels from there (the drag's start).
    bool event_down[3] = {false, false, false};
    Point event_press[3];
    std::optional<Point> drag_from[3];

    // A key as the frame's queue hands it over (note_key), and as GLFW reports it (note_key_event).
    void note_key(int key, int action, int mods = 0);
    void note_key_event(int key, int action);
    void note_cursor(double x, double y);
    void note_button(int button, int action, int mods = 0);
    void note_wheel() {
        wheel_at = cursor;
        wheel_shift = shift_down;
    }
    void note_enter(bool entered) { cursor_inside = entered; }
    // After the backend's NewFrame, before ImGui::NewFrame: the frame's pointer is where the
    // events handled so far left it. The GLFW backend reads the pointer from the X server
    // (XQueryPointer), which on a busy machine is ahead of the events: a drag would start
    // from a position no motion event had reached, and end a different length.
    void apply_pointer();
    // After ImGui::NewFrame: each button ImGui sees clicked this frame gets the position of
    // its press event as io.MouseClickedPos, and each it sees released its release's as
    // released_here; the wheel's turns since the last frame, the last one's as wheel_here.
    void apply_button_positions();
    // `key` was pressed since the last frame with Ctrl held (by its event, not the frame's state).
    bool pressed_with_ctrl(int key) const;
    // `key` went down as part of a chord and is still held.
    bool held_in_chord(int key) const;
    // The buttons held on the image for --status-file: 1 left, 2 right, 4 middle, 8 the divider.
    int pressed_bits() const;
    // Held arrow keys orbit as a drag does: the whole turn since they went down, from the
    // camera then (orbit_step), so a wall slides the camera the same whatever the frame rate.
    struct KeyOrbit {
        KeyOrbitGesture gesture;
        Camera last;                 // the camera as the arrows last left it
    };
    std::optional<KeyOrbit> key_orbit;
    // A held button or camera key: the window redraws at its frame rate.
    bool moving() const;
};

// What the keys ask of the window itself.
struct WindowRequests {
    bool toggle_fullscreen = false;  // F11 (pressed an odd number of times)
    bool quit = false;               // Esc
    bool cancel_question = false;    // Esc while a question is open: its safe answer
    bool confirm_question = false;   // Return while a question is open (the save-where question: Save)
};

WindowRequests handle_input(PanelContext& ctx, InputState& input);

}  // namespace kr::viewer
