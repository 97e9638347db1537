#!/usr/bin/env python3
"""tessera.widget's round trip per drag event (a benchmark, not a test):
a 256^3 u8 volume at 512^2, each drag message handled as the page's message
is (tessera/drag_view.py: DragImage's message handler -> Viewer.drag ->
Session.orbit, the sliders moved to the new camera, Session.render, PNG,
the frame handed to the widget, the answer that frees the page's next
drag). Prints a table (median and max per stage, per TF/mode) and one JSON
line. What the page adds on top (the websocket and the browser decoding
the PNG) is not measured here; tests/browser/widget-drag.test.mjs drives
the whole loop.

    PYTHONPATH=build/python /usr/bin/python3 bench/widget_drag.py
    PYTHONPATH=build/python /usr/bin/python3 bench/widget_drag.py --size 256 --drags 10
"""
import argparse
import json
import statistics
import time

import numpy as np

import tessera
from tessera.widget import Viewer


def blob(n):
    """The volume python_overhead.py times too: a smooth core and a shell."""
    i, j, k = np.mgrid[-1 : 1 : n * 1j, -1 : 1 : n * 1j, -1 : 1 : n * 1j].astype(np.float32)
    r = np.sqrt(i * i + 1.5 * j * j + 0.7 * k * k)
    return (250 * np.exp(-3 * r * r) + 200 * np.exp(-80 * (r - 0.6) ** 2)).astype(np.uint8)


class Stages:
    """Wraps the viewer's session and PNG encoder to time each stage of a drag."""

    def __init__(self, viewer):
        self.t = {"orbit": [], "render": [], "png": []}
        self._wrap(viewer.session, "orbit")
        self._wrap(viewer.session, "render")
        real_png = tessera._png

        def png(rgba, **kw):
            t0 = time.perf_counter()
            out = real_png(rgba, **kw)
            self.t["png"].append((time.perf_counter() - t0) * 1000)
            return out

        tessera._png = png

    def _wrap(self, obj, name):
        real = getattr(obj, name)

        def timed(*a, **k):
            t0 = time.perf_counter()
            out = real(*a, **k)
            self.t[name].append((time.perf_counter() - t0) * 1000)
            return out

        setattr(obj, name, timed)


def measure(volume, size, drags, dx, settings):
    v = Viewer(volume, size=size, **settings)
    v.drag_image._on_message(v.drag_image, {"event": "ready"})  # frames go to the drag view
    sent = []
    v.drag_image.send = sent.append  # no page: keep the answers
    stages = Stages(v)
    total = []
    for seq in range(1, drags + 1):
        t0 = time.perf_counter()
        msg = {"event": "drag", "dx": dx, "dy": 0, "moves": 1, "seq": seq}
        v.drag_image._on_message(v.drag_image, msg)
        total.append((time.perf_counter() - t0) * 1000)
    assert [m["seq"] for m in sent] == list(range(1, drags + 1))
    png_bytes = len(v.drag_image._b64value) * 3 // 4
    return total, stages.t, png_bytes, v.session.settings["camera"]["azimuth"]


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--n", type=int, default=256, help="volume edge (voxels)")
    p.add_argument("--size", type=int, default=512, help="frame edge (pixels)")
    p.add_argument("--drags", type=int, default=20, help="drag events timed per case")
    p.add_argument("--dx", type=float, default=10.0, help="pixels per drag event (4 degrees)")
    a = p.parse_args()
    vol = tessera.from_array(blob(a.n))
    cases = [
        ("ct-bone composite", dict(tf="ct-bone")),
        ("ct-bone composite, shaded", dict(tf="ct-bone", shade=True)),
        ("grey mip", dict(tf="grey", mode="mip")),
    ]
    med = statistics.median
    rows, result = [], {"volume": f"{a.n}^3 u8", "size": a.size, "drags": a.drags, "cases": {}}
    for name, settings in cases:
        total, t, png_bytes, az = measure(vol, a.size, a.drags, a.dx, settings)
        other = [x - o - r - g for x, o, r, g in zip(total, t["orbit"], t["render"], t["png"])]
        rows.append((name, med(total), max(total), med(t["orbit"]), med(t["render"]), med(t["png"]),
                     med(other), png_bytes))
        result["cases"][name] = {
            "round_trip_ms_median": med(total), "round_trip_ms_max": max(total),
            "orbit_ms": med(t["orbit"]), "render_ms": med(t["render"]), "png_ms": med(t["png"]),
            "rest_ms": med(other), "png_bytes": png_bytes, "final_azimuth": az,
        }
    print(f"tessera.widget drag round trip, {a.n}^3 u8 at {a.size}^2, {a.drags} drag events "
          f"of {a.dx:g} px per case (ms; device: {tessera.Session(vol)._core.device})")
    head = ("case", "median", "max", "orbit", "render", "PNG", "rest", "PNG bytes")
    print(f"{head[0]:<28}" + "".join(f"{h:>10}" for h in head[1:]))
    for r in rows:
        print(f"{r[0]:<28}" + "".join(f"{x:>10.1f}" for x in r[1:7]) + f"{r[7]:>10}")
    print(json.dumps(result))


if __name__ == "__main__":
    main()
