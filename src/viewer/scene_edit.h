// Edits of the scene's objects that the panels and the mouse make, on the authored scene,
// GL-free and unit-tested: lights on and off.
#pragma once

#include "scene/scene.h"

namespace kr::viewer {

// Turns light `index` of the file on (into the scene block's lights) or off.
void set_light_on(Scene& scene, int index, bool on);

}  // namespace kr::viewer
