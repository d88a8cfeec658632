#include "core/file_write.h"

#include <atomic>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <system_error>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/text.h"

namespace fs = std::filesystem;

namespace kr {

// ---- Temporary files that a signal must not leave behind ------------------------------
//
// A fixed table of path buffers, so the handler touches no heap and no lock: a slot is
// free (0), being filled (1), live (2), or taken by the handler (3). The owner registers a
// temporary before creating it and releases it after the rename or unlink; a slot the
// handler took is never reused (the process is about to end).
namespace {

constexpr int kTempSlots = 64;
struct TempSlot {
    std::atomic<int> state{0};
    char path[PATH_MAX];
};
TempSlot g_temp_slots[kTempSlots];

constexpr int kCleanupSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGXFSZ};
constexpr int kSignalCount = sizeof(kCleanupSignals) / sizeof(kCleanupSignals[0]);
struct sigaction g_previous_action[kSignalCount];
std::atomic<bool> g_stop_mode{false};  // a StopOnSignal is active
std::atomic<int> g_stop_signal{0};     // the signal it recorded
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free,
              "read and written by a signal handler");

void remove_live_temps() {
    for (TempSlot& slot : g_temp_slots) {
        int live = 2;
        if (slot.state.compare_exchange_strong(live, 3)) ::unlink(slot.path);  // async-signal-safe
    }
}

// Removes the live temporaries, then hands the signal to what handled it before: the
// default action (re-raised with it restored, so the exit status still says "killed by
// SIGTERM") or the program's own handler.
void on_cleanup_signal(int sig, siginfo_t* info, void* context) {
    if (g_stop_mode.load() && (sig == SIGINT || sig == SIGTERM)) {
        int none = 0;
        if (g_stop_signal.compare_exchange_strong(none, sig)) return;  // the first: a request to stop
    }
    remove_live_temps();
    for (int i = 0; i < kSignalCount; ++i) {
        if (kCleanupSignals[i] != sig) continue;
        const struct sigaction& previous = g_previous_action[i];
        if (previous.sa_flags & SA_SIGINFO) {
            previous.sa_sigaction(sig, info, context);
        } else if (previous.sa_handler != SIG_DFL && previous.sa_handler != SIG_IGN) {
            previous.sa_handler(sig);
        } else {
            ::sigaction(sig, &previous, nullptr);
            ::raise(sig);  // blocked until this handler returns, then acts by default
        }
    }
}

}  // namespace

void install_signal_cleanup() {
    static std::once_flag once;
    std::call_once(once, [] {
        for (int i = 0; i < kSignalCount; ++i) {
            struct sigaction current {};
            ::sigaction(kCleanupSignals[i], nullptr, &current);
            // An ignored signal (nohup's SIGHUP, a shell's `trap '' XFSZ`) stays ignored.
            if (!(current.sa_flags & SA_SIGINFO) && current.sa_handler == SIG_IGN) continue;
            g_previous_action[i] = current;
            struct sigaction action {};
            action.sa_sigaction = on_cleanup_signal;
            action.sa_flags = SA_SIGINFO | SA_RESTART;
            sigemptyset(&action.sa_mask);
            ::sigaction(kCleanupSignals[i], &action, nullptr);
        }
    });
}

StopOnSignal::StopOnSignal(bool active) : active_(active) {
    if (!active_) return;
    install_signal_cleanup();
    g_stop_mode.store(true);
}

void StopOnSignal::release() {
    if (active_) g_stop_mode.store(false);
    active_ = false;
}

int stop_signal() { return g_stop_signal.load(); }

namespace {

int register_temp(const std::string& path) {
    if (path.size() >= PATH_MAX) return -1;
    for (int i = 0; i < kTempSlots; ++i) {
        int free_slot = 0;
        if (!g_temp_slots[i].state.compare_exchange_strong(free_slot, 1)) continue;
        std::memcpy(g_temp_slots[i].path, path.c_str(), path.size() + 1);
        g_temp_slots[i].state.store(2);
        return i;
    }
    return -1;
}

void release_temp(int slot) {
    int live = 2;
    g_temp_slots[slot].state.compare_exchange_strong(live, 0);
}

// ---- Checking targets ----------------------------------------------------------------

std::string errno_text(int err) { return std::error_code(err, std::generic_category()).message(); }

std::runtime_error file_error(const fs::path& path, const std::string& what) {
    return std::runtime_error(quoted_path(path) + ": " + what);
}

const char* kind_of(mode_t mode) {
    if (S_ISDIR(mode)) return "a folder";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a regular file";
}

long name_max_in(const fs::path& folder) {
    const long limit = ::pathconf(folder.c_str(), _PC_NAME_MAX);
    return limit > 0 ? limit : 255;
}

// One target after its checks: where the bytes go, the folders to create first, the
// temporary's name, and the mode to keep when an old file is replaced.
struct Target {
    fs::path shown;  // as the caller named it, for messages
    fs::path path;   // symbolic links resolved
    std::vector<fs::path> missing_folders;  // outermost first
    fs::path temp;
    bool replaces = false;
    mode_t mode = 0;
};

Target check_target(const fs::path& requested) {
    Target t;
    t.shown = requested;
    if (requested.empty()) throw std::runtime_error("an empty output path; expected a file name");
    if (requested.native().find('\0') != std::string::npos)
        throw file_error(requested, "a file name cannot contain a NUL byte");
    const fs::path name = requested.filename();
    if (name.empty() || name == "." || name == "..")
        throw file_error(requested, "expected a file name, not a folder");
    if (requested.native().size() >= PATH_MAX)
        throw file_error(requested, "the path is " + std::to_string(requested.native().size()) +
                                        " bytes; the limit is " + std::to_string(PATH_MAX - 1));

    // Every name in the path within the file system's limit (that of the nearest existing
    // folder), checked first: lstat would only say "File name too long".
    fs::path existing = requested.parent_path();
    while (!existing.empty() && ::access(existing.c_str(), F_OK) != 0) existing = existing.parent_path();
    const long name_max = name_max_in(existing.empty() ? fs::path(".") : existing);
    for (const fs::path& part : requested)
        if (long(part.native().size()) > name_max)
            throw file_error(requested, "the name " + quoted_path(part) + " is " + std::to_string(part.native().size()) +
                                            " bytes; this file system allows " + std::to_string(name_max));

    t.path = requested;
    struct stat st {};
    if (::lstat(t.path.c_str(), &st) == 0 && S_ISLNK(st.st_mode)) {
        std::error_code ec;
        const fs::path resolved = fs::canonical(t.path, ec);
        if (ec) throw file_error(requested, "a symbolic link to nothing; expected a file or a link to one");
        t.path = resolved;
    }
    if (::lstat(t.path.c_str(), &st) == 0) {
        if (!S_ISREG(st.st_mode))
            throw file_error(requested, std::string("is ") + kind_of(st.st_mode) +
                                            "; expected a regular file or a new name (it is never replaced)");
        // Read-only: no write bit at all (root could write it anyway), or not writable by us.
        if ((st.st_mode & 0222) == 0 || (::access(t.path.c_str(), W_OK) != 0 && errno != EROFS))
            throw file_error(requested, "is read-only; make it writable or remove it to replace it");
        t.replaces = true;
        t.mode = st.st_mode & 0777;
    } else if (errno != ENOENT) {
        const int err = errno;
        if (err == ENOTDIR) throw file_error(requested, "a folder in the path is a file");
        throw file_error(requested, "cannot be examined: " + errno_text(err));
    }

    // The folder: every existing ancestor must be a folder; the missing ones are created.
    fs::path folder = t.path.parent_path();
    if (folder.empty()) folder = ".";
    existing = folder;
    for (;;) {
        struct stat dir_stat {};
        if (::stat(existing.c_str(), &dir_stat) == 0) {
            if (!S_ISDIR(dir_stat.st_mode))
                throw file_error(requested, quoted_path(existing) + " is " + kind_of(dir_stat.st_mode) +
                                                ", expected a folder");
            break;
        }
        if (errno != ENOENT) throw file_error(requested, "its folder cannot be examined: " + errno_text(errno));
        t.missing_folders.insert(t.missing_folders.begin(), existing);
        const fs::path up = existing.parent_path();
        existing = up.empty() || up == existing ? fs::path(".") : up;
    }

    // The temporary: hidden, beside the target, unique by process and call, and short
    // enough for the file system however long the target's name is.
    static std::atomic<unsigned long> counter{0};
    const std::string suffix =
        ".tmp" + std::to_string(long(::getpid())) + "-" + std::to_string(counter.fetch_add(1));
    std::string stem = t.path.filename().native();
    const size_t room = size_t(name_max) - 1 - suffix.size();
    if (stem.size() > room) stem.resize(room);
    t.temp = t.path.parent_path() / ("." + stem + suffix);
    return t;
}

// Writes every byte to `fd`, then flushes it to the disk: a full disk, a file size limit or
// an I/O error shows here, not after the rename.
void write_all(int fd, const std::string& bytes, const Target& t) {
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) throw file_error(t.shown, "cannot write: " + errno_text(n < 0 ? errno : EIO));
        done += size_t(n);
    }
    if (::fsync(fd) != 0) throw file_error(t.shown, "cannot write: " + errno_text(errno));
}

// What a call has made so far, undone unless it completes.
struct Undo {
    std::vector<fs::path> folders;                // created, outermost first
    std::vector<std::pair<fs::path, int>> temps;  // path, signal slot
    bool committed = false;

    ~Undo() {
        if (committed) return;
        for (const auto& [temp, slot] : temps) {
            ::unlink(temp.c_str());
            if (slot >= 0) release_temp(slot);
        }
        for (auto it = folders.rbegin(); it != folders.rend(); ++it) ::rmdir(it->c_str());
    }
};

// For tests of signals inside a write: KEITHRAY_TEST_STOP_BEFORE_RENAME=NAME:N stops the
// process (SIGSTOP) once, in the Nth write whose targets include a file named NAME, with
// every temporary whole and none renamed yet; the test then sends its signals and SIGCONT.
void stop_before_rename_for_tests(const std::vector<Target>& targets) {
    const char* hook = std::getenv("KEITHRAY_TEST_STOP_BEFORE_RENAME");
    if (!hook) return;
    const std::string spec = hook;
    const size_t colon = spec.rfind(':');
    const std::string name = spec.substr(0, colon);
    const long nth = colon == std::string::npos ? 1 : std::atol(spec.c_str() + colon + 1);
    static std::atomic<long> seen{0};
    for (const Target& t : targets)
        if (t.path.filename() == name) {
            if (seen.fetch_add(1) + 1 == nth) ::raise(SIGSTOP);
            return;
        }
}

}  // namespace

void check_output_targets(const std::vector<fs::path>& paths) {
    for (const fs::path& path : paths) check_target(path);
}

bool same_file(const fs::path& a, const fs::path& b) {
    std::error_code ec;
    if (fs::exists(a, ec) && fs::exists(b, ec) && fs::equivalent(a, b, ec)) return true;
    auto resolved = [](const fs::path& p) {
        std::error_code e;
        const fs::path absolute = fs::absolute(p, e);
        const fs::path canonical = fs::weakly_canonical(absolute, e);
        return e ? absolute.lexically_normal() : canonical;
    };
    return resolved(a) == resolved(b);
}

std::string quoted_path(const fs::path& path) {
    const std::string& text = path.native();
    constexpr size_t kHead = 60, kTail = 140;
    if (text.size() <= kHead + kTail) return quote_user_text(text, kHead + kTail);
    // Long paths keep their start and their end (the file's own name), each escaped.
    const std::string head = quote_user_text(std::string_view(text).substr(0, kHead), kHead);
    const std::string tail = quote_user_text(std::string_view(text).substr(text.size() - kTail), kTail);
    return head.substr(0, head.size() - 1) + "..." + tail.substr(1);
}

void write_files_atomic(const std::vector<FileOutput>& files) {
    // 1. Check every target before touching anything.
    std::vector<Target> targets;
    for (const FileOutput& file : files) targets.push_back(check_target(file.path));
    for (size_t i = 0; i < targets.size(); ++i)
        for (size_t j = 0; j < i; ++j) {
            std::error_code ec;
            const fs::path a = fs::weakly_canonical(fs::absolute(targets[i].path), ec);
            const fs::path b = fs::weakly_canonical(fs::absolute(targets[j].path), ec);
            if (a == b)
                throw file_error(targets[i].shown, "named twice among the files of one write (as " +
                                                       quoted_path(targets[j].shown) + ")");
        }

    install_signal_cleanup();
    Undo undo;
    undo.temps.reserve(targets.size());
    // 2. Missing folders.
    for (const Target& t : targets)
        for (const fs::path& folder : t.missing_folders) {
            if (::mkdir(folder.c_str(), 0777) == 0) undo.folders.push_back(folder);
            else if (errno != EEXIST) throw file_error(t.shown, "cannot create its folder: " + errno_text(errno));
        }
    // 3. Every temporary, whole and on disk.
    for (size_t i = 0; i < targets.size(); ++i) {
        const Target& t = targets[i];
        const int slot = register_temp(t.temp.native());
        if (slot < 0) throw file_error(t.shown, "too many files are being written at once");
        // Registered before it exists, so no moment leaves it unlisted; a name that could not
        // be created (taken) is not ours to remove.
        const int fd = ::open(t.temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0) {
            const int err = errno;
            release_temp(slot);
            throw file_error(t.shown, "cannot create a file beside it: " + errno_text(err));
        }
        undo.temps.emplace_back(t.temp, slot);
        try {
            if (t.replaces && ::fchmod(fd, t.mode) != 0)
                throw file_error(t.shown, "cannot keep its permissions: " + errno_text(errno));
            write_all(fd, files[i].bytes, t);
        } catch (...) {
            ::close(fd);
            throw;
        }
        if (::close(fd) != 0) throw file_error(t.shown, "cannot write: " + errno_text(errno));
    }
    stop_before_rename_for_tests(targets);
    // 4. All renames together.
    for (size_t i = 0; i < targets.size(); ++i) {
        if (::rename(targets[i].temp.c_str(), targets[i].path.c_str()) != 0)
            throw file_error(targets[i].shown, "cannot replace it: " + errno_text(errno));
        release_temp(undo.temps[i].second);
        undo.temps[i].second = -1;
    }
    undo.committed = true;
}

void write_file_atomic(const fs::path& path, const std::string& bytes) { write_files_atomic({{path, bytes}}); }

}  // namespace kr
