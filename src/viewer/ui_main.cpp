// `keithray view`: the command line (viewer/view_options.h) and the top-level error handling.
#include <cstdio>
#include <exception>
#include <string>

#include "core/memory.h"
#include "core/text.h"
#include "viewer/ui_app.h"
#include "viewer/view_options.h"
#include "viewer/viewer.h"

namespace kr::viewer {

int run_viewer(int argc, char** argv, SharedPasses* ranks) {
    ViewOptions options;
    try {
        options = parse_view_options(argc, argv);
    } catch (const UsageError& e) {
        std::fprintf(stderr, "error: %s\nRun 'keithray view --help' for the options.\n", e.message.c_str());
        return 2;
    }
    if (options.help) {
        std::fputs(view_usage().c_str(), stdout);
        return 0;  // the caller checks that standard output took it
    }
    if (const std::string problem = view_files_problem(options); !problem.empty()) {
        std::fprintf(stderr, "error: %s; nothing opened or written\n", problem.c_str());
        return 1;
    }
    const std::filesystem::path scene = options.scene;
    try {
        ViewerApp app(std::move(options), ranks);
        return app.run();
    } catch (const std::exception& e) {
        if (is_out_of_memory(e))
            std::fprintf(stderr, "error: %s: not enough memory for the viewer's images\n", show_user_text(scene.string()).c_str());
        else
            std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
}

}  // namespace kr::viewer
