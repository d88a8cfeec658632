// A benchmark's main: --help prints its usage; a bad argument or scene file (an exception
// from `run`) is one line on stderr and exit status 1, not an abort.
#pragma once

#include <cstdio>
#include <exception>
#include <string_view>

namespace kr::bench {

inline int bench_main(int argc, char** argv, const char* name, const char* usage, int (*run)(int, char**)) {
    for (int i = 1; i < argc; ++i)
        if (std::string_view(argv[i]) == "--help" || std::string_view(argv[i]) == "-h") {
            std::printf("usage: %s %s\n", name, usage);
            return 0;
        }
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: %s\n", name, e.what());
        return 1;
    }
}

}  // namespace kr::bench
