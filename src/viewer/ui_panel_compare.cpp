// The Inspect and compare panel: zoom, the view (render, image B, split, error, noise,
// samples, albedo, normal, depth), image B (the reference or a kept snapshot) with PSNR and RMSE, the locked probe.
#include <algorithm>
#include <array>
#include <cstdio>
#include <string>

#include <imgui.h>
#include <imgui_stdlib.h>

#include "core/image_compare.h"
#include "viewer/status.h"
#include "viewer/ui_compare.h"
#include "viewer/ui_panels.h"

namespace kr::viewer {

namespace {

// A horizontal bar of colour(t), t from 0 to 1, labelled `low` and `high` at its ends.
template <class Colour>
void colour_bar(double low, double high, const char* unit, Colour colour) {
    ImDrawList* draw = ImGui::GetWindowDrawList();
    const ImVec2 at = ImGui::GetCursorScreenPos();
    const float width = std::max(60.0f, ImGui::GetContentRegionAvail().x), height = 12;
    constexpr int kSteps = 64;
    for (int i = 0; i < kSteps; ++i) {
        const std::array<uint8_t, 3> c = colour((i + 0.5) / kSteps);
        draw->AddRectFilled(ImVec2(at.x + width * i / kSteps, at.y), ImVec2(at.x + width * (i + 1) / kSteps, at.y + height),
                            IM_COL32(c[0], c[1], c[2], 255));
    }
    ImGui::Dummy(ImVec2(width, height));
    ImGui::Text("%.4g%s", low, unit);
    char label[48];
    std::snprintf(label, sizeof label, "%.4g%s", high, unit);
    ImGui::SameLine(std::max(0.0f, width - ImGui::CalcTextSize(label).x));
    ImGui::TextUnformatted(label);
}

}  // namespace

void panel_compare(PanelContext& ctx) {
    CompareTool& tool = ctx.ui.compare;
    // Open and scrolled to from the start when the command line asked for a compare view or
    // a probe.
    const bool asked = tool.open_panel;
    tool.open_panel = false;
    if (asked) ImGui::SetNextItemOpen(true);
    if (!ImGui::CollapsingHeader("Inspect and compare", ImGuiTreeNodeFlags_DefaultOpen)) return;  // its tab's one panel
    if (asked) ImGui::SetScrollHereY(0.0f);
    const int w = ctx.model.scene().renderer.width, h = ctx.model.scene().renderer.height;
    const PixelRect area = ctx.view_area();
    // Zoom.
    ImGui::Text("zoom %s", tool.view.fitted() ? "fit" : "");
    if (!tool.view.fitted()) {
        ImGui::SameLine(0, 0);
        ImGui::Text("%gx", tool.view.scale(area, w, h));
    }
    ImGui::SameLine();
    if (ImGui::SmallButton("fit (0)")) tool.view.fit();
    ImGui::SameLine();
    if (ImGui::SmallButton("1:1 (1)")) tool.view.one_to_one(area, w, h);
    ImGui::SameLine();
    const double cx = area.x + area.width / 2, cy = area.y + area.height / 2;
    if (ImGui::SmallButton("+")) tool.view.zoom_steps(area, w, h, 1, cx, cy);
    ImGui::SameLine();
    if (ImGui::SmallButton("-")) tool.view.zoom_steps(area, w, h, -1, cx, cy);
    // The fit: any factor (smooth or in blocks), or whole screen pixels per image pixel.
    ImGui::Checkbox("fit in whole pixels", &tool.view.whole_pixels);
    ImGui::SameLine();
    ImGui::Checkbox("smooth (linear filter)", &tool.smooth);
    // The render's resolution: a scale of the file's, or the free area's size.
    ImGui::Text("render %d x %d", w, h);
    const auto [fw, fh] = ctx.model.file_resolution();
    for (const double f : {0.25, 0.5, 1.0, 2.0}) {
        ImGui::SameLine();
        char label[24];
        std::snprintf(label, sizeof label, f == 1 ? "file" : "%gx", f);
        if (ImGui::SmallButton(label) && !ctx.model.set_resolution(int(fw * f + 0.5), int(fh * f + 0.5), false))
            ctx.messages.show_error("resolution: the scene cannot be prepared at that size");
    }
    ImGui::SameLine();
    if (ImGui::SmallButton("window")) {
        const double to_points = 1.0 / std::max(1.0f, ImGui::GetIO().DisplayFramebufferScale.x);
        ctx.model.set_resolution(int(area.width * to_points), int(area.height * to_points), true);
        tool.view.fit();
    }
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("the free area's size; the camera's aspect follows");

    // The view.
    CompareSettings& cs = tool.comparison.settings;
    int mode = int(cs.mode);
    if (ImGui::Combo("view (V)", &mode, [](void*, int i, const char** out) {
            *out = view_mode_names.names[size_t(i)].data();
            return true;
        }, nullptr, int(view_mode_names.names.size())))
        cs.mode = ViewMode(mode);
    if (cs.mode == ViewMode::split) {
        float split = float(cs.split);
        if (ImGui::SliderFloat("divider", &split, 0, 1, "%.2f")) cs.split = split;
    }
    if (cs.mode == ViewMode::error) {
        int metric = int(cs.metric);
        if (ImGui::Combo("error", &metric, [](void*, int i, const char** out) {
                *out = error_metric_names.names[size_t(i)].data();
                return true;
            }, nullptr, int(error_metric_names.names.size())))
            cs.metric = ErrorMetric(metric);
        float top = float(cs.error_scale);
        if (ImGui::DragFloat("bar top", &top, 0.001f, 0, 100, top > 0 ? "%.4g" : "auto (99th percentile)"))
            cs.error_scale = std::max(0.0f, top);
    }
    if ((cs.mode == ViewMode::error || cs.mode == ViewMode::noise || cs.mode == ViewMode::samples) && tool.picture_current)
        colour_bar(0, tool.picture_scale, cs.mode == ViewMode::samples ? " spp" : "", [](double t) { return viridis(t); });
    else if (cs.mode == ViewMode::depth && tool.picture_current && tool.picture_range)
        colour_bar(tool.picture_range->near, tool.picture_range->far, "", [](double t) {
            const uint8_t g = quantize_unit(1.0 - (1.0 - kDepthFarGrey) * t);  // depth_picture's ramp
            return std::array<uint8_t, 3>{g, g, g};
        });
    else if (cs.mode == ViewMode::depth && tool.picture_current)
        ImGui::TextDisabled("no pixel hit a surface");
    else if (is_feature_view(cs.mode) && !tool.picture_current)
        ImGui::TextDisabled("%s", tool.picture_missing.empty() ? "waiting for the render thread" : tool.picture_missing.c_str());
    else if (cs.mode != ViewMode::render && !tool.picture_current)
        ImGui::TextDisabled(cs.mode == ViewMode::noise || cs.mode == ViewMode::samples
                                ? "shown after the preview"
                                : "needs image B of the image's size");

    // Image B: the reference or a kept snapshot.
    ImGui::Separator();
    ImGui::TextDisabled("image B");
    ImGui::InputText("reference", &tool.reference_path);
    ImGui::SameLine();
    if (ImGui::SmallButton("load") && !tool.reference_path.empty()) load_reference(ctx, tool.reference_path, false);
    if (ImGui::RadioButton(tool.comparison.reference() ? tool.comparison.reference()->name.c_str() : "(no reference)", cs.b == -1))
        cs.b = -1;
    for (int i = 0; i < kSnapshotSlots; ++i) {
        const auto& slot = tool.comparison.slots()[size_t(i)];
        if (!slot) continue;
        ImGui::PushID(i);
        if (ImGui::RadioButton(slot->name.c_str(), cs.b == i)) cs.b = i;
        ImGui::SameLine();
        if (ImGui::SmallButton("drop")) {
            tool.comparison.drop(i);
            tool.picture_key.clear();
        }
        ImGui::PopID();
    }
    const Snapshot* full = ctx.full_frame();
    ImGui::BeginDisabled(!full);
    if (ImGui::Button("keep this image as B (K)")) keep_image_b(ctx, *full);
    ImGui::EndDisabled();
    // A is the image shown: the panel names which (raw, denoised or split), as the stats JSON does.
    if (tool.figures && ctx.ui.shown)
        ImGui::Text("A (%s) vs B: %s%s, RMSE %.4g",
                    std::string(shown_word(*ctx.ui.shown, ctx.model.settings().denoise)).c_str(),
                    tool.figures->identical ? "" : "PSNR ", format_psnr(*tool.figures).c_str(), tool.figures->rmse);
    else if (!tool.figures_note.empty()) ImGui::TextDisabled("A vs B: %s", tool.figures_note.c_str());

    // The locked probe.
    ImGui::Separator();
    ImGui::TextDisabled("probe (Shift+click on the image)");
    if (!tool.locked_probe) {
        ImGui::TextDisabled("hover the image to read a pixel");
        return;
    }
    if (const auto p = probe(ctx, tool.locked_probe->first, tool.locked_probe->second); p && p->earlier_view) {
        ImGui::TextDisabled("%s", probe_line(*p).c_str());
    } else if (p) {
        ImGui::Text("pixel %d, %d: radiance %.4g %.4g %.4g", p->x, p->y, p->mean.x, p->mean.y, p->mean.z);
        ImGui::Text("shown %d %d %d", p->displayed[0], p->displayed[1], p->displayed[2]);
        if (!p->preview)
            ImGui::Text("%u samples, std. error %.3g", p->samples, p->standard_error);
    } else {
        ImGui::TextDisabled("pixel %d, %d is outside the image", tool.locked_probe->first, tool.locked_probe->second);
    }
    if (ImGui::SmallButton("release")) tool.locked_probe.reset();
}

}  // namespace kr::viewer
