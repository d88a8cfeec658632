// The viewer's GL side as the module keithray_viewer.so (core/module.h): `keithray view`
// (GLFW, Dear ImGui) and `render --gl` (OSMesa). The program loads it, with those libraries
// and the GL stack under them, only for those two commands.
#pragma once

#include <string>

#include "core/image.h"
#include "viewer/edit.h"

namespace kr {

namespace viewer {
class SharedPasses;
}

struct ViewerModule {
    // viewer/viewer.h's run_viewer.
    int (*run_viewer)(int argc, char** argv, viewer::SharedPasses* ranks);
    // viewer/gl_offscreen.h's display_offscreen.
    Rgb8Image (*display_offscreen)(const Image& radiance, const viewer::ToneSettings& tone,
                                   std::string* gl_description);
};

// Loads the module once; throws std::runtime_error (one line naming its file and what is
// missing) where it or a library it needs cannot be loaded.
const ViewerModule& viewer_module();

}  // namespace kr
