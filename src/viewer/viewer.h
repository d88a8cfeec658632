// Entry point of `keithray view`: the interactive GLFW + Dear ImGui viewer.
#pragma once

namespace kr::viewer {

// argv[1] is "view". Returns the process exit status (0 ok, 1 failure, 2 bad usage).
int run_viewer(int argc, char** argv);

}  // namespace kr::viewer
