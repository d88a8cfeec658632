// The panel column, top to bottom. A panel is a function over PanelContext (ui_context.h)
// in its own file, ui_panel_NAME.cpp, defining `void panel_NAME(PanelContext&)`; adding a
// panel is that file and its line in this list. PANEL(NAME, WHEN): WHEN is `always` (drawn
// before a scene has loaded) or `with_scene`.
#pragma once

#include "viewer/ui_context.h"

#define KR_VIEWER_PANELS(PANEL)  \
    PANEL(scene, always)         \
    PANEL(selection, with_scene) \
    PANEL(camera, with_scene)    \
    PANEL(lens, with_scene)      \
    PANEL(lights, with_scene)    \
    PANEL(materials, with_scene) \
    PANEL(tone_map, with_scene)  \
    PANEL(renderer, with_scene)  \
    PANEL(compare, with_scene)   \
    PANEL(stats, with_scene)     \
    PANEL(save, with_scene)

namespace kr::viewer {

#define KR_DECLARE_PANEL(name, when) void panel_##name(PanelContext& ctx);
KR_VIEWER_PANELS(KR_DECLARE_PANEL)
#undef KR_DECLARE_PANEL

// Draws the panels of the list that apply, in its order.
void draw_panel_list(PanelContext& ctx);

}  // namespace kr::viewer
