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
    while (!pending_.empty()) {
        const KeyEvent& e = pending_.front();
        if (e.text) {
            if (editing_key && !out.empty()) break;
        } else if (e.action != kRepeat) {
            if (std::find(changed.begin(), changed.end(), e.key) != changed.end()) break;
            changed.push_back(e.key);
            const bool modifier = e.key >= kFirstModifier && e.key <= kLastModifier;
            const bool chord = e.mods & (kModCtrl | kModAlt | kModSuper);
            if (e.action == kPress && !modifier && (e.key >= kFirstNonText || chord)) editing_key = true;
        }
        out.push_back(e);
        pending_.pop_front();
    }
    return out;
}

}  // namespace kr::viewer
