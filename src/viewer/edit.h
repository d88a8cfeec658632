// The viewer's reset rule: which edits change the rendered image (accumulation restarts)
// and which only change how it is displayed or how long it runs (samples are kept).
// Also the check of a value typed into a panel field before it is applied.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "core/image.h"
#include "scene/scene.h"  // DisplaySettings

namespace kr::viewer {

enum class Edit {
    camera,     // position, target, fov, aspect, active camera
    lens,       // camera type, focal distance, aperture
    light,      // active lights' position, power, area radius
    material,   // rho, roughness, eta, type
    object,     // a primitive: selected and moved, resized, given a material, made emissive, added, removed
    renderer,   // integrator, depth, estimator, light sampling, seed
    scene,      // another file, a reload, a watched file that changed
    bookmark,   // a camera bookmark stored: the file changes, the image does not
    tone_map,   // operator, exposure: re-display only
    run_control // pause, unlimited, target spp, stop rules: how long the same estimate refines
};

// True when the edit changes the image, so accumulated samples no longer belong to it.
constexpr bool edit_resets(Edit e) {
    switch (e) {
        case Edit::camera:
        case Edit::lens:
        case Edit::light:
        case Edit::material:
        case Edit::object:
        case Edit::renderer:
        case Edit::scene: return true;
        case Edit::bookmark:
        case Edit::tone_map:
        case Edit::run_control: return false;
    }
    return true;
}

// How the accumulated radiance is shown (and saved): the display shader's parameters,
// the scene file's `display` block (tone map, exposure in stops).
using ToneSettings = DisplaySettings;

// A value typed into the field `field`: nullopt when every component is finite and in
// [lo, hi], else the one-line reason the edit is refused ("fov (deg): -20 is below the
// minimum 0.5; the previous value is kept").
std::optional<std::string> check_typed_value(std::string_view field, const double* values, int count, double lo,
                                             double hi);

// A value from a widget that holds floats (ImGui's colour picker) as the shortest decimal that
// reads back as that float: 0.9f is 0.9, not 0.8999999761581421, in the panel and the file.
double shortest_decimal(float value);
// The colour a float picker gave (`rgb`) over `before`: a component the picker left as it
// was (the float of the old value) keeps the old value, a changed one is its shortest decimal.
Color picked_colour(const Color& before, const float rgb[3]);

}  // namespace kr::viewer
