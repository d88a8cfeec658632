// The viewer's reset rule: which edits change the rendered image (accumulation restarts)
// and which only change how it is displayed or how long it runs (samples are kept).
#pragma once

#include "core/image.h"

namespace kr::viewer {

enum class Edit {
    camera,     // position, target, fov, aspect, active camera
    lens,       // camera type, focal distance, aperture
    light,      // active lights' position, power, area radius
    material,   // rho, roughness, eta, type
    renderer,   // integrator, depth, estimator, light sampling, target spp, seed
    scene,      // another file, a reload, a watched file that changed
    tone_map,   // operator, exposure: re-display only
    run_control // pause, unlimited: how long the same estimate keeps refining
};

// True when the edit changes the image, so accumulated samples no longer belong to it.
constexpr bool edit_resets(Edit e) {
    switch (e) {
        case Edit::camera:
        case Edit::lens:
        case Edit::light:
        case Edit::material:
        case Edit::renderer:
        case Edit::scene: return true;
        case Edit::tone_map:
        case Edit::run_control: return false;
    }
    return true;
}

// How the accumulated radiance is shown (and saved): the display shader's parameters.
struct ToneSettings {
    ToneMap op = ToneMap::sigmoid;
    double exposure = 1.0;  // sigmoid only; cancels in the linear map (as in kr::tonemap)
};

}  // namespace kr::viewer
