#include "viewer/inspect.h"

#include <algorithm>
#include <cmath>

#include "core/image_compare.h"
#include "render/outputs.h"

namespace kr::viewer {

void record_pixel_statistics(const RenderState& totals, Snapshot& frame) {
    const size_t n = totals.sample_count().size();
    frame.sample_count = totals.sample_count();
    frame.standard_error.resize(n);
    for (size_t i = 0; i < n; ++i) frame.standard_error[i] = float(totals.pixel_standard_error(i));
    RenderEstimates layers = render_estimates(totals, kLayerDepth | kLayerVariance);
    frame.depth = std::move(layers.depth);
    frame.variance = std::move(layers.variance);
    frame.halves = std::move(layers.halves);
}

std::optional<PixelProbe> probe_pixel(const Snapshot& frame, int width, int height, int x, int y,
                                      const ToneSettings& tone, double linear_scale) {
    if (x < 0 || y < 0 || x >= width || y >= height || frame.radiance.width <= 0) return std::nullopt;
    PixelProbe p;
    p.x = x;
    p.y = y;
    // A preview covers the image with scale x scale blocks.
    const int px = std::min(x / frame.scale, frame.radiance.width - 1);
    const int py = std::min(y / frame.scale, frame.radiance.height - 1);
    p.mean = frame.radiance.at(px, py);
    const double scale = tone.tonemap == ToneMap::linear ? linear_scale : tone.exposure_scale();
    p.displayed = tonemap_color(p.mean, tone.tonemap, scale);
    const size_t i = size_t(py) * size_t(frame.radiance.width) + size_t(px);
    p.preview = frame.scale != 1 || i >= frame.sample_count.size();
    if (!p.preview) {
        p.samples = frame.sample_count[i];
        p.standard_error = frame.standard_error[i];
    }
    return p;
}

double robust_scale(const std::vector<float>& values, double q) {
    std::vector<float> finite;
    finite.reserve(values.size());
    for (float v : values)
        if (std::isfinite(v)) finite.push_back(v);
    if (finite.empty()) return 0;
    const size_t k = std::min(finite.size() - 1, size_t(q * double(finite.size())));
    std::nth_element(finite.begin(), finite.begin() + std::ptrdiff_t(k), finite.end());
    return finite[k];
}

Rgb8Image standard_error_map(const Snapshot& frame, double scale) {
    if (frame.standard_error.empty()) return {};
    std::vector<float> v = frame.standard_error;
    for (float& e : v)
        if (!std::isfinite(e)) e = INFINITY;  // viridis saturates
    return false_colour_picture(v, frame.radiance.width, frame.radiance.height, scale);
}

Rgb8Image sample_count_map(const Snapshot& frame, double scale) {
    if (frame.sample_count.empty()) return {};
    std::vector<float> v(frame.sample_count.begin(), frame.sample_count.end());
    return false_colour_picture(v, frame.radiance.width, frame.radiance.height, scale);
}

}  // namespace kr::viewer
