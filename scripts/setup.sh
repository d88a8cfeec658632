#!/usr/bin/env bash
# Installs the Debian 12 packages keithray needs, only those missing (sudo when not root),
# then configures and builds into build/. Usage: scripts/setup.sh [extra cmake args]
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(cmake g++ make pkg-config nlohmann-json3-dev libgtest-dev
          # OpenEXR: HDR output (-o OUT.exr) and reading it back (psnr, compare)
          libopenexr-dev
          # Embree: ray casting in scenes of more than 32 spheres (optional to CMake)
          libembree-dev
          # PNG reading and writing (src/core/image_io.cpp)
          libstb-dev
          # Open MPI: one render shared by many processes (mpirun -np N keithray render)
          libopenmpi-dev openmpi-bin
          # the viewer (keithray view) and its offscreen display (render --gl), and
          # the X server its window tests run under, with xdotool for real input events
          libglfw3-dev libgl-dev libosmesa6-dev libimgui-dev xvfb xdotool xauth
          # python3 reads a window back from the X server for the window tests (tests/x_window_shot.py)
          # and drops files on it (tests/x_drop.py); xprop sets the test X server's Xft.dpi
          # (the UI-scale window test)
          python3 x11-utils
          # the install tests (tests/install_check.sh): the Debian package's dependencies
          # (dpkg-shlibdeps, which CPack runs), the man page shown with man -l, the desktop
          # entry checked by desktop-file-validate
          dpkg-dev man-db desktop-file-utils
          # the sanitizer and fuzzing builds (scripts/check_sanitizers.sh): clang, its
          # sanitizer and libFuzzer runtimes, its OpenMP runtime (whose archer tool makes
          # OpenMP visible to ThreadSanitizer) and llvm-symbolizer for the reports' stacks
          clang libclang-rt-14-dev libomp-14-dev llvm)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get install -y --no-install-recommends "${missing[@]}" ||
    { "${sudo_cmd[@]}" apt-get update && "${sudo_cmd[@]}" apt-get install -y --no-install-recommends "${missing[@]}"; }
fi

# Configure quietly, but never hide what CMake warns about (e.g. Embree missing): on a
# warning or an error the whole configure log is shown.
configure_log=$(mktemp)
trap 'rm -f "$configure_log"' EXIT
if ! cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "$@" >"$configure_log" 2>&1; then
  cat "$configure_log" >&2
  exit 1
fi
if grep -qE "CMake (Warning|Deprecation Warning)|^WARNING" "$configure_log"; then
  cat "$configure_log" >&2
fi
cmake --build build -j"$(nproc)"
