// `keithray bench`: measurements that print figures (never pass/fail).
#pragma once

#include <filesystem>
#include <vector>

namespace kr {

// Every *.json in res/scenes (from the working directory, else the source tree), sorted.
std::vector<std::filesystem::path> default_scenes();

// argv[1] is "bench". Returns the process exit status.
int run_bench(int argc, char** argv);

}  // namespace kr
