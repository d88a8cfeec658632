// The display path shared by the window and the offscreen (OSMesa) mode: the mean
// radiance goes to a float texture and the shaders in shaders/ tone map it on the GPU.
#pragma once

#include "core/image.h"
#include "viewer/edit.h"
#include "viewer/gl_functions.h"

namespace kr::viewer {

// Pixel rectangle in a framebuffer, origin at the top-left.
struct PixelRect {
    double x = 0, y = 0, width = 0, height = 0;
};

class Display {
public:
    // Compiles the embedded shaders; throws std::runtime_error with the GLSL log.
    explicit Display(const GlFunctions& gl);
    ~Display();
    Display(const Display&) = delete;
    Display& operator=(const Display&) = delete;

    // Replaces the texture with `radiance` (any size: previews are smaller) and records
    // the linear tone map's scale from it.
    void upload(const Image& radiance);
    bool has_image() const { return tex_width_ > 0; }
    int image_width() const { return tex_width_; }
    int image_height() const { return tex_height_; }

    // Draws the image into `where` of a framebuffer of the given size (viewport set here).
    void draw(const PixelRect& where, int framebuffer_width, int framebuffer_height,
              const ToneSettings& tone) const;

private:
    const GlFunctions& gl_;
    GLuint program_ = 0, texture_ = 0, vertex_array_ = 0;
    GLint rect_loc_ = -1, op_loc_ = -1, exposure_loc_ = -1, inv_max_loc_ = -1, sampler_loc_ = -1;
    int tex_width_ = 0, tex_height_ = 0;
    double inv_max_ = 0;
};

}  // namespace kr::viewer
