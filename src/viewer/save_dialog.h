// The viewer's Save panel without its widgets: the paths it offers for a scene and what
// each of its buttons writes. GL-free; ui_save.cpp draws the panel and asks before it
// overwrites a file.
#pragma once

#include <filesystem>
#include <string>

#include "scene/scene.h"
#include "viewer/model.h"
#include "viewer/render_worker.h"

namespace kr::viewer {

enum class SaveKind { ppm, png, exr, pfm, scene, convergence };

// The panel's path fields, edited by the user.
struct SavePaths {
    std::string image, png, hdr, scene, convergence;

    // The defaults for `scene`: its "output" (else keithray.ppm) as .ppm, .png and .exr, and
    // the scene itself beside its file as NAME-edited.json, the convergence log as
    // OUTPUT-convergence.csv.
    static SavePaths for_scene(const Scene& scene);
};

// Writes `kind` to `path`: the edited scene as ViewerModel::scene_for_saving (the model then
// counts as saved), or the `shown` full-resolution image, tone mapped as the window shows
// it (PPM, PNG) or its radiance as floats (EXR, PFM), or `convergence_csv`. Returns the
// status line; throws std::exception with the reason when nothing was written.
std::string save_output(SaveKind kind, const std::filesystem::path& path, ViewerModel& model, const Snapshot* shown,
                        const std::string& convergence_csv = {});

}  // namespace kr::viewer
