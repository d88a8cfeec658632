#!/usr/bin/env bash
# The Debian package: sets up and builds (scripts/setup.sh), then `cpack -G DEB` in build/
# writes build/keithray_VERSION_ARCH.deb, installable on Debian 12 with
# `sudo apt-get install ./build/keithray_*.deb` (docs/install.md).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
(cd build && cpack -G DEB)
ls build/keithray_*.deb
