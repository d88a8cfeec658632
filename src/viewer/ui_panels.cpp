// The ImGui panels. Each shows only what the scene has; every change goes through
// ViewerApp::edit (and so ViewerModel's reset rule). Combos use the EnumNames tables.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>

#include <imgui.h>
#include <imgui_internal.h>  // TempInputIsActive: a drag field in its typed-text mode
#include <imgui_stdlib.h>

#include "core/image_hdr.h"
#include "core/image_io.h"
#include "core/text.h"
#include "scene/load.h"
#include "scene/scene_list.h"
#include "scene/save.h"
#include "viewer/ui_app.h"

#include <GLFW/glfw3.h>  // after ui_app.h: gl_functions.h includes the GL headers it needs first

namespace kr::viewer {

namespace {

namespace fs = std::filesystem;

constexpr double kHuge = 1e9;

// A field's name in messages: its label without the ImGui id suffix.
std::string field_name(const char* label) {
    const std::string s(label);
    return s.substr(0, s.find("##"));
}

// The keys and mouse controls, for the help window (F1 or ?).
constexpr const char* kHelpRows[][2] = {
    {"left drag", "orbit about the target"},
    {"right drag", "pan"},
    {"wheel, middle drag", "dolly (middle drag pans a zoomed image)"},
    {"Ctrl+wheel, + / -", "zoom the image about the pointer (up to 16x)"},
    {"0 / 1", "fit the image to the window / show it 1:1"},
    {"hover / Shift+click", "read a pixel / lock the probe on it"},
    {"V", "next view: render, reference, split, error, noise, samples"},
    {"K", "keep the image as a snapshot (image B)"},
    {"Ctrl+click, or F then click", "focus the lens on the clicked surface"},
    {"arrows", "orbit"},
    {"W / S", "dolly in / out"},
    {"A / D / Q / E", "pan left / right / down / up"},
    {"Home or R", "reset the view to the file's camera"},
    {"[ / ]", "halve / double the target spp (keeps the samples taken)"},
    {"Space", "pause / resume"},
    {"Ctrl+Z", "undo"},
    {"Ctrl+Shift+Z, Ctrl+Y", "redo"},
    {"Tab", "hide / show the panel"},
    {"F11", "fullscreen"},
    {"F1 or ?", "this help"},
    {"Esc", "close this help; quit (asks first with unsaved edits)"},
    {"typed numbers", "apply on Enter or when the field is left"},
};

template <typename Enum, size_t N>
bool combo(const char* label, Enum& value, const EnumNames<Enum, N>& names) {
    bool changed = false;
    const std::string current(names.name(value));
    if (ImGui::BeginCombo(label, current.c_str())) {
        for (size_t i = 0; i < N; ++i) {
            const std::string name(names.names[i]);
            const bool selected = static_cast<size_t>(value) == i;
            if (ImGui::Selectable(name.c_str(), selected)) {
                changed = !selected;
                value = static_cast<Enum>(i);
            }
            if (selected) ImGui::SetItemDefaultFocus();
        }
        ImGui::EndCombo();
    }
    return changed;
}

std::string format_duration(double s) {
    char buf[32];
    if (s < 60) std::snprintf(buf, sizeof buf, "%.1f s", s);
    else std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
    return buf;
}

}  // namespace

bool ViewerApp::field(const char* label, double* v, int count, float speed, double lo, double hi, const char* format) {
    const ImGuiID id = ImGui::GetID(label);
    std::vector<double> value(v, v + count);
    // No AlwaysClamp: a drag stays within [lo, hi]; a typed value is checked below instead.
    bool changed = count == 1 ? ImGui::DragScalar(label, ImGuiDataType_Double, value.data(), speed, &lo, &hi, format)
                              : ImGui::DragScalarN(label, ImGuiDataType_Double, value.data(), count, speed, &lo, &hi, format);
    const ImGuiContext& g = *ImGui::GetCurrentContext();
    const bool typing = g.TempInputId != 0 && g.ActiveId == g.TempInputId;
    if (changed && typing) {
        // Keystrokes are held: typing -20 must not apply -2 on the way.
        typed_.hold(id, value.data(), count);
        changed = false;
    }
    if (ImGui::IsItemDeactivated()) {
        if (auto held = typed_.take(id)) {
            value = *held;
            changed = true;
        }
    }
    if (!changed || std::equal(value.begin(), value.end(), v)) return false;
    if (auto why = check_typed_value(field_name(label), value.data(), count, lo, hi)) {
        show_error(*why);
        return false;
    }
    std::copy(value.begin(), value.end(), v);
    return true;
}

bool ViewerApp::field_int(const char* label, int& v, int lo, int hi) {
    const ImGuiID id = ImGui::GetID(label);
    int value = v;
    // A text field: every keystroke is held until Enter or focus loss.
    if (ImGui::InputInt(label, &value, 0, 0)) {
        const double d = value;
        typed_.hold(id, &d, 1);
    }
    if (!ImGui::IsItemDeactivated()) return false;
    const auto held = typed_.take(id);
    if (!held || (*held)[0] == v) return false;
    if (auto why = check_typed_value(field_name(label), held->data(), 1, lo, hi)) {
        show_error(*why);
        return false;
    }
    v = int((*held)[0]);
    return true;
}

void ViewerApp::draw_panels() {
    quit_popup();
    discard_popup();
    if (!panel_visible_) {
        overwrite_popup();
        return;
    }
    const ImGuiIO& io = ImGui::GetIO();
    const float bar_h = float(status_bar_height() / std::max(1.0f, io.DisplayFramebufferScale.y));
    // The panel keeps the right edge above the status bar; its left edge can be dragged.
    const float max_w = std::max(200.0f, io.DisplaySize.x * 0.5f);
    panel_width_ = std::clamp(panel_width_, 200.0f, max_w);
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - panel_width_, 0));
    ImGui::SetNextWindowSize(ImVec2(panel_width_, io.DisplaySize.y - bar_h));
    ImGui::SetNextWindowSizeConstraints(ImVec2(200, io.DisplaySize.y - bar_h), ImVec2(max_w, io.DisplaySize.y - bar_h));
    ImGui::Begin("keithray", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoTitleBar);
    // The width the user dragged it to, for the next frame's layout.
    if (ImGui::IsWindowFocused() && io.MouseDown[0]) panel_width_ = ImGui::GetWindowWidth();
    panel_scene();
    if (model_.has_scene()) {
        panel_camera();
        panel_lens();
        panel_lights();
        panel_materials();
        panel_tone_map();
        panel_renderer();
        panel_compare();
        panel_stats();
        panel_save();
    }
    overwrite_popup();
    ImGui::End();
}

void ViewerApp::draw_status_bar() {
    const ImGuiIO& io = ImGui::GetIO();
    const float bar_h = float(status_bar_height() / std::max(1.0f, io.DisplayFramebufferScale.y));
    ImGui::SetNextWindowPos(ImVec2(0, io.DisplaySize.y - bar_h));
    ImGui::SetNextWindowSize(ImVec2(io.DisplaySize.x, bar_h));
    ImGui::Begin("##status", nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                     ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoBringToFrontOnFocus);
    const bool current = shown_ && shown_->generation == model_.generation();
    const RunStatus st = run_status(current ? shown_.get() : nullptr, model_.settings(), !model_.has_scene());
    // Line 1: state, spp, progress with ETA, elapsed, Mrays/s, noise. Fixed-width fields, so
    // nothing moves as the figures change.
    static const ImVec4 kStateColours[] = {{0.8f, 0.8f, 0.8f, 1}, {0.5f, 0.8f, 1, 1}, {1, 0.8f, 0.3f, 1},
                                           {0.4f, 0.9f, 0.4f, 1}, {1, 0.4f, 0.4f, 1}};
    ImGui::AlignTextToFramePadding();
    ImGui::TextColored(kStateColours[size_t(st.state)], "%-9s", std::string(run_state_names.name(st.state)).c_str());
    ImGui::SameLine(90);
    if (st.unlimited) ImGui::Text("%d spp (unlimited)", st.spp);
    else ImGui::Text("%d / %d spp", st.spp, st.target);
    ImGui::SameLine(240);
    char overlay[64] = "";
    if (st.progress >= 0) {
        if (st.state == RunState::done) std::snprintf(overlay, sizeof overlay, "done (%s)", st.rule.c_str());
        else if (st.eta >= 0) std::snprintf(overlay, sizeof overlay, "ETA %s (%s)", format_duration(st.eta).c_str(), st.rule.c_str());
        else std::snprintf(overlay, sizeof overlay, "%s", st.rule.c_str());
    } else {
        std::snprintf(overlay, sizeof overlay, "no stop rule");
    }
    ImGui::ProgressBar(st.progress >= 0 ? float(st.progress) : 0.0f, ImVec2(220, 0), overlay);
    ImGui::SameLine(480);
    ImGui::Text("%s", st.preview ? "preview" : format_duration(st.elapsed).c_str());
    ImGui::SameLine(560);
    ImGui::Text("%.2f Mrays/s", st.mrays_per_second);
    ImGui::SameLine(680);
    if (st.noise >= 0) ImGui::Text("noise %.3g%%", 100 * st.noise);
    else ImGui::TextDisabled("noise: needs 2 spp");
    if (figures_ && current) {
        // Against image B (the reference, or a kept snapshot), as `keithray psnr` computes it.
        ImGui::SameLine(790);
        ImGui::Text("vs B %.2f dB", figures_->psnr);
    }
    // Line 2: one message, the most important first; full text on hover.
    const std::string* message = nullptr;
    ImVec4 colour(0.85f, 0.85f, 0.85f, 1);
    std::string inside;
    if (!error_.empty()) {
        message = &error_;
        colour = ImVec4(1, 0.4f, 0.4f, 1);
    } else if (inside_sphere_) {
        inside = "camera is inside sphere " + *inside_sphere_ + ": the image shows its inside (Home resets the view)";
        message = &inside;
        colour = ImVec4(1, 0.8f, 0.3f, 1);
    } else if (!status_.empty()) {
        message = &status_;
    }
    ImGui::AlignTextToFramePadding();
    if (message) {
        ImGui::PushStyleColor(ImGuiCol_Text, colour);
        ImGui::TextUnformatted(message->c_str());  // one line: the window clips it
        ImGui::PopStyleColor();
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", message->c_str());
        if (message == &error_) {
            ImGui::SameLine();
            if (ImGui::SmallButton("dismiss")) error_.clear();
        }
    } else {
        ImGui::TextDisabled("F1 or ?: keys and mouse   Tab: panel   F11: fullscreen");
    }
    ImGui::End();
}

void ViewerApp::draw_error_flash() {
    // A refused edit also shows where the user is looking: beside the pointer, briefly.
    if (error_.empty() || std::chrono::duration<double>(Clock::now() - error_time_).count() > 3) return;
    ImGui::BeginTooltip();
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.4f, 0.4f, 1));
    ImGui::PushTextWrapPos(ImGui::GetFontSize() * 30);
    ImGui::TextUnformatted(error_.c_str());
    ImGui::PopTextWrapPos();
    ImGui::PopStyleColor();
    ImGui::EndTooltip();
}

void ViewerApp::draw_help() {
    if (!help_visible_) return;
    const ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x * 0.5f, io.DisplaySize.y * 0.45f), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
    ImGui::Begin("Keys and mouse (F1, ? or Esc closes)", &help_visible_,
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

void ViewerApp::quit_popup() {
    if (quit_asked_) {
        ImGui::OpenPopup("Quit?");
        quit_asked_ = false;
    }
    if (!ImGui::BeginPopupModal("Quit?", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
    ImGui::Text("The scene has unsaved edits. Quit and lose them?");
    if (ImGui::Button("Quit without saving")) {
        glfwSetWindowShouldClose(window_, GLFW_TRUE);
        ImGui::CloseCurrentPopup();
    }
    ImGui::SameLine();
    if (ImGui::Button("Cancel") || ImGui::IsKeyPressed(GLFW_KEY_ESCAPE, false)) ImGui::CloseCurrentPopup();
    ImGui::EndPopup();
}

void ViewerApp::discard_popup() {
    if (open_pending_popup_) {
        ImGui::OpenPopup("Unsaved edits");
        open_pending_popup_ = false;
    }
    if (!ImGui::BeginPopupModal("Unsaved edits", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
    const bool same = pending_open_ && *pending_open_ == watch_.file();
    if (same) ImGui::Text("%s changed on disk, and the scene here has unsaved edits.", watch_.file().filename().string().c_str());
    else ImGui::Text("The scene has unsaved edits. Open %s and lose them?",
                     pending_open_ ? pending_open_->filename().string().c_str() : "");
    if (ImGui::Button(same ? "Reload (lose my edits)" : "Open (lose my edits)")) {
        if (pending_open_) open_scene(*pending_open_);
        pending_open_.reset();
        ImGui::CloseCurrentPopup();
    }
    ImGui::SameLine();
    if (ImGui::Button("Keep my edits") || ImGui::IsKeyPressed(GLFW_KEY_ESCAPE, false)) {
        if (same) status_ = "kept your edits; the file on disk differs (Save scene JSON to keep them)";
        pending_open_.reset();
        ImGui::CloseCurrentPopup();
    }
    ImGui::EndPopup();
}

void ViewerApp::panel_scene() {
    if (!ImGui::CollapsingHeader("Scene", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const fs::path current = watch_.file();
    ImGui::TextWrapped("%s", current.string().c_str());
    if (scene_list_.empty()) {
        // The scene's own folder, then the bundled scenes' (default_scenes); a file listed
        // from both shows once.
        std::vector<fs::path> folders{current.parent_path().empty() ? fs::path(".") : current.parent_path()};
        for (const fs::path& p : default_scenes())
            if (std::find(folders.begin(), folders.end(), p.parent_path()) == folders.end())
                folders.push_back(p.parent_path());
        scene_choices_ = scene_choices(folders);
        scene_list_ = folders;
    }
    if (ImGui::BeginCombo("open", current.filename().string().c_str())) {
        for (const SceneChoice& c : scene_choices_) {
            const std::string label = c.label + "##" + c.path.string();
            if (ImGui::Selectable(label.c_str(), c.path == current)) open_scene_asking(c.path);
        }
        ImGui::EndCombo();
    }
    if (ImGui::Button("Reload")) open_scene_asking(current);
    ImGui::SameLine();
    if (ImGui::Button("Rescan folder")) scene_list_.clear();
    ImGui::SameLine();
    ImGui::BeginDisabled(!model_.can_undo());
    if (ImGui::Button("Undo")) {
        model_.undo();
        error_.clear();
    }
    ImGui::EndDisabled();
    ImGui::SameLine();
    ImGui::BeginDisabled(!model_.can_redo());
    if (ImGui::Button("Redo")) {
        model_.redo();
        error_.clear();
    }
    ImGui::EndDisabled();
    ImGui::SameLine();
    if (ImGui::Button("Reset view")) model_.reset_view();
    ImGui::TextDisabled("the file is watched: saving it in an editor reloads it");
    for (const std::string& w : model_.warnings()) ImGui::TextWrapped("warning: %s", w.c_str());
}

void ViewerApp::panel_camera() {
    if (!ImGui::CollapsingHeader("Camera", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const Scene& scene = model_.scene();
    if (scene.cameras.size() > 1) {
        int active = scene.camera;
        if (ImGui::BeginCombo("active", scene.cameras[size_t(active)].id.c_str())) {
            for (size_t i = 0; i < scene.cameras.size(); ++i)
                if (ImGui::Selectable((scene.cameras[i].id + "##cam" + std::to_string(i)).c_str(), int(i) == active))
                    active = int(i);
            ImGui::EndCombo();
        }
        if (active != scene.camera) edit(Edit::camera, [&](Scene& s, ViewerSettings&) { s.camera = active; }, "active camera");
    }
    Camera cam = model_.camera();
    const double span = std::max(1.0, length(cam.target - cam.position));
    auto apply = [&](const char* name) {
        edit(Edit::camera, [&](Scene& s, ViewerSettings&) { s.cameras[size_t(s.camera)] = cam; }, name, name);
    };
    if (field("position", &cam.position.x, 3, float(0.005 * span), -kHuge, kHuge)) apply("camera position");
    if (field("target", &cam.target.x, 3, float(0.005 * span), -kHuge, kHuge)) apply("camera target");
    if (field("fov (deg)", &cam.fov, 1, 0.1f, 0.5, 179.5)) apply("fov");
    if (field("aspect", &cam.aspect, 1, 0.005f, 0.05, 20)) apply("aspect");
}

void ViewerApp::panel_lens() {
    if (!ImGui::CollapsingHeader("Lens", ImGuiTreeNodeFlags_DefaultOpen)) return;
    Camera cam = model_.camera();
    auto apply = [&](const char* name) {
        edit(Edit::lens, [&](Scene& s, ViewerSettings&) { s.cameras[size_t(s.camera)] = cam; }, name, name);
    };
    if (combo("camera type", cam.type, camera_type_names)) apply("camera type");
    if (cam.type == CameraType::lens) {
        if (field("focal distance", &cam.focal_distance, 1, float(0.01 * std::max(1.0, cam.focal_distance)), 1e-4, kHuge))
            apply("focal distance");
        if (field("aperture (alpha)", &cam.alpha, 1, 0.005f, 0.0, kHuge)) apply("aperture");
    }
    ImGui::Checkbox("pick focus (F)", &pick_focus_);
    ImGui::SameLine();
    ImGui::TextDisabled("or Ctrl+click the image");
}

void ViewerApp::panel_lights() {
    const Scene& scene = model_.scene();
    if (scene.active_lights.empty() || !ImGui::CollapsingHeader("Lights", ImGuiTreeNodeFlags_DefaultOpen)) return;
    for (int index : scene.active_lights) {
        const Light& light = scene.lights[size_t(index)];
        ImGui::PushID(index);
        ImGui::Text("%s (%s)", light.id.c_str(), std::string(light_type_names.name(light.type)).c_str());
        Light edited = light;
        const std::string name = "light " + light.id;
        if (light.type == LightType::point) {
            bool changed = field("position", &edited.position.x, 3, 0.02f, -kHuge, kHuge);
            changed |= field("intensity", &edited.power.x, 3, 0.5f, 0.0, kHuge);
            if (changed) edit(Edit::light, [&](Scene& s, ViewerSettings&) { s.lights[size_t(index)] = edited; }, name, name);
        } else {
            Shape shape = scene.shapes[size_t(light.shape)];
            bool changed = field("position", &shape.centre.x, 3, 0.02f, -kHuge, kHuge);
            changed |= field("radius", &shape.radius, 1, 0.005f, 1e-4, kHuge);
            changed |= field("radiance", &edited.power.x, 3, 0.1f, 0.0, kHuge);
            if (changed)
                edit(Edit::light, [&](Scene& s, ViewerSettings&) {
                    s.lights[size_t(index)] = edited;
                    s.shapes[size_t(light.shape)] = shape;
                }, name, name);
        }
        ImGui::PopID();
    }
}

void ViewerApp::panel_materials() {
    const Scene& scene = model_.scene();
    std::set<int> used;
    for (const Primitive& p : scene.primitives) used.insert(p.material);
    if (used.empty() || !ImGui::CollapsingHeader("Materials")) return;
    for (int index : used) {
        Material m = scene.materials[size_t(index)];
        ImGui::PushID(index);
        if (ImGui::TreeNode(m.id.c_str())) {
            bool changed = combo("type", m.type, material_type_names);
            for (const MaterialParam& param : material_params(m.type)) {
                const std::string label(param.name);
                if (param.colour) changed |= field(label.c_str(), &(m.*param.colour).x, 3, 0.005f, 0.0, 1.0);
                else
                    changed |= field(label.c_str(), &(m.*param.number), 1, param.edit_speed, param.edit_lo,
                                     param.edit_hi);
            }
            const std::string name = "material " + m.id;
            if (changed) edit(Edit::material, [&](Scene& s, ViewerSettings&) { s.materials[size_t(index)] = m; }, name, name);
            ImGui::TreePop();
        }
        ImGui::PopID();
    }
}

void ViewerApp::panel_tone_map() {
    if (!ImGui::CollapsingHeader("Tone map", ImGuiTreeNodeFlags_DefaultOpen)) return;
    ToneSettings tone = model_.settings().tone;
    bool changed = combo("operator", tone.tonemap, tonemap_names);
    changed |= field("exposure (EV)", &tone.exposure, 1, 0.02f, -kMaxExposureStops, kMaxExposureStops, "%.2f");
    if (tone.tonemap == ToneMap::linear) ImGui::TextDisabled("linear: 2^EV I / max(I)");
    if (changed) edit(Edit::tone_map, [&](Scene&, ViewerSettings& s) { s.tone = tone; }, "tone map", "tone map");
}

void ViewerApp::panel_renderer() {
    if (!ImGui::CollapsingHeader("Renderer", ImGuiTreeNodeFlags_DefaultOpen)) return;
    ViewerSettings settings = model_.settings();
    RenderSettings& r = settings.render;
    bool changed = combo("integrator", r.integrator, integrator_names);
    changed |= ImGui::SliderInt("depth", &r.max_depth, 0, kMaxDepth, "%d", ImGuiSliderFlags_AlwaysClamp);
    changed |= combo("estimator", r.estimator, estimator_names);
    changed |= combo("allocation", r.allocation, allocation_names);
    if (r.integrator != Integrator::wrt) changed |= combo("light sampling", r.light_sampling, light_sampling_names);
    const bool restart = ImGui::Button("Restart");
    if (changed || restart) {
        // depth and the renderer type also live in the authored renderer block (saved with the scene).
        edit(Edit::renderer, [&](Scene& s, ViewerSettings& out) {
            out.render = r;
            s.renderer.depth = r.max_depth;
            s.renderer.type = r.integrator == Integrator::wrt ? RendererType::wrt : RendererType::pt;
        }, "renderer", "renderer");
    }
    // The target keeps the samples already taken ([ and ] halve and double it).
    int spp = r.target_spp;
    ImGui::SetNextItemWidth(120);
    if (field_int("target spp", spp, 1, 1 << 24)) {
        model_.seal_undo_step();
        model_.set_target_spp(spp);
    }
    bool unlimited = settings.unlimited, paused = settings.paused;
    ImGui::SameLine();
    if (ImGui::Checkbox("unlimited", &unlimited))
        edit(Edit::run_control, [&](Scene&, ViewerSettings& s) { s.unlimited = unlimited; }, "unlimited");
    ImGui::SameLine();
    if (ImGui::Checkbox("pause (Space)", &paused))
        edit(Edit::run_control, [&](Scene&, ViewerSettings& s) { s.paused = paused; }, "pause");
    // The stop rules of render --time / --noise; 0 turns each off.
    double stop_seconds = settings.stop_seconds, stop_noise_percent = 100 * settings.stop_noise;
    ImGui::SetNextItemWidth(120);
    if (field("stop after s (0: off)", &stop_seconds, 1, 0.5f, 0.0, 1e9, "%.1f"))
        edit(Edit::run_control, [&](Scene&, ViewerSettings& s) { s.stop_seconds = stop_seconds; }, "stop after s");
    ImGui::SetNextItemWidth(120);
    if (field("stop at noise % (0: off, adaptive)", &stop_noise_percent, 1, 0.05f, 0.0, 100.0, "%.2f"))
        edit(Edit::run_control, [&](Scene&, ViewerSettings& s) { s.stop_noise = stop_noise_percent / 100; }, "stop at noise");
}

void ViewerApp::panel_stats() {
    if (!ImGui::CollapsingHeader("Stats")) return;
    // A fixed set of lines: what is live (spp, rate, noise) is in the status bar.
    const Scene& scene = model_.scene();
    ImGui::Text("image %dx%d, UI %.0f frames/s (%.1f ms of work each)", scene.renderer.width, scene.renderer.height,
                ui_fps_, 1e3 * ui_work_);
    if (const auto& prepared = model_.prepared())
        ImGui::Text("%zu spheres, %s BVH", prepared->spheres.size(),
                    prepared->bvh.backend() == AccelBackend::embree ? "Embree's" : "keithray's own");
    const bool current = shown_ && shown_->generation == model_.generation();
    const double passes_per_second = current && shown_->full_seconds > 0 ? shown_->spp / shown_->full_seconds : 0.0;
    ImGui::Text("%.2f passes/s, non-finite samples dropped: %llu", passes_per_second,
                static_cast<unsigned long long>(current ? shown_->nonfinite_samples : 0));
    plot_convergence();
}

}  // namespace kr::viewer
