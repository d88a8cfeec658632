// Image files: 8-bit RGB as binary PPM (P6) or PNG (stb from Debian's libstb), chosen by
// the name when writing and by the content when reading. Every write goes through
// write_files_atomic (core/file_write.h); every read is bounded.
//
// Reading limits (kMaxImageSide, kMaxImagePixels, kMaxImageFileBytes): an image of at most
// 32768 pixels a side and 2^28 pixels (16384 x 16384), from a file of at most 769 MiB. A
// header is checked against the file's size before any pixel memory is taken: a PPM must
// hold every pixel byte its header claims, and a PNG's pixels must fit within deflate's
// largest ratio (1032:1) of the file. Errors are std::runtime_error, one line naming the
// file; running out of memory says "not enough memory for ..." with the file.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include "core/file_write.h"
#include "core/image.h"

namespace kr {

inline constexpr int kMaxImageSide = 32768;
inline constexpr size_t kMaxImagePixels = size_t(1) << 28;
inline constexpr size_t kMaxImageFileBytes = 3 * kMaxImagePixels + (size_t(1) << 20);

// The file's bytes of each format.
std::string encode_ppm(const Rgb8Image& image);
std::string encode_png(const Rgb8Image& image);
// PNG when the path ends in .png (any case), otherwise binary PPM (core/image_formats.h).
std::string encode_image(const std::filesystem::path& path, const Rgb8Image& image);

// One file, written atomically (write_file_atomic). Throw std::runtime_error.
void write_ppm(const std::filesystem::path& path, const Rgb8Image& image);
void write_png(const std::filesystem::path& path, const Rgb8Image& image);
void write_image(const std::filesystem::path& path, const Rgb8Image& image);  // by name

// A binary PPM (P6, maxval 255), or either format told apart by its first bytes whatever
// the file's name. Throw std::runtime_error naming the file.
Rgb8Image read_ppm(const std::filesystem::path& path);
Rgb8Image read_image(const std::filesystem::path& path);
// The two steps of read_image: the file's bytes, read once (a pipe or FIFO too, up to
// `limit`; a regular file larger than it is refused by its size), and the image they hold.
std::string read_image_bytes(const std::filesystem::path& path, uint64_t limit = kMaxImageFileBytes);
Rgb8Image decode_image(const std::filesystem::path& path, const std::string& bytes);

}  // namespace kr
