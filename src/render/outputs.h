// What a finished render writes, decided once for `keithray render` and the viewer's Save:
// the render's per-pixel estimates are developed (the box blur; the first-surface layers
// where the format holds them) and encoded into every file of one output, the format
// chosen by the output's name (core/image_formats.h). The caller commits the files together
// with write_files_atomic.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include "core/file_write.h"
#include "core/image.h"
#include "core/image_formats.h"
#include "render/aov.h"
#include "render/denoise.h"
#include "render/progressive.h"
#include "render/render_scene.h"
#include "scene/scene.h"

namespace kr {

// A render's per-pixel estimates as develop reads them: from a film's sums
// (render_estimates), or the viewer's copy of them in its snapshot. A layer left empty was
// not asked for.
struct RenderEstimates {
    Image radiance;                 // the mean radiance (compensated sums)
    std::vector<double> depth;      // the mean primary hit distance
    std::vector<uint32_t> samples;  // samples per pixel
    std::vector<Color> variance;    // the variance of the mean radiance (the layer's floats in develop)
    // The denoiser's feature buffers (render/aov.h averaged_surface_layers), where the caller
    // keeps them (the viewer's render thread makes them once per edit); develop makes them
    // when it denoises and they are empty.
    std::vector<float> albedo, normal;  // 3 per pixel
    // The two independent halves of each pixel's samples (Film::halves), where the film keeps
    // them: the final denoiser's guides. Empty: none.
    Film::Halves halves;
};
// The estimates of `film` (a RenderState's) for the layers `layers` asks for (RenderLayer
// bits); kLayerHalves: the halves, where the film tracks them.
RenderEstimates render_estimates(const Film& film, unsigned layers);

// How a render is developed into its images. A new step (a denoiser reading the albedo and
// normal layers) is one more option here and one more step in develop().
struct DevelopOptions {
    int blur = 0;  // box blur radius of the radiance (0: none)
    // The denoiser (render/denoise.h), after the blur; it reads the depth and the variance and
    // the feature buffers (and the halves, where the estimates have them).
    Denoise denoise = Denoise::off;
    // Which filter denoises: the final one (denoise_nlmeans: render, the viewer's Save) or,
    // where true, the interactive one (denoise_atrous: the viewer's live display).
    bool interactive = false;
    // The render's settings: the feature buffers' camera samples are drawn as its are.
    RenderSettings sampling;
    // The denoiser's planes, where the caller keeps them between develops (the viewer).
    DenoiseWorkspace* workspace = nullptr;
    // Set by another thread when the picture is no longer wanted (the viewer's frame of a view
    // an edit replaced): the interactive filter stops at its next pass and gives an empty image.
    const std::atomic<bool>* cancel = nullptr;
};
// The feature buffers' camera samples per pixel (render/aov.h averaged_surface_layers).
inline constexpr int kFeatureSamples = 8;
// A Whitted render is denoised (by the interactive filter only) below this mean spp.
inline constexpr double kWhittedRawSpp = 4;
// The denoiser's feature buffers of a width x height render with `sampling`'s camera
// samples: albedo and normal, 3 floats per pixel, as develop makes them (the viewer's
// albedo and normal views show them).
void feature_buffers(const RenderScene& scene, const RenderSettings& sampling, int width, int height,
                     std::vector<float>& albedo, std::vector<float>& normal);
// The feature buffers of the sums of `samples` camera samples a pixel (render/aov.h
// add_surface_samples): of kFeatureSamples, what feature_buffers makes, bit for bit.
void feature_buffers_from_sums(const SurfaceLayers& sums, int samples, std::vector<float>& albedo,
                               std::vector<float>& normal);
// The same for the pixels of `box` of a `width`-wide image, each of its own count of samples
// (render/aov.h add_surface_samples over a box); the others keep their entries (zero when new).
void feature_buffers_from_sums(const SurfaceLayers& sums, const std::vector<uint8_t>& counts, int width,
                               const PixelBox& box, std::vector<float>& albedo, std::vector<float>& normal);
// What the denoiser reads of `estimates` (their feature buffers filled) for the image
// `radiance` (the mean, or its blurred picture), with the halves where `with_halves`.
DenoiseInput denoise_input(const RenderEstimates& estimates, const Image& radiance, bool with_halves);
// The denoised picture of `radiance` (the estimates' mean, or its blurred picture) as develop
// makes it for `options` (denoise on): the estimates hold the feature buffers and the layers
// develop_reads names; nothing is copied.
Image denoised_image(const RenderEstimates& estimates, const Image& radiance, const DevelopOptions& options);
// The layers develop reads for `options` besides those of its output.
unsigned develop_reads(const DevelopOptions& options);

// A developed render: the images an output's files are encoded from. Empty layers are absent.
struct Developed {
    Image radiance;                // after the blur
    std::vector<double> depth;     // the mean primary hit distance
    std::vector<float> albedo;     // 3 per pixel (render/aov.h)
    std::vector<float> normal;     // 3 per pixel
    std::vector<uint32_t> samples;
    std::vector<float> variance;   // 3 per pixel; left out when blurred (not the blurred mean's)
    Image raw;                     // denoised: the radiance before the denoiser (after the blur)
};
// Develops `estimates` of a render of `scene` into `layers` (RenderLayer bits): blurs the
// radiance, denoises it, traces the first-surface layers where asked (when denoised: the
// feature buffers, averaged over each pixel's camera samples), and drops the variance of a
// blurred radiance.
Developed develop(const RenderScene& scene, RenderEstimates estimates, const DevelopOptions& options,
                  unsigned layers = kAllLayers);

// An 8-bit picture of the radiance for display settings: kr::tonemap by default; `render
// --gl` passes the viewer's display shader.
using ToneMapper = std::function<Rgb8Image(const Image& radiance, const DisplaySettings& display)>;

// Every file of the output named `path` (format: output_format), encoded from `image`: the
// radiance tone mapped with `display` (8-bit) or as floats, and the depth as a layer (EXR
// with every layer) or in the depth file beside it (the 8-bit depth map, or a PFM of the
// distances).
std::vector<FileOutput> encode_outputs(const std::filesystem::path& path, Developed image,
                                       const DisplaySettings& display, const ToneMapper& tone_map = {});

// One output of a finished render: develop for the format's layers, then encode_outputs.
struct OutputRequest {
    std::filesystem::path path;
    DevelopOptions develop;
    DisplaySettings display;
    ToneMapper tone_map;  // empty: kr::tonemap
};
std::vector<FileOutput> output_files(const RenderScene& scene, RenderEstimates estimates, const OutputRequest& request);
std::vector<FileOutput> output_files(const RenderScene& scene, const RenderState& state, const OutputRequest& request);

// The HDR image of a developed render (its layers as floats).
HdrImage hdr_from_developed(Developed image);

// An upper estimate of the memory a render of width x height pixels holds at its peak: the
// RenderState (kRenderStateBytesPerPixel), then at the end the mean radiance (and, when
// blurred, two more radiance images), the mean depth, and the larger output stage: the two
// 8-bit images and their encoded bytes, or an EXR's 14 float layers and its encoded bytes.
// A denoised render adds its halves (film.h: kHalvesBytesPerPixel), its feature buffers and the
// denoiser's working images (render/denoise.h: kDenoiseBytesPerPixel).
uint64_t render_memory_bytes(int width, int height, bool blurred, bool denoised = false);

}  // namespace kr
