// The one way keithray writes a file: whole or not at all, and several files together.
//
// Every target is checked before anything is written, each file's bytes go to a temporary
// file beside its target (same folder, so the rename is atomic), are flushed to disk, and
// only when every temporary is complete are they renamed onto their targets. On any
// failure every temporary is removed and the targets are as they were. A temporary never
// outlives SIGINT, SIGTERM, SIGHUP or SIGXFSZ: a signal handler removes the live ones and
// then lets the signal do what it did before.
//
// Targets, decided:
// - absent: created with the usual 0666 & ~umask mode; missing parent folders are created
//   (and removed again when the write fails);
// - a regular file: replaced, keeping its permission bits; a read-only one (no write bit,
//   or not writable by this user) is refused, never replaced;
// - a symbolic link: followed; the file it names is the target (the link stays), and a
//   link to nothing is refused;
// - anything else (a folder, a character or block device such as /dev/null, a FIFO, a
//   socket): refused, never replaced or written through;
// - an empty path, a NUL byte in the path, a name longer than the file system allows, or
//   the same file twice in one call: refused.
// Errors are std::runtime_error, one line naming the file and what was expected.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace kr {

struct FileOutput {
    std::filesystem::path path;
    std::string bytes;
};

// Writes all `files` or none of them (see above). The only window where some but not all
// targets are replaced is a rename failing after another succeeded, which checked targets
// in existing folders do not do short of a crash of the machine.
void write_files_atomic(const std::vector<FileOutput>& files);

// The one-file case of write_files_atomic.
void write_file_atomic(const std::filesystem::path& path, const std::string& bytes);

// ---- Signals over a whole run ----------------------------------------------------------
//
// One handler for SIGINT, SIGTERM, SIGHUP and SIGXFSZ, installed once per process and never
// replaced: it removes the live temporaries of every write, then lets the signal do what it
// did before (its default action, re-raised, or the handler the program had then). A command
// installs it at its start, so that it covers every write from the first to the last
// (write_files_atomic installs it too); nothing may install another handler for these.
void install_signal_cleanup();

// While a StopOnSignal is active (a checkpointed render's passes), SIGINT and SIGTERM ask the
// run to stop: the first is only recorded (stop_signal()), and the run stops where it
// chooses; a write under way meanwhile completes or is undone by its writer, never left
// half. A second signal acts as without (temporaries removed, the signal's own action).
class StopOnSignal {
public:
    explicit StopOnSignal(bool active);
    ~StopOnSignal() { release(); }
    // From here on a signal ends the run at once again (the recorded one stays recorded).
    void release();
    StopOnSignal(const StopOnSignal&) = delete;
    StopOnSignal& operator=(const StopOnSignal&) = delete;

private:
    bool active_;
};

// The signal recorded while a StopOnSignal was active, else 0.
int stop_signal();

// Checks every target as write_files_atomic does before it writes (a folder, a device, a
// FIFO, a read-only file, a bad name are refused), writing nothing: for outputs written only
// after a long render (the images, a checkpoint). Throws std::runtime_error as it does.
void check_output_targets(const std::vector<std::filesystem::path>& paths);

// Whether writing path `a` would replace the existing file `b`: the same file under another
// name (hard or symbolic links), or the same path once resolved, e.g. "x/../scene.json"
// through a folder x that does not exist yet (the writer would create it). Only stats files:
// it never opens one (a FIFO does not block it).
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);

// A path for a message: quoted, control bytes escaped, at most about 200 bytes shown.
std::string quoted_path(const std::filesystem::path& path);

}  // namespace kr
