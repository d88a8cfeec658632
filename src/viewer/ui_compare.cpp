// The window's inspect and compare tools: the pixel inspector, image B and the compare and
// noise views, the convergence plot. Their figures and pictures come from the GL-free
// viewer/inspect.h, compare_view.h and convergence_log.h; this file draws them.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <imgui.h>
#include <imgui_stdlib.h>

#include "core/image_compare.h"
#include "core/text.h"
#include "viewer/ui_app.h"

namespace kr::viewer {

namespace fs = std::filesystem;

void ViewerApp::load_reference(const fs::path& file, bool automatic) {
    try {
        compare_.set_reference(kr::viewer::load_reference(file));
        reference_automatic_ = automatic;
        reference_path_ = file.string();
        picture_key_.clear();
    } catch (const std::exception& e) {
        show_error(std::string("reference: ") + e.what());
    }
}

std::optional<PixelProbe> ViewerApp::probe(int x, int y) const {
    if (!shown_ || !model_.has_scene()) return std::nullopt;
    return probe_pixel(*shown_, model_.scene().renderer.width, model_.scene().renderer.height, x, y,
                       model_.settings().tone, linear_scale_);
}

StatsFigures ViewerApp::stats_figures() const {
    const bool current = shown_ && shown_->generation == model_.generation();
    const RunStatus st = run_status(current ? shown_.get() : nullptr, model_.settings(), !model_.has_scene());
    StatsFigures f;
    f.state = std::string(run_state_names.name(st.state));
    f.spp = st.spp;
    f.target = st.target;
    f.elapsed = st.elapsed;
    f.mrays_per_second = st.mrays_per_second;
    f.noise = st.noise;
    if (const CompareImage* b = compare_.b()) f.reference = b->name;
    f.figures = figures_;
    if (locked_probe_) f.probe = probe(locked_probe_->first, locked_probe_->second);
    return f;
}

void ViewerApp::update_pictures() {
    if (!shown_ || !model_.has_scene()) return;
    const ToneSettings& tone = model_.settings().tone;
    const CompareSettings& cs = compare_.settings;
    const CompareImage* b = compare_.b();
    // Everything below follows from these (a new reference or slot clears the key);
    // recomputed only when one changes.
    char key[256];
    std::snprintf(key, sizeof key, "%llu %d %.17g %d %d %d %.17g %p", static_cast<unsigned long long>(shown_serial_),
                  int(tone.tonemap), tone.exposure, int(cs.mode), int(cs.metric), cs.b, cs.error_scale,
                  static_cast<const void*>(b));
    if (picture_key_ == key) return;
    picture_key_ = key;
    linear_scale_ = tonemap_scale(shown_->radiance, tone.tonemap, tone.exposure_scale());
    const bool full = shown_->scale == 1;

    // A (the render as displayed) against B: the figures, and the reference's for the log.
    Rgb8Image a;
    if (full && (b || compare_.reference())) a = tonemap(shown_->radiance, tone.tonemap, tone.exposure_scale());
    Rgb8Image b_bytes = b ? b->display(tone) : Rgb8Image{};
    figures_.reset();
    figures_note_.clear();
    if (b && full) {
        figures_ = compare_figures(a, b_bytes);
        if (!figures_)
            figures_note_ = "B is " + std::to_string(b->width()) + "x" + std::to_string(b->height()) + ", the image " +
                            std::to_string(a.width) + "x" + std::to_string(a.height);
    } else if (b) {
        figures_note_ = "after the preview";
    }
    if (shown_->generation == model_.generation()) {
        std::optional<CompareFigures> truth;
        if (full && compare_.reference())
            truth = b == &*compare_.reference() ? figures_ : compare_figures(a, compare_.reference()->display(tone));
        convergence_.record(*shown_, truth);
    }

    // The picture draw_bytes shows for the mode.
    picture_current_ = false;
    picture_scale_ = 0;
    Rgb8Image picture;
    switch (cs.mode) {
        case ViewMode::render: break;
        case ViewMode::reference:
        case ViewMode::split: picture = std::move(b_bytes); break;
        case ViewMode::error:
            if (figures_) {
                const std::vector<float> errors = pixel_errors(a, b_bytes, cs.metric);
                picture_scale_ = cs.error_scale > 0 ? cs.error_scale : robust_scale(errors);
                picture = false_colour_picture(errors, a.width, a.height, picture_scale_);
            }
            break;
        case ViewMode::noise:
            picture_scale_ = robust_scale(shown_->standard_error);
            picture = standard_error_map(*shown_, picture_scale_);
            break;
        case ViewMode::samples:
            if (!shown_->sample_count.empty())
                picture_scale_ = *std::max_element(shown_->sample_count.begin(), shown_->sample_count.end());
            picture = sample_count_map(*shown_, picture_scale_);
            break;
    }
    const int w = model_.scene().renderer.width, h = model_.scene().renderer.height;
    if (picture.width == w && picture.height == h) {
        display_->upload_bytes(picture);
        picture_current_ = true;
    }
}

void ViewerApp::draw_image(const PixelRect& rect, int fb_w, int fb_h) {
    const PixelRect area = view_area();
    const ToneSettings& tone = model_.settings().tone;
    const ViewMode mode = compare_.settings.mode;
    if (mode == ViewMode::render || !picture_current_) {
        display_->draw(rect, area, fb_w, fb_h, tone);  // the render, also while B or a map is missing
        return;
    }
    if (mode != ViewMode::split) {
        display_->draw_bytes(rect, area, fb_w, fb_h);
        return;
    }
    // Split: A left of the divider, B right of it, each clipped to the view.
    const double divider = std::round(rect.x + compare_.settings.split * rect.width);
    auto clip = [&](double x0, double x1) {
        const double a = std::max(x0, area.x), b = std::min(x1, area.x + area.width);
        return PixelRect{a, area.y, std::max(0.0, b - a), area.height};
    };
    display_->draw(rect, clip(rect.x, divider), fb_w, fb_h, tone);
    display_->draw_bytes(rect, clip(divider, rect.x + rect.width), fb_w, fb_h);
}

void ViewerApp::draw_inspector(const PixelRect& rect) {
    ImGuiIO& io = ImGui::GetIO();
    const float to_points = 1.0f / std::max(1.0f, io.DisplayFramebufferScale.x);
    ImDrawList* draw = ImGui::GetBackgroundDrawList();
    const double scale = rect.width / model_.scene().renderer.width;
    if (compare_.settings.mode == ViewMode::split && picture_current_) {
        const float x = float(std::round(rect.x + compare_.settings.split * rect.width)) * to_points;
        draw->AddLine(ImVec2(x, float(rect.y) * to_points), ImVec2(x, float(rect.y + rect.height) * to_points),
                      IM_COL32(255, 255, 255, 200), 1.0f);
    }
    if (locked_probe_) {
        // A square around the locked pixel (at least 7 points, so it shows at any zoom).
        const float size = std::max(7.0f, float(scale) * to_points);
        const float cx = float(rect.x + (locked_probe_->first + 0.5) * scale) * to_points;
        const float cy = float(rect.y + (locked_probe_->second + 0.5) * scale) * to_points;
        draw->AddRect(ImVec2(cx - size / 2 - 1, cy - size / 2 - 1), ImVec2(cx + size / 2 + 1, cy + size / 2 + 1),
                      IM_COL32(255, 80, 80, 255));
    }
    // Hovering the image with no button down shows its pixel.
    const PixelRect area = view_area();
    const double mx = io.MousePos.x / to_points, my = io.MousePos.y / to_points;
    const bool over = mx >= std::max(rect.x, area.x) && my >= std::max(rect.y, area.y) &&
                      mx < std::min(rect.x + rect.width, area.x + area.width) &&
                      my < std::min(rect.y + rect.height, area.y + area.height);
    if (!over || io.WantCaptureMouse || io.MouseDown[0] || io.MouseDown[1] || io.MouseDown[2] || !shown_) return;
    const auto p = probe(int(std::floor((mx - rect.x) / scale)), int(std::floor((my - rect.y) / scale)));
    if (!p) return;
    ImGui::BeginTooltip();
    ImGui::Text("pixel %d, %d", p->x, p->y);
    ImGui::Text("radiance %.4g %.4g %.4g", p->mean.x, p->mean.y, p->mean.z);
    ImGui::Text("shown    %d %d %d", p->displayed[0], p->displayed[1], p->displayed[2]);
    if (p->preview) ImGui::TextDisabled("preview: no statistics yet");
    else if (std::isfinite(p->standard_error))
        ImGui::Text("%u samples, std. error %.3g", p->samples, p->standard_error);
    else ImGui::Text("%u samples, std. error: needs 2", p->samples);
    ImGui::TextDisabled("Shift+click locks the probe");
    ImGui::EndTooltip();
}

namespace {

// A horizontal viridis bar from 0 to `scale` with its end labels.
void colour_bar(double scale, const char* unit) {
    ImDrawList* draw = ImGui::GetWindowDrawList();
    const ImVec2 at = ImGui::GetCursorScreenPos();
    const float width = std::max(60.0f, ImGui::GetContentRegionAvail().x), height = 12;
    constexpr int kSteps = 64;
    for (int i = 0; i < kSteps; ++i) {
        const auto c = viridis((i + 0.5) / kSteps);
        draw->AddRectFilled(ImVec2(at.x + width * i / kSteps, at.y), ImVec2(at.x + width * (i + 1) / kSteps, at.y + height),
                            IM_COL32(c[0], c[1], c[2], 255));
    }
    ImGui::Dummy(ImVec2(width, height));
    ImGui::Text("0");
    char label[48];
    std::snprintf(label, sizeof label, "%.3g%s", scale, unit);
    ImGui::SameLine(std::max(0.0f, width - ImGui::CalcTextSize(label).x));
    ImGui::TextUnformatted(label);
}

}  // namespace

void ViewerApp::panel_compare() {
    // Open and scrolled to from the start when the command line asked for a compare view or
    // a probe.
    const bool asked = !compare_panel_shown_ && (options_.compare.mode != ViewMode::render || options_.probe);
    compare_panel_shown_ = true;
    if (asked) ImGui::SetNextItemOpen(true);
    if (!ImGui::CollapsingHeader("Inspect and compare")) return;
    if (asked) ImGui::SetScrollHereY(0.0f);
    const int w = model_.scene().renderer.width, h = model_.scene().renderer.height;
    const PixelRect area = view_area();
    // Zoom.
    ImGui::Text("zoom %s", view_.fitted() ? "fit" : "");
    if (!view_.fitted()) {
        ImGui::SameLine(0, 0);
        ImGui::Text("%gx", view_.scale(area, w, h));
    }
    ImGui::SameLine();
    if (ImGui::SmallButton("fit (0)")) view_.fit();
    ImGui::SameLine();
    if (ImGui::SmallButton("1:1 (1)")) view_.one_to_one(area, w, h);
    ImGui::SameLine();
    const double cx = area.x + area.width / 2, cy = area.y + area.height / 2;
    if (ImGui::SmallButton("+")) view_.zoom_steps(area, w, h, 1, cx, cy);
    ImGui::SameLine();
    if (ImGui::SmallButton("-")) view_.zoom_steps(area, w, h, -1, cx, cy);

    // The view.
    CompareSettings& cs = compare_.settings;
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
    if ((cs.mode == ViewMode::error || cs.mode == ViewMode::noise || cs.mode == ViewMode::samples) && picture_current_)
        colour_bar(picture_scale_, cs.mode == ViewMode::samples ? " spp" : "");
    else if (cs.mode != ViewMode::render && !picture_current_)
        ImGui::TextDisabled(cs.mode == ViewMode::noise || cs.mode == ViewMode::samples
                                ? "shown after the preview"
                                : "needs image B of the image's size");

    // Image B: the reference or a kept snapshot.
    ImGui::Separator();
    ImGui::TextDisabled("image B");
    ImGui::InputText("reference", &reference_path_);
    ImGui::SameLine();
    if (ImGui::SmallButton("load") && !reference_path_.empty()) load_reference(reference_path_, false);
    if (ImGui::RadioButton(compare_.reference() ? compare_.reference()->name.c_str() : "(no reference)", cs.b == -1))
        cs.b = -1;
    for (int i = 0; i < kSnapshotSlots; ++i) {
        const auto& slot = compare_.slots()[size_t(i)];
        if (!slot) continue;
        ImGui::PushID(i);
        if (ImGui::RadioButton(slot->name.c_str(), cs.b == i)) cs.b = i;
        ImGui::SameLine();
        if (ImGui::SmallButton("drop")) {
            compare_.drop(i);
            picture_key_.clear();
        }
        ImGui::PopID();
    }
    const bool full = shown_ && shown_->scale == 1 && shown_->generation == model_.generation();
    ImGui::BeginDisabled(!full);
    if (ImGui::Button("keep this image as B (K)")) {
        cs.b = compare_.keep(shown_->radiance, shown_->spp);
        picture_key_.clear();
        status_ = "kept the image as " + compare_.slots()[size_t(cs.b)]->name + " (image B)";
    }
    ImGui::EndDisabled();
    if (figures_) ImGui::Text("A vs B: PSNR %.2f dB, RMSE %.4g", figures_->psnr, figures_->rmse);
    else if (!figures_note_.empty()) ImGui::TextDisabled("A vs B: %s", figures_note_.c_str());

    // The locked probe.
    ImGui::Separator();
    ImGui::TextDisabled("probe (Shift+click on the image)");
    if (!locked_probe_) {
        ImGui::TextDisabled("hover the image to read a pixel");
        return;
    }
    if (const auto p = probe(locked_probe_->first, locked_probe_->second)) {
        ImGui::Text("pixel %d, %d: radiance %.4g %.4g %.4g", p->x, p->y, p->mean.x, p->mean.y, p->mean.z);
        ImGui::Text("shown %d %d %d", p->displayed[0], p->displayed[1], p->displayed[2]);
        if (!p->preview)
            ImGui::Text("%u samples, std. error %.3g", p->samples, p->standard_error);
    } else {
        ImGui::TextDisabled("pixel %d, %d is outside the image", locked_probe_->first, locked_probe_->second);
    }
    if (ImGui::SmallButton("release")) locked_probe_.reset();
}

void ViewerApp::plot_convergence() {
    const std::vector<ConvergencePoint>& points = convergence_.points();
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
    ImGui::TextColored(ImVec4(1, 0.63f, 0.24f, 1), compare_.reference() ? "RMSE vs reference" : "(no reference)");
    ImGui::InputText("csv", &save_paths_.convergence);
    ImGui::BeginDisabled(points.empty());
    if (ImGui::Button("Save convergence CSV")) request_save(SaveKind::convergence, save_paths_.convergence);
    ImGui::EndDisabled();
}

}  // namespace kr::viewer
