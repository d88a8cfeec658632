#!/usr/bin/env python3
"""An orbit drag in a real `keithray view` window with real X input (xdotool), watched through
the X server's copy of the window (x_window_shot.py). Run inside xvfb-run. Prints key=value lines.

  viewer_drag.py test  KEITHRAY SCENE WORKDIR
      For tests/test_viewer_window.cpp; never waits for time, only for conditions (bounded by a
      generous limit): the button goes down, then each of STEPS moves of the pointer is
      followed by a wait until the window shows a frame of the camera that move made (the
      status file names it, then the X server's copy of the window changes), with the button
      still held; each such frame must differ from the one before. Then the button
      goes up. Prints steps=, shown_during_drag= (moves whose frame came before the next move),
      changed_during_drag=, still_pressed= and the final generation.

  viewer_drag.py bench KEITHRAY SCENE WORKDIR [--steps 24] [--step-px 5] [--interval 0.05]
      For scripts/bench_viewer.sh (prints figures, asserts nothing): a drag of STEPS moves at
      INTERVAL seconds, the window grabbed every 50 ms meanwhile (how many grabs changed), then
      after the release the grabs at 0.25, 0.5, 1, 2, 3 and 10 s against the settled image
      (a grab after --settle seconds): PSNR, and the time from the release to the first change.
"""
import argparse
import math
import os
import subprocess
import sys
import threading
import time

sys.dont_write_bytecode = True  # no __pycache__ left in the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import ctypes  # noqa: E402
from x_window_shot import XImage, open_x11, shift_of  # noqa: E402

LIMIT = float(os.environ.get("VIEWER_INPUT_LIMIT", "240"))  # seconds for any one condition


def xdotool(*args):
    subprocess.run(["xdotool", *[str(a) for a in args]], check=True, stdout=subprocess.DEVNULL)


class Viewer:
    def __init__(self, keithray, scene, workdir, extra):
        self.status_path = os.path.join(workdir, "status.txt")
        self.err = open(os.path.join(workdir, "view.err"), "w")
        self.proc = subprocess.Popen([keithray, "view", scene, "--status-file", self.status_path, *extra],
                                     stdout=subprocess.DEVNULL, stderr=self.err)
        self.window = int(subprocess.run(["xdotool", "search", "--sync", "--name", "^keithray"], check=True,
                                         capture_output=True, text=True).stdout.split()[0])
        self.x11, self.display = open_x11()

    def status(self):
        try:
            with open(self.status_path) as f:
                line = f.read()
        except OSError:
            return {}
        return dict(kv.split("=", 1) for kv in line.split() if "=" in kv)

    def wait(self, condition, what):
        end = time.monotonic() + LIMIT
        while time.monotonic() < end:
            if self.proc.poll() is not None:
                sys.exit("error=viewer exited (status %d) waiting for %s" % (self.proc.returncode, what))
            s = self.status()
            if s and condition(s):
                return s
            time.sleep(0.005)
        sys.exit("error=timed out waiting for %s (status: %s)" % (what, self.status()))

    def image(self, s):
        """The image area of the window as the X server holds it (the status line's
        image=x,y,fitS): its raw pixels, 4 bytes each, one of them unused (see rgb)."""
        x, y, fit = s["image"].split(",")
        scale = float(fit.replace("fit", ""))
        x, y = int(float(x)), int(float(y))
        w, h = int(self.size[0] * scale), int(self.size[1] * scale)
        all_planes = ctypes.c_ulong(-1).value
        image = self.x11.XGetImage(self.display, self.window, x, y, w, h, all_planes, 2)  # ZPixmap
        if not image:
            sys.exit("error=XGetImage failed")
        im = image.contents
        # The byte no colour mask covers (XGetImage's 32-bit pixels), for rgb().
        used = {shift_of(m) // 8 if im.byte_order == 0 else 3 - shift_of(m) // 8
                for m in (im.red_mask, im.green_mask, im.blue_mask)}
        self.unused = ({0, 1, 2, 3} - used).pop()
        raw = ctypes.string_at(im.data, im.bytes_per_line * h)  # (the XImage is left: a few per run)
        return raw

    def close(self):
        self.proc.terminate()
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()


def shown(s):
    """The shown frame's (generation, scale, spp)."""
    if s.get("shown", "none") == "none":
        return None
    g, scale, spp, _ = s["shown"].split(",")
    return int(g), int(scale), int(spp)


def psnr(a, b, unused):
    """PSNR of two raw grabs of the same area, over their colour bytes."""
    total, count = 0, 0
    for k in range(4):
        if k == unused:
            continue
        total += sum((x - y) ** 2 for x, y in zip(a[k::4], b[k::4]))
        count += len(a[k::4])
    mse = total / max(1, count)
    return 99.0 if mse == 0 else 10 * math.log10(255 * 255 / mse)


def start(args, extra):
    v = Viewer(args.keithray, args.scene, args.workdir, extra)
    s = v.wait(lambda s: s.get("state") in ("rendering", "done") and shown(s) and shown(s)[1] == 1, "a full frame")
    # The image's size: the scene's, from the first full frame's area (image=x,y,fitS and the
    # scene's renderer size are what the test scenes use: 512x512 unless --size says).
    v.size = tuple(int(n) for n in args.size.split("x"))
    xdotool("windowfocus", "--sync", v.window)
    x, y, _ = s["image"].split(",")
    # The pointer in the image's middle band, over the image.
    xdotool("mousemove", "--window", v.window, int(float(x)) + 150, int(float(y)) + 200)
    return v, s


def run_test(args):
    v, s = start(args, ["--spp", "64"])
    before = v.image(s)
    xdotool("mousedown", 1)
    v.wait(lambda s: s.get("press") not in (None, "0"), "the press")
    # Past the threshold first: the drag starts where it crosses it, a step that moves nothing
    # is no edit, so the steps below each move the camera from there.
    pointer = v.status()["pointer"]
    xdotool("mousemove_relative", "--", args.step_px, 0)
    v.wait(lambda s: s.get("pointer") != pointer, "the drag's start")
    shown_during, changed = 0, 0
    earlier_states = set()  # the status bar's state while an earlier view's frame is shown
    for step in range(args.steps):
        generation = int(v.status()["generation"])
        xdotool("mousemove_relative", "--", args.step_px, 0)
        s = v.wait(lambda s, g=generation: int(s["generation"]) > g, "the move's edit")
        if shown(s) and shown(s)[0] < int(s["generation"]):
            earlier_states.add(s["state"])
        g = int(s["generation"])
        s = v.wait(lambda s, g=g: shown(s) and shown(s)[0] >= g, "a frame of the moved camera")
        if s.get("press") not in (None, "0"):
            shown_during += 1
        # The status line is written as the frame is drawn, before the buffers swap: the
        # new picture reaches the X server a moment later. Wait for it (bounded), then for two
        # grabs alike (not one caught mid-copy).
        end = time.monotonic() + min(LIMIT, 30)
        now = v.image(s)
        while now == before and time.monotonic() < end:
            time.sleep(0.01)
            now = v.image(s)
        while time.monotonic() < end:
            again = v.image(s)
            if again == now:
                break
            now = again
        changed += now != before
        before = now
    pressed = v.status().get("press")
    xdotool("mouseup", 1)
    s = v.wait(lambda s: s.get("press") == "0", "the release")
    print("steps=%d" % args.steps)
    print("shown_during_drag=%d" % shown_during)
    print("changed_during_drag=%d" % changed)
    print("still_pressed=%d" % (pressed not in (None, "0")))
    print("states_with_an_earlier_view=%s" % ",".join(sorted(earlier_states)))
    print("generation=%s" % s["generation"])
    v.close()


def run_bench(args):
    v, s = start(args, ["--unlimited"])
    time.sleep(1.0)
    grabs, stop = [], threading.Event()

    def watch():
        last = None
        while not stop.is_set():
            t = time.monotonic()
            img = v.image(v.status())
            grabs.append((t, img != last))
            last = img
            time.sleep(max(0.0, 0.05 - (time.monotonic() - t)))

    xdotool("mousedown", 1)
    thread = threading.Thread(target=watch)
    thread.start()
    for _ in range(args.steps):
        t = time.monotonic()
        xdotool("mousemove_relative", "--", args.step_px, 0)
        time.sleep(max(0.0, args.interval - (time.monotonic() - t)))
    stop.set()
    thread.join()
    xdotool("mouseup", 1)
    released = time.monotonic()
    during = grabs[1:]
    print("drag: %d moves in %.2f s; %d of %d grabs (every 50 ms) changed" %
          (args.steps, args.steps * args.interval, sum(c for _, c in during), len(during)))
    # After the release: the first new frame on screen (the status file's shown frame, read
    # without grabbing), then one grab at each checkpoint; nothing else runs meanwhile.
    s = v.status()
    first_frame = shown(s)
    first_change = None
    while time.monotonic() - released < 1.0 and first_change is None:
        if shown(v.status()) != first_frame:
            first_change = time.monotonic() - released
        time.sleep(0.002)
    shots = []
    for c in [0.25, 0.5, 1.0, 2.0, 3.0, 10.0]:
        time.sleep(max(0.0, c - (time.monotonic() - released)))
        shots.append((c, v.image(s), shown(v.status())))
    time.sleep(max(0.0, args.settle - (time.monotonic() - released)))
    settled = v.image(s)
    print("release to the first new frame: %s" % ("%.0f ms" % (1e3 * first_change) if first_change is not None else "none within 1 s"))
    print("PSNR against the settled image (%g s): %s" % (args.settle, "  ".join(
        "%g s: %.1f dB (%s)" % (c, psnr(img, settled, v.unused), "%d spp%s" % (f[2], "" if f[1] == 1 else ", preview") if f else "-")
        for c, img, f in shots)))
    v.close()


def main():
    p = argparse.ArgumentParser()
    p.add_argument("mode", choices=["test", "bench"])
    p.add_argument("keithray")
    p.add_argument("scene")
    p.add_argument("workdir")
    p.add_argument("--steps", type=int, default=None)
    p.add_argument("--step-px", type=int, default=5)
    p.add_argument("--interval", type=float, default=0.05)
    p.add_argument("--settle", type=float, default=30)
    p.add_argument("--size", default="512x512")
    args = p.parse_args()
    if args.steps is None:
        args.steps = 6 if args.mode == "test" else 24
    (run_test if args.mode == "test" else run_bench)(args)


main()
