// The Tone map panel: the display's operator and exposure (a re-display, no restart).
#include <imgui.h>

#include "viewer/ui_panels.h"
#include "viewer/ui_widgets.h"

namespace kr::viewer {

void panel_tone_map(PanelContext& ctx) {
    if (!ImGui::CollapsingHeader("Tone map", ImGuiTreeNodeFlags_DefaultOpen)) return;
    ToneSettings tone = ctx.model.settings().tone;
    bool changed = combo("operator", tone.tonemap, tonemap_names);
    changed |= field(ctx, "exposure (EV)", &tone.exposure, 1, 0.02f, -kMaxExposureStops, kMaxExposureStops, "%.2f");
    if (tone.tonemap == ToneMap::linear) ImGui::TextDisabled("linear: 2^EV I / max(I)");
    if (changed) ctx.edit(Edit::tone_map, [&](Scene&, ViewerSettings& s) { s.tone = tone; }, "tone map", "tone map");
    // The denoiser's display: raw, denoised, or the two side by side (render/denoise.h).
    DenoiseView denoise = ctx.model.settings().denoise;
    if (combo("denoise", denoise, denoise_view_names))
        ctx.edit(Edit::tone_map, [&](Scene&, ViewerSettings& s) { s.denoise = denoise; }, "denoise", "denoise");
}

}  // namespace kr::viewer
