// The Materials panel: each used material's type and parameters.
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
            switch (m.type) {
                case MaterialType::diffuse:
                case MaterialType::specular: changed |= field(ctx, "rho", &m.rho.x, 3, 0.005f, 0.0, 1.0); break;
                case MaterialType::glossy:
                    changed |= field(ctx, "rho", &m.rho.x, 3, 0.005f, 0.0, 1.0);
                    changed |= field(ctx, "roughness", &m.roughness, 1, 0.002f, 0.0, 0.999);
                    break;
                case MaterialType::dielectric:
                case MaterialType::translucent:
                    changed |= field(ctx, "rhoR", &m.rho_r.x, 3, 0.005f, 0.0, 1.0);
                    changed |= field(ctx, "rhoT", &m.rho_t.x, 3, 0.005f, 0.0, 1.0);
                    changed |= field(ctx, "eta", &m.eta, 1, 0.002f, 1.0 / 4, 4.0);
                    if (m.type == MaterialType::translucent)
                        changed |= field(ctx, "roughness", &m.roughness, 1, 0.002f, 0.0, 0.999);
                    break;
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
