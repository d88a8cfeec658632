// The Stats panel: the image's size, the UI's frame rate, the scene's spheres and BVH, passes
// per second, dropped samples, and the convergence plot with its CSV.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <imgui.h>
#include <imgui_stdlib.h>

#include "viewer/ui_panels.h"

namespace kr::viewer {

namespace {

// The estimated error (and the RMSE against the reference) against spp or time, log-log,
// and its CSV.
void plot_convergence(PanelContext& ctx) {
    const std::vector<ConvergencePoint>& points = ctx.ui.compare.convergence.points();
    static bool by_time = false;
    ImGui::Checkbox("against time (else spp)", &by_time);
    // Log-log axes over the finite points.
    double x_lo = INFINITY, x_hi = 0, y_lo = INFINITY, y_hi = 0;
    auto x_of = [&](const ConvergencePoint& p) { return by_time ? p.seconds : double(p.spp); };
    for (const ConvergencePoint& p : points) {
        if (!(x_of(p) > 0)) continue;
        x_lo = std::min(x_lo, x_of(p));
        x_hi = std::max(x_hi, x_of(p));
        for (double y : {p.estimated, p.rmse})
            if (y > 0 && std::isfinite(y)) y_lo = std::min(y_lo, y), y_hi = std::max(y_hi, y);
    }
    const ImVec2 at = ImGui::GetCursorScreenPos();
    const float width = std::max(120.0f, ImGui::GetContentRegionAvail().x), height = 140;
    ImDrawList* draw = ImGui::GetWindowDrawList();
    draw->AddRectFilled(at, ImVec2(at.x + width, at.y + height), IM_COL32(20, 20, 24, 255));
    draw->AddRect(at, ImVec2(at.x + width, at.y + height), IM_COL32(90, 90, 90, 255));
    if (x_hi > x_lo && y_hi > 0) {
        // Whole decades on both axes, at least one wide.
        const double lx0 = std::floor(std::log10(x_lo)), lx1 = std::max(lx0 + 1, std::ceil(std::log10(x_hi)));
        const double ly0 = std::floor(std::log10(y_lo)), ly1 = std::max(ly0 + 1, std::ceil(std::log10(y_hi)));
        auto to_screen = [&](double x, double y) {
            return ImVec2(at.x + float((std::log10(x) - lx0) / (lx1 - lx0)) * width,
                          at.y + height - float((std::log10(y) - ly0) / (ly1 - ly0)) * height);
        };
        for (double d = lx0 + 1; d < lx1; ++d) {
            const float x = at.x + float((d - lx0) / (lx1 - lx0)) * width;
            draw->AddLine(ImVec2(x, at.y), ImVec2(x, at.y + height), IM_COL32(60, 60, 60, 255));
        }
        for (double d = ly0 + 1; d < ly1; ++d) {
            const float y = at.y + height - float((d - ly0) / (ly1 - ly0)) * height;
            draw->AddLine(ImVec2(at.x, y), ImVec2(at.x + width, y), IM_COL32(60, 60, 60, 255));
        }
        auto line = [&](double ConvergencePoint::*field, ImU32 colour) {
            std::vector<ImVec2> pts;
            for (const ConvergencePoint& p : points)
                if (x_of(p) > 0 && p.*field > 0 && std::isfinite(p.*field)) pts.push_back(to_screen(x_of(p), p.*field));
            if (pts.size() >= 2) draw->AddPolyline(pts.data(), int(pts.size()), colour, 0, 1.5f);
        };
        line(&ConvergencePoint::estimated, IM_COL32(90, 170, 255, 255));
        line(&ConvergencePoint::rmse, IM_COL32(255, 160, 60, 255));
        char text[96];
        std::snprintf(text, sizeof text, "1e%g", ly1);
        draw->AddText(ImVec2(at.x + 3, at.y + 2), IM_COL32(200, 200, 200, 255), text);
        std::snprintf(text, sizeof text, "1e%g", ly0);
        draw->AddText(ImVec2(at.x + 3, at.y + height - 16), IM_COL32(200, 200, 200, 255), text);
        std::snprintf(text, sizeof text, "%s 1e%g..1e%g", by_time ? "s" : "spp", lx0, lx1);
        draw->AddText(ImVec2(at.x + width - ImGui::CalcTextSize(text).x - 3, at.y + height - 16),
                      IM_COL32(200, 200, 200, 255), text);
    }
    ImGui::Dummy(ImVec2(width, height));
    ImGui::TextColored(ImVec4(0.35f, 0.67f, 1, 1), "estimated relative error");
    ImGui::SameLine();
    // The RMSE is of image A against image B, the reference or a kept snapshot, as picked.
    const CompareImage* b = ctx.ui.compare.comparison.b();
    ImGui::TextColored(ImVec4(1, 0.63f, 0.24f, 1), "%s", b ? ("RMSE vs B (" + b->name + ")").c_str() : "RMSE: no image B");
    ImGui::InputText("csv", &ctx.ui.save.paths.convergence);
    ImGui::BeginDisabled(points.empty());
    if (ImGui::Button("Save convergence CSV")) request_save(ctx, SaveKind::convergence, ctx.ui.save.paths.convergence);
    ImGui::EndDisabled();
}

}  // namespace

void panel_stats(PanelContext& ctx) {
    if (!ImGui::CollapsingHeader("Stats", ImGuiTreeNodeFlags_DefaultOpen)) return;
    // A fixed set of lines: what is live (spp, rate, noise) is in the status bar.
    const Scene& scene = ctx.model.scene();
    ImGui::Text("image %dx%d, UI %.0f frames/s (%.1f ms of work each)", scene.renderer.width, scene.renderer.height,
                ctx.ui.ui_fps, 1e3 * ctx.ui.ui_work);
    if (const auto& prepared = ctx.model.prepared())
        ImGui::Text("%zu spheres, %s BVH", prepared->spheres.size(),
                    prepared->bvh.backend() == AccelBackend::embree ? "Embree's" : "keithray's own");
    const Snapshot* current = ctx.frame();
    const double passes_per_second = current && current->full_seconds > 0 ? current->spp / current->full_seconds : 0.0;
    ImGui::Text("%.2f passes/s, non-finite samples dropped: %llu", passes_per_second,
                static_cast<unsigned long long>(current ? current->nonfinite_samples : 0));
    plot_convergence(ctx);
}

}  // namespace kr::viewer
