#!/usr/bin/env python3
"""What a Python user pays over the CLI, measured in one run (a benchmark, not
a test). Prints a table and one JSON line.

1. Per frame, the headline: `Session.render()` called from Python frame
   after frame (the session keeps the uploaded volume; each call prepares,
   draws, reads the image back and wraps it as a numpy array) against the
   CLI's per-frame time of `build/tessera render --repeat N` (draw only),
   alternating CLI and Python rounds in one run.
2. The same loop both ways: `Session.run(repeat=N)` from Python against the
   CLI's `--repeat N` frames (the noise floor: the same C++ loop).
3. For scale: the CLI's one-shot render of one frame (device, upload,
   shaders, frame, PNG; its total minus the read).
4. The widget's round trip per drag event: a 256^3 volume at 512^2, one
   azimuth step each: session update + render + PNG + hand-over to the
   ipywidgets Image, as the slider's (or a drag's) callback runs it.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py
    PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py --volume gen:shepp-logan:128 --size 256
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import tessera

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def cli_run(cli, volume, size, repeat, rotate, tf, out):
    args = [cli, "render", volume, "--size", f"{size}x{size}", "--tf", tf, "--repeat",
            str(repeat), "--rotate", str(rotate), "--json", "--out", out]
    t0 = time.perf_counter()
    r = subprocess.run(args, capture_output=True, text=True, check=True)
    wall = (time.perf_counter() - t0) * 1000
    return json.loads(r.stdout), wall


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--volume", default="/usr/share/mricron/templates/ch2.nii.gz")
    p.add_argument("--size", type=int, default=512)
    p.add_argument("--repeat", type=int, default=20, help="frames per run")
    p.add_argument("--rounds", type=int, default=3, help="alternating CLI/Python rounds")
    p.add_argument("--tf", default="mr-default")
    p.add_argument("--drags", type=int, default=20, help="widget drag events timed")
    p.add_argument("--cli", default=os.path.join(os.environ.get("TESSERA_BUILD_DIR",
                                                                os.path.join(ROOT, "build")),
                                                 "tessera"))
    a = p.parse_args()
    if not os.path.exists(a.volume) and not a.volume.startswith(("gen:", "head:")):
        a.volume = "gen:shepp-logan:128"
    tmp = tempfile.mkdtemp(prefix="tessera-bench-")
    out = os.path.join(tmp, "cli.png")
    rotate = 360.0 / a.repeat

    s = tessera.Session(tessera.open(a.volume), tf=a.tf)
    s.render(64, 64)  # the device and shaders warm, as the CLI's first frame is not timed apart
    cli_frames, py_frames, py_wall, cli_one, py_one = [], [], [], [], []
    for _ in range(a.rounds):
        j, _wall = cli_run(a.cli, a.volume, a.size, a.repeat, rotate, a.tf, out)
        cli_frames += j["frame_ms"]
        t0 = time.perf_counter()
        _, report = s.run(a.size, a.size, repeat=a.repeat, rotate=rotate)
        py_wall.append((time.perf_counter() - t0) * 1000 / a.repeat)
        py_frames += report["frame_ms"]
        j1, _ = cli_run(a.cli, a.volume, a.size, 1, 0, a.tf, out)
        cli_one.append(j1["total_ms"] - j1["load_ms"])
        for f in range(a.repeat):
            t0 = time.perf_counter()
            s.render(a.size, a.size, azimuth=f * rotate)
            py_one.append((time.perf_counter() - t0) * 1000)

    med = statistics.median
    frames_over = 100.0 * (med(py_frames) / med(cli_frames) - 1.0)
    render_over = 100.0 * (med(py_one) / med(cli_frames) - 1.0)

    # The widget: 256^3 u8 at 512^2, one azimuth step per drag event.
    from tessera.widget import Viewer

    i, j_, k = np.mgrid[-1:1:256j, -1:1:256j, -1:1:256j].astype(np.float32)
    r = np.sqrt(i * i + 1.5 * j_ * j_ + 0.7 * k * k)
    blob = (250 * np.exp(-3 * r * r) + 200 * np.exp(-80 * (r - 0.6) ** 2)).astype(np.uint8)
    del i, j_, k, r
    v = Viewer(tessera.from_array(blob), tf="ct-bone", size=512)
    drags = []
    for n in range(a.drags):
        t0 = time.perf_counter()
        v.azimuth.value = (v.azimuth.value + 4) % 360 - 180
        drags.append((time.perf_counter() - t0) * 1000)

    result = {
        "volume": a.volume,
        "size": a.size,
        "device": s._core.device,
        "cli_frame_ms_median": med(cli_frames),
        "python_render_ms_median": med(py_one),
        "render_overhead_percent": render_over,
        "python_run_frame_ms_median": med(py_frames),
        "run_overhead_percent": frames_over,
        "python_run_wall_per_frame_ms": med(py_wall),
        "cli_one_shot_ms": med(cli_one),
        "widget_drag_ms_median": med(drags),
        "widget_drag_ms_max": max(drags),
    }
    print(f"volume {a.volume} at {a.size}x{a.size}, tf {a.tf}, {a.rounds} alternating rounds")
    print(f"per frame              CLI --repeat {result['cli_frame_ms_median']:.1f} ms  "
          f"Python render() {result['python_render_ms_median']:.1f} ms  ({render_over:+.1f} %)")
    print(f"same loop              CLI --repeat {result['cli_frame_ms_median']:.1f} ms  "
          f"Python run(repeat) {result['python_run_frame_ms_median']:.1f} ms  "
          f"({frames_over:+.1f} %; wall incl. upload {result['python_run_wall_per_frame_ms']:.1f})")
    print(f"CLI one-shot render    {result['cli_one_shot_ms']:.1f} ms (device, upload, frame, PNG)")
    print(f"widget 256^3 at 512^2      {result['widget_drag_ms_median']:.1f} ms per drag event "
          f"(max {result['widget_drag_ms_max']:.1f})")
    print(json.dumps(result))


if __name__ == "__main__":
    sys.exit(main())
