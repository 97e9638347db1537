#!/usr/bin/env python3
"""Sends pointer input through the X server (XTest, as a mouse would), on a
schedule: latency.test.mjs's TESSERA_LATENCY_INPUT=x11 mode. argv[1] is a
JSON list of {"at": ms after the start, "kind": "move"|"press"|"release",
"x", "y" (screen pixels; move), "button" (1 left, 4/5 wheel up/down)}; the
start is argv[2] (epoch ms). Prints one JSON line per event sent, with the
epoch time (ms) just before and after the X server took it (XSync).
Needs libX11 and libXtst (xdotool's dependencies; scripts/setup.sh)."""
import ctypes
import json
import sys
import time

x11 = ctypes.CDLL("libX11.so.6")
xtst = ctypes.CDLL("libXtst.so.6")
x11.XOpenDisplay.restype = ctypes.c_void_p
x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
x11.XSync.argtypes = [ctypes.c_void_p, ctypes.c_int]
x11.XCloseDisplay.argtypes = [ctypes.c_void_p]
xtst.XTestFakeMotionEvent.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_int, ctypes.c_int, ctypes.c_ulong]
xtst.XTestFakeButtonEvent.argtypes = [ctypes.c_void_p, ctypes.c_uint, ctypes.c_int, ctypes.c_ulong]


def main():
    plan = json.loads(sys.argv[1])
    start = float(sys.argv[2]) if len(sys.argv) > 2 else time.time() * 1000
    display = x11.XOpenDisplay(None)
    if not display:
        sys.exit("x11_input.py: cannot open the X display (DISPLAY unset, or no server)")
    for i, e in enumerate(plan):
        due = start + e["at"]
        while True:
            left = due - time.time() * 1000
            if left <= 0:
                break
            time.sleep(min(left, 5) / 1000 if left > 1 else 0)
        before = time.time() * 1000
        if e["kind"] == "move":
            xtst.XTestFakeMotionEvent(display, -1, int(e["x"]), int(e["y"]), 0)
        else:
            xtst.XTestFakeButtonEvent(display, int(e["button"]), 1 if e["kind"] == "press" else 0, 0)
        x11.XSync(display, 0)
        after = time.time() * 1000
        print(json.dumps({"i": i, "kind": e["kind"], "before": before, "after": after}), flush=True)
    x11.XCloseDisplay(display)


if __name__ == "__main__":
    main()
