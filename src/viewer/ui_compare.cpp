// The window's inspect and compare tool: image B, the compare and noise views, the pixel
// inspector. Their figures and pictures come from the GL-free viewer/inspect.h,
// compare_view.h and convergence_log.h; this file draws them.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <imgui.h>
#include <imgui_stdlib.h>

#include "core/image_compare.h"
#include "core/text.h"
#include "viewer/scene_edit.h"
#include "viewer/status.h"
#include "viewer/ui_compare.h"

#include "viewer/ui_file_dialog.h"

namespace kr::viewer {

namespace fs = std::filesystem;

bool load_reference(PanelContext& ctx, const fs::path& file, bool automatic) {
    CompareTool& tool = ctx.ui.compare;
    try {
        tool.comparison.set_reference(kr::viewer::load_reference(file));
        tool.reference_automatic = automatic;
        tool.reference_path = file.string();
        tool.picture_key.clear();
    } catch (const std::exception& e) {
        ctx.messages.show_error(std::string("reference: ") + e.what());
        return false;
    }
    if (!automatic) note_recent_file(ctx, FilePurpose::open_image, file);
    return true;
}

void keep_image_b(PanelContext& ctx, const Snapshot& frame) {
    CompareTool& tool = ctx.ui.compare;
    // Image A as the window shows it (denoised when the display is), not the raw estimate.
    const DenoiseView view = ctx.model.settings().denoise;
    const RendererSettings& image = ctx.model.scene().renderer;
    tool.comparison.settings.b = tool.comparison.keep(shown_radiance(frame, view, image.width, image.height), frame.spp,
                                                      shown_word(frame, view));
    tool.picture_key.clear();
    ctx.messages.show_status("kept the image as " + tool.comparison.slots()[size_t(tool.comparison.settings.b)]->name +
                             " (image B)");
}

std::optional<PixelProbe> probe(const PanelContext& ctx, int x, int y) {
    const Snapshot* shown = ctx.ui.shown.get();
    const ViewerModel& model = ctx.model;
    if (!shown || !model.has_scene()) return std::nullopt;
    auto p = probe_pixel(*shown, model.scene().renderer.width, model.scene().renderer.height, x, y,
                         model.settings().tone, ctx.ui.compare.linear_scale, model.settings().denoise);
    // Right after an orbit the frame on screen is an earlier view's (shows_earlier_view).
    if (p) p->earlier_view = shown->generation != model.generation();
    return p;
}

StatsFigures stats_figures(const PanelContext& ctx) {
    const RunStatus st = run_status(ctx.frame(), ctx.model.settings(), !ctx.model.has_scene());
    const CompareTool& tool = ctx.ui.compare;
    StatsFigures f;
    f.state = std::string(run_state_names.name(st.state));
    f.spp = st.spp;
    f.target = st.target;
    f.elapsed = st.elapsed;
    f.mrays_per_second = st.mrays_per_second;
    f.noise = st.noise;
    if (const CompareImage* b = tool.comparison.b()) f.reference = b->name;
    if (const Snapshot* shown = ctx.ui.shown.get()) f.image = std::string(shown_word(*shown, ctx.model.settings().denoise));
    f.figures = tool.figures;
    if (tool.locked_probe) f.probe = probe(ctx, tool.locked_probe->first, tool.locked_probe->second);
    return f;
}

void update_pictures(PanelContext& ctx, Display& display) {
    CompareTool& tool = ctx.ui.compare;
    const Snapshot* shown = ctx.ui.shown.get();
    const ViewerModel& model = ctx.model;
    if (!shown || !model.has_scene()) return;
    const ToneSettings& tone = model.settings().tone;
    const CompareSettings& cs = tool.comparison.settings;
    const CompareImage* b = tool.comparison.b();
    // Everything below follows from these (a new reference or slot clears the key);
    // recomputed only when one changes.
    char key[256];
    const DenoiseView view = model.settings().denoise;
    std::snprintf(key, sizeof key, "%llu %d %.17g %d %d %d %d %.17g %p", static_cast<unsigned long long>(ctx.ui.shown_serial),
                  int(tone.tonemap), tone.exposure, int(view), int(cs.mode), int(cs.metric), cs.b, cs.error_scale,
                  static_cast<const void*>(b));
    if (tool.picture_key == key) return;
    tool.picture_key = key;
    // Image A at the frame's resolution (a preview's blocks unscaled).
    const Image shown_image = shown_radiance(*shown, view);
    tool.linear_scale = tonemap_scale(shown_image, tone.tonemap, tone.exposure_scale());
    const bool full = shown->scale == 1;

    // Image A is the render as the window shows it (denoised when the display is): its figures
    // against B, the error view and the reference's figures for the log.
    Rgb8Image a;
    if (full && (b || tool.comparison.reference())) a = tonemap(shown_image, tone.tonemap, tone.exposure_scale());
    Rgb8Image b_bytes = b ? b->display(tone) : Rgb8Image{};
    tool.figures.reset();
    tool.figures_note.clear();
    const bool reference_off_view =
        b && tool.comparison.reference() && b == &*tool.comparison.reference() && !model.view_as_loaded();
    if (reference_off_view) {
        // The reference is the file's view: another view's figures against it mean nothing.
        tool.figures_note = "the camera left the reference's view";
    } else if (b && full) {
        tool.figures = compare_figures(a, b_bytes);
        if (!tool.figures)
            tool.figures_note = "B is " + std::to_string(b->width()) + "x" + std::to_string(b->height()) + ", the image " +
                            std::to_string(a.width) + "x" + std::to_string(a.height);
    } else if (b) {
        tool.figures_note = "after the preview";
    }
    if (shown->generation == model.generation()) {
        std::optional<CompareFigures> truth;
        if (full && tool.comparison.reference() && model.view_as_loaded())
            truth = b == &*tool.comparison.reference() ? tool.figures : compare_figures(a, tool.comparison.reference()->display(tone));
        tool.convergence.record(*shown, truth);
    }

    // The picture draw_bytes shows for the mode.
    tool.picture_current = false;
    tool.picture_scale = 0;
    tool.picture_range.reset();
    tool.picture_missing.clear();
    Rgb8Image picture;
    switch (cs.mode) {
        case ViewMode::render: break;
        case ViewMode::reference:
        case ViewMode::split: picture = std::move(b_bytes); break;
        case ViewMode::error:
            if (tool.figures) {
                const std::vector<float> errors = pixel_errors(a, b_bytes, cs.metric);
                tool.picture_scale = cs.error_scale > 0 ? cs.error_scale : robust_scale(errors);
                picture = false_colour_picture(errors, a.width, a.height, tool.picture_scale);
            }
            break;
        case ViewMode::noise:
            tool.picture_scale = robust_scale(shown->standard_error);
            picture = standard_error_map(*shown, tool.picture_scale);
            break;
        case ViewMode::samples:
            if (!shown->sample_count.empty())
                tool.picture_scale = *std::max_element(shown->sample_count.begin(), shown->sample_count.end());
            picture = sample_count_map(*shown, tool.picture_scale);
            break;
        case ViewMode::albedo:
        case ViewMode::normal:
        case ViewMode::depth: {
            FeaturePicture f = feature_picture(*shown, cs.mode, model.scene().renderer.width, model.scene().renderer.height);
            picture = std::move(f.picture);
            tool.picture_range = f.range;
            tool.picture_missing = std::move(f.missing);
            break;
        }
    }
    const int w = model.scene().renderer.width, h = model.scene().renderer.height;
    if (picture.width == w && picture.height == h) {
        display.upload_bytes(picture);
        tool.picture_current = true;
    }
}

void draw_image(const PanelContext& ctx, Display& display, const PixelRect& rect, int fb_w, int fb_h) {
    const CompareTool& tool = ctx.ui.compare;
    const ViewerModel& model = ctx.model;
    const PixelRect area = ctx.view_area();
    const ToneSettings& tone = model.settings().tone;
    const ViewMode mode = tool.comparison.settings.mode;
    display.set_smooth(tool.smooth);
    if (mode == ViewMode::render || !tool.picture_current) {
        display.draw(rect, area, fb_w, fb_h, tone);  // the render, also while B or a map is missing
        return;
    }
    if (mode != ViewMode::split) {
        display.draw_bytes(rect, area, fb_w, fb_h);
        return;
    }
    // Split: A left of the divider, B right of it, each clipped to the view.
    const double divider = std::round(rect.x + tool.comparison.settings.split * rect.width);
    auto clip = [&](double x0, double x1) {
        const double a = std::max(x0, area.x), b = std::min(x1, area.x + area.width);
        return PixelRect{a, area.y, std::max(0.0, b - a), area.height};
    };
    display.draw(rect, clip(rect.x, divider), fb_w, fb_h, tone);
    display.draw_bytes(rect, clip(divider, rect.x + rect.width), fb_w, fb_h);
}

void draw_inspector(PanelContext& ctx, const PixelRect& rect) {
    CompareTool& tool = ctx.ui.compare;
    const ViewerModel& model = ctx.model;
    ImGuiIO& io = ImGui::GetIO();
    const float to_points = 1.0f / std::max(1.0f, io.DisplayFramebufferScale.x);
    ImDrawList* draw = ImGui::GetBackgroundDrawList();
    const double scale = rect.width / model.scene().renderer.width;
    if (tool.comparison.settings.mode == ViewMode::split && tool.picture_current) {
        const float x = float(std::round(rect.x + tool.comparison.settings.split * rect.width)) * to_points;
        draw->AddLine(ImVec2(x, float(rect.y) * to_points), ImVec2(x, float(rect.y + rect.height) * to_points),
                      IM_COL32(255, 255, 255, 200), 1.0f);
    }
    if (tool.locked_probe) {
        // A square around the locked pixel (at least 7 points, so it shows at any zoom).
        const float size = std::max(7.0f, float(scale) * to_points);
        const float cx = float(rect.x + (tool.locked_probe->first + 0.5) * scale) * to_points;
        const float cy = float(rect.y + (tool.locked_probe->second + 0.5) * scale) * to_points;
        draw->AddRect(ImVec2(cx - size / 2 - 1, cy - size / 2 - 1), ImVec2(cx + size / 2 + 1, cy + size / 2 + 1),
                      IM_COL32(255, 80, 80, 255));
    }
    // The selected sphere's outline, as the camera sees it; where that is not wholly on the
    // image (a wall, a sphere around the camera, one cut by the edge), also a tint over the
    // pixels that see it, so a selection always shows.
    if (const auto sel = ctx.selection(); sel && model.prepared()) {
        const Scene& s = model.scene();
        const Shape& shape = s.shapes[size_t(s.primitives[size_t(*sel)].shape)];
        const auto outline = sphere_outline(model.prepared()->camera, shape.centre, shape.radius, 64);
        std::vector<ImVec2> points;
        for (const auto& [fx, fy] : outline)
            points.emplace_back(float(rect.x + fx * rect.width) * to_points, float(rect.y + fy * rect.height) * to_points);
        const PixelRect view = ctx.view_area();
        draw->PushClipRect(ImVec2(float(view.x) * to_points, float(view.y) * to_points),
                           ImVec2(float(view.x + view.width) * to_points, float(view.y + view.height) * to_points));
        if (!outline_on_image(outline)) {
            UiState::SelectionTint& tint = ctx.ui.selection_tint;
            const int w = s.renderer.width, h = s.renderer.height;
            // Cells of about 4 image pixels (at most 160 a side): cheap enough to cast again
            // on every frame of an orbit.
            const int cols = std::clamp((w + 3) / 4, 1, 160), rows = std::clamp((h + 3) / 4, 1, 160);
            if (tint.generation != model.generation() || tint.primitive != *sel || tint.cols != cols || tint.rows != rows) {
                tint.cells = sphere_coverage(*model.prepared(), shape.centre, shape.radius, cols, rows);
                tint.any = std::find(tint.cells.begin(), tint.cells.end(), 1) != tint.cells.end();
                tint.generation = model.generation();
                tint.primitive = *sel;
                tint.cols = cols;
                tint.rows = rows;
            }
            const ImU32 colour = IM_COL32(255, 160, 0, 72);
            for (int y = 0; y < rows; ++y)
                for (int x = 0; x < cols;) {
                    if (!tint.cells[size_t(y) * size_t(cols) + size_t(x)]) {
                        ++x;
                        continue;
                    }
                    int end = x;  // one rectangle per run of covered cells
                    while (end < cols && tint.cells[size_t(y) * size_t(cols) + size_t(end)]) ++end;
                    draw->AddRectFilled(
                        ImVec2(float(rect.x + rect.width * x / cols) * to_points, float(rect.y + rect.height * y / rows) * to_points),
                        ImVec2(float(rect.x + rect.width * end / cols) * to_points,
                               float(rect.y + rect.height * (y + 1) / rows) * to_points),
                        colour);
                    x = end;
                }
            if (!tint.any) {
                // Nowhere on the image (behind the camera, out of the view, hidden): said at its top right.
                const std::string label = "selected: " + s.primitives[size_t(*sel)].id + " (not seen from here)";
                const ImVec2 size = ImGui::CalcTextSize(label.c_str());
                const float right = float(std::min(rect.x + rect.width, view.x + view.width)) * to_points;
                const ImVec2 at(right - size.x - 9, float(std::max(rect.y, view.y) + 6) * to_points);
                draw->AddRectFilled(ImVec2(at.x - 3, at.y - 2), ImVec2(at.x + size.x + 3, at.y + size.y + 2), IM_COL32(0, 0, 0, 170));
                draw->AddText(at, IM_COL32(255, 160, 0, 255), label.c_str());
            }
        }
        if (!points.empty())
            draw->AddPolyline(points.data(), int(points.size()), IM_COL32(255, 160, 0, 255), ImDrawFlags_Closed, 2.0f);
        draw->PopClipRect();
    }
    // A light selected as itself in the outliner (a point light): a marker where it is, as
    // a light gizmo (drawn over whatever hides it), or its name where it is off the image
    // (or nowhere: a light with no place in the scene, scene.h's light_anchor).
    if (const auto l = ctx.ui.selected_light;
        l && !ctx.selection() && model.prepared() && size_t(*l) < model.scene().lights.size()) {
        const Light& light = model.scene().lights[size_t(*l)];
        const LightAnchor anchor = light_anchor(light);
        const auto& shapes = model.scene().shapes;
        const bool on_shape = anchor.kind == LightAnchor::Kind::shape && anchor.shape >= 0 && size_t(anchor.shape) < shapes.size();
        const std::optional<ImageCircle> p =
            on_shape ? project_sphere(model.prepared()->camera, shapes[size_t(anchor.shape)].centre, 0)
            : anchor.kind == LightAnchor::Kind::point ? project_sphere(model.prepared()->camera, anchor.point, 0)
                                                      : std::nullopt;
        const PixelRect view = ctx.view_area();
        const ImU32 orange = IM_COL32(255, 160, 0, 255);
        if (p && p->fx >= 0 && p->fx <= 1 && p->fy >= 0 && p->fy <= 1) {
            const ImVec2 c(float(rect.x + p->fx * rect.width) * to_points, float(rect.y + p->fy * rect.height) * to_points);
            draw->AddCircle(c, 8, orange, 24, 2.0f);
            for (const auto& [dx, dy] : {std::pair{1.0f, 0.0f}, {0.0f, 1.0f}}) {
                draw->AddLine(ImVec2(c.x - 14 * dx, c.y - 14 * dy), ImVec2(c.x - 9 * dx, c.y - 9 * dy), orange, 2.0f);
                draw->AddLine(ImVec2(c.x + 9 * dx, c.y + 9 * dy), ImVec2(c.x + 14 * dx, c.y + 14 * dy), orange, 2.0f);
            }
            const ImVec2 size = ImGui::CalcTextSize(light.id.c_str()), text_at(c.x + 12, c.y + 8);
            draw->AddRectFilled(ImVec2(text_at.x - 2, text_at.y - 1), ImVec2(text_at.x + size.x + 2, text_at.y + size.y + 1),
                                IM_COL32(0, 0, 0, 170));
            draw->AddText(text_at, orange, light.id.c_str());
        } else {
            const std::string label = "selected: " + light.id + " (off the image)";
            const ImVec2 size = ImGui::CalcTextSize(label.c_str());
            const float right = float(std::min(rect.x + rect.width, view.x + view.width)) * to_points;
            const ImVec2 text_at(right - size.x - 9, float(std::max(rect.y, view.y) + 6) * to_points);
            draw->AddRectFilled(ImVec2(text_at.x - 3, text_at.y - 2), ImVec2(text_at.x + size.x + 3, text_at.y + size.y + 2),
                                IM_COL32(0, 0, 0, 170));
            draw->AddText(text_at, orange, label.c_str());
        }
    }
    // The render region (cyan), or the box being drawn (white).
    for (const auto& [box, colour] : {std::pair{ctx.ui.region, IM_COL32(0, 220, 255, 255)},
                                      std::pair{ctx.ui.region_draft, IM_COL32(255, 255, 255, 255)}})
        if (box)
            draw->AddRect(ImVec2(float(rect.x + box->x0 * scale) * to_points, float(rect.y + box->y0 * scale) * to_points),
                          ImVec2(float(rect.x + box->x1 * scale) * to_points, float(rect.y + box->y1 * scale) * to_points),
                          colour, 0.0f, 0, 1.0f);
    // A move (M): what it does, at the image's bottom left while it lasts.
    if (!ctx.ui.move_hint.empty()) {
        const PixelRect view = ctx.view_area();
        const ImVec2 size = ImGui::CalcTextSize(ctx.ui.move_hint.c_str());
        const float bottom = float(std::min(rect.y + rect.height, view.y + view.height)) * to_points;
        const ImVec2 at(float(std::max(rect.x, view.x) + 6) * to_points, bottom - size.y - 8);
        draw->AddRectFilled(ImVec2(at.x - 3, at.y - 2), ImVec2(at.x + size.x + 3, at.y + size.y + 2), IM_COL32(0, 0, 0, 170));
        draw->AddText(at, IM_COL32(255, 190, 80, 255), ctx.ui.move_hint.c_str());
    }
    // Which view the image shows, on the image (the render needs no label).
    const ViewMode mode = tool.comparison.settings.mode;
    if (mode != ViewMode::render) {
        const CompareImage* b = tool.comparison.b();
        std::string label = std::string(view_mode_names.name(mode));
        if (mode == ViewMode::split) label = "split: render | " + (b ? b->name : std::string("no image B"));
        else if ((mode == ViewMode::reference || mode == ViewMode::error) && b) label += ": " + b->name;
        if (mode == ViewMode::depth && tool.picture_current) {
            char range[96] = ": no hit";
            if (tool.picture_range)
                std::snprintf(range, sizeof range, ": %.4g (white) to %.4g (grey), black: no hit",
                              double(tool.picture_range->near), double(tool.picture_range->far));
            label += range;
        }
        if (is_feature_view(mode) && tool.picture_current && ctx.ui.shown && ctx.ui.shown->scale > 1)
            label += " (preview 1/" + std::to_string(ctx.ui.shown->scale) + ")";
        if (!tool.picture_current)
            label += " (not available" + (tool.picture_missing.empty() ? "" : ": " + tool.picture_missing) +
                     ": showing the render)";
        const PixelRect view = ctx.view_area();
        const ImVec2 at(float(std::max(rect.x, view.x) + 6) * to_points, float(std::max(rect.y, view.y) + 6) * to_points);
        const ImVec2 size = ImGui::CalcTextSize(label.c_str());
        draw->AddRectFilled(ImVec2(at.x - 3, at.y - 2), ImVec2(at.x + size.x + 3, at.y + size.y + 2), IM_COL32(0, 0, 0, 160));
        draw->AddText(at, IM_COL32(255, 255, 255, 230), label.c_str());
    }
    // Hovering the image with no button down shows its pixel.
    const PixelRect area = ctx.view_area();
    const double mx = io.MousePos.x / to_points, my = io.MousePos.y / to_points;
    const bool over = mx >= std::max(rect.x, area.x) && my >= std::max(rect.y, area.y) &&
                      mx < std::min(rect.x + rect.width, area.x + area.width) &&
                      my < std::min(rect.y + rect.height, area.y + area.height);
    tool.hover_text.clear();
    tool.hover_feature.clear();
    if (!over || io.WantCaptureMouse || io.MouseDown[0] || io.MouseDown[1] || io.MouseDown[2] || !ctx.ui.shown) return;
    const auto p = probe(ctx, int(std::floor((mx - rect.x) / scale)), int(std::floor((my - rect.y) / scale)));
    if (!p) return;
    // One line for the status bar; the box at the pointer only when asked for (I).
    const std::string line = probe_line(*p);
    // The feature view's layer at the pixel.
    const std::string& feature = tool.hover_feature =
        p->earlier_view ? std::string() : feature_readout(*ctx.ui.shown, mode, p->x, p->y);
    tool.hover_text = feature.empty() ? line : line + "   " + feature;
    if (!tool.probe_box) return;
    ImGui::BeginTooltip();
    if (p->earlier_view) {
        ImGui::TextUnformatted(line.c_str());
        ImGui::EndTooltip();
        return;
    }
    ImGui::Text("pixel %d, %d", p->x, p->y);
    ImGui::Text("radiance %.4g %.4g %.4g", p->mean.x, p->mean.y, p->mean.z);
    ImGui::Text("shown    %d %d %d", p->displayed[0], p->displayed[1], p->displayed[2]);
    if (!feature.empty()) ImGui::TextUnformatted(feature.c_str());
    if (p->preview) ImGui::TextDisabled("preview: no statistics yet");
    else if (std::isfinite(p->standard_error))
        ImGui::Text("%u samples, std. error %.3g", p->samples, p->standard_error);
    else ImGui::Text("%u samples, std. error: needs 2", p->samples);
    ImGui::TextDisabled("Shift+click locks the probe");
    ImGui::EndTooltip();
}

}  // namespace kr::viewer
