#!/usr/bin/env bash
# Fidelity benchmark: renders each reference scene at its own sample count and prints its
# PSNR against the brief's reference and the render time. Extra arguments go to render.
# Usage: scripts/fidelity.sh [render options]   (e.g. --light-sampling cone)
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/keithray ] || scripts/setup.sh
out=$(mktemp -d)
printf '| scene | renderer | spp | seconds | PSNR (dB) |\n|---|---|---|---|---|\n'
for scene in res/scenes/assignment_0*.json; do
  name=$(basename "$scene" .json)
  line=$(build/keithray render "$scene" -q -o "$out/$name.ppm" "$@")
  db=$(build/keithray psnr "$out/$name.ppm" "res/references/$name.ppm")
  # line: "NAME: WxH INTEGRATOR N spp, S s, ..."
  read -r _ _ integrator spp _ seconds _ <<<"$line"
  printf '| %s | %s | %s | %s | %s |\n' "$name" "$integrator" "$spp" "$seconds" "$db"
done
rm -rf "$out"
