#include "core/image.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include <unistd.h>

namespace kr {

uint8_t quantize_unit(double v) {
    if (!(v > 0)) return 0;  // also maps NaN to 0
    if (v >= 1) return 255;
    return static_cast<uint8_t>(std::lround(v * 255.0));
}

Rgb8Image tonemap(const Image& radiance, ToneMap op, double exposure) {
    Rgb8Image out{radiance.width, radiance.height, {}};
    out.bytes.resize(radiance.pixels.size() * 3);
    double scale = exposure;
    if (op == ToneMap::linear) {
        double max_value = 0;
        for (const Color& c : radiance.pixels)
            if (is_finite(c)) max_value = std::max(max_value, max_component(c));
        scale = max_value > 0 ? 1.0 / max_value : 0.0;  // exposure cancels in I / max(I)
    }
    for (size_t i = 0; i < radiance.pixels.size(); ++i) {
        const Color c = radiance.pixels[i] * scale;
        for (int k = 0; k < 3; ++k) {
            const double v = c[k];
            out.bytes[3 * i + k] = quantize_unit(op == ToneMap::sigmoid ? sigmoid_tonemap(v) : v);
        }
    }
    return out;
}

Image box_blur(const Image& src, int radius) {
    if (radius <= 0 || src.pixels.empty()) return src;
    // Two 1-D passes of a running sum; at the borders the box shrinks to the image.
    auto pass = [radius](const Image& in, bool horizontal) {
        Image out(in.width, in.height);
        const int n = horizontal ? in.width : in.height;
        const int lines = horizontal ? in.height : in.width;
        for (int line = 0; line < lines; ++line) {
            auto px = [&](int i) -> const Color& {
                return horizontal ? in.at(i, line) : in.at(line, i);
            };
            for (int i = 0; i < n; ++i) {
                const int lo = std::max(0, i - radius), hi = std::min(n - 1, i + radius);
                Color sum;
                for (int j = lo; j <= hi; ++j) sum += px(j);
                (horizontal ? out.at(i, line) : out.at(line, i)) = sum / double(hi - lo + 1);
            }
        }
        return out;
    };
    return pass(pass(src, true), false);
}

Rgb8Image depth_to_rgb8(const std::vector<double>& depth, int width, int height) {
    Rgb8Image out{width, height, std::vector<uint8_t>(depth.size() * 3)};
    for (size_t i = 0; i < depth.size(); ++i) {
        const double d = std::max(0.0, depth[i]);
        const uint8_t g = quantize_unit(1.0 - d / (1.0 + d));
        out.bytes[3 * i] = out.bytes[3 * i + 1] = out.bytes[3 * i + 2] = g;
    }
    return out;
}

void write_file_atomic(const std::filesystem::path& path, const std::string& bytes) {
    const std::filesystem::path dir = path.parent_path();
    std::error_code ec;
    if (!dir.empty()) std::filesystem::create_directories(dir, ec);
    // Unique temporary name beside the target, so the rename is atomic on one file system.
    const std::filesystem::path tmp =
        path.string() + ".tmp" + std::to_string(static_cast<long>(::getpid()));
    {
        std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
        if (!f) throw std::runtime_error("cannot write " + tmp.string());
        f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        f.flush();
        if (!f) {
            f.close();
            std::filesystem::remove(tmp, ec);
            throw std::runtime_error("cannot write " + tmp.string());
        }
    }
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        std::filesystem::remove(tmp, ec);
        throw std::runtime_error("cannot rename temporary file onto " + path.string());
    }
}

void write_ppm(const std::filesystem::path& path, const Rgb8Image& image) {
    if (image.bytes.size() != static_cast<size_t>(image.width) * image.height * 3)
        throw std::runtime_error("write_ppm: image size does not match its pixel data");
    std::string bytes = "P6\n" + std::to_string(image.width) + ' ' + std::to_string(image.height) + "\n255\n";
    bytes.append(reinterpret_cast<const char*>(image.bytes.data()), image.bytes.size());
    write_file_atomic(path, bytes);
}

Rgb8Image read_ppm(const std::filesystem::path& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw std::runtime_error("cannot open " + path.string());
    // Header: magic, width, height, maxval, separated by whitespace and comments.
    auto next_token = [&]() {
        std::string tok;
        char c;
        while (f.get(c)) {
            if (c == '#') {
                std::string rest;
                std::getline(f, rest);
                continue;
            }
            if (std::isspace(static_cast<unsigned char>(c))) {
                if (!tok.empty()) break;
                continue;
            }
            tok += c;
        }
        return tok;
    };
    const std::string magic = next_token();
    Rgb8Image img;
    int maxval = 0;
    try {
        img.width = std::stoi(next_token());
        img.height = std::stoi(next_token());
        maxval = std::stoi(next_token());
    } catch (const std::exception&) {
        throw std::runtime_error(path.string() + ": malformed PPM header");
    }
    if (magic != "P6" || maxval != 255 || img.width <= 0 || img.height <= 0)
        throw std::runtime_error(path.string() + ": only binary PPM (P6) with maxval 255 is read");
    // The header's size against the bytes the file has, before taking memory for them.
    const std::streamoff pixels_at = f.tellg();
    f.seekg(0, std::ios::end);
    const std::streamoff available = f.tellg() - pixels_at;
    f.seekg(pixels_at);
    const size_t want = static_cast<size_t>(img.width) * static_cast<size_t>(img.height) * 3;
    if (pixels_at < 0 || available < 0 || want > static_cast<size_t>(available))
        throw std::runtime_error(path.string() + ": truncated pixel data (the header's " + std::to_string(img.width) +
                                 "x" + std::to_string(img.height) + " needs " + std::to_string(want) + " bytes, the file has " +
                                 std::to_string(std::max<std::streamoff>(available, 0)) + ")");
    img.bytes.resize(want);
    f.read(reinterpret_cast<char*>(img.bytes.data()), static_cast<std::streamsize>(img.bytes.size()));
    if (f.gcount() != static_cast<std::streamsize>(img.bytes.size()))
        throw std::runtime_error(path.string() + ": truncated pixel data");
    return img;
}

double psnr(const Rgb8Image& a, const Rgb8Image& b) {
    if (a.width != b.width || a.height != b.height || a.bytes.size() != b.bytes.size())
        throw std::invalid_argument("psnr: images differ in size");
    double sum = 0;
    for (size_t i = 0; i < a.bytes.size(); ++i) {
        const double d = double(a.bytes[i]) - double(b.bytes[i]);
        sum += d * d;
    }
    const double mse = sum / double(a.bytes.size());
    return mse == 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

std::filesystem::path depth_path_for(const std::filesystem::path& output) {
    std::filesystem::path p = output;
    const std::string stem = p.stem().string();
    const std::string ext = p.has_extension() ? p.extension().string() : std::string(".ppm");
    return p.replace_filename(stem + "-depth" + ext);
}

}  // namespace kr
