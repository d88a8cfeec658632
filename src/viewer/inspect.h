// What the window shows about single pixels and where the samples went, GL-free: the pixel
// inspector's readout, and the noise and sample-count maps of the noise view.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/image.h"
#include "render/progressive.h"
#include "viewer/edit.h"
#include "viewer/render_worker.h"

namespace kr::viewer {

// Copies the per-pixel statistics the inspector, the noise view and Save (the depth and
// variance layers, viewer/save_dialog.h) read from the running totals into a
// full-resolution snapshot.
void record_pixel_statistics(const RenderState& totals, Snapshot& frame);

// One pixel as the inspector shows it.
struct PixelProbe {
    int x = 0, y = 0;                  // image pixel, origin top-left
    Color mean;                        // mean radiance
    std::array<uint8_t, 3> displayed{};  // the 8-bit value the display shows (tone map, exposure)
    uint32_t samples = 0;              // samples accumulated (0 in a preview)
    double standard_error = 0;         // of the mean luminance; infinite below two samples
    bool preview = false;              // the frame is a low-resolution preview: no statistics
};

// The pixel (x, y) of `frame` (full-resolution coordinates; a preview's pixel covering it),
// or nothing outside the image. `linear_scale` is tonemap_scale() of the frame's radiance.
std::optional<PixelProbe> probe_pixel(const Snapshot& frame, int width, int height, int x, int y,
                                      const ToneSettings& tone, double linear_scale);

// The noise view: per pixel the standard error of the mean luminance, in false colour from 0
// to `scale` (pixels below two samples saturate); and the samples per pixel, from 0 to
// `scale`. Empty for a preview frame.
Rgb8Image standard_error_map(const Snapshot& frame, double scale);
Rgb8Image sample_count_map(const Snapshot& frame, double scale);

// A scale for a false-colour map: the q-quantile of the finite values (0 when none), so one
// firefly does not make the rest of the map dark.
double robust_scale(const std::vector<float>& values, double q = 0.99);

}  // namespace kr::viewer
