#include "viewer/save_dialog.h"

#include <stdexcept>

#include <unistd.h>

#include "core/file_write.h"
#include "core/text.h"
#include "render/outputs.h"
#include "scene/save.h"

namespace kr::viewer {

namespace fs = std::filesystem;

namespace {

// Writes the shown frame as `render -o path` writes a render: its estimates developed and
// encoded by render/outputs.h, every file committed together.
void save_image(SaveKind kind, const fs::path& path, const ViewerModel& model, const Snapshot* shown) {
    if (!shown || shown->scale != 1) throw std::runtime_error("no full-resolution image yet");
    // The first-surface layers are traced in the model's scene: it must be the frame's.
    if (shown->generation != model.generation() || !model.prepared())
        throw std::runtime_error("the image shown is not of the current scene yet");
    const size_t n = shown->radiance.pixels.size();
    if (shown->depth.size() != n || shown->sample_count.size() != n || shown->variance.size() != n)
        throw std::runtime_error("no full-resolution image yet");
    if (image_save_kind(path) != kind) {
        const ImageFormatInfo& format = format_info(kind.format);
        throw std::invalid_argument(quoted_path(path) + ": a " + format.name + " image needs a name ending in " +
                                    format.extension);
    }
    // Denoised where the display is, with the final filter, as `render --denoise` develops it:
    // from the two halves of the samples (save_waits_for_halves).
    const bool denoised = model.settings().denoise != DenoiseView::off;
    if (denoised && !shown->has_halves())
        throw std::runtime_error("the image's two halves of the samples are not there yet");
    RenderEstimates estimates{shown->radiance, shown->depth, shown->sample_count, shown->variance, {}, {}, shown->halves};
    OutputRequest request;
    request.path = path;
    request.display = model.settings().tone;
    request.develop.denoise = denoised ? Denoise::on : Denoise::off;
    request.develop.sampling = model.settings().render;
    write_files_atomic(output_files(*model.prepared(), std::move(estimates), request));
}

}  // namespace

bool save_waits_for_halves(SaveKind kind, const ViewerModel& model, const Snapshot* shown) {
    return kind.what == SaveKind::image && model.settings().denoise != DenoiseView::off && shown &&
           shown->scale == 1 && shown->generation == model.generation() && shown->error.empty() &&
           !shown->has_halves();
}

bool scene_file_read_only(const fs::path& file, const std::optional<DataDir>& data) {
    if (data && path_inside(file, data->path)) return true;
    std::error_code ec;
    return fs::exists(file, ec) && ::access(file.c_str(), W_OK) != 0;
}

SavePaths SavePaths::for_scene(const Scene& scene, bool read_only) {
    SavePaths paths;
    fs::path image = scene.output_path();
    if (image.empty()) image = "keithray.ppm";
    paths.image = image.string();
    paths.convergence = (image.parent_path() / (image.stem().string() + "-convergence.csv")).string();
    const fs::path source = scene.source_file.empty() ? fs::path("scene.json") : scene.source_file;
    paths.scene = read_only ? source.filename().string()
                            : (source.parent_path() / (source.stem().string() + "-edited.json")).string();
    return paths;
}

SaveKind image_save_kind(const fs::path& path) { return output_format(path).format; }

fs::path image_save_path(ImageFormat format, const fs::path& path) {
    return fs::path(path).replace_extension(format_info(format).extension);
}

std::vector<fs::path> save_targets(SaveKind kind, const fs::path& path) {
    return kind.what == SaveKind::image ? output_file_paths(path) : std::vector<fs::path>{path};
}

std::string save_output(SaveKind kind, const fs::path& path, ViewerModel& model, const Snapshot* shown,
                        const std::string& convergence_csv) {
    if (kind.what == SaveKind::convergence) {
        write_file_atomic(path, convergence_csv);
    } else if (kind.what == SaveKind::scene || kind.what == SaveKind::scene_copy) {
        model.save_scene_to(path, kind.what == SaveKind::scene);
        if (kind.what == SaveKind::scene_copy) return "saved a copy as " + show_user_text(path.string());
    } else {
        save_image(kind, path, model, shown);
    }
    return "saved " + show_user_text(path.string());
}

}  // namespace kr::viewer
