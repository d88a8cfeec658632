// keithray's optional parts, built as shared objects and loaded only by a command that uses
// them (docs/architecture.md, "Modules"): the viewer (GLFW, Dear ImGui, OSMesa), the MPI
// cluster side (Open MPI) and Embree's BVH. The program itself links none of their
// libraries, so `keithray --help`, `compare` or a small render start without loading them.
//
// A module is found from the executable's own path: the install's lib/keithray/ at its
// place relative to bin/ (GNUInstallDirs), else the build tree's folder named in the marker
// file `kModuleMarker` that CMake writes beside a build's binaries (never installed). No path
// of the build machine is compiled in.
#pragma once

#include <filesystem>
#include <string>

namespace kr {

inline constexpr const char* kModuleMarker = "keithray-modules.path";

// Every module's entry point is `extern "C" const void* keithray_<name>_module(const char*
// version, const void* host)`: it returns its table of functions, or nullptr where `version`
// is not the one it was built with (a module of another build). `host` is what the loader
// passes the module (see each module's header).
using ModuleEntry = const void* (*)(const char* version, const void* host);

// The version string the program and its modules are built with (CMakeLists.txt).
const char* module_version();

// Where module `name` ("viewer", "mpi", "embree") is looked for: its path in the install
// tree if that file exists, else the build tree's (the marker's folder), else the install
// tree's path (for messages).
std::filesystem::path module_path(const std::string& name);
std::filesystem::path find_module(const std::filesystem::path& executable_folder, const std::string& name);

// The path from the install's bin/ to its lib/keithray/, as CMake computed it.
std::filesystem::path installed_modules_from_bin();

// Loads module `name` once per process and returns its table (never unloaded). Throws
// std::runtime_error with one line naming the module's file and why it cannot be used (not
// found, a library it needs missing, another build's module): `what` names the module for
// the message ("the viewer", "Embree") and `needs` the Debian package that holds its
// libraries.
const void* load_module(const std::string& name, const void* host, const char* what, const char* needs);

}  // namespace kr
