// The viewer's Save panel without its widgets: the paths it offers for a scene and what
// each of its buttons writes. GL-free; ui_panel_save.cpp draws the panel and asks before it
// overwrites a file. An image is written as `keithray render -o` writes the same name
// (render/outputs.h): the same bytes for the same render.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/data_dir.h"
#include "core/image_formats.h"
#include "scene/scene.h"
#include "viewer/model.h"
#include "viewer/render_worker.h"

namespace kr::viewer {

// What a Save writes: an image in one of the formats of core/image_formats.h (kImageFormats:
// the panel has a button for each), the scene (Save As: the file becomes the scene's), a
// copy of it (the scene's file stays) or the convergence log.
struct SaveKind {
    enum What { image, scene, scene_copy, convergence };
    What what = image;
    ImageFormat format = ImageFormat::ppm;  // an image's

    constexpr SaveKind(What w) : what(w) {}
    constexpr SaveKind(ImageFormat f) : format(f) {}
    bool operator==(const SaveKind&) const = default;
};

// The panel's path fields, edited by the user.
struct SavePaths {
    std::string image, scene, convergence;

    // The defaults for `scene`: its "output" (else keithray.ppm) for an image (each format's
    // button sets the extension), the scene itself beside its file as NAME-edited.json, the
    // convergence log as OUTPUT-convergence.csv.
    // A `read_only` scene's (scene_file_read_only) is saved as NAME.json in the current folder.
    static SavePaths for_scene(const Scene& scene, bool read_only = false);
};

// Whether the viewer must not save over `file`: a bundled scene (`data`, core/data_dir.h: the
// install tree's share/keithray or a build's res/, the brief's scenes and the examples, which
// open as they ship and are saved elsewhere), or a file this process cannot write.
bool scene_file_read_only(const std::filesystem::path& file, const std::optional<DataDir>& data);

// The image kind an output named `path` is (its format, core/image_formats.h).
SaveKind image_save_kind(const std::filesystem::path& path);
// `path` with the extension of image format `format` (what the panel's image buttons save to).
std::filesystem::path image_save_path(ImageFormat format, const std::filesystem::path& path);
// Every file saving `kind` to `path` writes: an image's depth file too (output_file_paths).
std::vector<std::filesystem::path> save_targets(SaveKind kind, const std::filesystem::path& path);

// Writes `kind` to `path`: the edited scene as ViewerModel::scene_for_saving (the model then
// counts as saved), or `convergence_csv`, or the `shown` full-resolution image of the
// model's current scene with every file and layer `keithray render -o PATH` writes (an
// image's kind must be its name's format): the radiance tone mapped with the model's tone
// settings and the depth map, or the radiance and the layers as floats. Returns the status
// line; throws std::exception with the reason when nothing was written.
std::string save_output(SaveKind kind, const std::filesystem::path& path, ViewerModel& model, const Snapshot* shown,
                        const std::string& convergence_csv = {});
// Whether saving `kind` now must wait for a frame with the two halves of the samples: a
// denoised image (the final filter reads them) whose `shown` frame of the current scene is a
// full-resolution one without them (a render still refining: RenderWorker::set_halves asks).
bool save_waits_for_halves(SaveKind kind, const ViewerModel& model, const Snapshot* shown);

}  // namespace kr::viewer
