// `keithray render` (render_command.cpp): scenes rendered headless into image files, one
// scene at a time, with checkpoints, stop rules and, under mpirun, the ranks sharing each.
#pragma once

#include <string>

namespace kr {

// argv[1] is "render": scenes and flags (render_options_help); `help` is what --help prints
// (keithray's usage, whose options are render's). Returns the exit status, the same in
// every rank.
int run_render(int argc, char** argv, const std::string& help);

// render's help text after the synopsis: its introduction, the flags it shares with view
// (render/options.h) and its own. The man page and the completion are made from it (app/docs.h).
std::string render_options_help();
// render's introduction, before its options (the man page's description starts with it).
const char* render_intro();

}  // namespace kr
