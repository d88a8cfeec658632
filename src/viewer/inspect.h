// What the window shows about single pixels and where the samples went, GL-free: the pixel
// inspector's readout, the noise and sample-count maps of the noise views, and the pictures
// of the feature views (albedo, normal, depth).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string>
#include <vector>

#include "core/image.h"
#include "render/outputs.h"
#include "render/progressive.h"
#include "viewer/compare_view.h"
#include "viewer/edit.h"
#include "viewer/model.h"  // DenoiseView
#include "viewer/render_worker.h"

namespace kr::viewer {

// Copies the per-pixel statistics the inspector, the noise view and Save (the depth and
// variance layers, viewer/save_dialog.h) read from the running totals into a
// full-resolution snapshot.
void record_pixel_statistics(const RenderState& totals, Snapshot& frame);
// The same with the totals' estimates already taken (render/outputs.h render_estimates with
// the depth, samples and variance layers), which it moves into the frame.
void record_pixel_statistics(const RenderState& totals, RenderEstimates estimates, Snapshot& frame);

// One pixel as the inspector shows it.
struct PixelProbe {
    int x = 0, y = 0;                  // image pixel, origin top-left
    Color mean;                        // mean radiance
    std::array<uint8_t, 3> displayed{};  // the 8-bit value the display shows: image A's pixel
                                         // (denoised where the view shows it), tone mapped
    uint32_t samples = 0;              // samples accumulated (0 in a preview)
    double standard_error = 0;         // of the mean luminance; infinite below two samples
    bool preview = false;              // the frame is a low-resolution preview: no statistics
    bool earlier_view = false;         // the frame is of an earlier view (the camera moved since):
                                       // not this view's pixel (set by the caller, who knows)
};

// The probe as one line (the status bar's): pixel, radiance, shown value, and its samples and
// standard error where the frame has them; a frame of an earlier view gives no figures, it
// says that this view's frame is coming.
std::string probe_line(const PixelProbe& p);

// The pixel (x, y) of `frame` (full-resolution coordinates; a preview's pixel covering it),
// or nothing outside the image. Its mean is the raw estimate's; its displayed value is that
// of the image shown under `view` (status.h shown_radiance). `linear_scale` is
// tonemap_scale() of that image.
std::optional<PixelProbe> probe_pixel(const Snapshot& frame, int width, int height, int x, int y,
                                      const ToneSettings& tone, double linear_scale,
                                      DenoiseView view = DenoiseView::off);

// The noise view: per pixel the standard error of the mean luminance, in false colour from 0
// to `scale` (pixels below two samples saturate); and the samples per pixel, from 0 to
// `scale`. Empty for a preview frame.
Rgb8Image standard_error_map(const Snapshot& frame, double scale);
Rgb8Image sample_count_map(const Snapshot& frame, double scale);

// The feature views (albedo, normal, depth). Per pixel of mean depths over `samples`
// samples each: the mean where every sample hit, infinite where one missed (a miss counts
// as kMissDepth in the mean, so a mean of at least kMissDepth / (2 n) has one, for hits
// nearer than that) or the pixel has none.
std::vector<float> hit_depths(const std::vector<double>& mean_depth, const std::vector<uint32_t>& samples);
// The nearest and farthest finite hit distance (none when no pixel hit).
struct DepthRange {
    float near = 0, far = 0;
};
std::optional<DepthRange> depth_range(const std::vector<float>& hit_depth);
// Grey from white at range.near to kDepthFarGrey at range.far; black where nothing was hit.
inline constexpr double kDepthFarGrey = 0.125;  // 32 of 255, apart from the misses' black
Rgb8Image depth_picture(const std::vector<float>& hit_depth, int width, int height, const DepthRange& range);
// The albedo clamped to [0, 1], and the normal n as n * 0.5 + 0.5 (a miss's zero normal is
// mid-grey), 8-bit as the display shows them.
Rgb8Image albedo_picture(const FeatureBuffers& features);
Rgb8Image normal_picture(const FeatureBuffers& features);
// A picture of a 1/scale preview as the display shows the preview: scale x scale blocks,
// cut to width x height.
Rgb8Image upscale_blocks(const Rgb8Image& picture, int scale, int width, int height);

// What a feature view shows of `frame`: the picture at the image's size (a preview's in
// blocks), the depth's range, or why there is none (`missing`).
struct FeaturePicture {
    Rgb8Image picture;
    std::optional<DepthRange> range;
    std::string missing;
};
FeaturePicture feature_picture(const Snapshot& frame, ViewMode mode, int width, int height);
// The pixel inspector's words for the feature view `mode` at image pixel (x, y) of `frame`
// (full-resolution coordinates): "albedo R G B", "normal X Y Z", "depth D" or "depth: no
// hit"; "MODE: not available" without the layer; empty for another view or outside.
std::string feature_readout(const Snapshot& frame, ViewMode mode, int x, int y);

// A scale for a false-colour map: the q-quantile of the finite values (0 when none), so one
// firefly does not make the rest of the map dark.
double robust_scale(const std::vector<float>& values, double q = 0.99);

}  // namespace kr::viewer
