#include "viewer/gl_offscreen.h"

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <vector>

#include <GL/osmesa.h>

namespace kr::viewer {

Rgb8Image display_offscreen(const Image& radiance, const ToneSettings& tone, std::string* gl_description) {
    const int w = radiance.width, h = radiance.height;
    if (w <= 0 || h <= 0) throw std::runtime_error("offscreen display: empty image");
    // A 3.3 core context: the version the window asks GLFW for, so both compile the same GLSL.
    const int attributes[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0,
                              OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 3,
                              OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
    std::unique_ptr<osmesa_context, void (*)(OSMesaContext)> context(
        OSMesaCreateContextAttribs(attributes, nullptr), &OSMesaDestroyContext);
    if (!context) throw std::runtime_error("offscreen display: cannot create an OSMesa 3.3 core context");
    std::vector<unsigned char> buffer(static_cast<size_t>(w) * h * 4);
    // Fails past OSMesa's maximum framebuffer size (OSMESA_MAX_WIDTH/HEIGHT).
    if (!OSMesaMakeCurrent(context.get(), buffer.data(), GL_UNSIGNED_BYTE, w, h))
        throw std::runtime_error("offscreen display: cannot make the OSMesa context current at " +
                                 std::to_string(w) + "x" + std::to_string(h));

    GlFunctions gl;
    gl.load(&OSMesaGetProcAddress);
    if (gl_description) *gl_description = gl.describe();
    // Which implementation answered (docs/viewer.md): KEITHRAY_GL_INFO=1 prints it.
    if (const char* info = std::getenv("KEITHRAY_GL_INFO"); info && *info && *info != '0')
        std::fprintf(stderr, "keithray: offscreen GL: %s\n", gl.describe().c_str());
    Rgb8Image out{w, h, std::vector<uint8_t>(static_cast<size_t>(w) * h * 3)};
    {
        Display display(gl);
        display.upload(radiance);
        gl.ClearColor(0, 0, 0, 1);
        gl.Clear(GL_COLOR_BUFFER_BIT);
        display.draw({0, 0, double(w), double(h)}, {0, 0, double(w), double(h)}, w, h, tone);
        gl.Finish();
        // Read through GL, as the window's screenshot does; rows come bottom row first.
        std::vector<unsigned char> rgba(static_cast<size_t>(w) * h * 4);
        gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
        gl.ReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
        if (const GLenum error = gl.GetError(); error != GL_NO_ERROR)
            throw std::runtime_error("offscreen display: GL error " + std::to_string(error));
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int k = 0; k < 3; ++k)
                    out.bytes[(static_cast<size_t>(y) * w + x) * 3 + k] =
                        rgba[(static_cast<size_t>(h - 1 - y) * w + x) * 4 + k];
    }
    OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);  // release before the context is destroyed
    return out;
}

}  // namespace kr::viewer
