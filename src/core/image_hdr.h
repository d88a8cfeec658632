// High-dynamic-range images: OpenEXR (through libopenexr's C++ API) and PFM, encoded to and
// decoded from bytes in memory, with the render's auxiliary layers (AOVs).
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "core/image.h"

namespace kr {

// A render's float image and its layers, row-major, top row first. A layer whose vector is
// empty is absent (a file without it, or a render that did not make it).
struct HdrImage {
    int width = 0, height = 0;
    std::vector<float> rgb;           // mean radiance, 3 per pixel
    std::vector<float> depth;         // mean primary hit distance; misses count as kMissDepth (1e6)
    std::vector<float> albedo;        // 3 per pixel: reflectance of the first non-specular hit
    std::vector<float> normal;        // 3 per pixel: its unit normal facing the ray, world space
    std::vector<uint32_t> samples;    // samples accumulated per pixel
    std::vector<float> variance;      // 3 per pixel: variance of the mean radiance (inf: < 2 samples)
    std::vector<float> raw;           // 3 per pixel: the radiance before denoising (rgb is denoised)

    size_t pixel_count() const { return static_cast<size_t>(width) * static_cast<size_t>(height); }
    Image radiance() const;  // rgb as an Image of doubles
};

// The largest image read or written: each side, and the pixel count (2^26, 768 MiB of RGB floats).
inline constexpr int kMaxHdrSide = 1 << 16;
inline constexpr size_t kMaxHdrPixels = size_t(1) << 26;

// A double as the files' 32-bit float: a finite value beyond float's range is clamped to
// its largest (a finite mean stays finite, so an image equals itself); an infinite value (an
// unknown variance) or a NaN stays what it is.
inline float stored_float(double v) {
    constexpr double kMax = std::numeric_limits<float>::max();
    return static_cast<float>(v > kMax && v <= std::numeric_limits<double>::max() ? kMax
                              : v < -kMax && v >= -std::numeric_limits<double>::max() ? -kMax
                                                                                        : v);
}
std::vector<float> stored_floats(const std::vector<double>& values);

// The HDR image of `radiance` alone (no other layer).
HdrImage hdr_from_radiance(const Image& radiance);

// OpenEXR bytes: R, G, B (32-bit float, ZIP compressed), then every present layer:
// depth.Z, albedo.R/G/B, normal.X/Y/Z, samples (32-bit unsigned), variance.R/G/B, raw.R/G/B.
// Throws std::invalid_argument if a layer's size does not match the image.
std::string encode_exr(const HdrImage& image);
// Decodes an OpenEXR file's bytes; `name` (the file) starts every error. Needs R, G and B;
// reads the other layers above where present (all three channels of a layer, or an error).
// Throws std::runtime_error with one line naming the file and what was expected.
HdrImage decode_exr(const std::string& bytes, const std::string& name);

// PFM bytes: "PF" (3 channels) of the radiance, or "Pf" of one channel, little-endian, rows
// bottom first as the format has them.
std::string encode_pfm_rgb(const HdrImage& image);
std::string encode_pfm_gray(const std::vector<float>& values, int width, int height);
// Decodes a PFM: a "PF" file fills rgb; a "Pf" one fills rgb with its grey value in all three
// channels and depth with the value itself. Strict: the header's sizes must give exactly the
// file's length. Throws std::runtime_error naming the file.
HdrImage decode_pfm(const std::string& bytes, const std::string& name);

// The largest HDR file read: an image within the limits with room for its headers.
inline constexpr uint64_t kMaxHdrFileBytes = uint64_t(kMaxHdrPixels) * 64 + (uint64_t(1) << 20);

// Whether `bytes` start like an OpenEXR or a PFM file.
bool is_hdr_bytes(const std::string& bytes);
// Reads an OpenEXR or PFM file (once: a pipe or FIFO too), told apart by their first bytes.
// Throws std::runtime_error naming the file.
HdrImage read_hdr(const std::filesystem::path& path);
// The image in an OpenEXR's or PFM's bytes; `name` (the file) starts every error.
HdrImage decode_hdr(const std::string& bytes, const std::string& name);

}  // namespace kr
