// Entry point of `keithray view`: the interactive GLFW + Dear ImGui viewer.
#pragma once

namespace kr::viewer {

class SharedPasses;

// argv[1] is "view". Returns the process exit status (0 ok, 1 failure, 2 bad usage). With
// `ranks`, this process is rank 0 of an MPI job and shares the full passes with the others
// (render_worker.h).
int run_viewer(int argc, char** argv, SharedPasses* ranks = nullptr);

}  // namespace kr::viewer
