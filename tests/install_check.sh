#!/usr/bin/env bash
# keithray as a user installs it (docs/install.md), for the CTest tests Install.*:
#   install_check.sh tree BUILD_DIR
#       `cmake --install` into a temporary prefix, the installed tree copied elsewhere and the
#       prefix removed; then, from another folder: --version, render without a scene (the
#       bundled scenes into ./output/), render of an installed scene, compare against a
#       bundled reference, the viewer under Xvfb (its default scene, the Open list's examples,
#       Save of a read-only bundled scene), the man page, the bash completion, the desktop entry;
#       the modules in lib/keithray/ (the program links none of their libraries; each missing
#       one refused in one line).
#   install_check.sh package BUILD_DIR
#       `cpack -G DEB` into a temporary folder: the package's file list and dependencies
#       (dpkg-deb -c, -I), and the program run from its files extracted into a folder.
# Prints what failed and exits 1 on the first failure; every check is cheap (1 to 8 spp).
set -euo pipefail
mode=$1
build=$(cd "$2" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/keithray_install_$mode.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
fail() {
  echo "FAIL: $*" >&2
  exit 1
}
# The source tree's res/, which the installed program must never read (nor name).
source_res=$(head -n1 "$build/keithray-res.path")
[ -d "$source_res/scenes" ] || fail "no res/ named in $build/keithray-res.path"

# check_program ROOT: the program installed under ROOT (ROOT/bin/keithray, ROOT/share/...),
# run from a folder of its own.
check_program() {
  local root=$1 kr=$1/bin/keithray data=$1/share/keithray
  [ -x "$kr" ] || fail "no $kr"
  [ ! -e "$root/bin/keithray-res.path" ] || fail "the build's marker file was installed"
  [ ! -e "$root/bin/keithray-modules.path" ] || fail "the build's module marker file was installed"
  # The modules (core/module.h), and the program itself links none of their libraries.
  local modules version
  version=$("$kr" --version)
  modules=$(grep -o 'module [^ ,)]*keithray_viewer.so' <<<"$version" | cut -d' ' -f2)
  modules=$(dirname "$modules")
  for m in viewer $(grep -q '^MPI: yes' <<<"$version" && echo mpi) $(grep -q '^Embree: yes' <<<"$version" && echo embree); do
    [ -f "$modules/keithray_$m.so" ] || fail "no module $modules/keithray_$m.so: $version"
    case $modules in "$root"/*) ;; *) fail "the module keithray_$m.so found outside the tree: $modules" ;; esac
    if grep -aqF "$source_res" "$modules/keithray_$m.so"; then fail "keithray_$m.so holds the source tree's path"; fi
  done
  if ldd "$kr" | grep -E 'libembree|libtbb|libmpi|libOSMesa|libglfw|libGL'; then
    fail "$kr links a module's library itself"
  fi
  # Nothing compiled in leads back to the sources.
  if grep -aqF "$source_res" "$kr"; then fail "$kr holds the source tree's path $source_res"; fi
  for n in 1 2 3 4 5 6 7 8; do
    [ -f "$data/scenes/assignment_0$n.json" ] || fail "no bundled scene $n"
    [ -f "$data/references/assignment_0$n.ppm" ] || fail "no bundled reference $n"
  done
  ls "$data"/scenes/examples/*.json >/dev/null || fail "no example scenes"
  local work=$tmp/work-$(basename "$root")
  mkdir -p "$work"
  cd "$work"
  find "$root" -printf '%p %s %T@\n' | sort >"$tmp/tree.before"

  # --version and -V
  "$kr" --version >version.txt || fail "--version exit $?"
  grep -Eq '^keithray [0-9]+\.[0-9]+' version.txt || fail "--version: $(cat version.txt)"
  if grep -q ', missing)' version.txt; then fail "--version says a module is missing: $(cat version.txt)"; fi
  grep -Fq "bundled scenes: $(cd "$data" && pwd -P) (installed)" version.txt ||
    grep -Fq "bundled scenes: $data (installed)" version.txt || fail "--version names no installed scenes: $(cat version.txt)"
  for word in "build: " "SIMD kernels on this CPU: " "Embree: " "MPI: " "viewer: yes"; do
    grep -Fq "$word" version.txt || fail "--version says no \"$word\": $(cat version.txt)"
  done
  "$kr" -V | cmp -s - version.txt || fail "-V differs from --version"

  # render without a scene: every bundled scene into ./output/, never into the install tree.
  "$kr" render --spp 1 --threads 2 -q >render.out 2>render.err || fail "render without a scene: $(cat render.err)"
  grep -q "bundled scenes of .* into output/" render.err || fail "render without a scene says: $(cat render.err)"
  for n in 1 2 3 4 5 6 7 8; do
    [ -s "output/assignment_0$n.ppm" ] || fail "render without a scene wrote no output/assignment_0$n.ppm"
  done
  # An installed scene named on the command line writes into ./output/ too; the brief's
  # reference beside it judges the render (a Whitted scene: 8 spp are within 2 dB of converged).
  rm -f output/assignment_02.ppm
  "$kr" render "$data/scenes/assignment_02.json" --threads 2 -q >render2.out 2>render2.err || fail "render of scene 2: $(cat render2.err)"
  [ -s output/assignment_02.ppm ] || fail "render of an installed scene wrote no output/assignment_02.ppm: $(cat render2.out)"
  "$kr" compare output/assignment_02.ppm "$data/references/assignment_02.ppm" --min-psnr 40 >compare.out ||
    fail "compare against the bundled reference: $(cat compare.out)"
  grep -q '^agree' compare.out || fail "compare says: $(cat compare.out)"

  # The viewer under Xvfb: its default scene, then each example the Open list offers, then
  # Save of the read-only default scene (tests/viewer_input.sh drives it with xdotool).
  if command -v xvfb-run >/dev/null && command -v xdotool >/dev/null; then
    local start=$((200 + ($$ % 20000)))
    xvfb-run -a -n "$start" -s '-screen 0 1280x1024x24 -noreset' bash -c '
      kr=$1 data=$2
      "$kr" view --frames 2 --spp 2 --denoise off --save-image default.ppm --timeout 300 >view.out 2>view.err ||
        { echo "view of the default scene: exit $?: $(cat view.err)"; exit 1; }
      for scene in "$data"/scenes/examples/*.json; do
        "$kr" view "$scene" --frames 2 --spp 2 --denoise off --timeout 300 >>view.out 2>view.err ||
          { echo "view of $scene: exit $?: $(cat view.err)"; exit 1; }
      done
      bash "$3/viewer_input.sh" save_where "$kr" "$data/scenes/assignment_03.json" "$PWD" >drive.out
    ' bash "$kr" "$data" "$here" >xvfb.out 2>&1 || fail "viewer: $(tail -c 600 xvfb.out)"
    # What the viewer saved of its default scene is what render writes of assignment_03.
    "$kr" render "$data/scenes/assignment_03.json" --spp 2 --threads 2 -q -o render3.ppm >/dev/null ||
      fail "render of scene 3"
    cmp -s default.ppm render3.ppm || fail "view's default scene is not the bundled assignment_03.json"
    grep -q '^asked=save-where' drive.out || fail "Save of a bundled scene did not ask where: $(cat drive.out)"
    grep -q '^question_after=none' drive.out || fail "Save of the saved copy asked again: $(cat drive.out)"
    [ -s assignment_03.json ] || fail "Save of the bundled scene wrote no ./assignment_03.json: $(cat drive.out)"
    grep -q '"output": "output/assignment_03.ppm"' assignment_03.json ||
      fail "the saved copy's output is not output/assignment_03.ppm: $(grep '"output"' assignment_03.json)"
  else
    fail "xvfb-run or xdotool missing (scripts/setup.sh installs them)"
  fi

  # Nothing of the above wrote into the install tree.
  find "$root" -printf '%p %s %T@\n' | sort >"$tmp/tree.after"
  diff "$tmp/tree.before" "$tmp/tree.after" >/dev/null || fail "the install tree changed: $(diff "$tmp/tree.before" "$tmp/tree.after" | head -5)"
  cd "$tmp"
}

# check_docs ROOT: the man page renders and names every flag of render --help; the
# completion offers the commands, the flags and their values; the desktop entry opens the viewer.
check_docs() {
  local root=$1 man=$1/share/man/man1/keithray.1.gz comp=$1/share/bash-completion/completions/keithray
  [ -f "$man" ] || fail "no man page $man"
  LC_ALL=C MANWIDTH=100 man --warnings -l "$man" >"$tmp/man.txt" 2>"$tmp/man.err" || fail "man -l: $(cat "$tmp/man.err")"
  [ ! -s "$tmp/man.err" ] || fail "man -l warns: $(head -c 400 "$tmp/man.err")"
  local flags
  flags=$("$root/bin/keithray" render --help | grep -oE '^ +(-[a-z], )?--[a-z-]+' | grep -oE -- '--[a-z-]+')
  for flag in $flags --version --unlimited --statistical; do
    grep -q -- "$flag" "$tmp/man.txt" || fail "the man page lacks $flag"
  done
  grep -q "KEITHRAY VIEW" "$tmp/man.txt" || fail "the man page has no section for view"
  [ -f "$comp" ] || fail "no completion $comp"
  complete_words() { # the completion's answer for the words given
    bash -c 'source "$1"; shift; COMP_WORDS=("$@"); COMP_CWORD=$(($# - 1)); _keithray; printf "%s\n" "${COMPREPLY[@]}"' \
      bash "$comp" "$@"
  }
  grep -qx render <<<"$(complete_words keithray "")" || fail "completion of keithray offers no render"
  grep -qx view <<<"$(complete_words keithray "v")" || fail "completion of keithray v offers no view"
  grep -qx -- --denoise <<<"$(complete_words keithray render --de)" || fail "completion of render --de offers no --denoise"
  grep -qx -- --denoise <<<"$(complete_words keithray view --de)" || fail "completion of view --de offers no --denoise"
  [ "$(grep -cxE 'on|off' <<<"$(complete_words keithray render --denoise "")")" = 2 ] || fail "completion of --denoise offers not on, off"
  [ "$(complete_words keithray render --integrator "" | tr '\n' ' ')" = "wrt pt pt-naive " ] ||
    fail "completion of --integrator: $(complete_words keithray render --integrator "")"
  grep -qx float8 <<<"$(complete_words keithray render --kernels "")" || fail "completion of --kernels offers no float8"
  grep -qx split <<<"$(complete_words keithray view --view "")" || fail "completion of view --view offers no split"
  grep -qx -- --statistical <<<"$(complete_words keithray compare --st)" || fail "completion of compare --st"
  grep -q . <<<"$(complete_words keithray render --spp "")" && fail "completion of --spp offers something"
  local desktop=$root/share/applications/keithray.desktop
  [ -f "$desktop" ] || fail "no desktop entry"
  grep -qx 'Exec=keithray view %f' "$desktop" || fail "the desktop entry does not open the viewer"
  grep -qx 'Icon=keithray' "$desktop" || fail "the desktop entry names no icon keithray"
  [ -s "$root/share/icons/hicolor/scalable/apps/keithray.svg" ] || fail "no icon"
  if command -v desktop-file-validate >/dev/null; then
    desktop-file-validate "$desktop" || fail "desktop-file-validate"
  else
    fail "desktop-file-validate missing (scripts/setup.sh installs desktop-file-utils)"
  fi
}

case $mode in
tree)
  cmake --install "$build" --prefix "$tmp/prefix" >"$tmp/install.log" || fail "cmake --install: $(cat "$tmp/install.log")"
  cp -a "$tmp/prefix" "$tmp/copy"
  rm -rf "$tmp/prefix"
  check_docs "$tmp/copy"
  check_program "$tmp/copy"
  # The program alone, without its share/: no bundled scenes, and a clear refusal naming
  # where it looked and what to pass (exit 2), never a scene found elsewhere.
  mkdir -p "$tmp/alone/bin" "$tmp/alone/work"
  cp "$tmp/copy/bin/keithray" "$tmp/alone/bin/"
  cd "$tmp/alone/work"
  status=0
  ../bin/keithray render -q >out.txt 2>err.txt || status=$?
  [ "$status" = 2 ] || fail "render without scene or share/: exit $status"
  grep -q "no bundled scenes found (looked in .*/alone/share/keithray.*give a SCENE.json" err.txt ||
    fail "render without scene or share/ says: $(cat err.txt)"
  [ ! -e output ] || fail "render without scene or share/ wrote output/"
  # Without its lib/keithray/: what needs a module says so in one line naming the file (exit 1);
  # what does not runs.
  status=0
  ../bin/keithray view "$tmp/copy/share/keithray/scenes/assignment_03.json" >out.txt 2>err.txt || status=$?
  [ "$status" = 1 ] || fail "view without its module: exit $status"
  [ "$(wc -l <err.txt)" = 1 ] && grep -q "^error: the viewer: its module .*/alone/lib/keithray/keithray_viewer.so is missing" err.txt ||
    fail "view without its module says: $(cat err.txt)"
  status=0
  ../bin/keithray render "$tmp/copy/share/keithray/scenes/assignment_03.json" --gl --spp 1 -q -o gl.png >out.txt 2>err.txt || status=$?
  [ "$status" = 1 ] || fail "render --gl without its module: exit $status"
  [ "$(wc -l <err.txt)" = 1 ] && grep -q "^error: --gl: the viewer: its module .*keithray_viewer.so is missing" err.txt ||
    fail "render --gl without its module says: $(cat err.txt)"
  [ ! -e gl.png ] || fail "render --gl without its module wrote gl.png"
  ../bin/keithray render "$tmp/copy/share/keithray/scenes/assignment_03.json" --spp 1 -q -o plain.png >out.txt 2>err.txt ||
    fail "render without the modules: $(cat err.txt)"
  if grep -q '^Embree: yes' <("$tmp/copy/bin/keithray" --version); then
    status=0
    ../bin/keithray bench --stress 40 --accel embree --runs 1 --size 8 >out.txt 2>err.txt || status=$?
    [ "$status" = 1 ] && [ "$(wc -l <err.txt)" = 1 ] &&
      grep -q "^error: bench --accel embree: Embree: its module .*keithray_embree.so is missing" err.txt ||
      fail "bench --accel embree without its module: exit $status: $(cat err.txt)"
    # auto: our own BVH takes the scene.
    ../bin/keithray bench --stress 40 --accel auto --runs 1 --size 8 >out.txt 2>err.txt ||
      fail "bench --accel auto without Embree's module: $(cat err.txt)"
    grep -q '| 40 | own |' out.txt || fail "bench --accel auto without Embree's module: $(cat out.txt)"
  fi
  ;;
package)
  command -v dpkg-deb >/dev/null || fail "dpkg-deb missing"
  (cd "$build" && cpack -G DEB -B "$tmp/pkg" >"$tmp/cpack.log" 2>&1) || fail "cpack: $(tail -c 800 "$tmp/cpack.log")"
  deb=$(ls "$tmp"/pkg/keithray_*.deb)
  [ -f "$deb" ] || fail "cpack wrote no keithray_*.deb"
  dpkg-deb -c "$deb" | awk '{print $6}' >"$tmp/files.txt"
  for f in ./usr/bin/keithray ./usr/share/keithray/scenes/assignment_03.json \
    ./usr/share/keithray/scenes/examples/many_spheres.json ./usr/share/keithray/references/assignment_08.ppm \
    ./usr/share/man/man1/keithray.1.gz ./usr/share/bash-completion/completions/keithray \
    ./usr/share/applications/keithray.desktop ./usr/share/icons/hicolor/scalable/apps/keithray.svg \
    ./usr/share/doc/keithray/README.md ./usr/share/doc/keithray/docs/cli.md ./usr/share/doc/keithray/docs/viewer.md; do
    grep -qx -- "$f" "$tmp/files.txt" || fail "the package lacks $f"
  done
  grep -qx './usr/lib/keithray/keithray_viewer.so' "$tmp/files.txt" || fail "the package lacks the viewer module"
  if grep -q 'keithray-res.path\|keithray-modules.path\|/output/' "$tmp/files.txt"; then fail "the package holds build files: $(grep 'keithray-res.path\|keithray-modules.path\|/output/' "$tmp/files.txt")"; fi
  dpkg-deb -I "$deb" >"$tmp/info.txt"
  grep -q '^ Package: keithray$' "$tmp/info.txt" || fail "package name: $(cat "$tmp/info.txt")"
  depends=$(grep '^ Depends:' "$tmp/info.txt") || fail "the package has no Depends: $(cat "$tmp/info.txt")"
  # The libraries this build linked, the program's and its modules', as their Debian packages.
  libs=$(ldd "$build/keithray" "$build"/modules/keithray_*.so)
  for pair in "libembree3:libembree3" "libOpenEXR:libopenexr" "libglfw:libglfw3" "libOSMesa:libosmesa6" \
    "libmpi:libopenmpi" "libgomp:libgomp1" "libstdc++:libstdc++6"; do
    lib=${pair%%:*} pkg=${pair#*:}
    if grep -q "$lib" <<<"$libs"; then
      grep -q "$pkg" <<<"$depends" || fail "Depends lacks $pkg though keithray links $lib: $depends"
    fi
  done
  mkdir "$tmp/root"
  dpkg-deb -x "$deb" "$tmp/root"
  check_docs "$tmp/root/usr"
  kr=$tmp/root/usr/bin/keithray
  mkdir "$tmp/work" && cd "$tmp/work"
  grep -q "(installed)" <<<"$("$kr" --version)" || fail "the packaged keithray finds no installed scenes: $("$kr" --version)"
  if grep -q ', missing)' <<<"$("$kr" --version)"; then fail "the packaged keithray misses a module: $("$kr" --version)"; fi
  "$kr" render "$tmp/root/usr/share/keithray/scenes/assignment_02.json" --spp 1 --threads 2 -q >/dev/null ||
    fail "the packaged keithray's render"
  [ -s output/assignment_02.ppm ] || fail "the packaged keithray wrote no output/assignment_02.ppm"
  ;;
*)
  fail "usage: install_check.sh tree|package BUILD_DIR"
  ;;
esac
echo "install_check $mode: ok"
