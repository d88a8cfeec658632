#include "viewer/files.h"

#include <system_error>

namespace kr::viewer {

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
