// What every command of the keithray program shares (main.cpp's dispatch, render_command.cpp).
#pragma once

#include <filesystem>
#include <string>

namespace kr {

// A file path in a message: as it is, or quoted and escaped when it holds control
// characters, bytes that are not UTF-8 or too many of them (core/text.h).
std::string shown_path(const std::filesystem::path& path);

// The OpenMP team started before anything else (core/memory.h start_thread_team): false,
// after one line naming `file`, where the threads' stacks do not fit the address space.
bool team_started(const std::string& file);

// Whether everything printed reached standard output: a full disk or /dev/full shows only
// when the buffer is flushed. Prints the error when not.
bool stdout_written();

}  // namespace kr
