#include "core/image_hdr.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfThreading.h>
#include <omp.h>

#include "core/file_write.h"
#include "core/image_io.h"
#include "core/text.h"

namespace kr {

static_assert(std::endian::native == std::endian::little, "PFM and EXR byte handling assumes a little-endian CPU");

Image HdrImage::radiance() const {
    Image img(width, height);
    for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = {rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]};
    return img;
}

HdrImage hdr_from_radiance(const Image& radiance) {
    HdrImage out;
    out.width = radiance.width;
    out.height = radiance.height;
    out.rgb.resize(radiance.pixels.size() * 3);
    for (size_t i = 0; i < radiance.pixels.size(); ++i)
        for (int k = 0; k < 3; ++k) out.rgb[3 * i + k] = stored_float(radiance.pixels[i][k]);
    return out;
}

std::vector<float> stored_floats(const std::vector<double>& values) {
    std::vector<float> out(values.size());
    for (size_t i = 0; i < values.size(); ++i) out[i] = stored_float(values[i]);
    return out;
}

namespace {

// A library's message as one bounded line: newlines become spaces, at most 160 characters.
std::string one_line(std::string text) {
    for (char& c : text)
        if (c == '\n' || c == '\r' || c == '\t') c = ' ';
    if (text.size() > 160) text = text.substr(0, 157) + "...";
    return text;
}

[[noreturn]] void fail(const std::string& name, const std::string& what) {
    throw std::runtime_error(show_user_text(name) + ": " + what);
}

void check_layer_size(size_t have, size_t want, const char* layer) {
    if (have != 0 && have != want)
        throw std::invalid_argument(std::string("HDR image: the ") + layer + " layer does not match the image size");
}

void check_image(const HdrImage& image) {
    if (image.width <= 0 || image.height <= 0 || image.width > kMaxHdrSide || image.height > kMaxHdrSide ||
        image.pixel_count() > kMaxHdrPixels)
        throw std::invalid_argument("HDR image: size " + std::to_string(image.width) + "x" +
                                    std::to_string(image.height) + " is out of range");
    const size_t n = image.pixel_count();
    if (image.rgb.size() != 3 * n) throw std::invalid_argument("HDR image: the radiance does not match the image size");
    check_layer_size(image.depth.size(), n, "depth");
    check_layer_size(image.albedo.size(), 3 * n, "albedo");
    check_layer_size(image.normal.size(), 3 * n, "normal");
    check_layer_size(image.samples.size(), n, "samples");
    check_layer_size(image.variance.size(), 3 * n, "variance");
    check_layer_size(image.raw.size(), 3 * n, "raw");
}

// OpenEXR's output stream into a string in memory (the file is then written atomically).
class StringOStream : public Imf::OStream {
public:
    StringOStream() : Imf::OStream("memory") {}
    void write(const char c[], int n) override {
        if (pos_ + size_t(n) > bytes_.size()) bytes_.resize(pos_ + size_t(n));
        std::memcpy(bytes_.data() + pos_, c, size_t(n));
        pos_ += size_t(n);
    }
    uint64_t tellp() override { return pos_; }
    void seekp(uint64_t pos) override { pos_ = size_t(pos); }
    std::string take() { return std::move(bytes_); }

private:
    std::string bytes_;
    size_t pos_ = 0;
};

// OpenEXR's input stream over bytes in memory; reading past the end throws, as the API asks.
class StringIStream : public Imf::IStream {
public:
    explicit StringIStream(const std::string& bytes) : Imf::IStream("memory"), bytes_(bytes) {}
    bool read(char c[], int n) override {
        if (n < 0 || pos_ > bytes_.size() || size_t(n) > bytes_.size() - pos_)
            throw std::runtime_error("the file ends early");
        std::memcpy(c, bytes_.data() + pos_, size_t(n));
        pos_ += size_t(n);
        return pos_ < bytes_.size();
    }
    uint64_t tellg() override { return pos_; }
    void seekg(uint64_t pos) override { pos_ = size_t(std::min<uint64_t>(pos, bytes_.size() + 1)); }

private:
    const std::string& bytes_;
    size_t pos_ = 0;
};

// The layers of the EXR file, their names for messages and their channels per pixel.
enum class ExrLayer { radiance, depth, albedo, normal, samples, variance, raw };
constexpr EnumNames<ExrLayer, 7> exr_layer_names{
    {"radiance", "depth", "albedo", "normal", "samples", "variance", "raw"}};
constexpr std::array<int, 7> kLayerChannels{3, 1, 3, 3, 1, 3, 3};
int channels_of(ExrLayer layer) { return kLayerChannels[size_t(layer)]; }

// Each EXR channel: its name, its layer and its place within the layer's pixel.
struct ExrChannel {
    const char* name;
    ExrLayer layer;
    int offset;
};
constexpr std::array<ExrChannel, 17> kExrChannels{{{"R", ExrLayer::radiance, 0},
                                                   {"G", ExrLayer::radiance, 1},
                                                   {"B", ExrLayer::radiance, 2},
                                                   {"depth.Z", ExrLayer::depth, 0},
                                                   {"albedo.R", ExrLayer::albedo, 0},
                                                   {"albedo.G", ExrLayer::albedo, 1},
                                                   {"albedo.B", ExrLayer::albedo, 2},
                                                   {"normal.X", ExrLayer::normal, 0},
                                                   {"normal.Y", ExrLayer::normal, 1},
                                                   {"normal.Z", ExrLayer::normal, 2},
                                                   {"samples", ExrLayer::samples, 0},
                                                   {"variance.R", ExrLayer::variance, 0},
                                                   {"variance.G", ExrLayer::variance, 1},
                                                   {"variance.B", ExrLayer::variance, 2},
                                                   {"raw.R", ExrLayer::raw, 0},
                                                   {"raw.G", ExrLayer::raw, 1},
                                                   {"raw.B", ExrLayer::raw, 2}}};

// The vector holding a float layer (samples, the one 32-bit unsigned layer, has none).
std::vector<float>* float_layer(HdrImage& image, ExrLayer layer) {
    switch (layer) {
        case ExrLayer::radiance: return &image.rgb;
        case ExrLayer::depth: return &image.depth;
        case ExrLayer::albedo: return &image.albedo;
        case ExrLayer::normal: return &image.normal;
        case ExrLayer::variance: return &image.variance;
        case ExrLayer::raw: return &image.raw;
        case ExrLayer::samples: return nullptr;
    }
    return nullptr;
}

}  // namespace

std::string encode_exr(const HdrImage& image) {
    check_image(image);
    // OpenEXR compresses its line blocks on a thread pool: one thread per OpenMP worker.
    static const bool pool_started = [] {
        Imf::setGlobalThreadCount(std::max(1, omp_get_max_threads()));
        return true;
    }();
    (void)pool_started;
    HdrImage& layers = const_cast<HdrImage&>(image);  // Imf::Slice takes char*; nothing is written
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    Imf::addComments(header, "keithray render: mean radiance in R,G,B; depth.Z is the primary hit distance "
                             "(1e6 where the ray missed); albedo and normal of the first non-specular hit; "
                             "samples per pixel; variance of the mean per channel" +
                                 std::string(image.raw.empty() ? "" : "; R,G,B denoised, raw.R/G/B before"));
    Imf::FrameBuffer frame;
    const size_t width = size_t(image.width);
    for (const ExrChannel& ch : kExrChannels) {
        const int stride = channels_of(ch.layer);
        if (ch.layer == ExrLayer::samples) {
            if (layers.samples.empty()) continue;
            header.channels().insert(ch.name, Imf::Channel(Imf::UINT));
            frame.insert(ch.name, Imf::Slice(Imf::UINT, reinterpret_cast<char*>(layers.samples.data()),
                                             sizeof(uint32_t), sizeof(uint32_t) * width));
            continue;
        }
        std::vector<float>& data = *float_layer(layers, ch.layer);
        if (data.empty()) continue;
        header.channels().insert(ch.name, Imf::Channel(Imf::FLOAT));
        frame.insert(ch.name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(data.data() + ch.offset),
                                         sizeof(float) * size_t(stride), sizeof(float) * size_t(stride) * width));
    }
    StringOStream stream;
    {
        Imf::OutputFile file(stream, header);
        file.setFrameBuffer(frame);
        file.writePixels(image.height);
    }  // the destructor writes the line offset table
    return stream.take();
}

namespace {

std::runtime_error out_of_memory(const std::string& name, int64_t width, int64_t height) {
    return std::runtime_error("not enough memory for " + quoted_path(name) + ", a " + std::to_string(width) + "x" +
                              std::to_string(height) + " image");
}

}  // namespace

HdrImage decode_exr(const std::string& bytes, const std::string& name) {
    HdrImage out;
    // OpenEXR passes an allocation failure on inside its own exceptions, with the name in the text.
    auto allocation_failed = [](const std::string& what) { return what.find("bad_alloc") != std::string::npos; };
    try {
        StringIStream stream(bytes);
        Imf::InputFile file(stream);
        const Imath::Box2i window = file.header().dataWindow();
        const int64_t w = int64_t(window.max.x) - window.min.x + 1, h = int64_t(window.max.y) - window.min.y + 1;
        if (w <= 0 || h <= 0 || w > kMaxHdrSide || h > kMaxHdrSide || size_t(w) * size_t(h) > kMaxHdrPixels)
            fail(name, "image size " + std::to_string(w) + "x" + std::to_string(h) + " is out of range (at most " +
                           std::to_string(kMaxHdrSide) + " a side and " + std::to_string(kMaxHdrPixels) + " pixels)");
        // A header whose pixels could not fit the file's bytes even compressed: deflate keeps
        // at most about 1000:1, under 200 pixels per byte for three half-float channels.
        if (size_t(w) * size_t(h) > bytes.size() * 4096)
            fail(name, "the header's size " + std::to_string(w) + "x" + std::to_string(h) +
                           " does not fit the file's " + std::to_string(bytes.size()) + " bytes");
        out.width = int(w);
        out.height = int(h);
        const size_t n = out.pixel_count();
        const Imf::ChannelList& channels = file.header().channels();
        std::array<int, 7> found{};  // channels present per layer
        for (const ExrChannel& ch : kExrChannels)
            if (channels.findChannel(ch.name)) ++found[size_t(ch.layer)];
        if (found[size_t(ExrLayer::radiance)] != 3) fail(name, "expected the channels R, G and B of an RGB radiance image");
        for (size_t layer = 0; layer < found.size(); ++layer)
            if (found[layer] != 0 && found[layer] != kLayerChannels[layer])
                fail(name, "the " + std::string(exr_layer_names.name(ExrLayer(layer))) + " layer is incomplete");
        Imf::FrameBuffer frame;
        // Slice::Make addresses the buffers from the data window's origin, which need not be (0, 0).
        for (const ExrChannel& ch : kExrChannels) {
            if (!found[size_t(ch.layer)]) continue;
            const size_t stride = size_t(channels_of(ch.layer));
            if (ch.layer == ExrLayer::samples) {
                out.samples.assign(n, 0);
                frame.insert(ch.name, Imf::Slice::Make(Imf::UINT, out.samples.data(), window, sizeof(uint32_t),
                                                       sizeof(uint32_t) * size_t(w)));
                continue;
            }
            std::vector<float>& data = *float_layer(out, ch.layer);
            data.resize(n * stride, 0.0f);
            frame.insert(ch.name, Imf::Slice::Make(Imf::FLOAT, data.data() + ch.offset, window, sizeof(float) * stride,
                                                   sizeof(float) * stride * size_t(w)));
        }
        file.setFrameBuffer(frame);
        if (!file.isComplete()) fail(name, "the file is truncated (pixel data missing)");
        file.readPixels(window.min.y, window.max.y);
    } catch (const std::bad_alloc&) {
        throw out_of_memory(name, out.width, out.height);
    } catch (const std::runtime_error& e) {
        const std::string what = e.what();
        if (what.rfind(name + ": ", 0) == 0) throw;
        if (allocation_failed(what)) throw out_of_memory(name, out.width, out.height);
        fail(name, "not a readable OpenEXR image: " + one_line(what));
    } catch (const std::exception& e) {
        if (allocation_failed(e.what())) throw out_of_memory(name, out.width, out.height);
        fail(name, "not a readable OpenEXR image: " + one_line(e.what()));
    }
    return out;
}

namespace {

std::string pfm_bytes(const float* values, int channels, int width, int height) {
    std::string out = std::string(channels == 3 ? "PF" : "Pf") + "\n" + std::to_string(width) + " " +
                      std::to_string(height) + "\n-1.0\n";  // negative scale: little-endian
    const size_t row = size_t(width) * size_t(channels);
    const size_t header = out.size();
    out.resize(header + row * size_t(height) * sizeof(float));
    // PFM rows run bottom to top.
    for (int y = 0; y < height; ++y)
        std::memcpy(out.data() + header + size_t(height - 1 - y) * row * sizeof(float), values + size_t(y) * row,
                    row * sizeof(float));
    return out;
}

}  // namespace

std::string encode_pfm_rgb(const HdrImage& image) {
    check_image(image);
    return pfm_bytes(image.rgb.data(), 3, image.width, image.height);
}

std::string encode_pfm_gray(const std::vector<float>& values, int width, int height) {
    if (width <= 0 || height <= 0 || values.size() != size_t(width) * size_t(height))
        throw std::invalid_argument("PFM: values do not match the image size");
    return pfm_bytes(values.data(), 1, width, height);
}

HdrImage decode_pfm(const std::string& bytes, const std::string& name) {
    // Header: three whitespace-separated tokens after the magic, then exactly one whitespace byte.
    size_t pos = 0;
    auto token = [&]() {
        while (pos < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
        const size_t start = pos;
        while (pos < bytes.size() && pos - start < 32 && !std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
        return bytes.substr(start, pos - start);
    };
    const std::string magic = token();
    if (magic != "PF" && magic != "Pf") fail(name, "not a PFM image (expected \"PF\" or \"Pf\" at the start)");
    const int channels = magic == "PF" ? 3 : 1;
    long long w = 0, h = 0;
    double scale = 0;
    try {
        size_t used = 0;
        const std::string ws = token(), hs = token(), ss = token();
        w = std::stoll(ws, &used);
        if (used != ws.size()) throw std::invalid_argument("width");
        h = std::stoll(hs, &used);
        if (used != hs.size()) throw std::invalid_argument("height");
        scale = std::stod(ss, &used);
        if (used != ss.size()) throw std::invalid_argument("scale");
    } catch (const std::exception&) {
        fail(name, "malformed PFM header (expected width, height and scale)");
    }
    if (pos >= bytes.size() || !std::isspace(static_cast<unsigned char>(bytes[pos])))
        fail(name, "malformed PFM header (expected whitespace after the scale)");
    ++pos;
    if (w <= 0 || h <= 0 || w > kMaxHdrSide || h > kMaxHdrSide || size_t(w) * size_t(h) > kMaxHdrPixels)
        fail(name, "image size " + std::to_string(w) + "x" + std::to_string(h) + " is out of range");
    if (!(scale < 0) && !(scale > 0)) fail(name, "the PFM scale must be a non-zero number");
    if (scale > 0) fail(name, "big-endian PFM (positive scale) is not read; expected a negative scale");
    const size_t row = size_t(w) * size_t(channels);
    const size_t want = row * size_t(h) * sizeof(float);
    if (bytes.size() - pos != want)
        fail(name, "expected " + std::to_string(want) + " bytes of pixel data for " + std::to_string(w) + "x" +
                       std::to_string(h) + ", found " + std::to_string(bytes.size() - pos));
    HdrImage out;
    out.width = int(w);
    out.height = int(h);
    const size_t n = out.pixel_count();
    try {
        std::vector<float> values(row * size_t(h));
        for (long long y = 0; y < h; ++y)  // bottom row first in the file
            std::memcpy(values.data() + size_t(y) * row, bytes.data() + pos + size_t(h - 1 - y) * row * sizeof(float),
                        row * sizeof(float));
        if (channels == 3) {
            out.rgb = std::move(values);
        } else {
            out.rgb.resize(3 * n);
            for (size_t i = 0; i < n; ++i) out.rgb[3 * i] = out.rgb[3 * i + 1] = out.rgb[3 * i + 2] = values[i];
            out.depth = std::move(values);
        }
    } catch (const std::bad_alloc&) {
        throw out_of_memory(name, w, h);
    }
    return out;
}

namespace {

constexpr char kExrMagic[4] = {0x76, 0x2f, 0x31, 0x01};

}  // namespace

bool is_hdr_bytes(const std::string& bytes) {
    return bytes.size() >= 4 && (std::memcmp(bytes.data(), kExrMagic, 4) == 0 ||
                                 (bytes[0] == 'P' && (bytes[1] == 'F' || bytes[1] == 'f')));
}

HdrImage read_hdr(const std::filesystem::path& path) {
    return decode_hdr(read_image_bytes(path, kMaxHdrFileBytes), path.string());
}

HdrImage decode_hdr(const std::string& bytes, const std::string& name) {
    if (bytes.size() >= 4 && std::memcmp(bytes.data(), kExrMagic, 4) == 0) return decode_exr(bytes, name);
    if (bytes.size() >= 2 && bytes[0] == 'P' && (bytes[1] == 'F' || bytes[1] == 'f')) return decode_pfm(bytes, name);
    throw std::runtime_error(quoted_path(name) + ": not an OpenEXR or PFM image");
}

}  // namespace kr
