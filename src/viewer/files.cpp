#include "viewer/files.h"

#include <algorithm>
#include <system_error>

#include "scene/load.h"
#include "scene/scene_list.h"  // list_scenes

namespace kr::viewer {

std::vector<SceneChoice> scene_choices(const std::vector<std::filesystem::path>& folders) {
    namespace fs = std::filesystem;
    std::vector<SceneChoice> choices;
    std::vector<fs::path> seen;  // canonical paths already listed
    for (const fs::path& folder : folders) {
        for (const fs::path& file : list_scenes(folder)) {
            std::error_code ec;
            fs::path canonical = fs::weakly_canonical(file, ec);
            if (ec) canonical = fs::absolute(file, ec).lexically_normal();
            if (std::find(seen.begin(), seen.end(), canonical) != seen.end()) continue;
            seen.push_back(canonical);
            choices.push_back({file, file.filename().string()});
        }
    }
    // Tell apart equal names from different folders.
    for (SceneChoice& c : choices) {
        const auto same_name = std::count_if(choices.begin(), choices.end(), [&](const SceneChoice& o) {
            return o.path.filename() == c.path.filename();
        });
        if (same_name > 1) c.label += "  (" + c.path.parent_path().string() + ")";
    }
    return choices;
}

FileWatch::Stamp FileWatch::stamp() const {
    Stamp s;
    std::error_code ec;
    s.time = std::filesystem::last_write_time(file_, ec);
    if (ec) return {};
    s.size = std::filesystem::file_size(file_, ec);
    s.exists = !ec;
    return s;
}

void FileWatch::watch(const std::filesystem::path& file) {
    file_ = file;
    seen_ = stamp();
    last_poll_ = std::chrono::steady_clock::now();
}

void FileWatch::acknowledge() { seen_ = stamp(); }

bool FileWatch::changed(std::chrono::steady_clock::time_point now) {
    if (file_.empty() || now - last_poll_ < interval_) return false;
    last_poll_ = now;
    const Stamp s = stamp();
    // A file being replaced may be missing for a moment: wait for it to come back.
    if (!s.exists || s == seen_) return false;
    seen_ = s;
    return true;
}

}  // namespace kr::viewer
