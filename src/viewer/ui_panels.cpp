// The panel list's drawing (the list itself: ui_panels.h).
#include "viewer/ui_panels.h"

#include <string>

#include <imgui.h>

#include "viewer/ui_widgets.h"

namespace kr::viewer {

std::string_view panel_tab_key(int tab) {
    static constexpr std::string_view kKeys[] = {"scene", "object", "camera", "render", "compare"};
    return tab >= 0 && tab < kPanelTabs ? kKeys[tab] : std::string_view("none");
}

void draw_panel_list(PanelContext& ctx) {
    [[maybe_unused]] constexpr bool always = true, with_scene = false;
    [[maybe_unused]] constexpr PanelTab top = PanelTab::top, scene = PanelTab::scene, object = PanelTab::object,
                                        camera = PanelTab::camera, render = PanelTab::render, compare = PanelTab::compare;
    const bool has_scene = ctx.model.has_scene();
#define KR_DRAW_PANEL(name, when, tab) \
    if ((when || has_scene) && tab == shown) panel_##name(ctx);
    {
        const PanelTab shown = PanelTab::top;
        KR_VIEWER_PANELS(KR_DRAW_PANEL)
    }
    // Without a scene only the Scene tab has anything to show (open another file).
    if (!has_scene) show_panel_tab(ctx, PanelTab::scene);
    // The command line asked for a compare view or a probe: the Compare tab, once.
    if (ctx.ui.compare.open_panel) show_panel_tab(ctx, PanelTab::compare);
    if (!ImGui::BeginTabBar("##panel tabs", ImGuiTabBarFlags_FittingPolicyResizeDown)) return;
    const bool forced = ctx.ui.show_tab;
    ctx.ui.show_tab = false;
    for (int t = 0; t < kPanelTabs; ++t) {
        const std::string label(kPanelTabNames[t]);
        const ImGuiTabItemFlags flags = forced && t == ctx.ui.panel_tab ? ImGuiTabItemFlags_SetSelected : 0;
        const bool open = ImGui::BeginTabItem(label.c_str(), nullptr, flags);
        mark_item(ctx, "tab:" + std::string(panel_tab_key(t)));
        if (!open) continue;
        if (!forced) ctx.ui.panel_tab = t;
        const PanelTab shown = PanelTab(t);
        KR_VIEWER_PANELS(KR_DRAW_PANEL)
        ImGui::EndTabItem();
    }
#undef KR_DRAW_PANEL
    ImGui::EndTabBar();
}

}  // namespace kr::viewer
