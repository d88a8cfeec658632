// Headless display: the same shaders as the window, drawn into an OSMesa (software)
// framebuffer and read back. Needs no display server and no GPU.
#pragma once

#include <string>

#include "core/image.h"
#include "viewer/gl_display.h"

namespace kr::viewer {

// Tone maps `radiance` on the GL display path at its own size. `gl_description`, when
// given, receives GL_RENDERER / GL_VERSION of the context used. Throws std::runtime_error.
Rgb8Image display_offscreen(const Image& radiance, const ToneSettings& tone,
                            std::string* gl_description = nullptr);

}  // namespace kr::viewer
