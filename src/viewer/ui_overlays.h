// The window around the panel column (ui_overlays.cpp).
#pragma once

#include "viewer/ui_context.h"

namespace kr::viewer {

// Two lines along the bottom: the render's state, spp, progress, time, rate and noise, then
// the most important message.
void draw_status_bar(PanelContext& ctx);
// The keys and mouse controls (F1 or ?).
void draw_help(UiState& ui);
// A refused edit, beside the pointer for a moment.
void draw_error_flash(const Messages& messages);
// The questions take Esc (`cancel`, from the frame's key presses: ImGui 1.86 misses a quick
// tap) as their safe answer.
// Asks before quitting with unsaved edits (opened when `asked`): true to quit now.
bool quit_popup(bool& asked, bool cancel);
// Asks before an open or reload drops unsaved edits (SceneFiles::pending_open).
void discard_popup(PanelContext& ctx, bool cancel);
// The question open (called at the top level): "quit", "discard", "overwrite" or "none".
const char* open_question();

}  // namespace kr::viewer
