#include "core/image_io.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <new>
#include <stdexcept>
#include <system_error>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/image_formats.h"

// Only the PNG decoder of stb_image is compiled in: the one format read besides PPM.
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_MAX_DIMENSIONS 32768
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

namespace fs = std::filesystem;

namespace kr {

namespace {

std::runtime_error read_error(const fs::path& path, const std::string& what) {
    return std::runtime_error("cannot read " + quoted_path(path) + ": " + what);
}

std::runtime_error out_of_memory(const fs::path& path, size_t width, size_t height) {
    return std::runtime_error("not enough memory for " + quoted_path(path) + ", a " + std::to_string(width) + "x" +
                              std::to_string(height) + " image");
}

void check_size(const Rgb8Image& image, const char* who) {
    if (image.width < 0 || image.height < 0 ||
        image.bytes.size() != static_cast<size_t>(image.width) * image.height * 3)
        throw std::runtime_error(std::string(who) + ": image size does not match its pixel data");
}

// Width and height as a header states them, checked against the reading limits.
void check_dimensions(const fs::path& path, uint64_t width, uint64_t height) {
    if (width < 1 || height < 1 || width > uint64_t(kMaxImageSide) || height > uint64_t(kMaxImageSide) ||
        width * height > kMaxImagePixels)
        throw read_error(path, "the header claims " + std::to_string(width) + "x" + std::to_string(height) +
                                   " pixels; images of 1 to " + std::to_string(kMaxImageSide) +
                                   " pixels a side and at most " + std::to_string(kMaxImagePixels) +
                                   " pixels are read");
}

}  // namespace

// The whole file, at most `limit` bytes of it. Pipes and other streams are read once, up to
// the same limit.
std::string read_image_bytes(const fs::path& path, uint64_t limit) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw read_error(path, std::error_code(errno, std::generic_category()).message());
    struct Closer {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};
    struct stat st {};
    if (::fstat(fd, &st) != 0 || S_ISDIR(st.st_mode)) throw read_error(path, "expected an image file, got a folder");
    if (S_ISREG(st.st_mode) && uint64_t(st.st_size) > limit)
        throw read_error(path, "the file is " + std::to_string(st.st_size) + " bytes; at most " +
                                   std::to_string(limit) + " are read");
    std::string bytes;
    try {
        if (S_ISREG(st.st_mode)) bytes.reserve(size_t(st.st_size));
        char chunk[1 << 16];
        for (;;) {
            const ssize_t n = ::read(fd, chunk, sizeof chunk);
            if (n < 0 && errno == EINTR) continue;
            if (n < 0) throw read_error(path, std::error_code(errno, std::generic_category()).message());
            if (n == 0) break;
            if (bytes.size() + size_t(n) > limit)
                throw read_error(path, "more than " + std::to_string(limit) + " bytes; that many are read at most");
            bytes.append(chunk, size_t(n));
        }
    } catch (const std::bad_alloc&) {
        throw std::runtime_error("not enough memory for " + quoted_path(path) + " (" +
                                 std::to_string(S_ISREG(st.st_mode) ? uint64_t(st.st_size) : uint64_t(bytes.size())) +
                                 " bytes)");
    }
    return bytes;
}

namespace {

Rgb8Image decode_ppm(const fs::path& path, const std::string& file) {
    // Header: magic, width, height, maxval, separated by whitespace and comments; then one
    // whitespace byte and the pixels.
    size_t at = 0;
    auto next_token = [&]() {
        for (;;) {
            while (at < file.size() && std::isspace(static_cast<unsigned char>(file[at]))) ++at;
            if (at < file.size() && file[at] == '#') {
                while (at < file.size() && file[at] != '\n') ++at;
                continue;
            }
            break;
        }
        const size_t start = at;
        while (at < file.size() && !std::isspace(static_cast<unsigned char>(file[at])) && file[at] != '#') ++at;
        return std::string_view(file).substr(start, at - start);
    };
    auto number = [&](const char* what) {
        const std::string_view token = next_token();
        uint64_t value = 0;
        if (token.empty() || token.size() > 9 ||
            !std::all_of(token.begin(), token.end(), [](char c) { return c >= '0' && c <= '9'; }))
            throw read_error(path, std::string("malformed PPM header: expected the ") + what + " as a number");
        for (char c : token) value = value * 10 + uint64_t(c - '0');
        return value;
    };
    if (next_token() != "P6") throw read_error(path, "not a binary PPM (P6)");
    const uint64_t width = number("width"), height = number("height"), maxval = number("maxval");
    if (maxval != 255) throw read_error(path, "only binary PPM (P6) with maxval 255 is read");
    check_dimensions(path, width, height);
    if (at >= file.size()) throw read_error(path, "truncated: the header ends without pixel data");
    ++at;  // the single whitespace byte after maxval
    const uint64_t needed = width * height * 3, present = file.size() - at;
    if (present < needed)
        throw read_error(path, "truncated: the header claims " + std::to_string(width) + "x" + std::to_string(height) +
                                   " pixels (" + std::to_string(needed) + " bytes), the file holds " +
                                   std::to_string(present));
    Rgb8Image image;
    try {
        image.bytes.assign(file.begin() + std::ptrdiff_t(at), file.begin() + std::ptrdiff_t(at + needed));
    } catch (const std::bad_alloc&) {
        throw out_of_memory(path, width, height);
    }
    image.width = int(width);
    image.height = int(height);
    return image;
}

uint32_t big_endian(const std::string& s, size_t at) {
    return uint32_t(uint8_t(s[at])) << 24 | uint32_t(uint8_t(s[at + 1])) << 16 | uint32_t(uint8_t(s[at + 2])) << 8 |
           uint32_t(uint8_t(s[at + 3]));
}

Rgb8Image decode_png(const fs::path& path, const std::string& file) {
    // The header chunk (IHDR) comes first: signature, length, "IHDR", width, height, bit
    // depth, colour type. Its claims are bounded before stb allocates anything.
    if (file.size() < 33 || file.compare(12, 4, "IHDR") != 0) throw read_error(path, "truncated or malformed PNG header");
    const uint64_t width = big_endian(file, 16), height = big_endian(file, 20);
    const unsigned bit_depth = uint8_t(file[24]), colour_type = uint8_t(file[25]);
    check_dimensions(path, width, height);
    const unsigned channels = colour_type == 2 ? 3 : colour_type == 4 ? 2 : colour_type == 6 ? 4 : 1;
    // Filtered scanlines: one filter byte plus the packed samples per row.
    const uint64_t raw_bytes = height * (1 + (width * channels * std::max(1u, bit_depth) + 7) / 8);
    constexpr uint64_t kDeflateMaxRatio = 1032;
    if (raw_bytes > kDeflateMaxRatio * file.size())
        throw read_error(path, "truncated: the header claims " + std::to_string(width) + "x" + std::to_string(height) +
                                   " pixels, more than " + std::to_string(file.size()) +
                                   " bytes of PNG can hold");
    int w = 0, h = 0, components = 0;
    unsigned char* pixels = stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(file.data()), int(file.size()),
                                                  &w, &h, &components, 3);
    if (!pixels) {
        const char* reason = stbi_failure_reason();
        if (reason && std::strcmp(reason, "outofmem") == 0) throw out_of_memory(path, width, height);
        throw read_error(path, std::string("not a valid PNG image (") + (reason ? reason : "unknown") + ")");
    }
    struct Freer {
        unsigned char* p;
        ~Freer() { stbi_image_free(p); }
    } freer{pixels};
    Rgb8Image image;
    try {
        image.bytes.assign(pixels, pixels + size_t(w) * size_t(h) * 3);
    } catch (const std::bad_alloc&) {
        throw out_of_memory(path, size_t(w), size_t(h));
    }
    image.width = w;
    image.height = h;
    return image;
}

}  // namespace

std::string encode_ppm(const Rgb8Image& image) {
    check_size(image, "encode_ppm");
    std::string bytes = "P6\n" + std::to_string(image.width) + ' ' + std::to_string(image.height) + "\n255\n";
    bytes.append(reinterpret_cast<const char*>(image.bytes.data()), image.bytes.size());
    return bytes;
}

std::string encode_png(const Rgb8Image& image) {
    check_size(image, "encode_png");
    std::string bytes;
    auto append = [](void* context, void* data, int size) {
        static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
    };
    if (!stbi_write_png_to_func(append, &bytes, image.width, image.height, 3, image.bytes.data(), image.width * 3))
        throw std::runtime_error("cannot encode a " + std::to_string(image.width) + "x" +
                                 std::to_string(image.height) + " image as PNG");
    return bytes;
}

std::string encode_image(const fs::path& path, const Rgb8Image& image) {
    return output_format(path).format == ImageFormat::png ? encode_png(image) : encode_ppm(image);
}

void write_ppm(const fs::path& path, const Rgb8Image& image) { write_file_atomic(path, encode_ppm(image)); }
void write_png(const fs::path& path, const Rgb8Image& image) { write_file_atomic(path, encode_png(image)); }
void write_image(const fs::path& path, const Rgb8Image& image) { write_file_atomic(path, encode_image(path, image)); }

Rgb8Image read_ppm(const fs::path& path) { return decode_ppm(path, read_image_bytes(path)); }

Rgb8Image read_image(const fs::path& path) { return decode_image(path, read_image_bytes(path)); }

Rgb8Image decode_image(const fs::path& path, const std::string& file) {
    // By content, not by name: a binary PPM starts with "P6", a PNG with its signature.
    if (file.size() > kMaxImageFileBytes)
        throw read_error(path, "the file is " + std::to_string(file.size()) + " bytes; at most " +
                                   std::to_string(kMaxImageFileBytes) + " are read");
    if (file.compare(0, 2, "P6") == 0) return decode_ppm(path, file);
    if (file.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0) return decode_png(path, file);
    throw read_error(path, "not a binary PPM (P6) or PNG image");
}

}  // namespace kr

