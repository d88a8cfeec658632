// The Lights panel: every light of the file with its fields as the file has them (scene.h's
// light_params through light_fields): a point light's position and power; an area light's
// sphere and power.
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
        // Its fields as the file has them; a light on a shape edits that sphere here too.
        const LightAnchor anchor = light_anchor(light);
        const int on_shape = anchor.kind == LightAnchor::Kind::shape && anchor.shape >= 0 &&
                                     size_t(anchor.shape) < scene.shapes.size() ? anchor.shape : -1;
        Shape shape = on_shape >= 0 ? scene.shapes[size_t(on_shape)] : Shape{};
        if (light_fields(ctx, edited, on_shape >= 0 ? &shape : nullptr) && on)
            ctx.edit(Edit::light, [&](Scene& s, ViewerSettings&) {
                s.lights[size_t(index)] = edited;
                if (on_shape >= 0) s.shapes[size_t(on_shape)] = shape;
            }, name, name);
        ImGui::EndDisabled();
        ImGui::PopID();
    }
}

}  // namespace kr::viewer
