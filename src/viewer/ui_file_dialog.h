// The window's file dialogs (viewer/file_browser.h is their model): Open scene, Open image B,
// Save scene as, Save image as, each the platform's chooser (zenity) where there is one, else
// an ImGui folder browser; the recent files; files dropped on the window; the UI scale.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "viewer/file_browser.h"
#include "viewer/ui_context.h"

namespace kr::viewer {

// The popup's name (an ImGui ID, begun at the top level by ViewerApp::draw_questions).
inline constexpr const char* kFileDialogPopup = "###file dialog";

// Reads the settings file (recent files, UI scale) into `ui.files`; a bad one is ignored with
// a message. `use_file` false (scripted runs): none is read or ever written.
void load_viewer_settings(PanelContext& ctx, bool use_file);
// Notes `file` as the newest recent scene or image B and writes the settings file.
void note_recent_file(PanelContext& ctx, FilePurpose purpose, const std::filesystem::path& file);
// Sets the UI scale the user chose (clamped), kept in the settings file.
void set_ui_scale(PanelContext& ctx, double scale);

// Opens the dialog for `purpose`: the platform's chooser, else the ImGui browser, starting
// at the folder of the file in question (the scene's, image B's, the Save panel's path).
void open_file_dialog(PanelContext& ctx, FilePurpose purpose);
// What a dialog's chosen file does: opens the scene (asking first with unsaved edits), makes
// the image image B, or saves (asking before it overwrites).
void file_chosen(PanelContext& ctx, FilePurpose purpose, const std::filesystem::path& file);
// The ImGui browser, drawn every frame after the other windows (Return: `confirm`, Esc: `cancel`).
void file_dialog_popup(PanelContext& ctx, bool cancel, bool confirm);
// The platform's chooser: its answer once it has ended (called every loop, never blocks).
bool poll_file_chooser(PanelContext& ctx);
// The files dropped on the window since the last frame (glfwSetDropCallback, --drop).
void handle_drops(PanelContext& ctx);
// The status file's dialog= ("none", "open-scene", ..., "chooser" while zenity runs) and
// folder= (the browser's folder).
std::string file_dialog_word(const UiState& ui);
// A drop-down of the recent scenes or images B; true when one was taken (file_chosen).
bool recent_files_combo(PanelContext& ctx, FilePurpose purpose, const char* label);

}  // namespace kr::viewer
