// File helpers of the viewer that need no window: the polling watch on the scene file and
// the Open list's choices. Image files are in core/image_io.h, the scene lists in scene/load.h.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace kr::viewer {

// The scenes offered by the Open list: the *.json files of each folder, once each however
// the folders are spelled (a relative and an absolute path to one folder, a symlink), in
// folder order. The label is the file name, followed by its folder when two listed files
// share a name.
struct SceneChoice {
    std::filesystem::path path;
    std::string label;
};
std::vector<SceneChoice> scene_choices(const std::vector<std::filesystem::path>& folders);

// Polls a file's modification time, at most once per `interval`.
class FileWatch {
public:
    explicit FileWatch(std::chrono::milliseconds interval = std::chrono::milliseconds(250))
        : interval_(interval) {}
    // Starts watching `file` from its current state.
    void watch(const std::filesystem::path& file);
    // Takes `file`'s current time as seen (after the viewer itself wrote it).
    void acknowledge();
    // True once per change of the modification time (or size) since the last call.
    bool changed(std::chrono::steady_clock::time_point now = std::chrono::steady_clock::now());
    const std::filesystem::path& file() const { return file_; }

private:
    struct Stamp {
        std::filesystem::file_time_type time{};
        uintmax_t size = 0;
        bool exists = false;
        bool operator==(const Stamp&) const = default;
    };
    Stamp stamp() const;

    std::chrono::milliseconds interval_;
    std::filesystem::path file_;
    Stamp seen_;
    std::chrono::steady_clock::time_point last_poll_{};
};

}  // namespace kr::viewer
