// The panel list's drawing (the list itself: ui_panels.h).
#include "viewer/ui_panels.h"

namespace kr::viewer {

void draw_panel_list(PanelContext& ctx) {
    [[maybe_unused]] constexpr bool always = true, with_scene = false;
    const bool has_scene = ctx.model.has_scene();
#define KR_DRAW_PANEL(name, when) \
    if (when || has_scene) panel_##name(ctx);
    KR_VIEWER_PANELS(KR_DRAW_PANEL)
#undef KR_DRAW_PANEL
}

}  // namespace kr::viewer
