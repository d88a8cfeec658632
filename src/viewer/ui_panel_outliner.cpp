// The Outliner, above the tabs: every object, light and camera of the scene. A click on a row
// selects what the image's click selects (the same ctx.ui.selected; a point light, which has
// no sphere to click, as ctx.ui.selected_light) and shows the Object tab; a camera's row makes
// it the active camera (an undoable camera edit). "." or numpad-. frames the selection.
#include <algorithm>
#include <string>

#include <imgui.h>

#include "viewer/outliner.h"
#include "viewer/ui_panels.h"
#include "viewer/ui_widgets.h"

namespace kr::viewer {

void select_primitive(PanelContext& ctx, std::optional<int> primitive) {
    ctx.ui.selected = primitive;
    ctx.ui.selected_light.reset();
    ctx.ui.axis_lock = -1;
}

void select_light(PanelContext& ctx, int light) {
    ctx.ui.selected.reset();
    ctx.ui.selected_light = light;
}

void panel_outliner(PanelContext& ctx) {
    if (!ImGui::CollapsingHeader("Outliner", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const Scene& scene = ctx.model.scene();
    const std::vector<OutlinerRow> rows = outliner_rows(scene);
    const auto sel = ctx.selection();
    int light = -1;  // a light selected as itself (no primitive selected)
    if (!sel && ctx.ui.selected_light && size_t(*ctx.ui.selected_light) < scene.lights.size()) light = *ctx.ui.selected_light;
    // A list of its own, at most a third of the panel's height (at least 4 rows): it scrolls.
    const float row_h = ImGui::GetTextLineHeightWithSpacing();
    const float most = std::max(4 * row_h, ImGui::GetIO().DisplaySize.y / 3);
    const float height = std::min(most, float(rows.size() + 3) * row_h + ImGui::GetStyle().WindowPadding.y * 2);
    ImGui::BeginChild("##outliner", ImVec2(0, height), true);
    // The selection's row scrolls into view when the selection changed (a click on the image).
    static std::string last_selected;
    const char* headings[] = {"Objects", "Lights", "Cameras"};
    int heading = -1;
    std::optional<Selection> picked;
    std::optional<int> activate;
    for (const OutlinerRow& row : rows) {
        if (int(row.kind) != heading) {
            heading = int(row.kind);
            ImGui::TextDisabled("%s", headings[heading]);
        }
        const bool selected = (row.kind == OutlinerKind::object && sel == row.index) ||
                              (row.kind == OutlinerKind::light && light == row.index) ||
                              (row.kind == OutlinerKind::light && sel &&
                               scene.primitives[size_t(*sel)].type == PrimitiveType::emissive &&
                               scene.primitives[size_t(*sel)].light == row.index);  // the active camera: "active"
        std::string key(1, "olc"[heading]);  // "o3": object 3; "l0": light 0; "c1": camera 1
        key += std::to_string(row.index);
        ImGui::PushID(key.c_str());
        const std::string text = "  " + row.label;
        if (ImGui::Selectable(text.c_str(), selected)) {
            if (row.kind == OutlinerKind::camera) activate = row.index;
            else picked = row_selection(scene, row);
        }
        if (ImGui::IsItemVisible()) mark_item(ctx, "row:" + key);  // rows scrolled away are not there to click
        if (!row.detail.empty()) {
            ImGui::SameLine();
            ImGui::TextDisabled("%s", row.detail.c_str());
        }
        if (selected && last_selected != key) {
            ImGui::SetScrollHereY(0.5f);
            last_selected = key;
        }
        ImGui::PopID();
    }
    if (!sel && light < 0) last_selected.clear();
    ImGui::EndChild();
    if (picked) {
        if (picked->primitive) select_primitive(ctx, picked->primitive);
        else if (picked->light) select_light(ctx, *picked->light);
        show_panel_tab(ctx, PanelTab::object);
    }
    if (activate && *activate != scene.camera) {
        ctx.model.seal_undo_step();
        const int c = *activate;
        ctx.edit(Edit::camera, [&](Scene& s, ViewerSettings&) { s.camera = c; }, "active camera");
    }
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped("\".\" frames the selection   numpad 1 3 7: views");  // wraps in a narrow panel
    ImGui::PopStyleColor();
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip(". or numpad-.: frame the selection\nnumpad 1 / 3 / 7: front / right / top view (Ctrl: back / left / bottom)");
}

}  // namespace kr::viewer
