#include "viewer/save_dialog.h"

#include <stdexcept>

#include "core/file_write.h"
#include "core/image_hdr.h"
#include "core/image_io.h"
#include "core/text.h"
#include "scene/save.h"

namespace kr::viewer {

namespace fs = std::filesystem;

SavePaths SavePaths::for_scene(const Scene& scene) {
    SavePaths paths;
    fs::path image = scene.output_path();
    if (image.empty()) image = "keithray.ppm";
    paths.image = image.replace_extension(".ppm").string();
    paths.png = fs::path(image).replace_extension(".png").string();
    paths.hdr = fs::path(image).replace_extension(".exr").string();
    paths.convergence = (image.parent_path() / (image.stem().string() + "-convergence.csv")).string();
    const fs::path source = scene.source_file.empty() ? fs::path("scene.json") : scene.source_file;
    paths.scene = (source.parent_path() / (source.stem().string() + "-edited.json")).string();
    return paths;
}

std::string save_output(SaveKind kind, const fs::path& path, ViewerModel& model, const Snapshot* shown,
                        const std::string& convergence_csv) {
    if (kind == SaveKind::convergence) {
        write_file_atomic(path, convergence_csv);
    } else if (kind == SaveKind::scene) {
        save_scene_json(model.scene_for_saving(), path);
        model.mark_saved();  // the edits are in a file now
    } else {
        if (!shown || shown->scale != 1) throw std::runtime_error("no full-resolution image yet");
        if (kind == SaveKind::exr || kind == SaveKind::pfm) {
            const HdrImage hdr = hdr_from_radiance(shown->radiance);
            write_file_atomic(path, kind == SaveKind::exr ? encode_exr(hdr) : encode_pfm_rgb(hdr));
        } else {
            const ToneSettings& tone = model.settings().tone;
            const Rgb8Image image = tonemap(shown->radiance, tone.tonemap, tone.exposure_scale());
            if (kind == SaveKind::ppm) write_ppm(path, image);
            else write_png(path, image);
        }
    }
    return "saved " + show_user_text(path.string());
}

}  // namespace kr::viewer
