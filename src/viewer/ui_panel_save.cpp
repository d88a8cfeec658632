// The Save panel and its overwrite question; what it writes: viewer/save_dialog.h.
#include <filesystem>
#include <string>

#include <imgui.h>
#include <imgui_stdlib.h>

#include "core/text.h"
#include "viewer/save_dialog.h"
#include "viewer/ui_file_dialog.h"
#include "viewer/ui_panels.h"
#include "viewer/ui_widgets.h"

namespace kr::viewer {

namespace fs = std::filesystem;

void panel_save(PanelContext& ctx) {
    if (!ImGui::CollapsingHeader("Save", ImGuiTreeNodeFlags_DefaultOpen)) return;
    SavePaths& paths = ctx.ui.save.paths;
    const bool full = ctx.full_frame() != nullptr;
    // The image as `render -o` writes it, in each format of the table (core/image_formats.h),
    // the path's extension set to match.
    ImGui::InputText("image", &paths.image);
    ImGui::BeginDisabled(!full);
    for (const ImageFormatInfo& format : kImageFormats) {
        if (&format != &kImageFormats.front()) ImGui::SameLine();
        if (ImGui::Button((std::string("Save ") + format.name).c_str()))
            request_save(ctx, format.format, image_save_path(format.format, paths.image));
        if (ImGui::IsItemVisible()) mark_item(ctx, std::string("save:") + (format.extension + 1));
    }
    // Any folder and name (the file chooser, else the built-in browser); its extension picks the format.
    if (ImGui::Button("Save image as...")) {
        ctx.ui.files.browser_name = format_info(image_save_kind(paths.image).format).extension;
        open_file_dialog(ctx, FilePurpose::save_image);
    }
    ImGui::EndDisabled();
    ImGui::InputText("scene", &paths.scene);
    // Save As: the file becomes the scene's (watched, in the title, saved); a copy leaves it.
    if (ImGui::Button("Save scene as")) request_save(ctx, SaveKind::scene, paths.scene);
    ImGui::SameLine();
    if (ImGui::Button("Save as... (Ctrl+Shift+S)")) open_file_dialog(ctx, FilePurpose::save_scene);
    ImGui::SameLine();
    if (ImGui::Button("Save a copy")) request_save(ctx, SaveKind::scene_copy, paths.scene);
    if (ImGui::Button("Save (Ctrl+S)")) save_scene_in_place(ctx);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("over the scene's own file");
    ImGui::TextDisabled("messages appear in the status bar");
}

namespace {

void save_now(PanelContext& ctx, SaveKind kind, const fs::path& path) {
    if (save_waits_for_halves(kind, ctx.model, ctx.ui.shown.get())) {
        ctx.ui.save.waiting = SaveTool::Waiting{kind, path, ctx.model.generation()};
        ctx.messages.show_status("saving " + show_user_text(path.string()) + " with the next frame");
        return;
    }
    try {
        ctx.messages.show_status(save_output(kind, path, ctx.model, ctx.ui.shown.get(), ctx.ui.compare.convergence.csv()));
        // Saving over the watched file should not read like an outside change; Save As
        // watches the new file.
        std::error_code ec;
        FileWatch& watch = ctx.ui.files.watch;
        if (kind.what == SaveKind::scene_copy && fs::equivalent(path, watch.file(), ec)) watch.acknowledge();
        if (kind.what == SaveKind::scene) {
            watch.watch(path);
            ctx.ui.save.read_only = false;
            note_recent_file(ctx, FilePurpose::open_scene, path);
        }
    } catch (const std::exception& e) {
        ctx.messages.show_error(std::string("save failed: ") + e.what());
    }
}

}  // namespace

void finish_waiting_save(PanelContext& ctx) {
    auto& waiting = ctx.ui.save.waiting;
    if (!waiting) return;
    if (waiting->generation != ctx.model.generation()) {
        ctx.messages.show_error("not saved: " + show_user_text(waiting->path.string()) +
                                ": the image changed before its next frame came");
        waiting.reset();
        return;
    }
    if (save_waits_for_halves(waiting->kind, ctx.model, ctx.ui.shown.get())) return;
    const SaveTool::Waiting now = *waiting;
    waiting.reset();
    save_now(ctx, now.kind, now.path);
}

void save_scene_in_place(PanelContext& ctx) {
    if (!ctx.model.has_scene()) return;
    // A bundled scene of the install tree (or a file that cannot be written) is never saved
    // over: Save asks where, and the file named there becomes the scene's.
    if (ctx.ui.save.read_only) {
        ctx.ui.save.ask_where = true;
        return;
    }
    save_now(ctx, SaveKind::scene, ctx.ui.files.watch.file());
}

void request_save(PanelContext& ctx, SaveKind kind, const fs::path& path) {
    // Never overwrite silently (an image's depth file included): the popup asks.
    for (const fs::path& target : save_targets(kind, path)) {
        std::error_code ec;
        if (!fs::exists(target, ec)) continue;
        ctx.ui.save.pending = std::make_pair(kind, path);
        ctx.ui.save.ask_overwrite = true;
        return;
    }
    save_now(ctx, kind, path);
}

void overwrite_popup(PanelContext& ctx, bool cancel, bool confirm) {
    // Save of a read-only scene: where to (the Save panel's scene path, the current folder's
    // NAME.json by default); an existing file is then asked about as any other.
    if (ctx.ui.save.ask_where) {
        ImGui::OpenPopup(kSaveWhereQuestion);
        ctx.ui.save.ask_where = false;
    }
    if (ImGui::BeginPopupModal(kSaveWhereQuestion, nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        ImGui::Text("%s is read-only. Save the scene as:", ctx.ui.files.watch.file().filename().string().c_str());
        // The name is typed at once; Return saves as the button does.
        if (ImGui::IsWindowAppearing()) ImGui::SetKeyboardFocusHere();
        const bool entered =
            ImGui::InputText("##where", &ctx.ui.save.paths.scene, ImGuiInputTextFlags_EnterReturnsTrue);
        if (ImGui::Button("Save") || entered || confirm) {
            ImGui::CloseCurrentPopup();
            request_save(ctx, SaveKind::scene, ctx.ui.save.paths.scene);
        }
        ImGui::SameLine();
        // Another folder: the file dialog, starting at the name given here.
        if (ImGui::Button("Browse...")) {
            ImGui::CloseCurrentPopup();
            open_file_dialog(ctx, FilePurpose::save_scene);
        }
        ImGui::SameLine();
        if (ImGui::Button("Cancel") || cancel) {
            ctx.messages.show_status("not saved");
            ImGui::CloseCurrentPopup();
        }
        ImGui::EndPopup();
        return;
    }
    auto& pending = ctx.ui.save.pending;
    if (ctx.ui.save.ask_overwrite) {
        ImGui::OpenPopup(kOverwriteQuestion);
        ctx.ui.save.ask_overwrite = false;
    }
    if (!ImGui::BeginPopupModal(kOverwriteQuestion, nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
    ImGui::Text("%s already exists. Overwrite it?", pending ? pending->second.string().c_str() : "");
    if (ImGui::Button("Overwrite")) {
        if (pending) save_now(ctx, pending->first, pending->second);
        pending.reset();
        ImGui::CloseCurrentPopup();
    }
    ImGui::SameLine();
    if (ImGui::Button("Cancel") || cancel) {
        pending.reset();
        ctx.messages.show_status("not saved");
        ImGui::CloseCurrentPopup();
    }
    ImGui::EndPopup();
}

}  // namespace kr::viewer
