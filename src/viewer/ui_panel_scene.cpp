// The Scene panel: the file shown, the scenes beside it and the bundled ones, reload, undo
// and redo, the loader's warnings.
#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <imgui.h>

#include "core/data_dir.h"
#include "scene/scene_list.h"
#include "viewer/ui_file_dialog.h"
#include "viewer/ui_panels.h"

namespace kr::viewer {

namespace fs = std::filesystem;

void panel_scene(PanelContext& ctx) {
    if (!ImGui::CollapsingHeader("Scene", ImGuiTreeNodeFlags_DefaultOpen)) return;
    SceneFiles& files = ctx.ui.files;
    ViewerModel& model = ctx.model;
    const fs::path current = files.watch.file();
    ImGui::TextWrapped("%s", current.string().c_str());
    // Any folder's scene (the platform's file chooser, else the built-in browser), the
    // recent ones, and image B from a file; dropping a file on the window does the same.
    if (ImGui::Button("Open... (Ctrl+O)")) open_file_dialog(ctx, FilePurpose::open_scene);
    ImGui::SameLine();
    if (ImGui::Button("Image B...")) open_file_dialog(ctx, FilePurpose::open_image);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("an image file as image B, the reference the compare views use");
    recent_files_combo(ctx, FilePurpose::open_scene, "recent scenes");
    recent_files_combo(ctx, FilePurpose::open_image, "recent images B");
    if (files.folders.empty()) {
        // The scene's own folder, then the bundled scenes' (default_scenes) and the examples'
        // (example_scenes); a file listed from two shows once.
        std::vector<fs::path> folders{current.parent_path().empty() ? fs::path(".") : current.parent_path()};
        std::vector<fs::path> bundled = default_scenes();
        for (fs::path& p : example_scenes()) bundled.push_back(std::move(p));
        for (const fs::path& p : bundled)
            if (std::find(folders.begin(), folders.end(), p.parent_path()) == folders.end())
                folders.push_back(p.parent_path());
        files.choices = scene_choices(folders);
        files.folders = folders;
    }
    // Every choice at once (as tall as the window allows), under a line per folder; a bundled
    // folder says that its scenes open as they ship and Save asks where.
    if (ImGui::BeginCombo("nearby", current.filename().string().c_str(), ImGuiComboFlags_HeightLargest)) {
        const std::optional<DataDir> data = data_dir();
        fs::path folder;
        for (size_t i = 0; i < files.choices.size(); ++i) {
            const SceneChoice& c = files.choices[i];
            if (i == 0 || c.path.parent_path() != folder) {
                folder = c.path.parent_path();
                if (i > 0) ImGui::Separator();
                const bool bundled = data && path_inside(c.path, data->path);
                ImGui::TextDisabled("%s%s", (folder.empty() ? std::string(".") : folder.string()).c_str(),
                                    bundled ? "  (bundled: Save asks where)" : "");
            }
            const std::string label = c.label + "##" + c.path.string();
            if (ImGui::Selectable(label.c_str(), c.path == current)) open_scene_asking(ctx, c.path);
        }
        ImGui::EndCombo();
    }
    if (ImGui::Button("Reload")) open_scene_asking(ctx, current);
    ImGui::SameLine();
    if (ImGui::Button("Rescan folder")) files.folders.clear();
    ImGui::SameLine();
    auto history = [&](const char* label, bool can, bool (ViewerModel::*step)()) {
        ImGui::BeginDisabled(!can);
        if (ImGui::Button(label)) {
            (model.*step)();
            ctx.messages.error.clear();
        }
        ImGui::EndDisabled();
    };
    history("Undo", model.can_undo(), &ViewerModel::undo);
    ImGui::SameLine();
    history("Redo", model.can_redo(), &ViewerModel::redo);
    ImGui::SameLine();
    if (ImGui::Button("Reset view")) model.reset_view();
    ImGui::TextDisabled("the file is watched: saving it in an editor reloads it");
    // The UI's size: times the monitor's content scale; kept with the recent files.
    // It applies when the slider is let go: the panel does not change size under the pointer.
    static std::optional<float> dragged;
    float scale = dragged.value_or(float(ctx.ui.files.ui_scale));
    if (ImGui::SliderFloat("UI scale", &scale, float(ViewerSettingsFile::kMinUiScale),
                           float(ViewerSettingsFile::kMaxUiScale), "%.2f"))
        dragged = scale;
    if (ImGui::IsItemDeactivated() && dragged) {
        set_ui_scale(ctx, *dragged);
        dragged.reset();
    }
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Ctrl+= / Ctrl+- / Ctrl+0; times the monitor's scale");
    // The loader's warnings under one line that is always there, folded: an edit that adds
    // or clears one moves no control under the pointer.
    const std::vector<std::string>& warnings = model.warnings();
    if (warnings.empty()) {
        ImGui::TextDisabled("no warnings");
    } else {
        const std::string head = std::to_string(warnings.size()) + (warnings.size() == 1 ? " warning" : " warnings") +
                                 "###warnings";
        ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.8f, 0.3f, 1.0f));
        const bool open = ImGui::TreeNode(head.c_str());
        ImGui::PopStyleColor();
        if (open) {
            for (const std::string& w : warnings) ImGui::TextWrapped("%s", w.c_str());
            ImGui::TreePop();
        }
    }
}

}  // namespace kr::viewer
