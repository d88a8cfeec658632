// The Renderer panel: integrator, depth, estimator, allocation, light sampling, and how long
// the estimate refines (target spp, unlimited, pause, the stop rules).
#include <imgui.h>

#include "viewer/ui_panels.h"
#include "viewer/ui_widgets.h"

namespace kr::viewer {

void panel_renderer(PanelContext& ctx) {
    if (!ImGui::CollapsingHeader("Renderer", ImGuiTreeNodeFlags_DefaultOpen)) return;
    ViewerSettings settings = ctx.model.settings();
    RenderSettings& r = settings.render;
    bool changed = combo("integrator", r.integrator, integrator_names);
    changed |= ImGui::SliderInt("depth", &r.max_depth, 0, kMaxDepth, "%d", ImGuiSliderFlags_AlwaysClamp);
    changed |= combo("estimator", r.estimator, estimator_names);
    changed |= combo("allocation", r.allocation, allocation_names);
    // Greyed for WRT (point lights only, no sampling of area lights): switching the
    // integrator moves no control.
    ImGui::BeginDisabled(r.integrator == Integrator::wrt);
    changed |= combo("light sampling", r.light_sampling, light_sampling_names);
    ImGui::EndDisabled();
    const bool restart = ImGui::Button("Restart");
    if (changed || restart) {
        // depth and the renderer type also live in the authored renderer block (saved with the scene).
        ctx.edit(Edit::renderer, [&](Scene& s, ViewerSettings& out) {
            out.render = r;
            s.renderer.depth = r.max_depth;
            s.renderer.type = r.integrator == Integrator::wrt ? RendererType::wrt : RendererType::pt;
        }, "renderer", "renderer");
    }
    // The target keeps the samples already taken ([ and ] halve and double it).
    int spp = r.target_spp;
    ImGui::SetNextItemWidth(120);
    if (field_int(ctx, "target spp", spp, 1, 1 << 24)) {
        ctx.model.seal_undo_step();
        ctx.model.set_target_spp(spp);
    }
    bool unlimited = settings.unlimited, paused = settings.paused;
    ImGui::SameLine();
    if (ImGui::Checkbox("unlimited", &unlimited))
        ctx.edit(Edit::run_control, [&](Scene&, ViewerSettings& s) { s.unlimited = unlimited; }, "unlimited");
    ImGui::SameLine();
    if (ImGui::Checkbox("pause (Space)", &paused))
        ctx.edit(Edit::run_control, [&](Scene&, ViewerSettings& s) { s.paused = paused; }, "pause");
    // The stop rules of render --time / --noise; 0 turns each off.
    double stop_seconds = settings.stop.seconds, stop_noise_percent = 100 * settings.stop.noise;
    ImGui::SetNextItemWidth(120);
    if (field(ctx, "stop after s (0: off)", &stop_seconds, 1, 0.5f, 0.0, 1e9, "%.1f"))
        ctx.edit(Edit::run_control, [&](Scene&, ViewerSettings& s) { s.stop.seconds = stop_seconds; }, "stop after s");
    ImGui::SetNextItemWidth(120);
    if (field(ctx, "stop at noise % (0: off, adaptive)", &stop_noise_percent, 1, 0.05f, 0.0, 100.0, "%.2f"))
        ctx.edit(Edit::run_control, [&](Scene&, ViewerSettings& s) { s.stop.noise = stop_noise_percent / 100; },
                 "stop at noise");
}

}  // namespace kr::viewer
