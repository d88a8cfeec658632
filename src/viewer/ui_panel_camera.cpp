// The Camera panel: the active camera, its position, target, field of view and aspect.
#include <algorithm>
#include <string>

#include <imgui.h>

#include "viewer/ui_panels.h"
#include "viewer/ui_widgets.h"

namespace kr::viewer {

void panel_camera(PanelContext& ctx) {
    if (!ImGui::CollapsingHeader("Camera", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const Scene& scene = ctx.model.scene();
    // Each camera by its id and its type as it is now: scene 3's camera "pinhole" becomes a
    // lens-based one by click-to-focus, and the Lens panel says so too.
    auto camera_label = [&](size_t i) {
        const Camera& c = scene.cameras[i];
        const std::string type(camera_type_names.name(c.type));
        return c.id == type ? c.id : c.id + " (" + type + ")";
    };
    if (scene.cameras.size() > 1) {
        int active = scene.camera;
        if (ImGui::BeginCombo("active", camera_label(size_t(active)).c_str())) {
            for (size_t i = 0; i < scene.cameras.size(); ++i)
                if (ImGui::Selectable((camera_label(i) + "##cam" + std::to_string(i)).c_str(), int(i) == active))
                    active = int(i);
            ImGui::EndCombo();
        }
        if (active != scene.camera) ctx.edit(Edit::camera, [&](Scene& s, ViewerSettings&) { s.camera = active; }, "active camera");
    } else {
        ImGui::TextDisabled("camera %s", camera_label(size_t(scene.camera)).c_str());
    }
    Camera cam = ctx.model.camera();
    const double span = std::max(1.0, length(cam.target - cam.position));
    auto apply = [&](const char* name) {
        ctx.edit(Edit::camera, [&](Scene& s, ViewerSettings&) { s.cameras[size_t(s.camera)] = cam; }, name, name);
    };
    if (field(ctx, "position", &cam.position.x, 3, float(0.005 * span), -kHuge, kHuge)) apply("camera position");
    if (field(ctx, "target", &cam.target.x, 3, float(0.005 * span), -kHuge, kHuge)) apply("camera target");
    if (field(ctx, "fov (deg)", &cam.fov, 1, 0.1f, 0.5, 179.5)) apply("fov");
    if (field(ctx, "aspect", &cam.aspect, 1, 0.005f, 0.05, 20)) apply("aspect");
    // How the mouse and keys move the camera: the window's, not the scene's.
    NavigationSettings& nav = ctx.ui.nav;
    ImGui::Separator();
    int mode = nav.fly ? 1 : 0;
    ImGui::RadioButton("orbit", &mode, 0);
    ImGui::SameLine();
    ImGui::RadioButton("fly (G)", &mode, 1);
    nav.fly = mode == 1;
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("left drag looks around; W/S forward, A/D sideways, Q/E down/up");
    float speed = float(nav.speed);
    if (ImGui::SliderFloat("speed", &speed, float(kMinSpeed), float(kMaxSpeed), "%.2fx", ImGuiSliderFlags_Logarithmic))
        nav.speed = std::clamp(double(speed), kMinSpeed, kMaxSpeed);
    ImGui::Checkbox("stop at surfaces", &nav.stop_at_surfaces);
    ImGui::Checkbox("orbit about the clicked surface", &nav.orbit_picked);
}

}  // namespace kr::viewer
