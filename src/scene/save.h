// Scene serialisation: the authored scene back to the JSON format scene/load.h reads.
#pragma once

#include <filesystem>
#include <string>

#include "scene/scene.h"

namespace kr {

// The scene as JSON text that parse_scene() reads back to an equal Scene (all cameras,
// materials, shapes and lights, used or not, in their order; numbers round-trip exactly).
// `output` is written as the scene holds it.
std::string scene_to_json(const Scene& scene);

// Writes scene_to_json() to `file` with write_file_atomic (core/file_write.h). The renderer's
// `output` is rewritten relative to the new file's folder so that it names the same file
// as before (Scene::output_path() is unchanged). Overwrites: callers ask first.
// Throws std::runtime_error on failure.
void save_scene_json(const Scene& scene, const std::filesystem::path& file);

// `scene` as the file `file` holds it once saved there: its source file `file`, its output
// rewritten relative to the new folder so it names the same file.
Scene scene_moved_to(const Scene& scene, const std::filesystem::path& file);

}  // namespace kr
