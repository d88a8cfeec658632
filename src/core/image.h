// Radiance images, tone mapping, blur, PSNR. Their files: core/image_io.h.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "core/math.h"
#include "core/enum_names.h"

namespace kr {

// Linear radiance, row-major, top row first.
struct Image {
    int width = 0, height = 0;
    std::vector<Color> pixels;

    Image() = default;
    Image(int w, int h) : width(w), height(h), pixels(static_cast<size_t>(w) * h) {}
    Color& at(int x, int y) { return pixels[static_cast<size_t>(y) * width + x]; }
    const Color& at(int x, int y) const { return pixels[static_cast<size_t>(y) * width + x]; }
};

// The pixels [x0, x1) x [y0, y1) of an image (a render region, a part of an image to work on).
struct PixelBox {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    bool operator==(const PixelBox& o) const { return x0 == o.x0 && y0 == o.y0 && x1 == o.x1 && y1 == o.y1; }
    bool operator!=(const PixelBox& o) const { return !(*this == o); }
};

// 8-bit RGB, row-major, top row first.
struct Rgb8Image {
    int width = 0, height = 0;
    std::vector<uint8_t> bytes;  // 3 per pixel
};

// Display tone maps: one table for the loader, the saver, the command lines and the viewer's
// combos.
enum class ToneMap { sigmoid, linear, srgb };
inline constexpr EnumNames<ToneMap, 3> tonemap_names{{"sigmoid", "linear", "srgb"}};
// The default tone map: a scene's without a display block, and the one by which psnr,
// compare and bench --convergence take an HDR image's 8-bit form. The brief's sigmoid, which
// its references were made with.
inline constexpr ToneMap kDefaultToneMap = ToneMap::sigmoid;

// Per channel, after `exposure` (2^EV) scales radiance: sigmoid I/(1+I), or linear I/max
// where max is the largest channel value of the whole image (one scale for all channels, so
// hues are kept), both with no gamma (the brief's operators, its references' convention); or
// srgb: clamped to [0, 1], then the sRGB transfer curve, as HDR viewers display radiance.
// Then x255 and round. At exposure 1 (EV 0) the brief's operators are exactly its own.
Rgb8Image tonemap(const Image& radiance, ToneMap op, double exposure = 1.0);

// The linear operator's scale: exposure / max over the finite channel values of the image
// (0 for a black image). The viewer's shader takes it as a uniform.
double linear_tonemap_scale(const Image& radiance, double exposure = 1.0);

// One pixel of tonemap(): `scale` is tonemap_scale() of the whole image (the linear
// operator's depends on the image's maximum).
double tonemap_scale(const Image& radiance, ToneMap op, double exposure = 1.0);
std::array<uint8_t, 3> tonemap_color(const Color& radiance, ToneMap op, double scale);

// The sRGB transfer curve (IEC 61966-2-1) of a linear value in [0, 1].
inline double srgb_encode(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055; }

// One channel value of the tone maps above, before quantisation, for callers
// that tone map themselves (the viewer's shader mirrors this).
// +inf (an overflowed pixel sum) saturates to 1 like any huge value, where inf/inf would be NaN.
inline double sigmoid_tonemap(double v) { return std::isinf(v) && v > 0 ? 1.0 : v / (1.0 + v); }
uint8_t quantize_unit(double v);  // clamp to [0,1], x255, round

// Box blur of half-width `radius` pixels (a (2r+1)^2 box, clamped at the borders),
// separable, applied to radiance, in O(pixels) whatever the radius (a compensated running sum
// per line). radius 0 returns the input.
Image box_blur(const Image& src, int radius);

// `src` stretched over a width x height image, bilinear between pixel centres (as a GPU's
// linear filter of a texture drawn over that many pixels, clamped at the edges): a preview
// rendered at a fraction of the resolution, shown smooth.
Image upscale_linear(const Image& src, int width, int height);

// The brief's depth map: each pixel shows 1 - d/(1+d) as grey.
Rgb8Image depth_to_rgb8(const std::vector<double>& depth, int width, int height);

// Text on an 8-bit image (plot labels, colour bars) with stb_easy_font: `text` with its top
// left at (x, y), each font unit `scale` pixels, clipped to the image. text_width: its width.
void draw_text(Rgb8Image& image, double x, double y, const std::string& text, const std::array<uint8_t, 3>& colour,
               double scale = 2);
int text_width(const std::string& text, double scale = 2);

// Peak signal-to-noise ratio in dB of two same-sized 8-bit images (99 when identical).
double psnr(const Rgb8Image& a, const Rgb8Image& b);

// The path beside OUT.ppm that holds the depth map: OUT-depth.ppm.
std::filesystem::path depth_path_for(const std::filesystem::path& output);

}  // namespace kr
