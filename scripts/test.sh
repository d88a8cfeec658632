#!/usr/bin/env bash
# Set up, build, and run the whole test suite (GoogleTest under CTest), then the same suite
# under AddressSanitizer + UBSan and under ThreadSanitizer, and a bounded fuzzing run of the
# scene loader (scripts/check_sanitizers.sh; about 10 more minutes on 2 cores).
# KEITHRAY_SANITIZERS=0 skips the sanitizer part (a quick local run; CI never sets it).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
# The benchmarks are built only when asked for: built here, none breaks unseen.
cmake --build build -j"$(nproc)" --target keithray_benches
(cd build && ctest --output-on-failure -j"$(nproc)" "$@")
if [ "${KEITHRAY_SANITIZERS:-1}" != 0 ]; then
  scripts/check_sanitizers.sh
fi
