#!/usr/bin/env bash
# The main job: set up, build, then open the default scene in the viewer when a display
# is set ($DISPLAY or $WAYLAND_DISPLAY), else render it headless.
# Usage: scripts/run.sh [SCENE.json] [keithray view / render options]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scene=${1:-res/scenes/assignment_03.json}
shift || true
# The interactive viewer where there is a display; a headless render where there is none.
if [ -n "${DISPLAY:-}" ] || [ -n "${WAYLAND_DISPLAY:-}" ]; then
  exec build/keithray view "$scene" "$@"
fi
exec build/keithray render "$scene" "$@"
