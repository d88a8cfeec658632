// The Materials panel: each used material's type and its parameters (material_fields).
#include <set>
#include <string>

#include <imgui.h>

#include "viewer/ui_panels.h"
#include "viewer/ui_widgets.h"

namespace kr::viewer {

void panel_materials(PanelContext& ctx) {
    const Scene& scene = ctx.model.scene();
    std::set<int> used;
    for (const Primitive& p : scene.primitives) used.insert(p.material);
    if (used.empty() || !ImGui::CollapsingHeader("Materials")) return;
    for (int index : used) {
        Material m = scene.materials[size_t(index)];
        ImGui::PushID(index);
        if (ImGui::TreeNode(m.id.c_str())) {
            const std::string name = "material " + m.id;
            if (material_fields(ctx, m))
                ctx.edit(Edit::material, [&](Scene& s, ViewerSettings&) { s.materials[size_t(index)] = m; }, name, name);
            ImGui::TreePop();
        }
        ImGui::PopID();
    }
}

}  // namespace kr::viewer
