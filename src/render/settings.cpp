#include "render/settings.h"

#include <algorithm>

namespace kr {

RenderSettings RenderSettings::from_scene(const RendererSettings& renderer) {
    RenderSettings s;
    s.integrator = renderer.type == RendererType::wrt ? Integrator::wrt : Integrator::pt;
    s.max_depth = std::clamp(renderer.depth, 0, kMaxDepth);
    s.target_spp = std::max(1, renderer.samples);
    return s;
}

}  // namespace kr
