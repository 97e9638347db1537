#!/usr/bin/python3
"""A store's t axis played over bricks in the desktop viewer, every frame
checked: runs `tessera view STORE --bricks --play FPS --play-record DIR`
under Xvfb until the series has looped once and one more (COUNT + 1 time
points shown after the first), renders each time point in core with `tessera render
STORE --time T` at the view's size and look, and prints, per time point
shown, the PSNR of the frame shown against its own time point in core and
against the nearest other one (a stale frame is nearer another), then the
viewer's playback and budget lines.

usage: desktop_playback.py TESSERA STORE COUNT [--size N] [--fps F] [--profile P]
                           [--out DIR] [VIEW-OPTION ...]
e.g.   bench/desktop_playback.py build/tessera /tmp/series256.ome.zarr 20 --size 512 --fps 10
"""
import argparse
import math
import os
import re
import subprocess
import sys
import time

import numpy as np
from PIL import Image

PANEL = 390  # frontends/desktop: kPanelWidth
LOOK = ["--tf", "grey", "--azimuth", "30", "--elevation", "20"]


def psnr(a, b):
    d = a[..., :3].astype(np.float64) - b[..., :3].astype(np.float64)
    mse = float(np.mean(d * d))
    return math.inf if mse == 0.0 else 10.0 * math.log10(255.0 * 255.0 / mse)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("tessera")
    p.add_argument("store")
    p.add_argument("count", type=int)
    p.add_argument("--size", type=int, default=512)
    p.add_argument("--fps", type=float, default=10.0)
    p.add_argument("--profile", default="gles3")
    p.add_argument("--out", default="desktop-playback")
    args, extra = p.parse_known_args()
    shown_dir = os.path.join(args.out, "shown")
    ref_dir = os.path.join(args.out, "in-core")
    os.makedirs(ref_dir, exist_ok=True)
    view = ["xvfb-run", "-a", "-s", "-screen 0 %dx%dx24" % (PANEL + args.size + 64, args.size + 64),
            args.tessera, "view", args.store, "--bricks", "--layout", "single", "--profile",
            args.profile, "--size", "%dx%d" % (PANEL + args.size, args.size), "--play",
            str(args.fps), "--play-time-points", str(args.count + 1), "--play-record", shown_dir,
            "--screenshot", os.path.join(args.out, "view.png")] + LOOK + extra
    t0 = time.time()
    run = subprocess.run(view, capture_output=True, text=True)
    wall = time.time() - t0
    if run.returncode != 0:
        sys.exit("tessera view failed (%d): %s%s" % (run.returncode, run.stdout, run.stderr))
    shown = [(int(m.group(1)), int(m.group(2)), float(m.group(3)))
             for m in re.finditer(r"shown (\d+): time point (\d+) complete at ([0-9.]+) s", run.stdout)]
    refs = []
    for t in range(args.count):
        out = os.path.join(ref_dir, "t%d.png" % t)
        subprocess.run([args.tessera, "render", args.store, "--time", str(t), "--profile",
                        args.profile, "--size", "%dx%d" % (args.size, args.size), "--out", out]
                       + LOOK, check=True, capture_output=True)
        refs.append(np.asarray(Image.open(out).convert("RGBA")))
    print("| shown | time point | at (s) | vs its own in core (dB) | vs the nearest other (dB) |")
    print("|---|---|---|---|---|")
    order_ok = True
    stale = 0
    for n, t, at in shown:
        img = np.asarray(Image.open(os.path.join(shown_dir, "%04d-t%d.png" % (n, t))).convert("RGBA"))
        own = psnr(img, refs[t])
        other = max(psnr(img, refs[u]) for u in range(args.count) if u != t)
        stale += other >= own
        order_ok &= t == n % args.count
        print("| %d | %d | %.2f | %.1f | %.1f |" % (n, t, at, own, other))
    print("%d time points shown, %s, %d frames nearer another time point than their own"
          % (len(shown), "every one in order" if order_ok and len(shown) == args.count + 2
             else "NOT every one in order", stale))
    for line in run.stdout.splitlines():
        if line.startswith(("playback:", "budgets:")):
            print(line)
    print("wall %.1f s for the viewer run" % wall)


if __name__ == "__main__":
    main()
