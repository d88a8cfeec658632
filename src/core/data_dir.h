// Where keithray's bundled files are (the brief's scenes, the example scenes, the brief's
// reference renders), found at run time from the executable's own path: an installed
// keithray reads them from the install tree, a built one from the build's source tree. No
// path of the machine it was built on is compiled in.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace kr {

// The folder of the bundled files: `scenes/`, `scenes/examples/` and `references/` in it.
struct DataDir {
    std::filesystem::path path;
    bool installed = false;  // an install tree's share/keithray (never written), not a build's res/
};

// The executable's folder, from /proc/self/exe (its links resolved); empty if unknown.
std::filesystem::path executable_dir();

// The bundled files: the install tree's share/keithray, at its place relative to the
// executable (the install's bin/ and share/ folders, GNUInstallDirs), else the build tree's
// res/ named in the file `kDataMarker` that CMake writes beside a build's binaries (never
// installed). nullopt when neither holds a `scenes` folder. Looked up once.
const std::optional<DataDir>& data_dir();
std::optional<DataDir> find_data_dir(const std::filesystem::path& executable_folder);

// The marker file's name, and where data_dir() looks, for messages: "/usr/bin/../share/keithray
// or the build tree's res/ named in /usr/bin/keithray-res.path".
inline constexpr const char* kDataMarker = "keithray-res.path";
std::string data_dir_places();

// The first line of a build's marker file (this one, or core/module.h's), a folder; empty
// where there is none.
std::filesystem::path marker_target(const std::filesystem::path& marker);

// The path from the install's bin/ to its share/keithray/, as CMake computed it.
std::filesystem::path installed_data_from_bin();

// Whether `file` lies inside `dir` (both made absolute and normal, links resolved as far as
// they exist).
bool path_inside(const std::filesystem::path& file, const std::filesystem::path& dir);

}  // namespace kr
