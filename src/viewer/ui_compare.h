// The inspect and compare tool in the window (its state: CompareTool, ui_context.h): image B,
// the picture each view shows, the image drawn as the view asks, the pixel inspector. Its
// panel is ui_panel_compare.cpp.
#pragma once

#include <filesystem>
#include <optional>

#include "viewer/gl_display.h"
#include "viewer/ui_context.h"

namespace kr::viewer {

// Reads image B's reference; a failure becomes the error message (false). One the user chose
// (not `automatic`) is noted in the recent images (ui_file_dialog.h).
bool load_reference(PanelContext& ctx, const std::filesystem::path& file, bool automatic);
// Keeps `frame` as image B (K, the panel's button).
void keep_image_b(PanelContext& ctx, const Snapshot& frame);
// Pixel (x, y) of the frame on screen.
std::optional<PixelProbe> probe(const PanelContext& ctx, int x, int y);
// What --stats-json writes.
StatsFigures stats_figures(const PanelContext& ctx);

// Image B, the error or noise map, the figures and the convergence log, for the frame on
// screen; made again only when something they follow from changed.
void update_pictures(PanelContext& ctx, Display& display);
// The image in `rect` as the view asks: the render, a picture, or both split.
void draw_image(const PanelContext& ctx, Display& display, const PixelRect& rect, int fb_w, int fb_h);
// The divider, the locked probe's square, and the hovered pixel's tooltip.
void draw_inspector(PanelContext& ctx, const PixelRect& rect);

}  // namespace kr::viewer
