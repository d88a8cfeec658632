#include "viewer/files.h"

#include <algorithm>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>

#include <unistd.h>

#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

namespace kr::viewer {

void write_png(const std::filesystem::path& path, const Rgb8Image& image) {
    namespace fs = std::filesystem;
    if (image.bytes.size() != static_cast<size_t>(image.width) * image.height * 3)
        throw std::runtime_error("write_png: image size does not match its pixel data");
    std::error_code ec;
    if (!path.parent_path().empty()) fs::create_directories(path.parent_path(), ec);
    const fs::path tmp = path.string() + ".tmp" + std::to_string(static_cast<long>(::getpid()));
    if (!stbi_write_png(tmp.c_str(), image.width, image.height, 3, image.bytes.data(), image.width * 3)) {
        fs::remove(tmp, ec);
        throw std::runtime_error("cannot write " + tmp.string());
    }
    fs::rename(tmp, path, ec);
    if (ec) {
        const std::string why = ec.message();
        fs::remove(tmp, ec);
        throw std::runtime_error("cannot rename " + tmp.string() + " to " + path.string() + ": " + why);
    }
}

namespace {
bool is_png_path(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext == ".png";
}
}  // namespace

Rgb8Image read_image(const std::filesystem::path& path) {
    // By content, not by name: a binary PPM starts with "P6", a PNG with its signature.
    char magic[2] = {};
    std::ifstream file(path, std::ios::binary);
    if (!file) throw std::runtime_error("cannot open " + path.string());
    file.read(magic, 2);
    if (magic[0] == 'P' && magic[1] == '6') return read_ppm(path);
    if (magic[0] != '\x89')
        throw std::runtime_error("cannot read " + path.string() + ": not a binary PPM (P6) or PNG image");
    int w = 0, h = 0, channels = 0;
    unsigned char* pixels = stbi_load(path.string().c_str(), &w, &h, &channels, 3);
    if (!pixels)
        throw std::runtime_error("cannot read " + path.string() + " as a PNG image: " + stbi_failure_reason());
    Rgb8Image img;
    img.width = w, img.height = h;
    img.bytes.assign(pixels, pixels + size_t(w) * size_t(h) * 3);
    stbi_image_free(pixels);
    return img;
}

void write_image(const std::filesystem::path& path, const Rgb8Image& image) {
    if (is_png_path(path)) write_png(path, image);
    else write_ppm(path, image);
}

std::vector<std::filesystem::path> list_scenes(const std::filesystem::path& dir) {
    std::vector<std::filesystem::path> found;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec))
        if (entry.path().extension() == ".json") found.push_back(entry.path());
    std::sort(found.begin(), found.end());
    return found;
}

std::vector<SceneChoice> scene_choices(const std::vector<std::filesystem::path>& folders) {
    namespace fs = std::filesystem;
    std::vector<SceneChoice> choices;
    std::vector<fs::path> seen;  // canonical paths already listed
    for (const fs::path& folder : folders) {
        for (const fs::path& file : list_scenes(folder)) {
            std::error_code ec;
            fs::path canonical = fs::weakly_canonical(file, ec);
            if (ec) canonical = fs::absolute(file, ec).lexically_normal();
            if (std::find(seen.begin(), seen.end(), canonical) != seen.end()) continue;
            seen.push_back(canonical);
            choices.push_back({file, file.filename().string()});
        }
    }
    // Tell apart equal names from different folders.
    for (SceneChoice& c : choices) {
        const auto same_name = std::count_if(choices.begin(), choices.end(), [&](const SceneChoice& o) {
            return o.path.filename() == c.path.filename();
        });
        if (same_name > 1) c.label += "  (" + c.path.parent_path().string() + ")";
    }
    return choices;
}

FileWatch::Stamp FileWatch::stamp() const {
    Stamp s;
    std::error_code ec;
    s.time = std::filesystem::last_write_time(file_, ec);
    if (ec) return {};
    s.size = std::filesystem::file_size(file_, ec);
    s.exists = !ec;
    return s;
}

void FileWatch::watch(const std::filesystem::path& file) {
    file_ = file;
    seen_ = stamp();
    last_poll_ = std::chrono::steady_clock::now();
}

void FileWatch::acknowledge() { seen_ = stamp(); }

bool FileWatch::changed(std::chrono::steady_clock::time_point now) {
    if (file_.empty() || now - last_poll_ < interval_) return false;
    last_poll_ = now;
    const Stamp s = stamp();
    // A file being replaced may be missing for a moment: wait for it to come back.
    if (!s.exists || s == seen_) return false;
    seen_ = s;
    return true;
}

}  // namespace kr::viewer
