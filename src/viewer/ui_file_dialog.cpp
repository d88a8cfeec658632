#include "viewer/ui_file_dialog.h"

#include <algorithm>
#include <cmath>
#include <system_error>

#include <imgui.h>
#include <imgui_internal.h>  // GetTopMostPopupModal: never a dialog over an open question
#include <imgui_stdlib.h>

#include "core/file_write.h"
#include "core/text.h"
#include "viewer/ui_compare.h"

namespace kr::viewer {

namespace fs = std::filesystem;

namespace {

void write_settings(PanelContext& ctx) {
    SceneFiles& files = ctx.ui.files;
    if (files.settings_file.empty()) return;
    try {
        write_settings_file(files.settings_file, files.settings);
    } catch (const std::exception& e) {
        // Said once: the recent files then live for this session only.
        ctx.messages.show_error(std::string("cannot keep the recent files: ") + e.what());
        files.settings_file.clear();
    }
}

// The folder and name a dialog starts with: beside the file in question.
std::pair<fs::path, std::string> dialog_start(const PanelContext& ctx, FilePurpose purpose) {
    const UiState& ui = ctx.ui;
    fs::path file;
    switch (purpose) {
        case FilePurpose::open_scene: file = ui.files.watch.file(); break;
        case FilePurpose::open_image:
            file = ui.compare.reference_path.empty() ? ui.files.watch.file().parent_path() / ""
                                                     : fs::path(ui.compare.reference_path);
            break;
        case FilePurpose::save_scene: file = ui.save.paths.scene; break;
        case FilePurpose::save_image: file = ui.save.paths.image; break;
    }
    std::error_code ec;
    fs::path folder = fs::absolute(file.parent_path().empty() ? fs::path(".") : file.parent_path(), ec);
    // A bundled scene's copy goes where the user works, not into the install tree.
    if (purpose == FilePurpose::save_scene && ui.save.read_only && file.parent_path().empty()) folder = fs::current_path(ec);
    const std::string name = purpose_saves(purpose) ? file.filename().string() : std::string();
    return {folder, name};
}

}  // namespace

void load_viewer_settings(PanelContext& ctx, bool use_file) {
    SceneFiles& files = ctx.ui.files;
    files.settings_file.clear();
    if (!use_file) return;
    const fs::path dir = config_dir();
    if (dir.empty()) return;
    files.settings_file = dir / kSettingsFileName;
    LoadedSettings loaded = read_settings_file(files.settings_file);
    files.settings = std::move(loaded.settings);
    if (files.settings.ui_scale) files.ui_scale = *files.settings.ui_scale;
    if (!loaded.problem.empty()) ctx.messages.show_error(loaded.problem);
}

void note_recent_file(PanelContext& ctx, FilePurpose purpose, const fs::path& file) {
    SceneFiles& files = ctx.ui.files;
    std::vector<fs::path>& list = purpose == FilePurpose::open_image ? files.settings.images : files.settings.scenes;
    const std::vector<fs::path> before = list;
    note_recent(list, file);
    if (list != before) write_settings(ctx);
}

void set_ui_scale(PanelContext& ctx, double scale) {
    SceneFiles& files = ctx.ui.files;
    scale = std::clamp(std::round(scale * 100) / 100, ViewerSettingsFile::kMinUiScale, ViewerSettingsFile::kMaxUiScale);
    if (scale == files.ui_scale && files.settings.ui_scale == scale) return;
    files.ui_scale = scale;
    files.settings.ui_scale = scale;
    write_settings(ctx);
}

void open_file_dialog(PanelContext& ctx, FilePurpose purpose) {
    SceneFiles& files = ctx.ui.files;
    // One at a time, and never over a question (opening it would close the question unanswered).
    if (files.browser || (files.chooser && files.chooser->running()) || ImGui::GetTopMostPopupModal()) return;
    const auto [folder, name] = dialog_start(ctx, purpose);
    if (const std::string chooser = native_chooser(); !chooser.empty()) {
        files.chooser = std::make_shared<ChildChooser>();
        if (files.chooser->start(zenity_arguments(purpose, folder, name), purpose)) {
            ctx.messages.show_status(std::string(purpose_title(purpose)) + ": in the file chooser");
            return;
        }
        // It would not start: the browser, saying why.
        ctx.messages.show_error(files.chooser->error + "; using the built-in browser");
        files.chooser.reset();
    }
    files.browser.emplace(purpose, folder, name);
    files.open_browser = true;
    files.browser_frames = 0;
}

void file_chosen(PanelContext& ctx, FilePurpose purpose, const fs::path& file) {
    switch (purpose) {
        case FilePurpose::open_scene: open_scene_asking(ctx, file); break;
        case FilePurpose::open_image:
            if (load_reference(ctx, file, false)) {
                ctx.ui.compare.comparison.settings.b = -1;  // image B is the reference
                ctx.messages.show_status("image B: " + show_user_text(file.string()));
            }
            break;
        case FilePurpose::save_scene:
            ctx.ui.save.paths.scene = file.string();
            request_save(ctx, SaveKind::scene, file);
            break;
        case FilePurpose::save_image:
            if (!format_by_extension(file)) {
                ctx.messages.show_error(quoted_path(file) + ": expected one of " + filter_words(purpose));
                break;
            }
            ctx.ui.save.paths.image = file.string();
            request_save(ctx, image_save_kind(file), file);
            break;
    }
}

bool poll_file_chooser(PanelContext& ctx) {
    SceneFiles& files = ctx.ui.files;
    if (!files.chooser) return false;
    const auto result = files.chooser->poll();
    if (!result) return false;
    const FilePurpose purpose = files.chooser->purpose();
    files.chooser.reset();
    ctx.messages.status.clear();
    if (!result->error.empty()) ctx.messages.show_error(result->error);
    else if (result->file) file_chosen(ctx, purpose, *result->file);
    return true;
}

void handle_drops(PanelContext& ctx) {
    SceneFiles& files = ctx.ui.files;
    // While a question or a dialog is open the drop waits for its answer (opening another
    // question now would close it unanswered).
    if (files.drops.empty() || ImGui::GetTopMostPopupModal() || files.browser) return;
    const std::vector<fs::path> dropped = std::move(files.drops);
    files.drops.clear();
    std::string refused;
    for (const DropAction& a : plan_drop(dropped)) {
        if (a.kind == DropAction::scene) file_chosen(ctx, FilePurpose::open_scene, a.file);
        else if (a.kind == DropAction::image) file_chosen(ctx, FilePurpose::open_image, a.file);
        else if (refused.empty()) refused = a.error;  // the first: one line
    }
    if (!refused.empty()) ctx.messages.show_error(refused);
}

std::string file_dialog_word(const UiState& ui) {
    if (ui.files.chooser && ui.files.chooser->running()) return "chooser";
    // Once its name field has the keyboard (focused as it appeared): keys typed then reach it.
    if (ui.files.browser && ui.files.browser_frames >= 2) return purpose_word(ui.files.browser->purpose());
    return "none";
}

bool recent_files_combo(PanelContext& ctx, FilePurpose purpose, const char* label) {
    bool taken = false;
    const std::vector<fs::path> list =
        purpose == FilePurpose::open_image ? ctx.ui.files.settings.images : ctx.ui.files.settings.scenes;
    ImGui::BeginDisabled(list.empty());
    if (ImGui::BeginCombo(label, list.empty() ? "(none yet)" : list.front().filename().string().c_str(),
                          ImGuiComboFlags_HeightLargest)) {
        for (const fs::path& p : list) {
            std::error_code ec;
            const bool there = fs::is_regular_file(p, ec);
            // A file that went away stays listed, greyed: it may come back (a mounted disk).
            ImGui::BeginDisabled(!there);
            if (ImGui::Selectable((p.filename().string() + "##" + p.string()).c_str())) {
                file_chosen(ctx, purpose, p);
                taken = true;
            }
            ImGui::EndDisabled();
            if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
                ImGui::SetTooltip("%s%s", p.string().c_str(), there ? "" : " (not there now)");
        }
        ImGui::EndCombo();
    }
    ImGui::EndDisabled();
    return taken;
}

void file_dialog_popup(PanelContext& ctx, bool cancel, bool confirm) {
    SceneFiles& files = ctx.ui.files;
    if (!files.browser) return;
    FileBrowser& b = *files.browser;
    // One ID per purpose: a dialog's name field never starts with another's state.
    const std::string title = std::string(purpose_title(b.purpose())) + kFileDialogPopup + purpose_word(b.purpose());
    if (files.open_browser) {
        ImGui::OpenPopup(title.c_str());
        files.open_browser = false;
    }
    const ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowSize(ImVec2(std::min(io.DisplaySize.x * 0.9f, 40 * ImGui::GetFontSize()),
                                    std::min(io.DisplaySize.y * 0.85f, 32 * ImGui::GetFontSize())),
                             ImGuiCond_Appearing);
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x / 2, io.DisplaySize.y / 2), ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    bool open = true;
    if (!ImGui::BeginPopupModal(title.c_str(), &open)) {
        if (!ImGui::IsPopupOpen(title.c_str())) files.browser.reset();  // closed by its X
        return;
    }
    ++files.browser_frames;
    bool done = false;
    std::optional<fs::path> chosen;
    // The folder, and the way up.
    if (ImGui::Button("Up")) b.up();
    ImGui::SameLine();
    ImGui::TextWrapped("%s", b.folder().string().c_str());
    const float footer = 4 * ImGui::GetFrameHeightWithSpacing() + ImGui::GetTextLineHeightWithSpacing();
    // Folders first (a click enters them), then the files the filter passes (a click names
    // one, a double click takes it).
    if (ImGui::BeginChild("##entries", ImVec2(0, -footer), true)) {
        std::optional<std::string> enter;
        for (const BrowserEntry& e : b.entries()) {
            const std::string label = (e.folder ? e.name + "/" : e.name) + "##" + e.name;
            if (ImGui::Selectable(label.c_str(), !e.folder && b.name == e.name, ImGuiSelectableFlags_AllowDoubleClick)) {
                if (e.folder) enter = e.name;
                else {
                    b.name = e.name;
                    if (ImGui::IsMouseDoubleClicked(ImGuiMouseButton_Left)) chosen = b.accept(files.browser_name);
                }
            }
        }
        if (b.entries().empty()) ImGui::TextDisabled("(no folders or %s here)", filter_words(b.purpose()).c_str());
        if (enter) b.go(*enter);
    }
    ImGui::EndChild();
    // The name: typed at once; Return takes it (a folder's name enters the folder).
    if (ImGui::IsWindowAppearing() || files.focus_name) ImGui::SetKeyboardFocusHere();
    files.focus_name = false;
    const bool entered = ImGui::InputText("name", &b.name, ImGuiInputTextFlags_EnterReturnsTrue);
    bool all = b.show_all();
    if (ImGui::Checkbox("all files", &all)) b.set_show_all(all);
    ImGui::SameLine();
    ImGui::TextDisabled("shown: %s", all ? "all files" : filter_words(b.purpose()).c_str());
    if (!b.error().empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", b.error().c_str());
    else ImGui::TextDisabled("Return: open a folder or take the file; Esc: cancel");
    if (ImGui::Button(purpose_saves(b.purpose()) ? "Save" : "Open") || entered || confirm) chosen = b.accept(files.browser_name);
    ImGui::SameLine();
    if (ImGui::Button("Cancel") || cancel || !open) done = true;
    if (!purpose_saves(b.purpose())) {
        ImGui::SameLine();
        // A recent file taken from the list: the dialog's work is done.
        if (recent_files_combo(ctx, b.purpose(), "recent")) done = true;
    }
    if (chosen) done = true;
    // Still open after Return (a folder entered, or a name that did not fit): keep typing.
    else if (entered || confirm) files.focus_name = true;
    if (done) {
        const FilePurpose purpose = b.purpose();
        ImGui::CloseCurrentPopup();
        files.browser.reset();
        if (chosen) file_chosen(ctx, purpose, *chosen);
    }
    ImGui::EndPopup();
}

}  // namespace kr::viewer
