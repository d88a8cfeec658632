#include "viewer/scene_edit.h"

#include <algorithm>

namespace kr::viewer {

void set_light_on(Scene& scene, int index, bool on) {
    std::vector<int>& active = scene.active_lights;
    const auto it = std::find(active.begin(), active.end(), index);
    if (on && it == active.end()) active.push_back(index);
    if (!on && it != active.end()) active.erase(it);
}

}  // namespace kr::viewer
