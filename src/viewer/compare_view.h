// The window's A/B comparison, GL-free: image B (a reference file or a kept snapshot of the
// render), the view modes, and the figures and false-colour pictures of A against B, so the
// tests compute what the window shows.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/enum_names.h"
#include "core/image.h"
#include "viewer/edit.h"

namespace kr::viewer {

// What the image area shows: the render (A), image B, A left of a divider and B right of
// it, the error of A against B, the render's noise: per-pixel standard error, samples; or
// the first-surface feature layers (viewer/inspect.h): albedo, normal, depth.
enum class ViewMode { render, reference, split, error, noise, samples, albedo, normal, depth };
inline constexpr EnumNames<ViewMode, 9> view_mode_names{
    {"render", "reference", "split", "error", "noise", "samples", "albedo", "normal", "depth"}};
// The views of the feature layers, which the render thread makes only while one is shown.
inline bool is_feature_view(ViewMode mode) {
    return mode == ViewMode::albedo || mode == ViewMode::normal || mode == ViewMode::depth;
}

// Per pixel, over the channels of the 8-bit values in [0, 1]: RMS of a - b, or of
// (a - b) / (b + 0.01) (relative; the 0.01 keeps black pixels from dominating).
enum class ErrorMetric { absolute, relative };
inline constexpr EnumNames<ErrorMetric, 2> error_metric_names{{"absolute", "relative"}};

// Image B: a reference read from a file or a snapshot of the render kept in a slot.
struct CompareImage {
    std::string name;  // the file name, or "slot 2 (64 spp, denoised)"
    Image radiance;    // an HDR file or a snapshot: tone mapped as the render is
    Rgb8Image bytes;   // an 8-bit file (PPM, PNG): shown as stored
    bool hdr() const { return !radiance.pixels.empty(); }
    int width() const { return hdr() ? radiance.width : bytes.width; }
    int height() const { return hdr() ? radiance.height : bytes.height; }
    // As displayed with the render's tone settings.
    Rgb8Image display(const ToneSettings& tone) const;
};

// Reads a reference: PPM or PNG (8-bit), OpenEXR or PFM (radiance). Throws
// std::runtime_error naming the file and what was expected.
CompareImage load_reference(const std::filesystem::path& path);

// The brief's reference render offered for a brief scene: for .../scenes/NAME.json, the file
// .../references/NAME.ppm when it exists.
std::optional<std::filesystem::path> brief_reference_for(const std::filesystem::path& scene);

// A against B on the 8-bit images: PSNR as `keithray psnr` computes it, and RMSE of the
// values in [0, 1]. Nothing when the sizes differ.
struct CompareFigures {
    double psnr = 0, rmse = 0;
    bool identical = false;  // no pixel differs (kr::psnr's 99 dB stands for it in files)
};
std::optional<CompareFigures> compare_figures(const Rgb8Image& a, const Rgb8Image& b);
// The PSNR as the window says it: "31.72 dB", or "identical" for equal images.
std::string format_psnr(const CompareFigures& figures);

// Per pixel, the error of a against b (same size) by `metric`.
std::vector<float> pixel_errors(const Rgb8Image& a, const Rgb8Image& b, ErrorMetric metric);

// What the compare controls hold; `b` picks image B: -1 the reference, k slot k.
inline constexpr int kSnapshotSlots = 8;
struct CompareSettings {
    ViewMode mode = ViewMode::render;
    ErrorMetric metric = ErrorMetric::absolute;
    double split = 0.5;        // fraction of the image's width left of the divider (A)
    double error_scale = 0;    // top of the colour bar; 0: the 99th percentile of the errors
    int b = -1;
};

class Comparison {
public:
    CompareSettings settings;

    void set_reference(CompareImage image) { reference_ = std::move(image); }
    void clear_reference() { reference_.reset(); }
    const std::optional<CompareImage>& reference() const { return reference_; }
    // Keeps `radiance` (image A as shown, `shown` naming it: "raw", "denoised", "split") in a
    // free slot (the oldest is replaced when all are full); its index.
    int keep(const Image& radiance, int spp, std::string_view shown = "raw");
    void drop(int slot);
    const std::vector<std::optional<CompareImage>>& slots() const { return slots_; }
    // Image B as settings.b picks it (null when that is empty).
    const CompareImage* b() const;

private:
    std::optional<CompareImage> reference_;
    std::vector<std::optional<CompareImage>> slots_ = std::vector<std::optional<CompareImage>>(kSnapshotSlots);
    int next_slot_ = 0;
};

}  // namespace kr::viewer
