#include "core/data_dir.h"

#include <fstream>
#include <system_error>

// The install's bin/ to share/keithray/, relative (CMakeLists.txt: GNUInstallDirs' BINDIR and
// DATADIR). Relative, so the tree may be installed under any prefix or copied whole.
#ifndef KEITHRAY_DATA_FROM_BIN
#define KEITHRAY_DATA_FROM_BIN "../share/keithray"
#endif

namespace kr {

namespace fs = std::filesystem;

namespace {

bool holds_scenes(const fs::path& dir) {
    std::error_code ec;
    return !dir.empty() && fs::is_directory(dir / "scenes", ec);
}

}  // namespace

fs::path marker_target(const fs::path& marker) {
    std::ifstream in(marker);
    std::string line;
    if (!in || !std::getline(in, line)) return {};
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    return line;
}

fs::path installed_data_from_bin() { return KEITHRAY_DATA_FROM_BIN; }

fs::path executable_dir() {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    return ec ? fs::path() : exe.parent_path();
}

std::optional<DataDir> find_data_dir(const fs::path& bin) {
    if (bin.empty()) return std::nullopt;
    const fs::path installed = (bin / installed_data_from_bin()).lexically_normal();
    if (holds_scenes(installed)) return DataDir{installed, true};
    const fs::path built = marker_target(bin / kDataMarker);
    if (holds_scenes(built)) return DataDir{built.lexically_normal(), false};
    return std::nullopt;
}

const std::optional<DataDir>& data_dir() {
    static const std::optional<DataDir> found = find_data_dir(executable_dir());
    return found;
}

std::string data_dir_places() {
    const fs::path bin = executable_dir();
    return (bin / installed_data_from_bin()).lexically_normal().string() + " or the build tree's res/ named in " +
           (bin / kDataMarker).string();
}

bool path_inside(const fs::path& file, const fs::path& dir) {
    std::error_code ec;
    const fs::path f = fs::weakly_canonical(fs::absolute(file, ec), ec);
    const fs::path d = fs::weakly_canonical(fs::absolute(dir, ec), ec);
    if (d.empty()) return false;
    const fs::path rel = f.lexically_relative(d);
    return !rel.empty() && *rel.begin() != "..";
}

}  // namespace kr
