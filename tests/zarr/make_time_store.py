#!/usr/bin/python3
"""Writes an OME-NGFF 0.4 store (Zarr v2, zlib) of a time series with
zarr-python: N^3 u8 voxels per time point, COUNT time points on a t axis,
two levels (the second the 2x2x2 mean). Each time point is a thin smooth dim shell with
a bright cube whose x position moves with t, so every time point renders
differently and a frame shows which one it is. The omero window (0..255)
is the series' one window. With CHANNELS 2 the store has a c axis too: channel
1's cube moves along y instead (the same shell), red and green.

usage: make_time_store.py OUT.ome.zarr N COUNT [CHANNELS]
"""
import sys

import numcodecs
import numpy as np
import zarr


def shell(n):
    c = (n - 1) / 2.0
    z, y, x = np.ogrid[0:n, 0:n, 0:n]
    d = np.sqrt((x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2, dtype=np.float32) - np.float32(0.44 * n)
    # A smooth profile about a voxel and a half wide at any size: never
    # thick enough to hide the cube, and band-limited, so that ray casters
    # sampling it at different points do not draw different moire.
    return np.round(60.0 * np.exp(-(d / 1.5) ** 2)).astype(np.uint8)  # z, y, x


def time_point(base, t, count):
    n = base.shape[0]
    v = base.copy()
    side = max(2, n // 8)
    x0 = int(round(n * 0.1 + t * (n * 0.8 - side) / max(1, count - 1)))
    lo = n // 2 - side // 2
    v[lo:lo + side, lo:lo + side, x0:x0 + side] = 255
    return v


def half(v):
    """The 2x2x2 mean, rounded half up (integer arithmetic)."""
    s = v.astype(np.uint16)
    s = s[0::2] + s[1::2]
    s = s[:, 0::2] + s[:, 1::2]
    s = s[:, :, 0::2] + s[:, :, 1::2]
    return ((s + 4) // 8).astype(np.uint8)


def main(out, n, count, channels=1):
    g = zarr.open_group(zarr.NestedDirectoryStore(out), mode="w")
    chunk = min(n, 64)
    h = n // 2
    lead = (count,) if channels == 1 else (count, channels)
    ones = (1,) * len(lead)
    compressor = numcodecs.Zlib(level=1)
    a0 = g.create_dataset("0", shape=lead + (n, n, n), chunks=ones + (chunk, chunk, chunk),
                          dtype="u1", compressor=compressor)
    a1 = g.create_dataset("1", shape=lead + (h, h, h), chunks=ones + (min(h, 64),) * 3,
                          dtype="u1", compressor=compressor)
    base = shell(n)
    for t in range(count):
        v = time_point(base, t, count)
        if channels == 1:
            a0[t] = v
            a1[t] = half(v)
            continue
        for c in range(channels):
            w = v if c == 0 else np.ascontiguousarray(v.transpose(0, 2, 1))  # the cube moves along y
            a0[t, c] = w
            a1[t, c] = half(w)
    axes = [{"name": "t", "type": "time", "unit": "second"}]
    if channels > 1:
        axes.append({"name": "c", "type": "channel"})
    axes += [{"name": a, "type": "space", "unit": "millimeter"} for a in "zyx"]
    lead1 = [1.0] * len(lead)
    g.attrs["multiscales"] = [{
        "version": "0.4", "name": "moving cube", "axes": axes, "type": "mean",
        "datasets": [
            {"path": "0", "coordinateTransformations": [{"type": "scale", "scale": lead1 + [1.0, 1.0, 1.0]}]},
            {"path": "1", "coordinateTransformations": [
                {"type": "scale", "scale": lead1 + [2.0, 2.0, 2.0]},
                {"type": "translation", "translation": [0.0] * len(lead) + [0.5, 0.5, 0.5]}]},
        ],
    }]
    window = {"min": 0, "max": 255, "start": 0, "end": 255}
    if channels == 1:
        g.attrs["omero"] = {"channels": [{"label": "cube", "color": "FFFFFF", "active": True, "window": window}]}
    else:
        colours = ["FF0000", "00FF00", "0000FF"]
        g.attrs["omero"] = {"channels": [{"label": f"cube{c}", "color": colours[c % 3], "active": True,
                                          "window": window} for c in range(channels)]}


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]) if len(sys.argv) > 4 else 1)
