#!/usr/bin/env bash
# A benchmark of the viewer (prints figures, asserts nothing): for scenes 3 and 6, the
# viewer's idle CPU once the render is done and once paused (% of one core over 10 s with no
# input), and the latency from an orbit edit to the first frame of the new image on screen
# (median and 90th percentile over 30 edits). Runs a real window under Xvfb. Then the
# per-frame cost of the inspect and compare tools (bench/compare_tools.cpp) and of the
# feature views (bench/feature_views.cpp). Then the render pipeline: the viewer's passes per second
# against render's, a 1.2 s orbit drag with real input (frames during it, PSNR after it),
# the render thread's frames after an orbit, a 4 % region, the first full frame at 1920x1080.
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

# The viewer at the engine's speed (docs/viewer.md, "The render pipeline").
echo "== passes: view --spp 64 --frames 64 against render --spp 64, scene 3, each less its 2-spp run (medians of 3, interleaved)"
python3 - "$exe" <<'PY'
import statistics, subprocess, sys, time
exe, scene = sys.argv[1], "res/scenes/assignment_03.json"
xvfb = ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24"]
def timed(cmd):
    start = time.monotonic()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.monotonic() - start
runs = {}
for _ in range(3):
    for spp in (64, 2):
        runs.setdefault(("render", spp), []).append(timed([exe, "render", scene, "--spp", str(spp), "-q", "-o", "/tmp/keithray-bench-viewer.ppm"]))
        for display in ("on", "off"):
            runs.setdefault((display, spp), []).append(timed(xvfb + [exe, "view", scene, "--spp", str(spp), "--frames", str(spp), "--denoise", display]))
m = {k: statistics.median(v) for k, v in runs.items()}
render = m[("render", 64)] - m[("render", 2)]
for display in ("on", "off"):
    view = m[(display, 64)] - m[(display, 2)]
    print("  render %.2f s, view (denoise %s) %.2f s: the viewer at %.2fx render's passes per second" % (render, display, view, render / view))
subprocess.run(["rm", "-f", "/tmp/keithray-bench-viewer.ppm"])
PY
for scene in res/scenes/assignment_03.json res/scenes/assignment_08.json res/scenes/examples/many_spheres.json; do
  echo "== a 1.2 s orbit drag with real input, then the frames after the release: $scene"
  work=$(mktemp -d)
  xvfb-run -a -s "-screen 0 1280x1024x24" python3 tests/viewer_drag.py bench "$exe" "$scene" "$work" --settle 30 || true
  rm -rf "$work"
done
echo "== the render thread after a 120-pixel orbit (bench/viewer_frames.cpp): frames, PSNR, a 4 % region"
cmake --build "$(dirname "$exe")" --target keithray_bench_frames >/dev/null
for scene in res/scenes/assignment_03.json res/scenes/assignment_08.json res/scenes/examples/many_spheres.json; do
  "$(dirname "$exe")/keithray_bench_frames" "$scene" --seconds 10 | grep -v "^ *[0-9.]* s  1/"
done
echo "== at 1920x1080: the first full-resolution frame after an edit, denoised display and raw"
for scene in res/scenes/assignment_03.json res/scenes/assignment_08.json; do
  for raw in "" --raw; do
    "$(dirname "$exe")/keithray_bench_frames" "$scene" --size 1920x1080 --seconds 4 --settle-spp 16 --no-region $raw |
      grep -E "^res|first full"
  done
done
echo "== at 1920x1080: each thread's CPU while the render refines (10 s of a real window, no input; the UI thread redraws only on a new frame)"
python3 - "$exe" <<'PY'
import json, os, subprocess, sys, tempfile, time
exe = sys.argv[1]
work = tempfile.mkdtemp()
scene = json.load(open("res/scenes/assignment_03.json"))
scene["scene"]["renderer"]["dimensions"] = [1920, 1080]
for camera in scene["cameras"]:
    camera["aspect"] = 1920 / 1080
path = os.path.join(work, "assignment_03_1080p.json")
json.dump(scene, open(path, "w"))
viewer = subprocess.Popen(["xvfb-run", "-a", "-s", "-screen 0 2560x1440x24", exe, "view", path, "--unlimited"],
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
time.sleep(5)  # past the first frames
pid = int(subprocess.run(["pgrep", "-n", "-f", "view " + path], capture_output=True, text=True).stdout.split()[0])
tick = os.sysconf("SC_CLK_TCK")
def threads():
    out = {}
    for tid in os.listdir("/proc/%d/task" % pid):
        stat = open("/proc/%d/task/%s/stat" % (pid, tid)).read()
        fields = stat[stat.rindex(")") + 2:].split()
        out[int(tid)] = (stat[stat.index("(") + 1:stat.rindex(")")], (int(fields[11]) + int(fields[12])) / tick)
    return out
before, start = threads(), time.monotonic()
time.sleep(10)
after, span = threads(), time.monotonic() - start
os.kill(pid, 15)  # the viewer itself (xvfb-run ends with it)
viewer.wait()
for tid in sorted(after):
    if tid in before and after[tid][1] > before[tid][1]:
        role = "UI thread" if tid == pid else after[tid][0]
        print("  %-14s %5.1f %% of a core" % (role, 100 * (after[tid][1] - before[tid][1]) / span))
subprocess.run(["rm", "-rf", work])
PY
