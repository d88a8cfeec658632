#include "core/module.h"

#include <dlfcn.h>

#include <map>
#include <mutex>
#include <stdexcept>
#include <system_error>

#include "core/data_dir.h"

// The install's bin/ to its lib/keithray/, relative (CMakeLists.txt: GNUInstallDirs' BINDIR
// and LIBDIR), so the tree may be installed under any prefix or copied whole.
#ifndef KEITHRAY_MODULES_FROM_BIN
#define KEITHRAY_MODULES_FROM_BIN "../lib/keithray"
#endif
#ifndef KEITHRAY_MODULE_VERSION
#define KEITHRAY_MODULE_VERSION "unversioned"
#endif

namespace kr {

namespace fs = std::filesystem;

namespace {

std::string file_name(const std::string& name) { return "keithray_" + name + ".so"; }

}  // namespace

const char* module_version() { return KEITHRAY_MODULE_VERSION; }

fs::path installed_modules_from_bin() { return KEITHRAY_MODULES_FROM_BIN; }

fs::path module_path(const std::string& name) { return find_module(executable_dir(), name); }

fs::path find_module(const fs::path& bin, const std::string& name) {
    const fs::path installed = (bin / KEITHRAY_MODULES_FROM_BIN / file_name(name)).lexically_normal();
    std::error_code ec;
    if (fs::is_regular_file(installed, ec)) return installed;
    const fs::path built = marker_target(bin / kModuleMarker);
    if (!built.empty() && fs::is_regular_file(built / file_name(name), ec)) return (built / file_name(name)).lexically_normal();
    return installed;
}

const void* load_module(const std::string& name, const void* host, const char* what, const char* needs) {
    // Loaded once: the tables live as long as the process (a module is never closed: its
    // code runs until exit, in Embree's callbacks and the viewer's threads).
    static std::mutex mutex;
    static std::map<std::string, const void*> loaded;
    const std::lock_guard<std::mutex> lock(mutex);
    if (const auto found = loaded.find(name); found != loaded.end()) return found->second;
    const fs::path path = module_path(name);
    const std::string shown = path.string();
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
        throw std::runtime_error(std::string(what) + ": its module " + shown + " is missing (reinstall keithray)");
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
        const char* why = dlerror();
        throw std::runtime_error(std::string(what) + ": cannot load its module " + shown + ": " +
                                 (why ? why : "unknown error") + " (it needs " + needs + ")");
    }
    const std::string symbol = "keithray_" + name + "_module";
    const auto entry = reinterpret_cast<ModuleEntry>(dlsym(handle, symbol.c_str()));
    const void* table = entry ? entry(module_version(), host) : nullptr;
    if (!table) {
        dlclose(handle);
        throw std::runtime_error(std::string(what) + ": the module " + shown + " is not of this keithray " +
                                 module_version() + " (expected its entry point " + symbol + "; reinstall keithray)");
    }
    loaded.emplace(name, table);
    return table;
}

}  // namespace kr
