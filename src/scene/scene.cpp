#include "scene/scene.h"

namespace kr {

// The file stores the output relative to itself so scenes can move with their outputs;
// a scene built in code (no source file) resolves against the current directory.
std::filesystem::path Scene::output_path() const {
    const std::filesystem::path output(renderer.output);
    if (source_file.empty()) return output.lexically_normal();
    return (source_file.parent_path() / output).lexically_normal();
}

}  // namespace kr
