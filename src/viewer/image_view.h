// Where the image sits in the window: fit to the free area (any factor, or whole pixels),
// or zoomed (up to 16x; the zoom levels from 1:1 up are whole, so pixels show as blocks) and panned. GL-free:
// the window and the tests place the image with the same functions.
#pragma once

namespace kr::viewer {

// Pixel rectangle in a framebuffer, origin at the top-left.
struct PixelRect {
    double x = 0, y = 0, width = 0, height = 0;
};

inline constexpr double kMaxZoom = 16;

class ImageView {
public:
    // Fit fills the free area by any factor; with whole_pixels, by a whole number of screen
    // pixels per image pixel when the image fits at 1:1 or more (blocks, no resampling).
    bool whole_pixels = false;
    // Screen pixels per image pixel: the fit scale, or the zoom.
    double scale(const PixelRect& area, int width, int height) const;
    bool fitted() const { return zoom_ == 0; }
    // The image's rectangle in the framebuffer (it may reach past `area`: the caller clips).
    // Its corner is on whole pixels, so at an integer zoom each image pixel is a block.
    PixelRect placement(const PixelRect& area, int width, int height) const;
    // Framebuffer point to image point (image pixels, fractional).
    void to_image(const PixelRect& area, int width, int height, double sx, double sy, double& ix, double& iy) const;

    // The next zoom level in (steps > 0) or out, keeping the image point under (sx, sy)
    // where it is; zooming out past the fit scale fits. Levels: 1/8 .. 3/4, then 1, 2, 3, 4,
    // 6, 8, 12, 16.
    void zoom_steps(const PixelRect& area, int width, int height, int steps, double sx, double sy);
    // A zoom of `zoom` (clamped to [fit, 16]) about the image point (ix, iy).
    void set_zoom(const PixelRect& area, int width, int height, double zoom, double ix, double iy);
    // Moves the image by (dx, dy) framebuffer pixels; some of it stays in view.
    void pan(const PixelRect& area, int width, int height, double dx, double dy);
    void fit() { zoom_ = 0; }
    // 1:1 about the centre of the view.
    void one_to_one(const PixelRect& area, int width, int height);

private:
    void clamp_centre(int width, int height);
    double fit_scale(const PixelRect& area, int width, int height) const;
    double zoom_ = 0;                     // 0: fit
    double centre_x_ = 0, centre_y_ = 0;  // image point at the area's centre when zoomed
};

}  // namespace kr::viewer
