#!/usr/bin/env bash
# The main job: set up, build, and render the default scene headless.
# Usage: scripts/run.sh [SCENE.json] [keithray render options]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scene=${1:-res/scenes/assignment_03.json}
shift || true
exec build/keithray render "$scene" "$@"
