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
// Asks before quitting with unsaved edits (opened when `asked`): save them and quit (Ctrl+S's
// save: over the scene's file, or, `save_asks_where`, a bundled or read-only scene's copy
// where the user says; Return, `confirm`), quit without saving, or stay (Esc).
enum class QuitAnswer { none, save_and_quit, quit, stay };
QuitAnswer quit_popup(bool& asked, bool cancel, bool confirm = false, bool save_asks_where = false);
// Asks before an open or reload drops unsaved edits (SceneFiles::pending_open).
void discard_popup(PanelContext& ctx, bool cancel);
// The question open (called at the top level): "quit", "discard", "overwrite" or "none".
const char* open_question();

}  // namespace kr::viewer
