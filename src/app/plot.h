// Log-log line plots as 8-bit images, for `keithray bench --convergence`: no plotting
// library in Debian's C++ packages fits, and the needs are small (lines, grid, labels).
#pragma once

#include <string>
#include <vector>

#include "core/image.h"

namespace kr {

struct PlotSeries {
    std::string name;
    std::vector<double> x, y;  // points with x <= 0 or y <= 0 are skipped (log axes)
};

struct PlotSpec {
    std::string title, x_label, y_label;
    std::vector<PlotSeries> series;
};

// Both axes logarithmic, spanning the data rounded out to powers of ten. Labels are drawn
// with stb_easy_font; one colour per series, with a legend.
Rgb8Image plot_loglog(const PlotSpec& spec, int width = 960, int height = 640);

}  // namespace kr
