// The window's key and text events, held in order and handed to ImGui a frame's worth at a
// time. ImGui 1.86 (Debian 12) keeps only whether a key is down when a frame starts, so a
// key pressed and released between two frames (a quick Enter, Ctrl+A on a busy machine)
// never shows as pressed to its text fields. Here such a release waits for the next frame,
// as ImGui 1.87's "input trickling" does: every press is down for at least one frame, and
// text keeps its order with the keys that edit it. GL-free (the GLFW values are copied).
#pragma once

#include <deque>
#include <vector>

namespace kr::viewer {

struct KeyEvent {
    bool text = false;       // a typed character (codepoint), else a key event
    int key = 0, scancode = 0, action = 0, mods = 0;  // as GLFW reports them
    unsigned codepoint = 0;
};

class KeyEventQueue {
public:
    // GLFW's values (ui_app.cpp checks them against glfw3.h).
    static constexpr int kRelease = 0, kPress = 1, kRepeat = 2;
    static constexpr int kModCtrl = 0x2, kModAlt = 0x4, kModSuper = 0x8;
    static constexpr int kFirstNonText = 256;             // GLFW_KEY_ESCAPE: keys below type text
    static constexpr int kFirstModifier = 340, kLastModifier = 347;  // GLFW_KEY_LEFT_SHIFT .. RIGHT_SUPER

    void push(const KeyEvent& e);
    // The events for the next frame, oldest first, up to the first that would hide one of
    // them from the frame: a second change of a key already pressed or released in it, a
    // modifier that changes after a key's press in it (the key would be seen with the
    // modifiers as they are at the frame's start), or text after a key that edits text
    // (Enter, Backspace, arrows, a Ctrl chord) pressed in it (ImGui applies a frame's text
    // before its keys). At least one event when any is queued.
    std::vector<KeyEvent> take_frame();
    bool empty() const { return pending_.empty(); }

private:
    std::deque<KeyEvent> pending_;
};

}  // namespace kr::viewer
