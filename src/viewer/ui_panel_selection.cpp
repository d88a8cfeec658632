// The Selection panel (Object tab): everything about the selected object in one place: its
// shape (centre, radius), its material (one-click colours, a picker, the type's parameters,
// material_fields as the Materials panel has them), its light; and the object edits
// (viewer/scene_edit.h): add, duplicate, delete, any material or a new one, emissive. A point
// light selected in the outliner shows its position and power here.
#include <string>

#include <imgui.h>

#include "viewer/outliner.h"
#include "viewer/scene_edit.h"
#include "viewer/ui_panels.h"
#include "viewer/ui_widgets.h"

namespace kr::viewer {

namespace {

void heading(const char* text) {
    ImGui::Spacing();
    ImGui::TextDisabled("%s", text);
    ImGui::Separator();
}

// A light with no primitive of its own (a point light), selected in the outliner.
void light_section(PanelContext& ctx, int index) {
    const Scene& scene = ctx.model.scene();
    Light light = scene.lights[size_t(index)];
    // On or off as the Lights panel has it; its fields greyed while off (nothing moves).
    const bool on = light_checkbox(ctx, index);
    ImGui::SameLine();
    ImGui::TextDisabled("%s", on ? "on" : "off");
    const std::string name = "light " + light.id;
    bool changed = false;
    ImGui::BeginDisabled(!on);
    // Its fields as the file has them; a light on a shape shows its sphere in the Lights panel.
    changed |= light_fields(ctx, light, nullptr);
    ImGui::EndDisabled();
    if (changed && on) ctx.edit(Edit::light, [&](Scene& s, ViewerSettings&) { s.lights[size_t(index)] = light; }, name, name);
}

// The selection's material: one click on a colour recolours this object alone (a material
// shared with others is copied for it first); the picker and the type's parameters likewise.
void material_section(PanelContext& ctx, int p, const std::string& name) {
    // Read again after each edit: an edit replaces the scene's lists.
    auto prim = [&]() -> const Primitive& { return ctx.model.scene().primitives[size_t(p)]; };
    heading("Material");
    ImGui::PushID("palette");
    for (const PaletteColour& c : kPalette) {
        if (&c != kPalette) ImGui::SameLine(0, 4);
        const ImVec4 col(float(c.rho.x), float(c.rho.y), float(c.rho.z), 1.0f);
        if (ImGui::ColorButton(c.name, col, ImGuiColorEditFlags_NoTooltip, ImVec2(20, 20))) {
            ctx.model.seal_undo_step();
            ctx.edit(Edit::material, [&](Scene& s, ViewerSettings&) { recolour_primitive(s, p, c.rho); }, name, "recolour");
            ctx.model.seal_undo_step();
        }
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s: recolour %s", c.name, prim().id.c_str());
        mark_item(ctx, std::string("palette:") + c.name);
    }
    ImGui::PopID();
    // Any of the file's materials, or a new one (a copy of this one).
    const Scene& scene = ctx.model.scene();
    const std::string current = prim().material >= 0 ? scene.materials[size_t(prim().material)].id : "(none)";
    int material = prim().material;
    if (ImGui::BeginCombo("material", current.c_str())) {
        for (size_t i = 0; i < scene.materials.size(); ++i)
            if (ImGui::Selectable((scene.materials[i].id + "##m" + std::to_string(i)).c_str(), int(i) == material))
                material = int(i);
        ImGui::EndCombo();
    }
    if (material != prim().material)
        ctx.edit(Edit::object, [&](Scene& s, ViewerSettings&) { s.primitives[size_t(p)].material = material; }, name);
    if (ImGui::Button("New material"))
        ctx.edit(Edit::object, [&](Scene& s, ViewerSettings&) { new_material_for(s, p); }, name);
    if (prim().material < 0) return;
    const int users = material_users(ctx.model.scene(), prim().material);
    ImGui::SameLine();
    if (users > 1) {
        ImGui::TextDisabled("shared by %d objects (?)", users);
        if (ImGui::IsItemHovered())
            ImGui::SetTooltip("an edit here gives %s a copy of its own; the Materials panel edits it for all", prim().id.c_str());
    } else {
        ImGui::TextDisabled("used by this object only");
    }
    Material m = ctx.model.scene().materials[size_t(prim().material)];
    ImGui::PushID("selection material");
    if (material_fields(ctx, m))
        ctx.edit(Edit::material, [&](Scene& s, ViewerSettings&) {
            Material& own = s.materials[size_t(own_material(s, p))];
            const std::string id = own.id;  // a copy keeps its new id
            own = m;
            own.id = id;
        }, name, "material of " + name);
    ImGui::PopID();
}

}  // namespace

void panel_selection(PanelContext& ctx) {
    if (!ImGui::CollapsingHeader("Selection", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const auto sel = ctx.selection();
    if (ImGui::Button("Add sphere")) add_sphere_at_target(ctx);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("a diffuse sphere at the camera's target, or nearer where that is taken");
    const Scene& scene = ctx.model.scene();
    if (!sel) {
        if (ctx.ui.selected_light && size_t(*ctx.ui.selected_light) < scene.lights.size())
            return light_section(ctx, *ctx.ui.selected_light);
        ImGui::SameLine();
        ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
        ImGui::TextWrapped("click a sphere on the image or a row above");  // wraps in a narrow panel
        ImGui::PopStyleColor();
        return;
    }
    ImGui::SameLine();
    if (ImGui::Button("Duplicate (Ctrl+D)")) duplicate_selection(ctx);
    ImGui::SameLine();
    if (ImGui::Button("Delete (Del)")) {
        delete_selection(ctx);
        return;
    }
    const int p = *sel;
    const Primitive& prim = scene.primitives[size_t(p)];
    const std::string name = "object " + prim.id;
    ImGui::TextUnformatted(primitive_label(scene, p).c_str());
    heading("Shape");
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
    material_section(ctx, p, name);
    // Light: emissive with its area light's power, or not.
    heading("Light");
    const Primitive& now = ctx.model.scene().primitives[size_t(p)];  // the material edits replaced the scene
    bool emissive = now.type == PrimitiveType::emissive;
    if (ImGui::Checkbox("emissive", &emissive))
        ctx.edit(Edit::object, [&](Scene& s, ViewerSettings&) { set_emissive(s, p, emissive); }, name);
    // Its light's power, greyed while it has none: checking "emissive" moves no control.
    const Primitive& after = ctx.model.scene().primitives[size_t(p)];
    const bool has_light = after.type == PrimitiveType::emissive && after.light >= 0;
    // Without one, the fields of the light an emissive primitive gets (greyed).
    Light light;
    light.type = kShapeLightType;
    if (has_light) light = ctx.model.scene().lights[size_t(after.light)];
    ImGui::SameLine();
    ImGui::TextDisabled("%s", has_light ? ("light " + light.id).c_str() : "no light");
    ImGui::BeginDisabled(!has_light);
    const int light_index = after.light;
    if (light_fields(ctx, light, nullptr) && has_light)
        ctx.edit(Edit::light, [&](Scene& s, ViewerSettings&) { s.lights[size_t(light_index)] = light; }, name, name);
    ImGui::EndDisabled();
}

}  // namespace kr::viewer
