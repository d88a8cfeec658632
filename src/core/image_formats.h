// The image file formats in one table: the extension that names each, whether it holds the
// radiance as floats (HDR) or tone mapped to 8 bits, which of a render's layers an output
// in it holds and where its depth goes. `keithray render -o`, the viewer's Save,
// `psnr`/`compare` and the viewer's image B all go by it; the render's side (developing a
// render and encoding its files) is render/outputs.h.
#pragma once

#include <array>
#include <filesystem>
#include <vector>

#include "core/image.h"
#include "core/image_hdr.h"

namespace kr {

enum class ImageFormat { ppm, png, exr, pfm };

// The layers of a render an output can hold (bits of ImageFormatInfo::layers).
enum RenderLayer : unsigned {
    kLayerRadiance = 1u << 0,  // the mean radiance (blurred where asked)
    kLayerDepth = 1u << 1,     // the mean primary hit distance
    kLayerAlbedo = 1u << 2,    // the first non-specular surface's albedo (render/aov.h)
    kLayerNormal = 1u << 3,    // and its normal
    kLayerSamples = 1u << 4,   // samples per pixel
    kLayerVariance = 1u << 5,  // the variance of the mean radiance (left out of a blurred render)
    // Not a file's: the two halves of each pixel's samples, which the final denoiser reads
    // (render/outputs.h render_estimates, develop_reads).
    kLayerHalves = 1u << 6,
};
inline constexpr unsigned kAllLayers =
    kLayerRadiance | kLayerDepth | kLayerAlbedo | kLayerNormal | kLayerSamples | kLayerVariance;

struct ImageFormatInfo {
    ImageFormat format;
    const char* extension;  // lower case, with its dot; matched in any case
    const char* name;       // in messages
    bool hdr;               // the radiance as 32-bit floats; else 8-bit RGB, tone mapped
    unsigned layers;        // what an output of a render in this format holds
    bool depth_beside;      // the depth goes to NAME-depth.EXT in the same format (else a layer)
};

// Writing each: render/outputs.cpp (encode_outputs); reading: read_image (8-bit) and read_hdr
// (HDR), which tell the formats of a kind apart by their first bytes.
inline constexpr std::array<ImageFormatInfo, 4> kImageFormats{{
    {ImageFormat::ppm, ".ppm", "PPM", false, kLayerRadiance | kLayerDepth, true},
    {ImageFormat::png, ".png", "PNG", false, kLayerRadiance | kLayerDepth, true},
    {ImageFormat::exr, ".exr", "OpenEXR", true, kAllLayers, false},
    {ImageFormat::pfm, ".pfm", "PFM", true, kLayerRadiance | kLayerDepth, true},
}};

const ImageFormatInfo& format_info(ImageFormat format);
// The format whose extension `path` has (any case), or null when it has none of them.
const ImageFormatInfo* format_by_extension(const std::filesystem::path& path);
// What an image written to `path` is: its extension's format, binary PPM for any other name.
const ImageFormatInfo& output_format(const std::filesystem::path& path);
// Throws std::runtime_error when `path` names an image format keithray does not write
// (.jpg, .tiff, .hdr, ...): a PPM under that name would not be what the name says.
void check_output_extension(const std::filesystem::path& path);
// Every file one output named `path` writes: `path`, then its depth file where the format
// puts the depth beside it (depth_path_for).
std::vector<std::filesystem::path> output_file_paths(const std::filesystem::path& path);

// An image file as read, whatever its name: the radiance of an HDR one (`hdr`), or the
// pixels of an 8-bit one.
struct ImageFile {
    bool hdr = false;
    HdrImage radiance;  // hdr: OpenEXR (with its layers) or PFM
    Rgb8Image rgb8;     // else: PPM or PNG
    int width() const { return hdr ? radiance.width : rgb8.width; }
    int height() const { return hdr ? radiance.height : rgb8.height; }
};
// Reads any format of the table, told apart by its first bytes. Throws std::runtime_error
// naming the file.
ImageFile read_image_file(const std::filesystem::path& path);

}  // namespace kr
