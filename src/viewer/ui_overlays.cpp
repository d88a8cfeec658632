// The window around the panel column: the status bar, the help window, a refused edit
// flashed at the pointer, and the quit and discard questions.
#include "viewer/ui_overlays.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <GLFW/glfw3.h>
#include <imgui.h>

namespace kr::viewer {

namespace {

// The keys and mouse controls, for the help window (F1 or ?).
constexpr const char* kHelpRows[][2] = {
    {"left drag", "orbit about the surface under the pointer (else the target), also from the selection; stops at surfaces"},
    {"left drag (fly mode)", "look around"},
    {"click", "select the sphere under the pointer (Esc: none); shown outlined, or tinted; also in the outliner"},
    {"M", "move the selection with the pointer: click or Return places it, Esc or right click puts it back"},
    {"M, then X / Y / Z", "move along world x, y or z only (again: the view plane)"},
    {"right drag", "pan"},
    {"wheel, Ctrl+wheel, + / -", "zoom the image about the pointer (samples kept)"},
    {"Shift+wheel, Shift+middle drag", "dolly the camera"},
    {"middle drag", "pan the image"},
    {"0 / 1", "fit the image to the window / show it 1:1"},
    {"hover / Shift+click", "read a pixel in the status bar / lock the probe on it"},
    {"I", "the pixel's numbers also in a box at the pointer"},
    {"V", "next view: render, reference, split, error, noise, samples, albedo, normal, depth"},
    {"K", "keep the image as a snapshot (image B)"},
    {"Ctrl+click, or F then click", "focus the lens on the clicked surface"},
    {"G", "fly mode on / off (speed: Camera panel)"},
    {"arrows", "orbit (fly mode: look)"},
    {"W / S", "dolly in / out (fly mode: forward / back)"},
    {"A / D, Page Up / Page Down", "pan left / right / up / down (fly mode: A / D, Q / E fly)"},
    {"E / Shift+E", "exposure up / down half a stop (an undoable display edit; fly mode: E flies up)"},
    {"Home or R", "reset the view to the file's camera (the lens stays)"},
    {". or numpad-.", "frame the selection (an object or a light; Ctrl+Z undoes it)"},
    {"numpad 1 / 3 / 7", "front / right / top view about the target (Ctrl: back / left / bottom)"},
    {"Ctrl+1..9 / Shift+1..9", "store the view as bookmark N (saved with the cameras) / go to it"},
    {"B, then a left drag / Shift+B", "render region: only its pixels refine / the whole image"},
    {"Ctrl+D / Delete", "duplicate / delete the selection"},
    {"Ctrl+S", "save the scene over its file (a read-only one: asks where)"},
    {"Ctrl+O / Ctrl+Shift+S", "open a scene / save it as: the file chooser, or a folder browser"},
    {"drop a file on the window", "a scene (.json) opens; an image becomes image B"},
    {"Ctrl+= / Ctrl+- / Ctrl+0", "UI scale up / down / 1 (times the monitor's scale)"},
    {"[ / ]", "halve / double the target spp (keeps the samples taken)"},
    {"Space", "pause / resume"},
    {"Ctrl+Z", "undo"},
    {"Ctrl+Shift+Z, Ctrl+Y", "redo"},
    {"Tab", "hide / show the panel (drag its left edge to resize it)"},
    {"F11", "fullscreen"},
    {"F1 or ?", "this help"},
    {"Esc", "cancel a move; close the help, a drop-down or the selection; quit (asks first with unsaved edits)"},
    {"typed numbers", "apply on Enter or when the field is left"},
};

std::string format_duration(double s) {
    char buf[32];
    if (s < 60) std::snprintf(buf, sizeof buf, "%.1f s", s);
    else std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
    return buf;
}

}  // namespace

void draw_status_bar(PanelContext& ctx) {
    Messages& messages = ctx.messages;
    const ImGuiIO& io = ImGui::GetIO();
    const float bar_h = float(ctx.status_bar_height() / std::max(1.0f, io.DisplayFramebufferScale.y));
    ImGui::SetNextWindowPos(ImVec2(0, io.DisplaySize.y - bar_h));
    ImGui::SetNextWindowSize(ImVec2(io.DisplaySize.x, bar_h));
    ImGui::Begin("##status", nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                     ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoBringToFrontOnFocus);
    const Snapshot* current = ctx.frame();
    const RunStatus st = run_status(current, ctx.model.settings(), !ctx.model.has_scene(), ctx.shows_earlier_view());
    // Line 1: state, spp, progress with ETA, elapsed, Mrays/s, noise, PSNR: fields of fixed
    // widths (their widest figures), so nothing moves as the figures change; where the window
    // is narrow, the least important go (fit_status_fields).
    static const ImVec4 kStateColours[] = {{0.8f, 0.8f, 0.8f, 1}, {0.5f, 0.8f, 1, 1}, {0.5f, 0.8f, 1, 1},
                                           {1, 0.8f, 0.3f, 1},     {0.4f, 0.9f, 0.4f, 1}, {1, 0.4f, 0.4f, 1}};
    static_assert(std::size(kStateColours) == run_state_names.names.size());
    auto text_width = [](const std::string& s) { return double(ImGui::CalcTextSize(s.c_str()).x); };
    const std::string shown(current ? shown_word(*current, ctx.model.settings().denoise) : "");
    char text[128];
    if (st.unlimited) std::snprintf(text, sizeof text, "%d spp (unlimited) %s", st.spp, shown.c_str());
    else std::snprintf(text, sizeof text, "%d / %d spp %s", st.spp, st.target, shown.c_str());
    const std::string spp = text;
    // Its widest: the spp as many digits as the target (at least 3), the longest word.
    const int digits = int(std::to_string(std::max({st.target, st.spp, 999})).size());
    const std::string wide_number(size_t(digits), '8');
    const std::string spp_wide = st.unlimited ? wide_number + " spp (unlimited) denoised"
                                              : wide_number + " / " + wide_number + " spp denoised";
    char overlay[64] = "";
    if (st.progress >= 0) {
        if (st.state == RunState::done) std::snprintf(overlay, sizeof overlay, "done (%s)", st.rule.c_str());
        else if (st.eta >= 0) std::snprintf(overlay, sizeof overlay, "ETA %s (%s)", format_duration(st.eta).c_str(), st.rule.c_str());
        else std::snprintf(overlay, sizeof overlay, "%s", st.rule.c_str());
    } else if (st.state == RunState::moving) {
        std::snprintf(overlay, sizeof overlay, "an earlier view");  // the camera moves: its frame is coming
    } else if (!st.unlimited) {
        std::snprintf(overlay, sizeof overlay, "starting (spp)");  // no frame yet: towards the target
    } else {
        std::snprintf(overlay, sizeof overlay, "unlimited: no stop rule");
    }
    const std::string elapsed = st.preview ? "preview" : format_duration(st.elapsed);
    std::snprintf(text, sizeof text, "%.2f Mrays/s", st.mrays_per_second);
    const std::string rate = text;
    // With a render region, the region's own samples and noise instead (the whole image's in
    // the tooltip): the spp and the stop rules count the whole image.
    std::optional<RegionStatus> region;
    if (ctx.ui.region && current) region = region_status(*current, *ctx.ui.region);
    const std::string noise = st.noise >= 0 ? "noise " + format_noise(st.noise) : "noise: needs 2 spp";
    std::string noise_text = noise;
    if (region) {
        const std::string region_noise = region->noise >= 0 ? format_noise(region->noise) : "needs 2 spp";
        std::snprintf(text, sizeof text, "region %.4g spp, noise %s", region->samples_per_pixel, region_noise.c_str());
        noise_text = text;
    }
    const std::optional<CompareFigures>& figures = ctx.ui.compare.figures;
    // Against image B (the reference, or a kept snapshot), as `keithray psnr` computes it.
    const std::string psnr = figures && current ? "vs B " + format_psnr(*figures) : "";
    enum Field { state, spp_field, progress, time, mrays, noise_field, psnr_field };
    const double spacing = ImGui::GetStyle().ItemSpacing.x * 2;
    const std::vector<StatusField> fields = {
        {text_width("rendering"), 0},
        {text_width(spp_wide), 0},
        {std::max(120.0, text_width("ETA 59m59s (noise)") + 16), 2},
        {text_width("59m59s"), 3},
        {text_width("99999.99 Mrays/s"), 4},
        {text_width(region ? "region 99999 spp, noise needs 2 spp" : "noise: needs 2 spp"), 1},
        {psnr.empty() ? 0.0 : text_width("vs B identical"), 1},
    };
    const std::vector<bool> show = fit_status_fields(fields, io.DisplaySize.x - 2 * ImGui::GetStyle().WindowPadding.x, spacing);
    static constexpr const char* kFieldNames[] = {"state", "spp", "progress", "time", "rate", "noise", "psnr"};
    ctx.ui.status_fields.clear();
    for (size_t i = 0; i < show.size(); ++i)
        if (show[i] && (i != size_t(psnr_field) || !psnr.empty()))
            ctx.ui.status_fields += (ctx.ui.status_fields.empty() ? "" : ",") + std::string(kFieldNames[i]);
    ImGui::AlignTextToFramePadding();
    double x = ImGui::GetCursorPosX();
    bool first = true;
    auto place = [&](Field f) {
        if (!show[size_t(f)]) return false;
        if (!first) ImGui::SameLine(float(x));
        first = false;
        x += fields[size_t(f)].width + spacing;
        return true;
    };
    if (place(state)) ImGui::TextColored(kStateColours[size_t(st.state)], "%s", std::string(run_state_names.name(st.state)).c_str());
    if (place(spp_field)) ImGui::TextUnformatted(spp.c_str());
    if (place(progress)) {
        // A dark fill under the light overlay text: legible over the filled part too.
        ImGui::PushStyleColor(ImGuiCol_PlotHistogram, ImVec4(0.16f, 0.42f, 0.62f, 1));
        ImGui::ProgressBar(st.progress >= 0 ? float(st.progress) : 0.0f, ImVec2(float(fields[progress].width), 0), overlay);
        ImGui::PopStyleColor();
    }
    if (place(time)) ImGui::TextUnformatted(elapsed.c_str());
    if (place(mrays)) ImGui::TextUnformatted(rate.c_str());
    if (place(noise_field)) {
        if (region) {
            ImGui::TextColored(ImVec4(0, 0.86f, 1, 1), "%s", noise_text.c_str());
            if (ImGui::IsItemHovered())
                ImGui::SetTooltip("the render region's pixels: mean samples, estimated relative error\n"
                                  "the whole image (the spp and the stop rules count it): %s", noise.c_str());
        } else if (st.noise >= 0) {
            ImGui::TextUnformatted(noise.c_str());
        } else {
            ImGui::TextDisabled("%s", noise.c_str());
        }
    }
    if (!psnr.empty() && place(psnr_field)) ImGui::TextUnformatted(psnr.c_str());
    // Line 2: one message, the most important first; full text on hover.
    const std::string* message = nullptr;
    ImVec4 colour(0.85f, 0.85f, 0.85f, 1);
    std::string inside;
    if (!messages.error.empty()) {
        message = &messages.error;
        colour = ImVec4(1, 0.4f, 0.4f, 1);
    } else if (ctx.ui.inside_sphere) {
        inside = "camera is inside sphere " + *ctx.ui.inside_sphere + ": the image shows its inside (Home resets the view)";
        message = &inside;
        colour = ImVec4(1, 0.8f, 0.3f, 1);
    } else if (!messages.status.empty()) {
        message = &messages.status;
    }
    ImGui::AlignTextToFramePadding();
    if (message) {
        ImGui::PushStyleColor(ImGuiCol_Text, colour);
        ImGui::TextUnformatted(message->c_str());  // one line: the window clips it
        ImGui::PopStyleColor();
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", message->c_str());
        if (message == &messages.error) {
            ImGui::SameLine();
            if (ImGui::SmallButton("dismiss")) messages.error.clear();
        }
    } else if (!ctx.ui.compare.hover_text.empty()) {
        // The inspector's numbers for the pixel under the pointer: here, not over the image.
        ImGui::TextUnformatted(ctx.ui.compare.hover_text.c_str());
    } else {
        ImGui::TextDisabled("F1 or ?: keys and mouse   Tab: panel   F11: fullscreen   I: pixel box at the pointer");
    }
    ImGui::End();
}

void draw_error_flash(const Messages& messages) {
    // A refused edit also shows where the user is looking: beside the pointer, briefly.
    if (!messages.flashing(UiClock::now())) return;
    ImGui::BeginTooltip();
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.4f, 0.4f, 1));
    ImGui::PushTextWrapPos(ImGui::GetFontSize() * 30);
    ImGui::TextUnformatted(messages.error.c_str());
    ImGui::PopTextWrapPos();
    ImGui::PopStyleColor();
    ImGui::EndTooltip();
}

void draw_help(UiState& ui) {
    if (!ui.help_visible) return;
    const ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x * 0.5f, io.DisplaySize.y * 0.45f), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
    ImGui::Begin("Keys and mouse (F1, ? or Esc closes)", &ui.help_visible,
                 ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoSavedSettings);
    if (ImGui::BeginTable("keys", 2)) {
        for (const auto& row : kHelpRows) {
            ImGui::TableNextRow();
            ImGui::TableNextColumn();
            ImGui::TextUnformatted(row[0]);
            ImGui::TableNextColumn();
            ImGui::TextUnformatted(row[1]);
        }
        ImGui::EndTable();
    }
    ImGui::TextDisabled("mouse and keys act on the image; the panel takes them while the pointer is over it");
    ImGui::End();
}

QuitAnswer quit_popup(bool& asked, bool cancel, bool confirm, bool save_asks_where) {
    if (asked) {
        ImGui::OpenPopup(kQuitQuestion);
        asked = false;
    }
    if (!ImGui::BeginPopupModal(kQuitQuestion, nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return QuitAnswer::none;
    ImGui::Text("The scene has unsaved edits. Save them before quitting?");
    QuitAnswer quit = QuitAnswer::none;
    if (ImGui::Button(save_asks_where ? "Save as... and quit (Return)" : "Save and quit (Return)") || confirm) {
        quit = QuitAnswer::save_and_quit;
        ImGui::CloseCurrentPopup();
    }
    ImGui::SameLine();
    if (ImGui::Button("Quit without saving")) {
        quit = QuitAnswer::quit;
        ImGui::CloseCurrentPopup();
    }
    ImGui::SameLine();
    if (ImGui::Button("Cancel") || (cancel && quit == QuitAnswer::none)) {
        quit = QuitAnswer::stay;
        ImGui::CloseCurrentPopup();
    }
    ImGui::EndPopup();
    return quit;
}

const char* open_question() {
    if (ImGui::IsPopupOpen(kQuitQuestion)) return "quit";
    if (ImGui::IsPopupOpen(kDiscardQuestion)) return "discard";
    if (ImGui::IsPopupOpen(kOverwriteQuestion)) return "overwrite";
    if (ImGui::IsPopupOpen(kSaveWhereQuestion)) return "save-where";
    return "none";
}

void discard_popup(PanelContext& ctx, bool cancel) {
    SceneFiles& files = ctx.ui.files;
    if (files.ask_discard) {
        ImGui::OpenPopup(kDiscardQuestion);
        files.ask_discard = false;
    }
    if (!ImGui::BeginPopupModal(kDiscardQuestion, nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
    const bool same = files.pending_open && *files.pending_open == files.watch.file();
    if (same) ImGui::Text("%s changed on disk, and the scene here has unsaved edits.", files.watch.file().filename().string().c_str());
    else ImGui::Text("The scene has unsaved edits. Open %s and lose them?",
                     files.pending_open ? files.pending_open->filename().string().c_str() : "");
    if (ImGui::Button(same ? "Reload (lose my edits)" : "Open (lose my edits)")) {
        if (files.pending_open) open_scene(ctx, *files.pending_open);
        files.pending_open.reset();
        ImGui::CloseCurrentPopup();
    }
    ImGui::SameLine();
    if (same && ImGui::Button("Take the file's changes, keep my view")) {
        open_scene(ctx, *files.pending_open, true);
        files.pending_open.reset();
        ImGui::CloseCurrentPopup();
    }
    if (same) ImGui::SameLine();
    if (ImGui::Button("Keep my edits") || cancel) {
        if (same) ctx.messages.show_status("kept your edits; the file on disk differs (Save scene JSON to keep them)");
        files.pending_open.reset();
        ImGui::CloseCurrentPopup();
    }
    ImGui::EndPopup();
}

}  // namespace kr::viewer
