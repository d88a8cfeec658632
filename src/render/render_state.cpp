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

void RenderState::add_pass_to_half(int sign) {
    if (!tracks_halves()) return;
    const auto data = [](const std::vector<uint8_t>& v) { return v.empty() ? nullptr : v.data(); };
    add_sums_to_half(sign, data(active_rows), data(plan.active), data(plan.pass_samples));
}

}  // namespace kr
