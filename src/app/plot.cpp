#include "app/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>


namespace kr {

namespace {

struct Rgb {
    uint8_t r, g, b;
};

constexpr Rgb kPalette[] = {{31, 119, 180}, {255, 127, 14}, {44, 160, 44},  {214, 39, 40},
                            {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {80, 80, 80},
                            {188, 189, 34}, {23, 190, 207}};

struct Canvas {
    Rgb8Image image;

    void pixel(int x, int y, Rgb c) {
        if (x < 0 || y < 0 || x >= image.width || y >= image.height) return;
        uint8_t* p = &image.bytes[(size_t(y) * image.width + x) * 3];
        p[0] = c.r, p[1] = c.g, p[2] = c.b;
    }
    void rect(int x0, int y0, int x1, int y1, Rgb c) {
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) pixel(x, y, c);
    }
    // A line `thickness` pixels wide, stepped along its longer axis.
    void line(double x0, double y0, double x1, double y1, Rgb c, int thickness) {
        const int steps = int(std::max(std::abs(x1 - x0), std::abs(y1 - y0))) + 1;
        for (int i = 0; i <= steps; ++i) {
            const double t = double(i) / steps;
            const int x = int(std::lround(x0 + t * (x1 - x0))), y = int(std::lround(y0 + t * (y1 - y0)));
            rect(x - thickness / 2, y - thickness / 2, x - thickness / 2 + thickness, y - thickness / 2 + thickness, c);
        }
    }
    void text(double x, double y, const std::string& s, Rgb c, int scale = 2) {
        draw_text(image, x, y, s, {c.r, c.g, c.b}, scale);
    }
    static int text_width(const std::string& s, int scale = 2) { return kr::text_width(s, scale); }
};

std::string decade_label(int exponent) {
    char buf[32];
    if (exponent >= -3 && exponent <= 4) std::snprintf(buf, sizeof buf, "%g", std::pow(10.0, exponent));
    else std::snprintf(buf, sizeof buf, "1e%d", exponent);
    return buf;
}

}  // namespace

Rgb8Image plot_loglog(const PlotSpec& spec, int width, int height) {
    Canvas c;
    c.image.width = width;
    c.image.height = height;
    c.image.bytes.assign(size_t(width) * height * 3, 255);

    // Data range in decades, rounded out to whole powers of ten.
    double x_lo = 1e300, x_hi = -1e300, y_lo = 1e300, y_hi = -1e300;
    for (const PlotSeries& s : spec.series)
        for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
            if (s.x[i] > 0 && s.y[i] > 0 && std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
                x_lo = std::min(x_lo, std::log10(s.x[i])), x_hi = std::max(x_hi, std::log10(s.x[i]));
                y_lo = std::min(y_lo, std::log10(s.y[i])), y_hi = std::max(y_hi, std::log10(s.y[i]));
            }
    if (x_lo > x_hi) x_lo = 0, x_hi = 1, y_lo = 0, y_hi = 1;
    x_lo = std::floor(x_lo), x_hi = std::max(std::ceil(x_hi), x_lo + 1);
    y_lo = std::floor(y_lo), y_hi = std::max(std::ceil(y_hi), y_lo + 1);

    const int left = 90, right = width - 310, top = 70, bottom = height - 70;
    auto px = [&](double lx) { return left + (lx - x_lo) / (x_hi - x_lo) * (right - left); };
    auto py = [&](double ly) { return bottom - (ly - y_lo) / (y_hi - y_lo) * (bottom - top); };

    const Rgb grid{225, 225, 225}, minor{242, 242, 242}, ink{20, 20, 20};
    // Grid: a line per decade, lighter ones at 2..9 times it.
    for (int e = int(x_lo); e <= int(x_hi); ++e) {
        for (int k = 2; k < 10 && e < int(x_hi); ++k) c.line(px(e + std::log10(k)), top, px(e + std::log10(k)), bottom, minor, 1);
        c.line(px(e), top, px(e), bottom, grid, 1);
        const std::string label = decade_label(e);
        c.text(px(e) - Canvas::text_width(label) / 2.0, bottom + 8, label, ink);
    }
    for (int e = int(y_lo); e <= int(y_hi); ++e) {
        for (int k = 2; k < 10 && e < int(y_hi); ++k) c.line(left, py(e + std::log10(k)), right, py(e + std::log10(k)), minor, 1);
        c.line(left, py(e), right, py(e), grid, 1);
        const std::string label = decade_label(e);
        c.text(left - 8 - Canvas::text_width(label), py(e) - 7, label, ink);
    }
    c.line(left, top, left, bottom, ink, 2);
    c.line(left, bottom, right, bottom, ink, 2);

    for (size_t s = 0; s < spec.series.size(); ++s) {
        const PlotSeries& series = spec.series[s];
        const Rgb colour = kPalette[s % std::size(kPalette)];
        bool have_last = false;
        double last_x = 0, last_y = 0;
        for (size_t i = 0; i < series.x.size() && i < series.y.size(); ++i) {
            if (!(series.x[i] > 0 && series.y[i] > 0)) continue;
            const double x = px(std::log10(series.x[i])), y = py(std::log10(series.y[i]));
            if (have_last) c.line(last_x, last_y, x, y, colour, 3);
            c.rect(int(x) - 3, int(y) - 3, int(x) + 4, int(y) + 4, colour);
            last_x = x, last_y = y, have_last = true;
        }
        // Legend entry.
        const int ly = top + 10 + int(s) * 24;
        c.rect(right + 20, ly + 4, right + 50, ly + 10, colour);
        c.text(right + 58, ly, series.name, ink);
    }
    c.text((left + right) / 2.0 - Canvas::text_width(spec.title, 3) / 2.0, 8, spec.title, ink, 3);
    c.text((left + right) / 2.0 - Canvas::text_width(spec.x_label) / 2.0, bottom + 36, spec.x_label, ink);
    c.text(left - 60, top - 28, spec.y_label, ink);
    return c.image;
}

}  // namespace kr
