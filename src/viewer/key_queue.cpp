#include "viewer/key_queue.h"

#include <algorithm>

namespace kr::viewer {

void KeyEventQueue::push(const KeyEvent& e) {
    // Bounded: a flood of events (far more than a frame's worth) drops the newest.
    constexpr size_t kMaxPending = 4096;
    if (pending_.size() < kMaxPending) pending_.push_back(e);
}

std::vector<KeyEvent> KeyEventQueue::take_frame() {
    std::vector<KeyEvent> out;
    std::vector<int> changed;  // keys pressed or released in this frame
    bool editing_key = false;  // a key that edits text was pressed in this frame
    bool key_pressed = false;  // a key other than a modifier was pressed in this frame
    while (!pending_.empty()) {
        const KeyEvent& e = pending_.front();
        if (e.text) {
            if (editing_key && !out.empty()) break;
        } else if (e.action != kRepeat) {
            if (std::find(changed.begin(), changed.end(), e.key) != changed.end()) break;
            const bool modifier = e.key >= kFirstModifier && e.key <= kLastModifier;
            // ImGui reads the modifiers as they are when the frame starts: one that goes up
            // (or down) after a key's press in the same frame would take the chord from the
            // key (Ctrl+A's Ctrl released before its A: xdotool's order) or give it one.
            if (modifier && key_pressed) break;
            changed.push_back(e.key);
            const bool chord = e.mods & (kModCtrl | kModAlt | kModSuper);
            if (e.action == kPress && !modifier) key_pressed = true;
            if (e.action == kPress && !modifier && (e.key >= kFirstNonText || chord)) editing_key = true;
        }
        out.push_back(e);
        pending_.pop_front();
    }
    return out;
}

}  // namespace kr::viewer
