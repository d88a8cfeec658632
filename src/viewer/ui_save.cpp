// The Save panel and its overwrite question (ImGui); what it writes: viewer/save_dialog.h.
#include <filesystem>
#include <string>

#include <imgui.h>
#include <imgui_stdlib.h>

#include "viewer/save_dialog.h"
#include "viewer/ui_app.h"

namespace kr::viewer {

namespace fs = std::filesystem;

void ViewerApp::reset_save_paths() {
    if (model_.has_scene()) save_paths_ = SavePaths::for_scene(model_.scene());
}

void ViewerApp::panel_save() {
    if (!ImGui::CollapsingHeader("Save", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const bool full = ui_.shown && ui_.shown->generation == model_.generation() && ui_.shown->scale == 1;
    ImGui::InputText("image", &save_paths_.image);
    ImGui::BeginDisabled(!full);
    // Each image as `render -o` writes it, the path's extension set to match.
    if (ImGui::Button("Save PPM")) request_save(SaveKind::ppm, image_save_path(SaveKind::ppm, save_paths_.image));
    ImGui::EndDisabled();
    ImGui::InputText("png", &save_paths_.png);
    ImGui::BeginDisabled(!full);
    if (ImGui::Button("Save PNG")) request_save(SaveKind::png, image_save_path(SaveKind::png, save_paths_.png));
    ImGui::EndDisabled();
    // The radiance as floats: OpenEXR (with every layer) or PFM (and the depth beside it).
    ImGui::InputText("hdr", &save_paths_.hdr);
    ImGui::BeginDisabled(!full);
    if (ImGui::Button("Save EXR")) request_save(SaveKind::exr, image_save_path(SaveKind::exr, save_paths_.hdr));
    ImGui::SameLine();
    if (ImGui::Button("Save PFM")) request_save(SaveKind::pfm, image_save_path(SaveKind::pfm, save_paths_.hdr));
    ImGui::EndDisabled();
    ImGui::InputText("scene", &save_paths_.scene);
    if (ImGui::Button("Save scene JSON")) request_save(SaveKind::scene, save_paths_.scene);
    ImGui::TextDisabled("messages appear in the status bar");
}

void ViewerApp::request_save(SaveKind kind, const fs::path& path) {
    // Never overwrite silently (an image's depth file included): the popup asks.
    for (const fs::path& target : save_targets(kind, path)) {
        std::error_code ec;
        if (!fs::exists(target, ec)) continue;
        pending_save_ = std::make_pair(kind, path);
        ImGui::OpenPopup("Overwrite?");
        return;
    }
    save_now(kind, path);
}

void ViewerApp::overwrite_popup() {
    if (!ImGui::BeginPopupModal("Overwrite?", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
    ImGui::Text("%s already exists. Overwrite it?", pending_save_ ? pending_save_->second.string().c_str() : "");
    if (ImGui::Button("Overwrite")) {
        if (pending_save_) save_now(pending_save_->first, pending_save_->second);
        pending_save_.reset();
        ImGui::CloseCurrentPopup();
    }
    ImGui::SameLine();
    if (ImGui::Button("Cancel")) {
        pending_save_.reset();
        messages_.status = "not saved";
        ImGui::CloseCurrentPopup();
    }
    ImGui::EndPopup();
}

void ViewerApp::save_now(SaveKind kind, const fs::path& path) {
    try {
        messages_.status = save_output(kind, path, model_, ui_.shown.get(), ui_.compare.convergence.csv());
        // Saving over the watched file should not read like an outside change.
        std::error_code ec;
        if (kind == SaveKind::scene && fs::equivalent(path, ui_.files.watch.file(), ec)) ui_.files.watch.acknowledge();
    } catch (const std::exception& e) {
        messages_.status = std::string("save failed: ") + e.what();
    }
}

}  // namespace kr::viewer
