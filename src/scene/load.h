// Strict scene loading from the JSON format of docs/scene-format.md (the brief's format, with
// the translucent material and the optional display block).
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "scene/scene.h"

namespace kr {

// A scene file that cannot be loaded. what() is the whole one-line message:
//   "<file>: <json pointer>: <what was expected>"
class SceneError : public std::runtime_error {
public:
    SceneError(std::string file, std::string json_path, std::string message);
    const std::string& file() const { return file_; }
    const std::string& json_path() const { return json_path_; }  // e.g. "/scene/primitives/3/material"
    const std::string& message() const { return message_; }

private:
    std::string file_, json_path_, message_;
};

// User text (an id, a key) for a message: quoted, escaped and bounded (core/text.h).
std::string in_quotes(std::string_view s);

struct LoadedScene {
    Scene scene;
    // Non-fatal findings, each formatted like a SceneError message
    // (depth above 20 clamped, out-of-range values in unreferenced objects, ...).
    std::vector<std::string> warnings;
};

// Reads a scene file's bytes (at most kMaxSceneFileBytes). Throws SceneError.
std::string read_scene_text(const std::filesystem::path& file);

// Reads and validates a scene file. Throws SceneError (never anything else for bad input).
LoadedScene load_scene_file(const std::filesystem::path& file);

// Same, from text; `file` is only used in messages and to resolve the output path.
LoadedScene parse_scene(std::string_view json_text, const std::filesystem::path& file);

}  // namespace kr
