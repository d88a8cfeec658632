// `keithray bench`: measurements that print figures (never pass/fail).
#pragma once

namespace kr {

// argv[1] is "bench". Returns the process exit status.
int run_bench(int argc, char** argv);

}  // namespace kr
