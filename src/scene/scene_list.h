// The scene files a folder holds, and the bundled scenes: what `keithray render` renders
// without a scene, what bench measures and what the viewer's Open list shows.
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include "core/data_dir.h"
#include "scene/scene.h"

namespace kr {

// The *.json files of `folder`, sorted; none if it cannot be read.
std::vector<std::filesystem::path> list_scenes(const std::filesystem::path& folder);

// The bundled scenes: list_scenes() of the bundled files' scenes/ (core/data_dir.h: the
// install tree's share/keithray, else the build tree's res/); none where there are none.
std::vector<std::filesystem::path> default_scenes();
// The example scenes shipped beside them (scenes/examples); the viewer's Open list shows
// them, the benchmarks keep to the brief's.
std::vector<std::filesystem::path> example_scenes();
// `keithray view`'s scene when none is given: the bundled assignment_03.json; empty where
// there are no bundled files.
std::filesystem::path default_view_scene();

// Where a render of a bundled scene writes when its file's "output" is not to be used (the
// install tree is never written, and a render of the bundled scenes without a scene
// argument writes into the current folder): output/NAME under the current folder, NAME
// the file's output's name (else the scene's, as .ppm).
std::filesystem::path output_in_current_folder(const Scene& scene);
// output_in_current_folder() where the file's output lies inside the install tree's bundled
// files `data` (a scene of share/keithray, or one whose output points there); nullopt where
// the file's output may be written.
std::optional<std::filesystem::path> output_outside_install(const Scene& scene, const std::optional<DataDir>& data);

}  // namespace kr
