#include "scene/scene_list.h"

#include <algorithm>
#include <system_error>

namespace kr {

std::vector<std::filesystem::path> list_scenes(const std::filesystem::path& folder) {
    std::vector<std::filesystem::path> found;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(folder, ec))
        if (entry.path().extension() == ".json") found.push_back(entry.path());
    std::sort(found.begin(), found.end());
    return found;
}

std::vector<std::filesystem::path> default_scenes() {
    std::vector<std::filesystem::path> found = list_scenes("res/scenes");
#ifdef KEITHRAY_SCENES_DIR
    if (found.empty()) found = list_scenes(KEITHRAY_SCENES_DIR);
#endif
    return found;
}

std::vector<std::filesystem::path> example_scenes() {
    std::vector<std::filesystem::path> found = list_scenes("res/scenes/examples");
#ifdef KEITHRAY_SCENES_DIR
    if (found.empty()) found = list_scenes(std::filesystem::path(KEITHRAY_SCENES_DIR) / "examples");
#endif
    return found;
}

}  // namespace kr
