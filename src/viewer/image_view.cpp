#include "viewer/image_view.h"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace kr::viewer {

namespace {

constexpr double kLevels[] = {0.125, 0.25, 0.5, 0.75, 1, 2, 3, 4, 6, 8, 12, 16};

}  // namespace

double ImageView::fit_scale(const PixelRect& area, int width, int height) const {
    const double s = std::min(std::max(1.0, area.width) / width, std::max(1.0, area.height) / height);
    return whole_pixels && s >= 1 ? std::floor(s) : s;
}

double ImageView::scale(const PixelRect& area, int width, int height) const {
    return zoom_ > 0 ? zoom_ : fit_scale(area, width, height);
}

PixelRect ImageView::placement(const PixelRect& area, int width, int height) const {
    if (width <= 0 || height <= 0) return {};
    const double s = scale(area, width, height);
    const double w = width * s, h = height * s;
    if (zoom_ == 0) return {area.x + std::floor((area.width - w) / 2), area.y + std::floor((area.height - h) / 2), w, h};
    return {std::floor(area.x + area.width / 2 - centre_x_ * s), std::floor(area.y + area.height / 2 - centre_y_ * s), w, h};
}

void ImageView::to_image(const PixelRect& area, int width, int height, double sx, double sy, double& ix,
                         double& iy) const {
    const PixelRect r = placement(area, width, height);
    const double s = scale(area, width, height);
    ix = (sx - r.x) / s;
    iy = (sy - r.y) / s;
}

void ImageView::set_zoom(const PixelRect& area, int width, int height, double zoom, double ix, double iy) {
    const double fit = fit_scale(area, width, height);
    if (!(zoom > fit)) {
        zoom_ = 0;
        return;
    }
    // Keep (ix, iy) where it is on screen: its offset from the area's centre scales with the zoom.
    double sx = 0, sy = 0;
    {
        const PixelRect r = placement(area, width, height);
        const double s = scale(area, width, height);
        sx = r.x + ix * s;
        sy = r.y + iy * s;
    }
    zoom_ = std::min(zoom, kMaxZoom);
    centre_x_ = ix - (sx - (area.x + area.width / 2)) / zoom_;
    centre_y_ = iy - (sy - (area.y + area.height / 2)) / zoom_;
    clamp_centre(width, height);
}

void ImageView::zoom_steps(const PixelRect& area, int width, int height, int steps, double sx, double sy) {
    double ix = 0, iy = 0;
    to_image(area, width, height, sx, sy, ix, iy);
    double s = scale(area, width, height);
    for (; steps > 0; --steps) {
        const double* next = std::upper_bound(std::begin(kLevels), std::end(kLevels), s + 1e-9);
        s = next == std::end(kLevels) ? kMaxZoom : *next;
    }
    for (; steps < 0; ++steps) {
        const double* below = std::lower_bound(std::begin(kLevels), std::end(kLevels), s - 1e-9);
        s = below == std::begin(kLevels) ? 0 : *(below - 1);
    }
    set_zoom(area, width, height, s, ix, iy);
}

void ImageView::pan(const PixelRect& area, int width, int height, double dx, double dy) {
    if (zoom_ == 0) {
        // Panning a fitted image starts a zoom at the fit scale about its centre.
        const double s = scale(area, width, height);
        if (s * width <= area.width && s * height <= area.height) return;  // nothing hidden
        zoom_ = s;
        centre_x_ = width / 2.0;
        centre_y_ = height / 2.0;
    }
    centre_x_ -= dx / zoom_;
    centre_y_ -= dy / zoom_;
    clamp_centre(width, height);
}

void ImageView::one_to_one(const PixelRect& area, int width, int height) {
    double ix = 0, iy = 0;
    to_image(area, width, height, area.x + area.width / 2, area.y + area.height / 2, ix, iy);
    zoom_ = 1;
    centre_x_ = ix;
    centre_y_ = iy;
    clamp_centre(width, height);
}

void ImageView::clamp_centre(int width, int height) {
    // The centre stays on the image, so the view always shows some of it.
    centre_x_ = std::clamp(centre_x_, 0.0, double(width));
    centre_y_ = std::clamp(centre_y_, 0.0, double(height));
}

}  // namespace kr::viewer
