#include "render/render_state.h"

#include <utility>

namespace kr {

void RenderState::reset(int w, int h, std::vector<int> held) {
    Film::reset(w, h, std::move(held));
    plan.clear();
    active_rows.clear();
    passes = 0;
    rays = 0;
    nonfinite_samples = 0;
}

}  // namespace kr
