// The Lens panel: pinhole or thin lens, focal distance and aperture, click-to-focus.
#include <algorithm>

#include <imgui.h>

#include "viewer/ui_panels.h"
#include "viewer/ui_widgets.h"

namespace kr::viewer {

void panel_lens(PanelContext& ctx) {
    if (!ImGui::CollapsingHeader("Lens", ImGuiTreeNodeFlags_DefaultOpen)) return;
    Camera cam = ctx.model.camera();
    auto apply = [&](const char* name) {
        ctx.edit(Edit::lens, [&](Scene& s, ViewerSettings&) { s.cameras[size_t(s.camera)] = cam; }, name, name);
    };
    // The type of the active camera (whose id, in the Camera panel, may be a type's name).
    if (combo("camera type", cam.type, camera_type_names)) apply("camera type");
    // The lens's fields show for a pinhole too, greyed: switching the type moves no control.
    ImGui::BeginDisabled(cam.type != CameraType::lens);
    if (field(ctx, "focal distance", &cam.focal_distance, 1, float(0.01 * std::max(1.0, cam.focal_distance)), 1e-4,
              kHuge))
        apply("focal distance");
    if (field(ctx, "aperture (alpha)", &cam.alpha, 1, 0.005f, 0.0, kHuge)) apply("aperture");
    ImGui::EndDisabled();
    ImGui::Checkbox("pick focus (F)", &ctx.ui.pick_focus);
    ImGui::SameLine();
    ImGui::TextDisabled("or Ctrl+click the image");
}

}  // namespace kr::viewer
