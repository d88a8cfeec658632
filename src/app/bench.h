// `keithray bench`: measurements that print figures (never pass/fail).
#pragma once

#include <filesystem>
#include <vector>

namespace kr {

// argv[1] is "bench". Returns the process exit status.
int run_bench(int argc, char** argv);

// `keithray bench --convergence ...` (convergence.cpp): error against a converged reference
// as samples and seconds grow, per configuration.
int bench_convergence(int argc, char** argv);

// Their help texts (`keithray bench --help`, `keithray bench --convergence --help`), which
// the man page and the shell completion are made from (app/docs.h).
const char* bench_usage();
const char* convergence_usage();

}  // namespace kr
