#include "viewer/compare_view.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include "core/image_formats.h"

namespace kr::viewer {

Rgb8Image CompareImage::display(const ToneSettings& tone) const {
    return hdr() ? tonemap(radiance, tone.tonemap, tone.exposure_scale()) : bytes;
}

CompareImage load_reference(const std::filesystem::path& path) {
    CompareImage image;
    image.name = path.filename().string();
    ImageFile file = read_image_file(path);
    if (file.hdr) image.radiance = file.radiance.radiance();
    else image.bytes = std::move(file.rgb8);
    return image;
}

std::optional<std::filesystem::path> brief_reference_for(const std::filesystem::path& scene) {
    const std::filesystem::path dir = scene.parent_path();
    if (dir.filename() != "scenes" || scene.extension() != ".json") return std::nullopt;
    std::filesystem::path reference = dir.parent_path() / "references" / scene.stem();
    reference += ".ppm";
    std::error_code ec;
    if (!std::filesystem::is_regular_file(reference, ec)) return std::nullopt;
    return reference;
}

std::optional<CompareFigures> compare_figures(const Rgb8Image& a, const Rgb8Image& b) {
    if (a.width != b.width || a.height != b.height || a.bytes.size() != b.bytes.size() || a.bytes.empty())
        return std::nullopt;
    // One pass over the values: the RMSE follows from the PSNR's mean squared error
    // (kr::psnr says 99 dB for identical images).
    const double db = psnr(a, b);
    const bool identical = a.bytes == b.bytes;
    return CompareFigures{db, identical ? 0.0 : std::pow(10.0, -db / 20), identical};
}

std::string format_psnr(const CompareFigures& figures) {
    if (figures.identical) return "identical";
    char text[32];
    std::snprintf(text, sizeof text, "%.2f dB", figures.psnr);
    return text;
}

std::vector<float> pixel_errors(const Rgb8Image& a, const Rgb8Image& b, ErrorMetric metric) {
    if (a.bytes.size() != b.bytes.size()) throw std::invalid_argument("pixel_errors: images differ in size");
    std::vector<float> error(a.bytes.size() / 3);
    for (size_t i = 0; i < error.size(); ++i) {
        double sum = 0;
        for (size_t k = 3 * i; k < 3 * i + 3; ++k) {
            const double t = a.bytes[k] / 255.0, r = b.bytes[k] / 255.0;
            const double d = metric == ErrorMetric::absolute ? t - r : (t - r) / (r + 0.01);
            sum += d * d;
        }
        error[i] = float(std::sqrt(sum / 3));
    }
    return error;
}

int Comparison::keep(const Image& radiance, int spp, std::string_view shown) {
    int slot = -1;
    for (int i = 0; i < kSnapshotSlots && slot < 0; ++i)
        if (!slots_[size_t(i)]) slot = i;
    if (slot < 0) slot = next_slot_;  // all full: the oldest goes
    next_slot_ = (slot + 1) % kSnapshotSlots;
    CompareImage image;
    image.name = "slot " + std::to_string(slot + 1) + " (" + std::to_string(spp) + " spp, " + std::string(shown) + ")";
    image.radiance = radiance;
    slots_[size_t(slot)] = std::move(image);
    return slot;
}

void Comparison::drop(int slot) {
    if (slot >= 0 && slot < kSnapshotSlots) slots_[size_t(slot)].reset();
    if (settings.b == slot) settings.b = -1;
}

const CompareImage* Comparison::b() const {
    if (settings.b < 0) return reference_ ? &*reference_ : nullptr;
    if (settings.b >= kSnapshotSlots) return nullptr;
    const auto& slot = slots_[size_t(settings.b)];
    return slot ? &*slot : nullptr;
}

}  // namespace kr::viewer
