#!/usr/bin/env bash
# A benchmark of the viewer (prints figures, asserts nothing): for scenes 3 and 6, the
# viewer's idle CPU once the render is done and once paused (% of one core over 10 s with no
# input), and the latency from an orbit edit to the first frame of the new image on screen
# (median and 90th percentile over 30 edits). Runs a real window under Xvfb. Then the
# per-frame cost of the inspect and compare tools (bench/compare_tools.cpp) and of the
# feature views (bench/feature_views.cpp).
# Usage: scripts/bench_viewer.sh [build/keithray]   (docs/viewer.md records its figures)
set -euo pipefail
cd "$(dirname "$0")/.."
exe=${1:-build/keithray}
for n in 3 6; do
  scene=res/scenes/assignment_0$n.json
  echo "== $scene"
  xvfb-run -a -s "-screen 0 1280x1024x24" "$exe" view "$scene" --spp 4 --measure-idle 10 2>/dev/null |
    grep -i "idle\|core" || true
  xvfb-run -a -s "-screen 0 1280x1024x24" "$exe" view "$scene" --measure-latency 30 2>/dev/null |
    grep "^latency" || true
done
echo "== inspect and compare, per full-resolution frame"
cmake --build "$(dirname "$exe")" --target keithray_bench_compare >/dev/null
"$(dirname "$exe")/keithray_bench_compare"
echo "== feature views (albedo, normal, depth)"
cmake --build "$(dirname "$exe")" --target keithray_bench_features >/dev/null
"$(dirname "$exe")/keithray_bench_features" res/scenes/assignment_03.json
