#!/usr/bin/env bash
# Set up, build, and run the whole test suite (GoogleTest under CTest), then the same
# suite under AddressSanitizer + UBSan and ThreadSanitizer, and a bounded fuzzing run of
# the scene loader (scripts/check_sanitizers.sh; KEITHRAY_SKIP_SANITIZERS=1 skips them).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
(cd build && ctest --output-on-failure -j"$(nproc)" "$@")
if [ "${KEITHRAY_SKIP_SANITIZERS:-0}" != 1 ]; then
  scripts/check_sanitizers.sh
fi
