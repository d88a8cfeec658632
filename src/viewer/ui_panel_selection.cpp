// The Selection panel: the selected primitive's shape, material and light, and the object
// edits (viewer/scene_edit.h): typed centre and radius, any material or a new one, emissive,
// duplicate, delete, add.
#include <string>

#include <imgui.h>

#include "viewer/scene_edit.h"
#include "viewer/ui_panels.h"
#include "viewer/ui_widgets.h"

namespace kr::viewer {

void panel_selection(PanelContext& ctx) {
    if (!ImGui::CollapsingHeader("Selection", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const auto sel = ctx.selection();
    if (ImGui::Button("Add sphere")) add_sphere_at_target(ctx);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("a diffuse sphere at the camera's target, or nearer where that is taken");
    if (!sel) {
        ImGui::SameLine();
        ImGui::TextDisabled("click a sphere on the image to select it");
        return;
    }
    ImGui::SameLine();
    if (ImGui::Button("Duplicate (Ctrl+D)")) duplicate_selection(ctx);
    ImGui::SameLine();
    if (ImGui::Button("Delete (Del)")) {
        delete_selection(ctx);
        return;
    }
    const Scene& scene = ctx.model.scene();
    const int p = *sel;
    const Primitive& prim = scene.primitives[size_t(p)];
    const std::string name = "object " + prim.id;
    ImGui::TextUnformatted(primitive_label(scene, p).c_str());
    Shape shape = scene.shapes[size_t(prim.shape)];
    const double span = std::max(1.0, shape.radius);
    bool moved = field(ctx, "centre", &shape.centre.x, 3, float(0.01 * span), -kHuge, kHuge);
    moved |= field(ctx, "radius", &shape.radius, 1, float(0.005 * span), 1e-6, kHuge);
    if (moved)
        ctx.edit(Edit::object, [&](Scene& s, ViewerSettings&) {
            Shape& own = own_shape(s, p);
            own.centre = shape.centre;
            own.radius = shape.radius;
        }, name, name);
    // M moves it with the pointer (a left drag orbits); X, Y or Z then, or here, locks an axis.
    ImGui::TextUnformatted("M: move; lock:");
    for (int a = -1; a < 3; ++a) {
        ImGui::SameLine();
        ImGui::RadioButton(a < 0 ? "view plane" : a == 0 ? "x" : a == 1 ? "y" : "z", &ctx.ui.axis_lock, a);
    }
    // Material: any of the file's, or a new one (a copy to edit in the Materials panel).
    const std::string current = prim.material >= 0 ? scene.materials[size_t(prim.material)].id : "(none)";
    int material = prim.material;
    if (ImGui::BeginCombo("material", current.c_str())) {
        for (size_t i = 0; i < scene.materials.size(); ++i)
            if (ImGui::Selectable((scene.materials[i].id + "##m" + std::to_string(i)).c_str(), int(i) == material))
                material = int(i);
        ImGui::EndCombo();
    }
    if (material != prim.material)
        ctx.edit(Edit::object, [&](Scene& s, ViewerSettings&) { s.primitives[size_t(p)].material = material; }, name);
    if (ImGui::Button("New material"))
        ctx.edit(Edit::object, [&](Scene& s, ViewerSettings&) { new_material_for(s, p); }, name);
    // Light: emissive with its area light's power, or not.
    bool emissive = prim.type == PrimitiveType::emissive;
    if (ImGui::Checkbox("emissive", &emissive))
        ctx.edit(Edit::object, [&](Scene& s, ViewerSettings&) { set_emissive(s, p, emissive); }, name);
    // Its light's power, greyed while it has none: checking "emissive" moves no control.
    const bool has_light = emissive && prim.light >= 0;
    Light light = has_light ? scene.lights[size_t(prim.light)] : Light{};
    ImGui::SameLine();
    ImGui::TextDisabled("%s", has_light ? ("light " + light.id).c_str() : "no light");
    ImGui::BeginDisabled(!has_light);
    if (power_fields(ctx, light.power) && has_light)
        ctx.edit(Edit::light, [&](Scene& s, ViewerSettings&) { s.lights[size_t(prim.light)] = light; }, name, name);
    ImGui::EndDisabled();
}

}  // namespace kr::viewer
