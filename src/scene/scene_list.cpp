#include "scene/scene_list.h"

#include <algorithm>
#include <system_error>

namespace kr {

namespace fs = std::filesystem;

std::vector<fs::path> list_scenes(const fs::path& folder) {
    std::vector<fs::path> found;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(folder, ec))
        if (entry.path().extension() == ".json") found.push_back(entry.path());
    std::sort(found.begin(), found.end());
    return found;
}

std::vector<fs::path> default_scenes() {
    const std::optional<DataDir>& data = data_dir();
    return data ? list_scenes(data->path / "scenes") : std::vector<fs::path>{};
}

std::vector<fs::path> example_scenes() {
    const std::optional<DataDir>& data = data_dir();
    return data ? list_scenes(data->path / "scenes" / "examples") : std::vector<fs::path>{};
}

fs::path default_view_scene() {
    const std::optional<DataDir>& data = data_dir();
    return data ? data->path / "scenes" / "assignment_03.json" : fs::path();
}

fs::path output_in_current_folder(const Scene& scene) {
    fs::path name = fs::path(scene.renderer.output).filename();
    if (name.empty() || name == "." || name == "..")
        name = (scene.source_file.empty() ? fs::path("keithray") : scene.source_file.stem()).string() + ".ppm";
    return fs::path("output") / name;
}

std::optional<fs::path> output_outside_install(const Scene& scene, const std::optional<DataDir>& data) {
    if (!data || !data->installed) return std::nullopt;
    if (!path_inside(scene.output_path(), data->path)) return std::nullopt;
    return output_in_current_folder(scene);
}

}  // namespace kr
