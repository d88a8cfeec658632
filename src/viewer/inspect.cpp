#include "viewer/inspect.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/image_compare.h"
#include "render/outputs.h"
#include "render/trace.h"

namespace kr::viewer {

void record_pixel_statistics(const RenderState& totals, Snapshot& frame) {
    record_pixel_statistics(totals, render_estimates(totals, kLayerDepth | kLayerSamples | kLayerVariance), frame);
}

void record_pixel_statistics(const RenderState& totals, RenderEstimates estimates, Snapshot& frame) {
    const size_t n = totals.sample_count().size();
    frame.standard_error.resize(n);
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; ++i) frame.standard_error[i] = float(totals.pixel_standard_error(i));
    frame.sample_count = std::move(estimates.samples);
    frame.depth = std::move(estimates.depth);
    frame.variance = std::move(estimates.variance);
    frame.halves = std::move(estimates.halves);
}

std::optional<PixelProbe> probe_pixel(const Snapshot& frame, int width, int height, int x, int y,
                                      const ToneSettings& tone, double linear_scale, DenoiseView view) {
    if (x < 0 || y < 0 || x >= width || y >= height || frame.radiance.width <= 0) return std::nullopt;
    PixelProbe p;
    p.x = x;
    p.y = y;
    // A preview covers the image with scale x scale blocks.
    const int px = std::min(x / frame.scale, frame.radiance.width - 1);
    const int py = std::min(y / frame.scale, frame.radiance.height - 1);
    p.mean = frame.radiance.at(px, py);
    const double scale = tone.tonemap == ToneMap::linear ? linear_scale : tone.exposure_scale();
    // The pixel of image A, as shown_radiance composes it: denoised in the "on" view, and in
    // the split view right of the middle column.
    const bool denoised = view != DenoiseView::off && frame.denoised.pixels.size() == frame.radiance.pixels.size() &&
                          (view == DenoiseView::on || px >= frame.radiance.width / 2);
    p.displayed = tonemap_color(denoised ? frame.denoised.at(px, py) : p.mean, tone.tonemap, scale);
    const size_t i = size_t(py) * size_t(frame.radiance.width) + size_t(px);
    p.preview = frame.scale != 1 || i >= frame.sample_count.size();
    if (!p.preview) {
        p.samples = frame.sample_count[i];
        p.standard_error = frame.standard_error[i];
    }
    return p;
}

std::string probe_line(const PixelProbe& p) {
    char line[256];
    if (p.earlier_view) {
        std::snprintf(line, sizeof line, "pixel %d, %d   (an earlier view on screen: this view's frame is coming)", p.x,
                      p.y);
        return line;
    }
    const int n = std::snprintf(line, sizeof line, "pixel %d, %d   radiance %.4g %.4g %.4g   shown %d %d %d", p.x, p.y,
                                p.mean.x, p.mean.y, p.mean.z, p.displayed[0], p.displayed[1], p.displayed[2]);
    if (n > 0 && size_t(n) < sizeof line && !p.preview && std::isfinite(p.standard_error))
        std::snprintf(line + n, sizeof line - size_t(n), "   %u samples, std. error %.3g", p.samples, p.standard_error);
    return line;
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

std::vector<float> hit_depths(const std::vector<double>& mean_depth, const std::vector<uint32_t>& samples) {
    std::vector<float> out(mean_depth.size(), INFINITY);
    for (size_t i = 0; i < out.size() && i < samples.size(); ++i) {
        const double n = samples[i];
        // One miss alone adds kMissDepth to the sum of n distances.
        if (n > 0 && mean_depth[i] * n < 0.5 * kMissDepth) out[i] = float(mean_depth[i]);
    }
    return out;
}

std::optional<DepthRange> depth_range(const std::vector<float>& hit_depth) {
    std::optional<DepthRange> r;
    for (const float d : hit_depth) {
        if (!std::isfinite(d)) continue;
        if (!r) r = DepthRange{d, d};
        r->near = std::min(r->near, d);
        r->far = std::max(r->far, d);
    }
    return r;
}

Rgb8Image depth_picture(const std::vector<float>& hit_depth, int width, int height, const DepthRange& range) {
    Rgb8Image out{width, height, std::vector<uint8_t>(size_t(width) * size_t(height) * 3, 0)};
    const double span = double(range.far) - double(range.near);
    for (size_t i = 0; i < hit_depth.size() && 3 * i < out.bytes.size(); ++i) {
        if (!std::isfinite(hit_depth[i])) continue;
        // Where the pixel sits between near (0) and far (1); one distance: all near.
        const double t = span > 0 ? (double(hit_depth[i]) - range.near) / span : 0.0;
        out.bytes[3 * i] = out.bytes[3 * i + 1] = out.bytes[3 * i + 2] = quantize_unit(1.0 - (1.0 - kDepthFarGrey) * t);
    }
    return out;
}

namespace {

// Per channel f(v) of 3 floats per pixel, 8-bit.
template <class F>
Rgb8Image layer_picture(const std::vector<float>& layer, int width, int height, F f) {
    Rgb8Image out{width, height, std::vector<uint8_t>(size_t(width) * size_t(height) * 3, 0)};
    for (size_t i = 0; i < layer.size() && i < out.bytes.size(); ++i) out.bytes[i] = quantize_unit(f(double(layer[i])));
    return out;
}

}  // namespace

Rgb8Image albedo_picture(const FeatureBuffers& features) {
    return layer_picture(features.albedo, features.width, features.height, [](double v) { return v; });
}

Rgb8Image normal_picture(const FeatureBuffers& features) {
    return layer_picture(features.normal, features.width, features.height, [](double v) { return v * 0.5 + 0.5; });
}

Rgb8Image upscale_blocks(const Rgb8Image& picture, int scale, int width, int height) {
    if (scale == 1 || picture.width <= 0 || picture.height <= 0) return picture;
    Rgb8Image out{width, height, std::vector<uint8_t>(size_t(width) * size_t(height) * 3)};
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const size_t from = size_t(std::min(y / scale, picture.height - 1)) * size_t(picture.width) +
                                size_t(std::min(x / scale, picture.width - 1));
            std::copy_n(&picture.bytes[3 * from], 3, &out.bytes[3 * (size_t(y) * size_t(width) + size_t(x))]);
        }
    return out;
}

FeaturePicture feature_picture(const Snapshot& frame, ViewMode mode, int width, int height) {
    FeaturePicture out;
    const std::string name(view_mode_names.name(mode));
    const int fw = frame.radiance.width, fh = frame.radiance.height;
    Rgb8Image picture;
    if (mode == ViewMode::depth) {
        if (frame.hit_depth.size() != size_t(fw) * size_t(fh)) {
            out.missing = "no depth in this frame";
            return out;
        }
        out.range = depth_range(frame.hit_depth);
        picture = out.range ? depth_picture(frame.hit_depth, fw, fh, *out.range)
                            : Rgb8Image{fw, fh, std::vector<uint8_t>(size_t(fw) * size_t(fh) * 3, 0)};
    } else if (is_feature_view(mode)) {
        const FeatureBuffers* f = frame.features.get();
        if (!f || f->width != fw || f->height != fh || f->albedo.size() != 3 * size_t(fw) * size_t(fh) ||
            f->normal.size() != f->albedo.size()) {
            out.missing = "no " + name + " in this frame";
            return out;
        }
        picture = mode == ViewMode::albedo ? albedo_picture(*f) : normal_picture(*f);
    } else {
        return out;
    }
    out.picture = upscale_blocks(picture, frame.scale, width, height);
    if (out.picture.width != width || out.picture.height != height) {
        out.picture = {};
        out.missing = "the frame is not of the image's size";
    }
    return out;
}

std::string feature_readout(const Snapshot& frame, ViewMode mode, int x, int y) {
    if (!is_feature_view(mode) || x < 0 || y < 0 || frame.radiance.width <= 0) return {};
    const int fw = frame.radiance.width, fh = frame.radiance.height;
    const size_t i = size_t(std::min(y / frame.scale, fh - 1)) * size_t(fw) + size_t(std::min(x / frame.scale, fw - 1));
    const std::string name(view_mode_names.name(mode));
    char text[96];
    if (mode == ViewMode::depth) {
        if (frame.hit_depth.size() != size_t(fw) * size_t(fh)) return name + ": not available";
        const float d = frame.hit_depth[i];
        if (!std::isfinite(d)) return "depth: no hit";
        std::snprintf(text, sizeof text, "depth %.4g", double(d));
        return text;
    }
    const FeatureBuffers* f = frame.features.get();
    const std::vector<float>* layer = f ? (mode == ViewMode::albedo ? &f->albedo : &f->normal) : nullptr;
    if (!layer || f->width != fw || f->height != fh || layer->size() != 3 * size_t(fw) * size_t(fh))
        return name + ": not available";
    std::snprintf(text, sizeof text, mode == ViewMode::albedo ? "albedo %.3f %.3f %.3f" : "normal %+.3f %+.3f %+.3f",
                  double((*layer)[3 * i]), double((*layer)[3 * i + 1]), double((*layer)[3 * i + 2]));
    return text;
}

}  // namespace kr::viewer
