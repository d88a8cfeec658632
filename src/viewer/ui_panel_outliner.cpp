// The Outliner, above the tabs: every object, light and camera of the scene. A click on a row
// selects what the image's click selects (the same ctx.ui.selected; a point light, which has
// no sphere to click, as ctx.ui.selected_light) and shows the Object tab; a camera's row makes
// it the active camera (an undoable camera edit) and shows the Camera tab. "." or numpad-. frames the selection.
#include <algorithm>
#include <string>
#include <vector>

#include <imgui.h>
#include <imgui_stdlib.h>

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
    const auto sel = ctx.selection();
    int light = -1;  // a light selected as itself (no primitive selected)
    if (!sel && ctx.ui.selected_light && size_t(*ctx.ui.selected_light) < scene.lights.size()) light = *ctx.ui.selected_light;
    // A filter over the rows' names and details (case-insensitive).
    ImGui::SetNextItemWidth(-1);
    ImGui::InputTextWithHint("##outliner filter", "filter: name, material, on / off", &ctx.ui.outliner_filter);
    mark_item(ctx, "outliner:filter");
    // The list: a heading, then the rows of each kind. Only the rows in view are made
    // (ImGuiListClipper): a scene may hold many thousands of spheres. Filtered, the lines
    // that match are listed first (each row made once per frame, only while filtering).
    static constexpr OutlinerKind kKinds[] = {OutlinerKind::object, OutlinerKind::light, OutlinerKind::camera};
    static constexpr const char* kHeadings[] = {"Objects", "Lights", "Cameras"};
    struct Line {
        int kind, index;  // index -1: the kind's heading
    };
    const bool filtering = ctx.ui.outliner_filter.find_first_not_of(' ') != std::string::npos;
    std::vector<Line> matching;
    int counts[3], starts[3], total = 0;
    for (int k = 0; k < 3; ++k) {
        counts[k] = outliner_count(scene, kKinds[k]);
        starts[k] = total;  // the heading's line; its rows follow
        total += 1 + counts[k];
        if (filtering) {
            const size_t heading = matching.size();
            for (int i = 0; i < counts[k]; ++i)
                if (outliner_row_matches(outliner_row(scene, kKinds[k], i), ctx.ui.outliner_filter)) {
                    if (matching.size() == heading) matching.push_back({k, -1});
                    matching.push_back({k, i});
                }
        }
    }
    auto line_at = [&](int n) {
        if (filtering) return matching[size_t(n)];
        int k = 2;
        while (n < starts[k]) --k;
        return Line{k, n - starts[k] - 1};
    };
    const int lines = filtering ? int(matching.size()) : total;
    // The selection's line: its object, or the light selected as itself.
    int selected_line = -1;
    const Line want = sel ? Line{0, *sel} : light >= 0 ? Line{1, light} : Line{-1, -1};
    if (want.kind >= 0 && !filtering) selected_line = starts[want.kind] + 1 + want.index;
    for (int n = 0; filtering && n < lines && want.kind >= 0; ++n)
        if (matching[size_t(n)].kind == want.kind && matching[size_t(n)].index == want.index) selected_line = n;
    // An emissive selection's light row is highlighted too.
    const int carried = sel && scene.primitives[size_t(*sel)].type == PrimitiveType::emissive ? scene.primitives[size_t(*sel)].light : -1;
    // At most a third of the window's height (at least 4 rows); it scrolls.
    const float row_h = ImGui::GetTextLineHeightWithSpacing();
    const float most = std::max(4 * row_h, ImGui::GetIO().DisplaySize.y / 3);
    const float height = std::min(most, float(std::max(lines, 1) + 1) * row_h + ImGui::GetStyle().WindowPadding.y * 2);
    ImGui::BeginChild("##outliner", ImVec2(0, height), true);
    // A new selection (a click on the image, say) scrolls its row into view.
    if (selected_line != ctx.ui.outliner_shown_line) {
        ctx.ui.outliner_shown_line = selected_line;
        if (selected_line >= 0) {
            const float y = float(selected_line) * row_h, top = ImGui::GetScrollY(), view = ImGui::GetWindowHeight() - 2 * row_h;
            if (y < top || y > top + view) ImGui::SetScrollY(std::max(0.0f, y - 0.5f * view));
        }
    }
    if (filtering && lines == 0) ImGui::TextDisabled("nothing matches \"%s\"", ctx.ui.outliner_filter.c_str());
    std::optional<Selection> picked;
    std::optional<int> activate;
    ImGuiListClipper clipper;
    clipper.Begin(lines, row_h);
    while (clipper.Step())
        for (int line = clipper.DisplayStart; line < clipper.DisplayEnd; ++line) {
            const auto [k, index] = line_at(line);
            if (index < 0) {
                ImGui::TextDisabled("%s", kHeadings[k]);
                continue;
            }
            const OutlinerRow row = outliner_row(scene, kKinds[k], index);
            const bool selected = line == selected_line || (k == 1 && index == carried);
            std::string key(1, "olc"[k]);  // "o3": object 3; "l0": light 0; "c1": camera 1
            key += std::to_string(index);
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
            ImGui::PopID();
        }
    ImGui::EndChild();
    if (picked) {
        if (picked->primitive) select_primitive(ctx, picked->primitive);
        else if (picked->light) select_light(ctx, *picked->light);
        show_panel_tab(ctx, PanelTab::object);
    }
    if (activate) {
        show_panel_tab(ctx, PanelTab::camera);  // its properties
        if (*activate != scene.camera) {
            ctx.model.seal_undo_step();
            const int c = *activate;
            ctx.edit(Edit::camera, [&](Scene& s, ViewerSettings&) { s.camera = c; }, "active camera");
        }
    }
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped("\".\" frames the selection   numpad 1 3 7: views");  // wraps in a narrow panel
    ImGui::PopStyleColor();
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip(". or numpad-.: frame the selection\nnumpad 1 / 3 / 7: front / right / top view (Ctrl: back / left / bottom)");
}

}  // namespace kr::viewer
