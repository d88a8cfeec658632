// The display path shared by the window and the offscreen (OSMesa) mode: the mean
// radiance goes to a float texture and the shaders in shaders/ tone map it on the GPU.
#pragma once

#include <vector>

#include "core/image.h"
#include "viewer/edit.h"
#include "viewer/gl_functions.h"
#include "viewer/image_view.h"  // PixelRect

namespace kr::viewer {

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

    // An 8-bit picture shown as it is (image B, an error or noise map) by draw_bytes.
    void upload_bytes(const Rgb8Image& picture);
    bool has_bytes() const { return bytes_width_ > 0; }

    // Draws the tone-mapped radiance into `where` of a framebuffer of the given size,
    // clipped to `clip` (viewport and scissor set here).
    void draw(const PixelRect& where, const PixelRect& clip, int framebuffer_width, int framebuffer_height,
              const ToneSettings& tone) const;
    // Draws the 8-bit picture the same way, unchanged.
    void draw_bytes(const PixelRect& where, const PixelRect& clip, int framebuffer_width,
                    int framebuffer_height) const;

    // Linear filtering where the image is scaled (a fit by any factor); else nearest, so
    // pixels show as blocks and at 1:1 every fragment reads exactly its pixel.
    void set_smooth(bool smooth) { smooth_ = smooth; }

private:
    void draw_quad(const PixelRect& where, const PixelRect& clip, int framebuffer_width, int framebuffer_height,
                   int op, float exposure, float inv_max, GLuint texture) const;
    const GlFunctions& gl_;
    GLuint program_ = 0, texture_ = 0, bytes_texture_ = 0, vertex_array_ = 0;
    int bytes_width_ = 0;
    GLint rect_loc_ = -1, op_loc_ = -1, exposure_loc_ = -1, inv_max_loc_ = -1, sampler_loc_ = -1;
    int tex_width_ = 0, tex_height_ = 0;
    std::vector<float> texels_;  // the upload's floats, kept between frames
    double inv_max_ = 0;
    bool smooth_ = false;
};

}  // namespace kr::viewer
