// The Scene panel: the file shown, the scenes beside it and the bundled ones, reload, undo
// and redo, the loader's warnings.
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <imgui.h>

#include "scene/scene_list.h"
#include "viewer/ui_panels.h"

namespace kr::viewer {

namespace fs = std::filesystem;

void panel_scene(PanelContext& ctx) {
    if (!ImGui::CollapsingHeader("Scene", ImGuiTreeNodeFlags_DefaultOpen)) return;
    SceneFiles& files = ctx.ui.files;
    ViewerModel& model = ctx.model;
    const fs::path current = files.watch.file();
    ImGui::TextWrapped("%s", current.string().c_str());
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
    if (ImGui::BeginCombo("open", current.filename().string().c_str())) {
        for (const SceneChoice& c : files.choices) {
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
    for (const std::string& w : model.warnings()) ImGui::TextWrapped("warning: %s", w.c_str());
}

}  // namespace kr::viewer
