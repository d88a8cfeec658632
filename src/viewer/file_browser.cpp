#include "viewer/file_browser.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>

#include <nlohmann/json.hpp>

#include "core/file_write.h"
#include "core/image_formats.h"
#include "core/text.h"

extern char** environ;

namespace kr::viewer {

namespace fs = std::filesystem;

namespace {

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

bool is_scene_purpose(FilePurpose p) { return p == FilePurpose::open_scene || p == FilePurpose::save_scene; }

// The settings file's size is bounded: a larger file is not ours.
constexpr uintmax_t kMaxSettingsBytes = 256 * 1024;
constexpr size_t kMaxPathBytes = 4096;

}  // namespace

bool purpose_saves(FilePurpose purpose) {
    return purpose == FilePurpose::save_scene || purpose == FilePurpose::save_image;
}

const char* purpose_title(FilePurpose purpose) {
    switch (purpose) {
        case FilePurpose::open_scene: return "Open scene";
        case FilePurpose::open_image: return "Open image B (reference)";
        case FilePurpose::save_scene: return "Save scene as";
        case FilePurpose::save_image: return "Save image as";
    }
    return "";
}

const char* purpose_word(FilePurpose purpose) {
    switch (purpose) {
        case FilePurpose::open_scene: return "open-scene";
        case FilePurpose::open_image: return "open-image";
        case FilePurpose::save_scene: return "save-scene";
        case FilePurpose::save_image: return "save-image";
    }
    return "none";
}

bool matches_filter(const fs::path& file, FilePurpose purpose) {
    if (is_scene_purpose(purpose)) return lower(file.extension().string()) == ".json";
    return format_by_extension(file) != nullptr;
}

std::string filter_words(FilePurpose purpose) {
    if (is_scene_purpose(purpose)) return "scenes (*.json)";
    std::string words = "images (";
    for (const ImageFormatInfo& f : kImageFormats) {
        if (&f != &kImageFormats.front()) words += " ";
        words += std::string("*") + f.extension;
    }
    return words + ")";
}

// ---- FileBrowser ----

FileBrowser::FileBrowser(FilePurpose purpose, const fs::path& folder, std::string start_name)
    : name(std::move(start_name)), purpose_(purpose) {
    std::error_code ec;
    fs::path start = folder.empty() ? fs::current_path(ec) : fs::absolute(folder, ec);
    if (!go(start)) {
        // A folder that went away: the current one, where the viewer was started.
        const std::string why = error_;
        if (!go(fs::current_path(ec))) go("/");
        error_ = why;
    }
}

void FileBrowser::refresh() {
    entries_.clear();
    error_.clear();
    std::error_code ec;
    fs::directory_iterator it(folder_, fs::directory_options::skip_permission_denied, ec);
    if (ec) {
        error_ = quoted_path(folder_) + ": cannot list the folder (" + ec.message() + ")";
        return;
    }
    std::vector<BrowserEntry> folders, files;
    for (; it != fs::directory_iterator(); it.increment(ec)) {
        if (ec) break;
        const std::string entry_name = it->path().filename().string();
        if (entry_name.empty() || entry_name[0] == '.') continue;
        std::error_code type_ec;
        if (it->is_directory(type_ec)) folders.push_back({entry_name, true});  // a link to one too
        else if (show_all_ || matches_filter(it->path(), purpose_)) files.push_back({entry_name, false});
    }
    auto by_name = [](const BrowserEntry& a, const BrowserEntry& b) { return a.name < b.name; };
    std::sort(folders.begin(), folders.end(), by_name);
    std::sort(files.begin(), files.end(), by_name);
    entries_ = std::move(folders);
    entries_.insert(entries_.end(), files.begin(), files.end());
}

void FileBrowser::set_show_all(bool all) {
    if (all == show_all_) return;
    show_all_ = all;
    refresh();
}

bool FileBrowser::go(const fs::path& folder) {
    std::error_code ec;
    fs::path target = folder.is_absolute() ? folder : folder_ / folder;
    target = fs::weakly_canonical(target, ec);
    if (ec) target = fs::absolute(folder, ec).lexically_normal();
    if (!fs::is_directory(target, ec)) {
        error_ = quoted_path(folder) + ": not a folder";
        return false;
    }
    fs::directory_iterator probe(target, ec);
    if (ec) {
        error_ = quoted_path(target) + ": cannot list the folder (" + ec.message() + ")";
        return false;
    }
    folder_ = target;
    refresh();
    return true;
}

void FileBrowser::up() {
    if (folder_.has_parent_path() && folder_.parent_path() != folder_) go(folder_.parent_path());
}

fs::path FileBrowser::resolve(const std::string& text) const {
    fs::path p(text);
    if (text == "~" || text.rfind("~/", 0) == 0) {
        const char* home = std::getenv("HOME");
        if (home && *home) p = fs::path(home) / text.substr(std::min<size_t>(2, text.size()));
    }
    return p.is_absolute() ? p : folder_ / p;
}

std::optional<fs::path> FileBrowser::accept(const std::string& default_extension) {
    error_.clear();
    if (name.empty()) {
        error_ = purpose_saves(purpose_) ? "type a file name to save to" : "pick a file, or type its name";
        return std::nullopt;
    }
    if (name.size() > kMaxPathBytes) {
        error_ = quote_user_text(name, 60) + ": too long for a file name";
        return std::nullopt;
    }
    const fs::path p = resolve(name);
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
        if (go(p)) name.clear();
        return std::nullopt;
    }
    if (!purpose_saves(purpose_)) {
        if (!fs::exists(p, ec)) error_ = quoted_path(p) + ": no such file";
        else if (!fs::is_regular_file(p, ec)) error_ = quoted_path(p) + ": not a regular file";
        else if (!matches_filter(p, purpose_)) error_ = quoted_path(p) + ": expected one of " + filter_words(purpose_);
        if (!error_.empty()) return std::nullopt;
        return p.lexically_normal();
    }
    // Save: the folder must be there; a name without an extension takes the filter's.
    fs::path target = p;
    if (!target.has_extension()) target += is_scene_purpose(purpose_) ? std::string(".json") : default_extension;
    if (!fs::is_directory(target.parent_path(), ec)) {
        error_ = quoted_path(target.parent_path()) + ": no such folder";
        return std::nullopt;
    }
    if (!matches_filter(target, purpose_)) {
        error_ = quoted_path(target) + ": expected one of " + filter_words(purpose_);
        return std::nullopt;
    }
    if (fs::exists(target, ec) && !fs::is_regular_file(target, ec)) {
        error_ = quoted_path(target) + ": not a regular file";
        return std::nullopt;
    }
    return target.lexically_normal();
}

// ---- Settings file ----

fs::path config_dir() {
    // XDG base directories: a relative XDG_CONFIG_HOME is invalid and ignored.
    if (const char* xdg = std::getenv("XDG_CONFIG_HOME"); xdg && *xdg && fs::path(xdg).is_absolute())
        return fs::path(xdg) / "keithray";
    if (const char* home = std::getenv("HOME"); home && *home) return fs::path(home) / ".config" / "keithray";
    return {};
}

void note_recent(std::vector<fs::path>& list, const fs::path& file) {
    std::error_code ec;
    fs::path p = fs::absolute(file, ec);
    if (ec) p = file;
    p = p.lexically_normal();
    list.erase(std::remove(list.begin(), list.end(), p), list.end());
    list.insert(list.begin(), p);
    if (list.size() > ViewerSettingsFile::kMaxRecent) list.resize(ViewerSettingsFile::kMaxRecent);
}

LoadedSettings read_settings_file(const fs::path& file) {
    LoadedSettings out;
    std::error_code ec;
    if (!fs::exists(file, ec)) return out;
    const std::string where = quoted_path(file);
    auto bad = [&](const std::string& what) {
        if (out.problem.empty()) out.problem = where + ": " + what + "; ignored";
    };
    if (!fs::is_regular_file(file, ec)) {
        bad("not a regular file");
        return out;
    }
    const uintmax_t size = fs::file_size(file, ec);
    if (ec || size > kMaxSettingsBytes) {
        bad("larger than a viewer settings file (" + std::to_string(kMaxSettingsBytes / 1024) + " KiB)");
        return out;
    }
    std::ifstream in(file, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    if (!in && !in.eof()) {
        bad("cannot be read");
        return out;
    }
    const nlohmann::json j = nlohmann::json::parse(text.str(), nullptr, false);
    if (j.is_discarded() || !j.is_object()) {
        bad("not a viewer settings file (expected a JSON object with \"recent_scenes\", \"recent_images\", \"ui_scale\")");
        return out;
    }
    auto read_list = [&](const char* key, std::vector<fs::path>& list) {
        if (!j.contains(key)) return;
        const nlohmann::json& a = j[key];
        if (!a.is_array()) {
            bad(std::string("\"") + key + "\" is not a list of paths");
            return;
        }
        for (const nlohmann::json& e : a) {
            if (!e.is_string() || e.get_ref<const std::string&>().empty() ||
                e.get_ref<const std::string&>().size() > kMaxPathBytes || !fs::path(e.get<std::string>()).is_absolute()) {
                bad(std::string("\"") + key + "\" holds an entry that is not an absolute path");
                continue;
            }
            const fs::path p(e.get<std::string>());
            if (std::find(list.begin(), list.end(), p) == list.end() && list.size() < ViewerSettingsFile::kMaxRecent)
                list.push_back(p);
        }
    };
    read_list("recent_scenes", out.settings.scenes);
    read_list("recent_images", out.settings.images);
    if (j.contains("ui_scale")) {
        const nlohmann::json& s = j["ui_scale"];
        if (s.is_number() && std::isfinite(s.get<double>()) && s.get<double>() >= ViewerSettingsFile::kMinUiScale &&
            s.get<double>() <= ViewerSettingsFile::kMaxUiScale)
            out.settings.ui_scale = s.get<double>();
        else
            bad("\"ui_scale\" is not a number from 0.5 to 3");
    }
    return out;
}

void write_settings_file(const fs::path& file, const ViewerSettingsFile& settings) {
    nlohmann::json j = nlohmann::json::object();
    auto list = [](const std::vector<fs::path>& paths) {
        nlohmann::json a = nlohmann::json::array();
        for (const fs::path& p : paths) a.push_back(utf8_escaped(p.string()));
        return a;
    };
    j["recent_scenes"] = list(settings.scenes);
    j["recent_images"] = list(settings.images);
    if (settings.ui_scale) j["ui_scale"] = *settings.ui_scale;
    std::error_code ec;
    fs::create_directories(file.parent_path(), ec);
    if (ec) throw std::runtime_error(quoted_path(file.parent_path()) + ": cannot make the folder (" + ec.message() + ")");
    write_file_atomic(file, j.dump(2) + "\n");
}

// ---- Drops ----

std::vector<DropAction> plan_drop(const std::vector<fs::path>& files) {
    std::vector<DropAction> actions;
    bool scene = false, image = false;
    for (const fs::path& f : files) {
        DropAction a;
        a.file = f;
        std::error_code ec;
        const std::string name = quoted_path(f);
        if (fs::is_directory(f, ec)) {
            a.error = name + ": a folder; drop a scene (*.json) or an image";
        } else if (!fs::exists(f, ec)) {
            a.error = name + ": no such file";
        } else if (!fs::is_regular_file(f, ec)) {
            // A FIFO or a device would block the window's thread on its first read.
            a.error = name + ": not a regular file; nothing opened";
        } else if (matches_filter(f, FilePurpose::open_scene)) {
            if (scene) a.error = name + ": one scene opens at a time; not opened";
            else a.kind = DropAction::scene, scene = true;
        } else if (matches_filter(f, FilePurpose::open_image)) {
            if (image) a.error = name + ": one image B at a time; not loaded";
            else a.kind = DropAction::image, image = true;
        } else {
            a.error = name + ": not a scene (*.json) or an image " + filter_words(FilePurpose::open_image).substr(7) +
                      "; nothing opened";
        }
        actions.push_back(std::move(a));
    }
    return actions;
}

// ---- The platform's chooser ----

fs::path find_on_path(const std::string& program) {
    if (program.empty()) return {};
    if (program.find('/') != std::string::npos) return ::access(program.c_str(), X_OK) == 0 ? fs::path(program) : fs::path();
    const char* path = std::getenv("PATH");
    if (!path) return {};
    std::string dirs(path);
    for (size_t start = 0; start <= dirs.size();) {
        const size_t end = std::min(dirs.find(':', start), dirs.size());
        const std::string dir = dirs.substr(start, end - start);
        const fs::path candidate = fs::path(dir.empty() ? "." : dir) / program;
        std::error_code ec;
        if (fs::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0) return candidate;
        start = end + 1;
    }
    return {};
}

std::string native_chooser() {
    const char* choice = std::getenv("KEITHRAY_FILE_CHOOSER");
    const std::string want = choice ? choice : "";
    if (want == "builtin") return {};
    if (!want.empty() && want != "zenity") return {};  // an unknown one: the browser
    return find_on_path("zenity").empty() ? std::string() : std::string("zenity");
}

std::vector<std::string> zenity_arguments(FilePurpose purpose, const fs::path& folder, const std::string& name) {
    std::vector<std::string> args{"zenity", "--file-selection", std::string("--title=keithray: ") + purpose_title(purpose)};
    if (purpose_saves(purpose)) args.push_back("--save");
    // zenity opens the folder of --filename; a trailing slash names the folder itself.
    std::string start = name.empty() ? folder.string() : (folder / name).string();
    if (name.empty() && (start.empty() || start.back() != '/')) start += '/';
    args.push_back("--filename=" + start);
    std::string patterns;
    if (is_scene_purpose(purpose)) patterns = "*.json";
    else
        for (const ImageFormatInfo& f : kImageFormats) {
            const std::string ext = f.extension;
            patterns += (patterns.empty() ? "" : " ") + std::string("*") + ext;
            std::string upper = ext;
            std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char c) { return char(std::toupper(c)); });
            patterns += " *" + upper;
        }
    args.push_back(std::string("--file-filter=") + (is_scene_purpose(purpose) ? "Scenes" : "Images") + " | " + patterns);
    args.push_back("--file-filter=All files | *");
    return args;
}

ChildChooser::~ChildChooser() {
    if (pid_ > 0) {
        ::kill(pid_, SIGTERM);
        int status = 0;
        ::waitpid(pid_, &status, 0);
    }
    if (out_ >= 0) ::close(out_);
}

bool ChildChooser::start(const std::vector<std::string>& argv, FilePurpose purpose) {
    error.clear();
    output_.clear();
    purpose_ = purpose;
    if (pid_ > 0 || argv.empty()) {
        error = argv.empty() ? "no chooser to run" : "a file chooser is already open";
        return false;
    }
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) {
        error = std::string("cannot run ") + argv[0] + ": " + std::strerror(errno);
        return false;
    }
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    // Its toolkit's warnings are not the viewer's: only the answer (stdout) and the status count.
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    pid_t pid = -1;
    const int rc = ::posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(fds[1]);
    if (rc != 0) {
        ::close(fds[0]);
        error = std::string("cannot run ") + argv[0] + ": " + std::strerror(rc);
        return false;
    }
    ::fcntl(fds[0], F_SETFL, ::fcntl(fds[0], F_GETFL) | O_NONBLOCK);
    pid_ = pid;
    out_ = fds[0];
    return true;
}

std::optional<ChildChooser::Result> ChildChooser::finish(int status) {
    pid_ = -1;
    // The rest of its output (it has ended: the pipe's end is near).
    if (out_ >= 0) {
        ::fcntl(out_, F_SETFL, ::fcntl(out_, F_GETFL) & ~O_NONBLOCK);
        char buf[4096];
        for (ssize_t n; (n = ::read(out_, buf, sizeof buf)) > 0;)
            if (output_.size() < 2 * kMaxPathBytes) output_.append(buf, size_t(n));
        ::close(out_);
        out_ = -1;
    }
    Result r;
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
        std::string line = output_.substr(0, output_.find('\n'));
        if (line.empty()) r.error = "the file chooser chose no file";
        else if (line.size() > kMaxPathBytes) r.error = "the file chooser's answer is too long for a path";
        else r.file = fs::path(line);
    } else if (WIFEXITED(status) && WEXITSTATUS(status) == 1) {
        // Cancel (or the window closed): nothing chosen, nothing to say.
    } else {
        r.error = WIFEXITED(status) ? "the file chooser failed (exit status " + std::to_string(WEXITSTATUS(status)) + ")"
                                    : "the file chooser ended by a signal";
    }
    return r;
}

std::optional<ChildChooser::Result> ChildChooser::poll() {
    if (pid_ <= 0) return std::nullopt;
    char buf[4096];
    for (ssize_t n; (n = ::read(out_, buf, sizeof buf)) > 0;)
        if (output_.size() < 2 * kMaxPathBytes) output_.append(buf, size_t(n));
    int status = 0;
    const pid_t done = ::waitpid(pid_, &status, WNOHANG);
    if (done == 0) return std::nullopt;
    if (done < 0) status = 0xff00;  // lost: an error
    return finish(status);
}

ChildChooser::Result ChildChooser::wait() {
    if (pid_ <= 0) return {};
    int status = 0;
    // Drain while waiting: a full pipe would block the child.
    ::fcntl(out_, F_SETFL, ::fcntl(out_, F_GETFL) & ~O_NONBLOCK);
    char buf[4096];
    for (ssize_t n; (n = ::read(out_, buf, sizeof buf)) > 0;)
        if (output_.size() < 2 * kMaxPathBytes) output_.append(buf, size_t(n));
    if (::waitpid(pid_, &status, 0) < 0) status = 0xff00;
    return *finish(status);
}

}  // namespace kr::viewer
