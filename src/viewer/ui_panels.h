// The panel column: the outliner on top, then tabs (Scene, Object, Camera, Render, Compare),
// each showing its panels top to bottom. A panel is a function over PanelContext
// (ui_context.h) in its own file, ui_panel_NAME.cpp, defining `void panel_NAME(PanelContext&)`;
// adding a panel is that file and its line in this list. PANEL(NAME, WHEN, TAB): WHEN is
// `always` (drawn before a scene has loaded) or `with_scene`; TAB is the tab that shows it,
// or `top` (above the tabs, whatever tab is shown).
#pragma once

#include <string_view>

#include "viewer/ui_context.h"

#define KR_VIEWER_PANELS(PANEL)          \
    PANEL(outliner, with_scene, top)     \
    PANEL(scene, always, scene)          \
    PANEL(save, with_scene, scene)       \
    PANEL(selection, with_scene, object) \
    PANEL(lights, with_scene, object)    \
    PANEL(materials, with_scene, object) \
    PANEL(camera, with_scene, camera)    \
    PANEL(lens, with_scene, camera)      \
    PANEL(renderer, with_scene, render)  \
    PANEL(tone_map, with_scene, render)  \
    PANEL(stats, with_scene, render)     \
    PANEL(compare, with_scene, compare)

namespace kr::viewer {

// The tabs, left to right; `top` is no tab (drawn above them).
enum class PanelTab { scene, object, camera, render, compare, top };
inline constexpr std::string_view kPanelTabNames[] = {"Scene", "Object", "Camera", "Render", "Compare"};
inline constexpr int kPanelTabs = 5;
// "scene", "object", ... (the status file's tab=).
std::string_view panel_tab_key(int tab);

#define KR_DECLARE_PANEL(name, when, tab) void panel_##name(PanelContext& ctx);
KR_VIEWER_PANELS(KR_DECLARE_PANEL)
#undef KR_DECLARE_PANEL

// Draws the panels of the list that apply: those above the tabs, the tab bar, the chosen
// tab's panels in the list's order.
void draw_panel_list(PanelContext& ctx);

// Brings `tab` to the front on the next frame.
inline void show_panel_tab(PanelContext& ctx, PanelTab tab) {
    ctx.ui.panel_tab = int(tab);
    ctx.ui.show_tab = true;
}

// The selection (a primitive or a light of its own) changes: the outliner, the image and the
// keys all go through it.
void select_primitive(PanelContext& ctx, std::optional<int> primitive);
void select_light(PanelContext& ctx, int light);

}  // namespace kr::viewer
