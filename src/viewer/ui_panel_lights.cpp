// The Lights panel: each active light's position and power; an area light's sphere.
#include <string>

#include <imgui.h>

#include "viewer/ui_panels.h"
#include "viewer/ui_widgets.h"

namespace kr::viewer {

void panel_lights(PanelContext& ctx) {
    const Scene& scene = ctx.model.scene();
    if (scene.active_lights.empty() || !ImGui::CollapsingHeader("Lights", ImGuiTreeNodeFlags_DefaultOpen)) return;
    for (int index : scene.active_lights) {
        const Light& light = scene.lights[size_t(index)];
        ImGui::PushID(index);
        ImGui::Text("%s (%s)", light.id.c_str(), std::string(light_type_names.name(light.type)).c_str());
        Light edited = light;
        const std::string name = "light " + light.id;
        if (light.type == LightType::point) {
            bool changed = field(ctx, "position", &edited.position.x, 3, 0.02f, -kHuge, kHuge);
            changed |= field(ctx, "intensity", &edited.power.x, 3, 0.5f, 0.0, kHuge);
            if (changed) ctx.edit(Edit::light, [&](Scene& s, ViewerSettings&) { s.lights[size_t(index)] = edited; }, name, name);
        } else {
            Shape shape = scene.shapes[size_t(light.shape)];
            bool changed = field(ctx, "position", &shape.centre.x, 3, 0.02f, -kHuge, kHuge);
            changed |= field(ctx, "radius", &shape.radius, 1, 0.005f, 1e-4, kHuge);
            changed |= field(ctx, "radiance", &edited.power.x, 3, 0.1f, 0.0, kHuge);
            if (changed)
                ctx.edit(Edit::light, [&](Scene& s, ViewerSettings&) {
                    s.lights[size_t(index)] = edited;
                    s.shapes[size_t(light.shape)] = shape;
                }, name, name);
        }
        ImGui::PopID();
    }
}

}  // namespace kr::viewer
