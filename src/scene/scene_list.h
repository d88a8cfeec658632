// The scene files a folder holds, and the bundled scenes: what `keithray render` renders
// without a scene, what bench measures and what the viewer's Open list shows.
#pragma once

#include <filesystem>
#include <vector>

namespace kr {

// The *.json files of `folder`, sorted; none if it cannot be read.
std::vector<std::filesystem::path> list_scenes(const std::filesystem::path& folder);

// The bundled scenes, list_scenes() of res/scenes under the working directory, else of the
// source tree's res/scenes.
std::vector<std::filesystem::path> default_scenes();
// The example scenes shipped beside them (res/scenes/examples, found the same way); the
// viewer's Open list shows them, the benchmarks keep to the brief's.
std::vector<std::filesystem::path> example_scenes();

}  // namespace kr
