#include "core/image_formats.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/file_write.h"
#include "core/image_io.h"
#include "core/text.h"

namespace kr {

const ImageFormatInfo& format_info(ImageFormat format) {
    for (const ImageFormatInfo& f : kImageFormats)
        if (f.format == format) return f;
    return kImageFormats[0];
}

namespace {

// `path`'s extension in lower case, with its dot.
std::string lower_extension(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

}  // namespace

const ImageFormatInfo* format_by_extension(const std::filesystem::path& path) {
    const std::string ext = lower_extension(path);
    for (const ImageFormatInfo& f : kImageFormats)
        if (ext == f.extension) return &f;
    return nullptr;
}

const ImageFormatInfo& output_format(const std::filesystem::path& path) {
    const ImageFormatInfo* f = format_by_extension(path);
    return f ? *f : format_info(ImageFormat::ppm);
}

void check_output_extension(const std::filesystem::path& path) {
    struct Other {
        const char* extension;
        const char* name;
    };
    static constexpr Other kOthers[] = {{".jpg", "JPEG"}, {".jpeg", "JPEG"}, {".tif", "TIFF"}, {".tiff", "TIFF"},
                                        {".bmp", "BMP"},  {".gif", "GIF"},   {".webp", "WebP"}, {".hdr", "Radiance HDR"},
                                        {".tga", "TGA"},  {".pgm", "PGM"},   {".pnm", "PNM"},   {".jxl", "JPEG XL"}};
    const std::string ext = lower_extension(path);
    for (const Other& o : kOthers)
        if (ext == o.extension)
            throw std::runtime_error(quoted_path(path) + ": a " + o.name +
                                     " name; keithray writes .ppm, .png, .exr or .pfm images (a name without one of "
                                     "these extensions gets a PPM)");
}

std::vector<std::filesystem::path> output_file_paths(const std::filesystem::path& path) {
    std::vector<std::filesystem::path> paths{path};
    if (output_format(path).depth_beside) paths.push_back(depth_path_for(path));
    return paths;
}

ImageFile read_image_file(const std::filesystem::path& path) {
    // Read once, then told apart by the first bytes: a pipe or FIFO cannot be opened twice.
    const std::string bytes = read_image_bytes(path, std::max<uint64_t>(kMaxHdrFileBytes, kMaxImageFileBytes));
    ImageFile file;
    file.hdr = is_hdr_bytes(bytes);
    if (file.hdr) {
        file.radiance = decode_hdr(bytes, path.string());
        // A NaN or an infinity is no radiance: compared, it would pass as agreement with anything.
        const std::vector<float>& rgb = file.radiance.rgb;
        const auto bad = std::find_if(rgb.begin(), rgb.end(), [](float v) { return !std::isfinite(v); });
        if (bad != rgb.end()) {
            const size_t pixel = size_t(bad - rgb.begin()) / 3, w = size_t(file.radiance.width);
            const size_t count = size_t(std::count_if(rgb.begin(), rgb.end(), [](float v) { return !std::isfinite(v); }));
            throw std::runtime_error(show_user_text(path.string()) + ": " + std::to_string(count) +
                                     " radiance values are not finite, the first " + (std::isnan(*bad) ? "NaN" : "infinite") +
                                     " at pixel (" + std::to_string(pixel % w) + ", " + std::to_string(pixel / w) +
                                     "); expected finite numbers");
        }
    } else {
        file.rgb8 = decode_image(path, bytes);
    }
    return file;
}

}  // namespace kr
