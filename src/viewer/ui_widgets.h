// The panels' widgets: number fields that apply a drag live and a typed value on Enter or
// focus loss (after check_typed_value), combos over an enum's name table, a material's fields.
#pragma once

#include <cstddef>
#include <string>

#include <imgui.h>

#include "core/enum_names.h"
#include "viewer/ui_context.h"

namespace kr::viewer {

// The range of a field with no natural bound (positions, powers).
inline constexpr double kHuge = 1e9;

// True when `v` (`count` components) was changed and should be applied; a typed value
// outside [lo, hi] is refused with a message instead.
bool field(PanelContext& ctx, const char* label, double* v, int count, float speed, double lo, double hi,
           const char* format = "%.4g");
// A typed integer in [lo, hi].
bool field_int(PanelContext& ctx, const char* label, int& v, int lo, int hi);

// A colour swatch on the line before, opening ImGui's picker (ColorEdit3, values in [0, 1]).
bool colour_picker(const char* label, Color& c);
// A light's power as the file has it (`label`, "power"), and the same split as a colour (a
// picker, its largest component 1) times a "strength" (split_power): editing either sets it.
bool power_fields(PanelContext& ctx, const char* label, Color& power, float speed);

// A light's fields as the file has them (scene.h's light_params), each at its row's step: a
// vector as three numbers, a colour as power_fields, a shape reference as its sphere's
// "position" (centre) and "radius" where `shape` is given (the shape it names, edited in
// place: the Lights panel), else nothing (the Selection panel shows an object's sphere under
// Shape). True when `light` or `*shape` was changed. The Lights panel and the Selection
// panel both edit lights through it.
bool light_fields(PanelContext& ctx, Light& light, Shape* shape);

// A material's type and its parameters as the file has them (scene.h's material_params):
// colour parameters as a picker and three numbers. True when `m` was changed. The Materials
// panel and the Selection panel both edit materials through it.
bool material_fields(PanelContext& ctx, Material& m);

// Light `index`'s on/off checkbox, labelled with light_label: checking it switches the light
// on or off (set_light_on, one undoable edit) and says so in the status line, with why a light
// switched on adds nothing to the picture (light_unseen_reason). Returns whether it is on now.
bool light_checkbox(PanelContext& ctx, int index);

// Records the last item's centre under `name` for this frame (UiState::marks: the status
// file's at=, which the window tests click).
void mark_item(PanelContext& ctx, std::string name);

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

}  // namespace kr::viewer
