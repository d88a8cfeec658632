#include "core/image.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <stb/stb_easy_font.h>

#include "core/text.h"

namespace kr {

uint8_t quantize_unit(double v) {
    if (!(v > 0)) return 0;  // also maps NaN to 0
    if (v >= 1) return 255;
    // lround of x in (0, 255) without the library call: x - trunc(x) is exact, so this is
    // its rounding of halves away from zero.
    const double x = v * 255.0;
    const int whole = int(x);
    return static_cast<uint8_t>(whole + (x - whole >= 0.5));
}

std::array<uint8_t, 3> tonemap_color(const Color& radiance, ToneMap op, double scale) {
    const Color c = radiance * scale;
    std::array<uint8_t, 3> out{};
    for (int k = 0; k < 3; ++k) {
        const double v = c[k];
        double unit = v;
        switch (op) {
            case ToneMap::sigmoid: unit = sigmoid_tonemap(v); break;
            case ToneMap::linear: break;
            case ToneMap::srgb: unit = v > 0 ? srgb_encode(std::min(v, 1.0)) : v; break;  // NaN stays NaN: 0
        }
        out[size_t(k)] = quantize_unit(unit);
    }
    return out;
}

double tonemap_scale(const Image& radiance, ToneMap op, double exposure) {
    return op == ToneMap::linear ? linear_tonemap_scale(radiance, exposure) : exposure;
}

Rgb8Image tonemap(const Image& radiance, ToneMap op, double exposure) {
    Rgb8Image out{radiance.width, radiance.height, {}};
    out.bytes.resize(radiance.pixels.size() * 3);
    const double scale = tonemap_scale(radiance, op, exposure);
    for (size_t i = 0; i < radiance.pixels.size(); ++i) {
        const std::array<uint8_t, 3> c = tonemap_color(radiance.pixels[i], op, scale);
        std::copy(c.begin(), c.end(), out.bytes.begin() + std::ptrdiff_t(3 * i));
    }
    return out;
}

double linear_tonemap_scale(const Image& radiance, double exposure) {
    double max_value = 0;
    for (const Color& c : radiance.pixels)
        if (is_finite(c)) max_value = std::max(max_value, max_component(c));
    return max_value > 0 ? exposure / max_value : 0.0;
}

namespace {

// One channel's running sum over a sliding window, with Neumaier's compensation: radiance
// spans many orders of magnitude (a firefly of 1e20 beside pixels of 0.5), and a plain
// running sum would lose the small values added while the large one was in the window once
// it leaves. Non-finite values are counted instead of summed (inf - inf would be NaN).
struct WindowSum {
    double sum = 0, compensation = 0;
    int nonfinite = 0;
    void add(double x) {
        if (!std::isfinite(x)) {
            ++nonfinite;
            return;
        }
        const double t = sum + x;
        compensation += std::abs(sum) >= std::abs(x) ? (sum - t) + x : (x - t) + sum;
        sum = t;
    }
    void remove(double x) {
        if (!std::isfinite(x)) --nonfinite;
        else add(-x);
    }
};

// Blurs one line of `n` colours (3 doubles each) from `in` into `out`: the mean over
// [i - r, i + r] clamped to [0, n - 1], in O(n) whatever r.
void blur_line(const double* in, double* out, int n, int radius) {
    WindowSum window[3];
    for (int j = 0; j <= std::min(n - 1, radius); ++j)
        for (int k = 0; k < 3; ++k) window[k].add(in[3 * j + k]);
    for (int i = 0; i < n; ++i) {
        const int lo = std::max(0, i - radius), hi = std::min(n - 1, i + radius);
        const double count = hi - lo + 1;
        for (int k = 0; k < 3; ++k) {
            if (window[k].nonfinite == 0) {
                out[3 * i + k] = (window[k].sum + window[k].compensation) / count;
            } else {  // an inf or NaN in the window: the direct sum says which (rare)
                double direct = 0;
                for (int j = lo; j <= hi; ++j) direct += in[3 * j + k];
                out[3 * i + k] = direct / count;
            }
        }
        // Slide the window to i + 1: the pixel at i + r + 1 enters, the one at i - r leaves.
        if (i + radius + 1 < n)
            for (int k = 0; k < 3; ++k) window[k].add(in[3 * (i + radius + 1) + k]);
        if (i - radius >= 0)
            for (int k = 0; k < 3; ++k) window[k].remove(in[3 * (i - radius) + k]);
    }
}

}  // namespace

Image upscale_linear(const Image& src, int width, int height) {
    Image out(width, height);
    if (src.width <= 0 || src.height <= 0) return out;
    // Source coordinates of each destination pixel centre: the lower sample and the weight of
    // the upper one, clamped to the edge.
    struct Tap {
        int lo, hi;
        double t;
    };
    auto taps = [](int n, int source) {
        std::vector<Tap> out(size_t(std::max(0, n)));
        for (int i = 0; i < n; ++i) {
            const double u = std::clamp((i + 0.5) * source / n - 0.5, 0.0, double(source - 1));
            const int lo = std::min(int(u), source - 1);
            out[size_t(i)] = {lo, std::min(lo + 1, source - 1), u - lo};
        }
        return out;
    };
    const std::vector<Tap> xs = taps(width, src.width), ys = taps(height, src.height);
    for (int y = 0; y < height; ++y) {
        const Tap ty = ys[size_t(y)];
        for (int x = 0; x < width; ++x) {
            const Tap tx = xs[size_t(x)];
            const Color top = src.at(tx.lo, ty.lo) * (1 - tx.t) + src.at(tx.hi, ty.lo) * tx.t;
            const Color bottom = src.at(tx.lo, ty.hi) * (1 - tx.t) + src.at(tx.hi, ty.hi) * tx.t;
            out.at(x, y) = top * (1 - ty.t) + bottom * ty.t;
        }
    }
    return out;
}

Image box_blur(const Image& src, int radius) {
    if (radius <= 0 || src.pixels.empty()) return src;
    // Two 1-D passes (rows, then columns), each a running sum over a line copied into a
    // contiguous buffer; at the borders the box shrinks to the image.
    auto pass = [radius](const Image& in, bool horizontal) {
        Image out(in.width, in.height);
        const int n = horizontal ? in.width : in.height;
        const int lines = horizontal ? in.height : in.width;
        std::vector<double> line_in(3 * size_t(n)), line_out(3 * size_t(n));
        for (int line = 0; line < lines; ++line) {
            for (int i = 0; i < n; ++i) {
                const Color& c = horizontal ? in.at(i, line) : in.at(line, i);
                line_in[3 * size_t(i)] = c.x, line_in[3 * size_t(i) + 1] = c.y, line_in[3 * size_t(i) + 2] = c.z;
            }
            blur_line(line_in.data(), line_out.data(), n, radius);
            for (int i = 0; i < n; ++i)
                (horizontal ? out.at(i, line) : out.at(line, i)) =
                    Color{line_out[3 * size_t(i)], line_out[3 * size_t(i) + 1], line_out[3 * size_t(i) + 2]};
        }
        return out;
    };
    return pass(pass(src, true), false);
}

Rgb8Image depth_to_rgb8(const std::vector<double>& depth, int width, int height) {
    Rgb8Image out{width, height, std::vector<uint8_t>(depth.size() * 3)};
    for (size_t i = 0; i < depth.size(); ++i) {
        const double d = std::max(0.0, depth[i]);
        const uint8_t g = std::isinf(d) ? 0 : quantize_unit(1.0 - d / (1.0 + d));  // inf / inf is NaN
        out.bytes[3 * i] = out.bytes[3 * i + 1] = out.bytes[3 * i + 2] = g;
    }
    return out;
}

void draw_text(Rgb8Image& image, double x, double y, const std::string& text, const std::array<uint8_t, 3>& colour,
               double scale) {
    std::vector<char> buffer(text.size() * 300 + 64);  // stb_easy_font: at most 270 bytes a character
    std::string copy = text;
    const int quads = stb_easy_font_print(0, 0, copy.data(), nullptr, buffer.data(), int(buffer.size()));
    const float* v = reinterpret_cast<const float*>(buffer.data());
    for (int q = 0; q < quads; ++q) {
        // Four vertices of 16 bytes (x, y, z, colour); corners 0 and 2 are opposite.
        const float* a = v + q * 16;
        const float* b = a + 8;
        const int x0 = std::max(0, int(x + a[0] * scale)), y0 = std::max(0, int(y + a[1] * scale));
        const int x1 = std::min(image.width, int(x + b[0] * scale)), y1 = std::min(image.height, int(y + b[1] * scale));
        for (int py = y0; py < y1; ++py)
            for (int px = x0; px < x1; ++px) {
                uint8_t* p = &image.bytes[3 * (size_t(py) * size_t(image.width) + size_t(px))];
                p[0] = colour[0], p[1] = colour[1], p[2] = colour[2];
            }
    }
}

int text_width(const std::string& text, double scale) {
    std::string copy = text;
    return int(stb_easy_font_width(copy.data()) * scale);
}

double psnr(const Rgb8Image& a, const Rgb8Image& b) {
    if (a.width != b.width || a.height != b.height || a.bytes.size() != b.bytes.size())
        throw std::invalid_argument("psnr: images differ in size");
    double sum = 0;
    for (size_t i = 0; i < a.bytes.size(); ++i) {
        const double d = double(a.bytes[i]) - double(b.bytes[i]);
        sum += d * d;
    }
    const double mse = sum / double(a.bytes.size());
    return mse == 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

std::filesystem::path depth_path_for(const std::filesystem::path& output) {
    std::filesystem::path p = output;
    const std::string stem = p.stem().string();
    const std::string ext = p.has_extension() ? p.extension().string() : std::string(".ppm");
    return p.replace_filename(stem + "-depth" + ext);
}

}  // namespace kr
