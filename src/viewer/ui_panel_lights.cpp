// The Lights panel: each active light's position and power; an area light's sphere.
#include <string>

#include <imgui.h>

#include "viewer/scene_edit.h"
#include "viewer/ui_panels.h"
#include "viewer/ui_widgets.h"

namespace kr::viewer {

void panel_lights(PanelContext& ctx) {
    const Scene& scene = ctx.model.scene();
    if (scene.lights.empty() || !ImGui::CollapsingHeader("Lights", ImGuiTreeNodeFlags_DefaultOpen)) return;
    // Every light of the file, on (in the scene block) or off. Its fields show either way
    // (greyed when off), so checking a light moves no control under the pointer; why a light
    // that is on shows nothing is a mark on its line, its reason in a tooltip.
    for (int index = 0; index < int(scene.lights.size()); ++index) {
        const Light light = scene.lights[size_t(index)];  // a copy: an edit replaces the scene
        ImGui::PushID(index);
        const bool on = light_checkbox(ctx, index);
        const std::string unseen = on ? light_unseen_reason(ctx.model.scene(), index) : std::string();
        ImGui::SameLine();
        if (!unseen.empty()) {
            ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "not seen (?)");
            if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", unseen.c_str());
        } else {
            ImGui::TextDisabled(on ? "on" : "off");
        }
        ImGui::BeginDisabled(!on);
        Light edited = light;
        const std::string name = "light " + light.id;
        if (light.type == LightType::point) {
            bool changed = field(ctx, "position", &edited.position.x, 3, 0.02f, -kHuge, kHuge);
            // "power" as the file says it: a point light's intensity, an area light's radiance.
            changed |= power_fields(ctx, edited.power, 0.5f);
            if (changed && on)
                ctx.edit(Edit::light, [&](Scene& s, ViewerSettings&) { s.lights[size_t(index)] = edited; }, name, name);
        } else {
            Shape shape = scene.shapes[size_t(light.shape)];
            bool changed = field(ctx, "position", &shape.centre.x, 3, 0.02f, -kHuge, kHuge);
            changed |= field(ctx, "radius", &shape.radius, 1, 0.005f, 1e-4, kHuge);
            changed |= power_fields(ctx, edited.power);
            if (changed && on)
                ctx.edit(Edit::light, [&](Scene& s, ViewerSettings&) {
                    s.lights[size_t(index)] = edited;
                    s.shapes[size_t(light.shape)] = shape;
                }, name, name);
        }
        ImGui::EndDisabled();
        ImGui::PopID();
    }
}

}  // namespace kr::viewer
