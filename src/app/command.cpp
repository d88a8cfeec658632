// What every command of the keithray program shares: file paths in messages, the OpenMP
// team started first, and whether standard output took everything printed.
#include "app/command.h"

#include <cerrno>
#include <cstdio>
#include <cstring>

#include <omp.h>

#include "core/memory.h"
#include "core/text.h"

namespace kr {

std::string shown_path(const std::filesystem::path& path) { return show_user_text(path.string()); }

bool team_started(const std::string& file) {
    const int wanted = omp_get_max_threads(), started = start_thread_team();
    if (started == wanted) return true;
    std::fprintf(stderr, "error: %s: not enough memory for the stacks of %d threads, only of %d (--threads %d, or OMP_NUM_THREADS=%d)\n",
                 file.c_str(), wanted, started, started, started);
    return false;
}

bool stdout_written() {
    if (std::fflush(stdout) == 0 && !std::ferror(stdout)) return true;
    const int err = errno;
    std::fprintf(stderr, "error: cannot write the results to standard output: %s\n",
                 err ? std::strerror(err) : "write error");
    return false;
}

}  // namespace kr
