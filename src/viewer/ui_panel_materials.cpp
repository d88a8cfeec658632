// The Materials panel: each used material's type and its parameters (material_params).
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
            bool changed = combo("type", m.type, material_type_names);
            // The type's parameters as the file has them (scene.h's material_params).
            for (const MaterialParam& param : material_params(m.type)) {
                const std::string label(param.name);
                if (param.colour) {
                    // A picker, then the numbers as the file has them.
                    changed |= colour_picker(label.c_str(), m.*param.colour);
                    ImGui::SameLine();
                    changed |= field(ctx, label.c_str(), &(m.*param.colour).x, 3, 0.005f, 0.0, 1.0);
                } else
                    changed |= field(ctx, label.c_str(), &(m.*param.number), 1, param.edit_speed, param.edit_lo,
                                     param.edit_hi);
            }
            const std::string name = "material " + m.id;
            if (changed)
                ctx.edit(Edit::material, [&](Scene& s, ViewerSettings&) { s.materials[size_t(index)] = m; }, name, name);
            ImGui::TreePop();
        }
        ImGui::PopID();
    }
}

}  // namespace kr::viewer
