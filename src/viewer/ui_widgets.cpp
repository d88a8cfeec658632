#include "viewer/ui_widgets.h"

#include <algorithm>
#include <vector>

#include <imgui_internal.h>  // TempInputIsActive: a drag field in its typed-text mode

#include "core/text.h"
#include "viewer/scene_edit.h"

namespace kr::viewer {

namespace {

// A field's name in messages: its label without the ImGui id suffix.
std::string field_name(const char* label) {
    const std::string s(label);
    return s.substr(0, s.find("##"));
}

}  // namespace

bool field(PanelContext& ctx, const char* label, double* v, int count, float speed, double lo, double hi,
           const char* format) {
    const ImGuiID id = ImGui::GetID(label);
    std::vector<double> value(v, v + count);
    // No AlwaysClamp: a drag stays within [lo, hi]; a typed value is checked below instead.
    bool changed = count == 1 ? ImGui::DragScalar(label, ImGuiDataType_Double, value.data(), speed, &lo, &hi, format)
                              : ImGui::DragScalarN(label, ImGuiDataType_Double, value.data(), count, speed, &lo, &hi, format);
    const ImGuiContext& g = *ImGui::GetCurrentContext();
    const bool typing = g.TempInputId != 0 && g.ActiveId == g.TempInputId;
    if (changed && typing) {
        // Keystrokes are held: typing -20 must not apply -2 on the way.
        ctx.ui.typed.hold(id, value.data(), count);
        changed = false;
    }
    if (ImGui::IsItemDeactivated()) {
        if (auto held = ctx.ui.typed.take(id)) {
            value = *held;
            changed = true;
        }
    }
    if (!changed || std::equal(value.begin(), value.end(), v)) return false;
    if (auto why = check_typed_value(field_name(label), value.data(), count, lo, hi)) {
        ctx.messages.show_error(*why);
        return false;
    }
    std::copy(value.begin(), value.end(), v);
    return true;
}

bool field_int(PanelContext& ctx, const char* label, int& v, int lo, int hi) {
    const ImGuiID id = ImGui::GetID(label);
    int value = v;
    // A text field: every keystroke is held until Enter or focus loss.
    if (ImGui::InputInt(label, &value, 0, 0)) {
        const double d = value;
        ctx.ui.typed.hold(id, &d, 1);
    }
    if (!ImGui::IsItemDeactivated()) return false;
    const auto held = ctx.ui.typed.take(id);
    if (!held || (*held)[0] == v) return false;
    if (auto why = check_typed_value(field_name(label), held->data(), 1, lo, hi)) {
        ctx.messages.show_error(*why);
        return false;
    }
    v = int((*held)[0]);
    return true;
}

bool colour_picker(const char* label, Color& c) {
    float rgb[3] = {float(c.x), float(c.y), float(c.z)};
    const std::string id = std::string("##pick ") + label;
    if (!ImGui::ColorEdit3(id.c_str(), rgb, ImGuiColorEditFlags_NoInputs | ImGuiColorEditFlags_Float)) return false;
    c = picked_colour(c, rgb);  // 0.9, not the float's 0.8999999761581421
    return true;
}

bool power_fields(PanelContext& ctx, const char* label, Color& power, float speed) {
    bool changed = field(ctx, label, &power.x, 3, speed, 0.0, kHuge);
    // power = colour x strength: the colour's largest component is 1.
    ColourStrength cs = split_power(power);
    bool split = colour_picker("light colour", cs.colour);
    ImGui::SameLine();
    split |= field(ctx, "strength", &cs.strength, 1, speed, 0.0, kHuge);
    if (split) power = join_power(cs);
    return changed || split;
}

bool material_fields(PanelContext& ctx, Material& m) {
    bool changed = combo("type", m.type, material_type_names);
    // The type's parameters as the file has them (scene.h's material_params).
    for (const MaterialParam& param : material_params(m.type)) {
        const std::string label(param.name);
        if (param.colour) {
            // A picker, then the numbers as the file has them.
            changed |= colour_picker(label.c_str(), m.*param.colour);
            ImGui::SameLine();
            changed |= field(ctx, label.c_str(), &(m.*param.colour).x, 3, 0.005f, 0.0, 1.0);
        } else
            changed |= field(ctx, label.c_str(), &(m.*param.number), 1, param.edit_speed, param.edit_lo, param.edit_hi);
    }
    return changed;
}

bool light_fields(PanelContext& ctx, Light& light, Shape* shape) {
    bool changed = false;
    for (const LightParam& param : light_params(light.type)) {
        const std::string label(param.name);
        switch (param.kind) {
        case LightFieldKind::vector:
            changed |= field(ctx, label.c_str(), &(light.*param.value).x, 3, param.edit_speed, -kHuge, kHuge);
            break;
        case LightFieldKind::colour: changed |= power_fields(ctx, label.c_str(), light.*param.value, param.edit_speed); break;
        case LightFieldKind::shape:
            if (!shape) break;
            changed |= field(ctx, "position", &shape->centre.x, 3, 0.02f, -kHuge, kHuge);
            changed |= field(ctx, "radius", &shape->radius, 1, 0.005f, 1e-4, kHuge);
            break;
        }
    }
    return changed;
}

bool light_checkbox(PanelContext& ctx, int index) {
    const Scene& scene = ctx.model.scene();
    const Light light = scene.lights[size_t(index)];  // a copy: an edit replaces the scene
    bool on = std::find(scene.active_lights.begin(), scene.active_lights.end(), index) != scene.active_lights.end();
    if (ImGui::Checkbox(light_label(light).c_str(), &on) &&
        ctx.edit(Edit::light, [&](Scene& s, ViewerSettings&) { set_light_on(s, index, on); }, "light on/off")) {
        const std::string unseen = on ? light_unseen_reason(ctx.model.scene(), index) : std::string();
        ctx.messages.show_status("light " + show_user_text(light.id) + (on ? " on" : " off: it emits nothing") +
                                 (unseen.empty() ? "" : "; it adds nothing to the picture: " + unseen));
    }
    const auto& active = ctx.model.scene().active_lights;
    return std::find(active.begin(), active.end(), index) != active.end();
}

void mark_item(PanelContext& ctx, std::string name) {
    const ImVec2 a = ImGui::GetItemRectMin(), b = ImGui::GetItemRectMax();
    ctx.ui.marks.push_back({std::move(name), 0.5f * (a.x + b.x), 0.5f * (a.y + b.y)});
}

}  // namespace kr::viewer
