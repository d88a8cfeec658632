// The ImGui panels. Each shows only what the scene has; every change goes through
// ViewerApp::edit (and so ViewerModel's reset rule). Combos use the EnumNames tables.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>

#include <imgui.h>
#include <imgui_stdlib.h>

#include "core/image_io.h"
#include "scene/load.h"
#include "core/image_hdr.h"
#include "scene/save.h"
#include "viewer/ui_app.h"

namespace kr::viewer {

namespace {

namespace fs = std::filesystem;

constexpr double kHuge = 1e9;
constexpr double kMinExposure = 1.0 / 64, kMaxExposure = 64;

bool drag3(const char* label, Vec3& v, float speed, double lo = -kHuge, double hi = kHuge) {
    // Vec3 is three contiguous doubles.
    return ImGui::DragScalarN(label, ImGuiDataType_Double, &v.x, 3, speed, &lo, &hi, "%.4g",
                              ImGuiSliderFlags_AlwaysClamp);
}

bool drag1(const char* label, double& v, float speed, double lo, double hi, const char* format = "%.4g") {
    return ImGui::DragScalar(label, ImGuiDataType_Double, &v, speed, &lo, &hi, format, ImGuiSliderFlags_AlwaysClamp);
}

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

void ViewerApp::reset_save_paths() {
    if (!model_.has_scene()) return;
    const Scene& scene = model_.scene();
    fs::path image = scene.output_path();
    if (image.empty()) image = "keithray.ppm";
    image_path_ = image.replace_extension(".ppm").string();
    png_path_ = fs::path(image).replace_extension(".png").string();
    hdr_path_ = fs::path(image).replace_extension(".exr").string();
    const fs::path source = scene.source_file.empty() ? fs::path("scene.json") : scene.source_file;
    scene_path_ = (source.parent_path() / (source.stem().string() + "-edited.json")).string();
}

void ViewerApp::draw_panels() {
    const ImGuiIO& io = ImGui::GetIO();
    const float scale = io.DisplayFramebufferScale.x > 0 ? io.DisplayFramebufferScale.x : 1.0f;
    const float panel_w = 420.0f / scale;
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - panel_w, 0));
    ImGui::SetNextWindowSize(ImVec2(panel_w, io.DisplaySize.y));
    ImGui::Begin("keithray", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
    if (!error_.empty()) {
        ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.4f, 0.4f, 1.0f));
        ImGui::TextWrapped("%s", error_.c_str());
        ImGui::PopStyleColor();
        if (ImGui::SmallButton("dismiss")) error_.clear();
    }
    panel_scene();
    if (model_.has_scene()) {
        panel_camera();
        panel_lens();
        panel_lights();
        panel_materials();
        panel_tone_map();
        panel_renderer();
        panel_stats();
        panel_save();
    }
    overwrite_popup();
    ImGui::End();
}

void ViewerApp::panel_scene() {
    if (!ImGui::CollapsingHeader("Scene", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const fs::path current = watch_.file();
    ImGui::TextWrapped("%s", current.string().c_str());
    if (ImGui::IsWindowAppearing() || scene_list_.empty()) {
        scene_list_ = list_scenes(current.parent_path().empty() ? fs::path(".") : current.parent_path());
        for (const fs::path& p : default_scenes())
            if (std::find(scene_list_.begin(), scene_list_.end(), p) == scene_list_.end()) scene_list_.push_back(p);
    }
    if (ImGui::BeginCombo("open", current.filename().string().c_str())) {
        for (const fs::path& p : scene_list_) {
            const std::string label = p.filename().string() + "##" + p.string();
            if (ImGui::Selectable(label.c_str(), p == current)) open_scene(p);
        }
        ImGui::EndCombo();
    }
    if (ImGui::Button("Reload")) open_scene(current);
    ImGui::SameLine();
    if (ImGui::Button("Rescan folder")) scene_list_.clear();
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
        if (active != scene.camera) edit(Edit::camera, [&](Scene& s, ViewerSettings&) { s.camera = active; });
    }
    Camera cam = model_.camera();
    const double span = std::max(1.0, length(cam.target - cam.position));
    bool changed = false;
    changed |= drag3("position", cam.position, float(0.005 * span));
    changed |= drag3("target", cam.target, float(0.005 * span));
    changed |= drag1("fov (deg)", cam.fov, 0.1f, 0.5, 179.5);
    changed |= drag1("aspect", cam.aspect, 0.005f, 0.05, 20);
    if (changed) edit(Edit::camera, [&](Scene& s, ViewerSettings&) { s.cameras[size_t(s.camera)] = cam; });
    ImGui::TextDisabled("left drag: orbit   right drag: pan   wheel / middle drag: dolly");
    ImGui::TextDisabled("arrows: orbit   W/S: dolly   A/D/Q/E: pan");
}

void ViewerApp::panel_lens() {
    if (!ImGui::CollapsingHeader("Lens", ImGuiTreeNodeFlags_DefaultOpen)) return;
    Camera cam = model_.camera();
    bool changed = combo("camera type", cam.type, camera_type_names);
    if (cam.type == CameraType::lens) {
        changed |= drag1("focal distance", cam.focal_distance, float(0.01 * std::max(1.0, cam.focal_distance)), 1e-4, kHuge);
        changed |= drag1("aperture (alpha)", cam.alpha, 0.005f, 0.0, kHuge);
    }
    if (changed) edit(Edit::lens, [&](Scene& s, ViewerSettings&) { s.cameras[size_t(s.camera)] = cam; });
    ImGui::Checkbox("pick focus (F)", &pick_focus_);
    ImGui::SameLine();
    ImGui::TextDisabled("or Ctrl+click the image");
    if (cam.type == CameraType::pinhole)
        ImGui::TextDisabled("a click-to-focus turns the pinhole into a thin lens");
}

void ViewerApp::panel_lights() {
    const Scene& scene = model_.scene();
    if (scene.active_lights.empty() || !ImGui::CollapsingHeader("Lights", ImGuiTreeNodeFlags_DefaultOpen)) return;
    for (int index : scene.active_lights) {
        const Light& light = scene.lights[size_t(index)];
        ImGui::PushID(index);
        ImGui::Text("%s (%s)", light.id.c_str(), std::string(light_type_names.name(light.type)).c_str());
        Light edited = light;
        bool changed = false;
        if (light.type == LightType::point) {
            changed |= drag3("position", edited.position, 0.02f);
            changed |= drag3("intensity", edited.power, 0.5f, 0.0, kHuge);
            if (changed) edit(Edit::light, [&](Scene& s, ViewerSettings&) { s.lights[size_t(index)] = edited; });
        } else {
            Shape shape = scene.shapes[size_t(light.shape)];
            changed |= drag3("position", shape.centre, 0.02f);
            changed |= drag1("radius", shape.radius, 0.005f, 1e-4, kHuge);
            changed |= drag3("radiance", edited.power, 0.1f, 0.0, kHuge);
            if (changed)
                edit(Edit::light, [&](Scene& s, ViewerSettings&) {
                    s.lights[size_t(index)] = edited;
                    s.shapes[size_t(light.shape)] = shape;
                });
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
            switch (m.type) {
                case MaterialType::diffuse:
                case MaterialType::specular: changed |= drag3("rho", m.rho, 0.005f, 0.0, 1.0); break;
                case MaterialType::glossy:
                    changed |= drag3("rho", m.rho, 0.005f, 0.0, 1.0);
                    changed |= drag1("roughness", m.roughness, 0.002f, 0.0, 0.999);
                    break;
                case MaterialType::dielectric:
                case MaterialType::translucent:
                    changed |= drag3("rhoR", m.rho_r, 0.005f, 0.0, 1.0);
                    changed |= drag3("rhoT", m.rho_t, 0.005f, 0.0, 1.0);
                    changed |= drag1("eta", m.eta, 0.002f, 1.0 / 4, 4.0);
                    if (m.type == MaterialType::translucent)
                        changed |= drag1("roughness", m.roughness, 0.002f, 0.0, 0.999);
                    break;
            }
            if (changed) edit(Edit::material, [&](Scene& s, ViewerSettings&) { s.materials[size_t(index)] = m; });
            ImGui::TreePop();
        }
        ImGui::PopID();
    }
}

void ViewerApp::panel_tone_map() {
    if (!ImGui::CollapsingHeader("Tone map", ImGuiTreeNodeFlags_DefaultOpen)) return;
    ToneSettings tone = model_.settings().tone;
    bool changed = combo("operator", tone.op, tonemap_names);
    ImGui::BeginDisabled(tone.op == ToneMap::linear);
    changed |= ImGui::SliderScalar("exposure", ImGuiDataType_Double, &tone.exposure, &kMinExposure, &kMaxExposure,
                                   "%.3g", ImGuiSliderFlags_Logarithmic | ImGuiSliderFlags_AlwaysClamp);
    ImGui::EndDisabled();
    if (tone.op == ToneMap::linear) ImGui::TextDisabled("linear: I / max(I), exposure cancels (as in render)");
    if (changed) edit(Edit::tone_map, [&](Scene&, ViewerSettings& s) { s.tone = tone; });
}

void ViewerApp::panel_renderer() {
    if (!ImGui::CollapsingHeader("Renderer", ImGuiTreeNodeFlags_DefaultOpen)) return;
    ViewerSettings settings = model_.settings();
    RenderSettings& r = settings.render;
    bool changed = combo("integrator", r.integrator, integrator_names);
    changed |= ImGui::SliderInt("depth", &r.max_depth, 0, kMaxDepth);
    changed |= combo("estimator", r.estimator, estimator_names);
    changed |= combo("allocation", r.allocation, allocation_names);
    if (r.integrator != Integrator::wrt) changed |= combo("light sampling", r.light_sampling, light_sampling_names);
    int spp = r.target_spp;
    if (ImGui::InputInt("target spp", &spp, 1, 16, ImGuiInputTextFlags_EnterReturnsTrue)) {
        r.target_spp = std::clamp(spp, 1, 1 << 24);
        changed |= r.target_spp != model_.settings().render.target_spp;
    }
    const bool restart = ImGui::Button("Restart");
    if (changed || restart) {
        // target_spp and depth also live in the authored renderer block (saved with the scene).
        edit(Edit::renderer, [&](Scene& s, ViewerSettings& out) {
            out.render = r;
            s.renderer.depth = r.max_depth;
            s.renderer.samples = r.target_spp;
            s.renderer.type = r.integrator == Integrator::wrt ? RendererType::wrt : RendererType::pt;
        });
    }
    bool unlimited = settings.unlimited, paused = settings.paused;
    ImGui::SameLine();
    if (ImGui::Checkbox("unlimited", &unlimited))
        edit(Edit::run_control, [&](Scene&, ViewerSettings& s) { s.unlimited = unlimited; });
    ImGui::SameLine();
    if (ImGui::Checkbox("pause (Space)", &paused))
        edit(Edit::run_control, [&](Scene&, ViewerSettings& s) { s.paused = paused; });
    // The stop rules of render --time / --noise; 0 turns each off.
    double stop_seconds = settings.stop_seconds, stop_noise_percent = 100 * settings.stop_noise;
    ImGui::SetNextItemWidth(120);
    if (ImGui::InputDouble("stop after s (0: off)", &stop_seconds, 1, 10, "%.1f", ImGuiInputTextFlags_EnterReturnsTrue))
        edit(Edit::run_control, [&](Scene&, ViewerSettings& s) { s.stop_seconds = std::max(0.0, stop_seconds); });
    ImGui::SetNextItemWidth(120);
    if (ImGui::InputDouble("stop at noise % (0: off, adaptive)", &stop_noise_percent, 0.1, 1, "%.2f",
                           ImGuiInputTextFlags_EnterReturnsTrue))
        edit(Edit::run_control,
             [&](Scene&, ViewerSettings& s) { s.stop_noise = std::clamp(stop_noise_percent, 0.0, 100.0) / 100; });
}

void ViewerApp::panel_stats() {
    if (!ImGui::CollapsingHeader("Stats", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const Scene& scene = model_.scene();
    ImGui::Text("image %dx%d, UI %.0f frames/s (%.1f ms of work each)", scene.renderer.width,
                scene.renderer.height, ui_fps_, 1e3 * ui_work_);
    if (const auto& prepared = model_.prepared())
        ImGui::Text("%zu spheres, %s BVH", prepared->spheres.size(),
                    prepared->bvh.backend() == AccelBackend::embree ? "Embree's" : "keithray's own");
    const bool current = shown_ && shown_->generation == model_.generation();
    if (!current) {
        ImGui::Text("rendering the first preview...");
        return;
    }
    const Snapshot& f = *shown_;
    if (f.scale > 1) {
        ImGui::Text("preview at 1/%d resolution", f.scale);
        return;
    }
    const bool unlimited = model_.settings().unlimited;
    if (unlimited) ImGui::Text("spp %d (unlimited)%s", f.spp, model_.settings().paused ? ", paused" : "");
    else ImGui::Text("spp %d / %d%s", f.spp, f.target_spp, f.finished ? ", done" : (model_.settings().paused ? ", paused" : ""));
    if (f.finished && f.stopped_by[0]) ImGui::Text("stopped by the %s rule", f.stopped_by);
    ImGui::Text("elapsed %s, %.2f passes/s, %.2f Mrays/s", format_duration(f.seconds).c_str(),
                f.full_seconds > 0 ? f.spp / f.full_seconds : 0.0, f.full_seconds > 0 ? f.rays / f.full_seconds * 1e-6 : 0.0);
    if (std::isfinite(f.relative_error)) ImGui::Text("noise estimate %.3g%% (relative RMS)", 100 * f.relative_error);
    else ImGui::Text("noise estimate: needs 2 spp");
    ImGui::Text("non-finite samples dropped: %llu", static_cast<unsigned long long>(f.nonfinite_samples));
}

void ViewerApp::panel_save() {
    if (!ImGui::CollapsingHeader("Save", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const bool full = shown_ && shown_->generation == model_.generation() && shown_->scale == 1;
    ImGui::InputText("image", &image_path_);
    ImGui::BeginDisabled(!full);
    if (ImGui::Button("Save PPM")) request_save(SaveKind::ppm, image_path_);
    ImGui::EndDisabled();
    ImGui::InputText("png", &png_path_);
    ImGui::BeginDisabled(!full);
    if (ImGui::Button("Save PNG")) request_save(SaveKind::png, png_path_);
    ImGui::EndDisabled();
    // The radiance as floats: OpenEXR (R, G, B) or PFM, the path's extension set to match.
    ImGui::InputText("hdr", &hdr_path_);
    ImGui::BeginDisabled(!full);
    if (ImGui::Button("Save EXR")) request_save(SaveKind::exr, fs::path(hdr_path_).replace_extension(".exr"));
    ImGui::SameLine();
    if (ImGui::Button("Save PFM")) request_save(SaveKind::pfm, fs::path(hdr_path_).replace_extension(".pfm"));
    ImGui::EndDisabled();
    ImGui::InputText("scene", &scene_path_);
    if (ImGui::Button("Save scene JSON")) request_save(SaveKind::scene, scene_path_);
    if (!status_.empty()) ImGui::TextWrapped("%s", status_.c_str());
}

void ViewerApp::request_save(SaveKind kind, const fs::path& path) {
    std::error_code ec;
    if (fs::exists(path, ec)) {
        // Never overwrite silently: the popup asks.
        pending_save_ = std::make_pair(kind, path);
        ImGui::OpenPopup("Overwrite?");
        return;
    }
    save_now(kind, path);
}

void ViewerApp::overwrite_popup() {
    if (!ImGui::BeginPopupModal("Overwrite?", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
    ImGui::Text("%s already exists. Overwrite it?", pending_save_ ? pending_save_->second.string().c_str() : "");
    if (ImGui::Button("Overwrite")) {
        if (pending_save_) save_now(pending_save_->first, pending_save_->second);
        pending_save_.reset();
        ImGui::CloseCurrentPopup();
    }
    ImGui::SameLine();
    if (ImGui::Button("Cancel")) {
        pending_save_.reset();
        status_ = "not saved";
        ImGui::CloseCurrentPopup();
    }
    ImGui::EndPopup();
}

void ViewerApp::save_now(SaveKind kind, const fs::path& path) {
    try {
        if (kind == SaveKind::scene) {
            save_scene_json(model_.scene_for_saving(), path);
            // Saving over the watched file should not read like an outside change.
            std::error_code ec;
            if (fs::equivalent(path, watch_.file(), ec)) watch_.acknowledge();
        } else {
            if (!shown_ || shown_->scale != 1) throw std::runtime_error("no full-resolution image yet");
            if (kind == SaveKind::exr || kind == SaveKind::pfm) {
                const HdrImage hdr = hdr_from_radiance(shown_->radiance);
                write_file_atomic(path, kind == SaveKind::exr ? encode_exr(hdr) : encode_pfm_rgb(hdr));
                status_ = "saved " + path.string();
                return;
            }
            const ToneSettings& tone = model_.settings().tone;
            const Rgb8Image image = tonemap(shown_->radiance, tone.op, tone.exposure);
            if (kind == SaveKind::ppm) write_ppm(path, image);
            else write_png(path, image);
        }
        status_ = "saved " + path.string();
    } catch (const std::exception& e) {
        status_ = std::string("save failed: ") + e.what();
    }
}

}  // namespace kr::viewer
