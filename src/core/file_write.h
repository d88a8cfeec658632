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

// A path for a message: quoted, control bytes escaped, at most about 200 bytes shown.
std::string quoted_path(const std::filesystem::path& path);

}  // namespace kr
