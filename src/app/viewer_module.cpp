// The entry point of the module keithray_viewer.so (app/viewer_module.h): the viewer's GL
// side, whose GL-free parts (viewer_core) and everything below them it takes from the
// program that loads it.
#include <cstring>

#include "app/viewer_module.h"
#include "viewer/gl_offscreen.h"
#include "viewer/viewer.h"

namespace kr {
namespace {

Rgb8Image display_offscreen(const Image& radiance, const viewer::ToneSettings& tone, std::string* gl_description) {
    return viewer::display_offscreen(radiance, tone, gl_description);
}

int run_viewer(int argc, char** argv, viewer::SharedPasses* ranks) { return viewer::run_viewer(argc, argv, ranks); }

constexpr ViewerModule kModule{run_viewer, display_offscreen};

}  // namespace
}  // namespace kr

extern "C" __attribute__((visibility("default"))) const void* keithray_viewer_module(const char* version, const void*) {
    return std::strcmp(version, KEITHRAY_MODULE_VERSION) == 0 ? &kr::kModule : nullptr;
}
