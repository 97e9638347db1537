#!/usr/bin/python3
"""Reads a store Tessera wrote with zarr-python (the independent reader of
tests/io/ZarrInteropTest.cpp) and checks it against the source volume:
level 0 voxel-exact; every level the 2x2x2 mean of the one before (partial
edge blocks averaged over the voxels present, integers rounded to nearest,
ties away from zero), computed here in numpy; NGFF 0.4 multiscales metadata
(axes z, y, x of type space in millimetres, datasets 0..n-1, per level
scale = spacing * 2^l and translation = origin + spacing * (2^l - 1) / 2).

usage: check_store.py STORE SOURCE.bin DTYPE X Y Z SX SY SZ OX OY OZ
Prints one JSON object; exit status 0 when every check passes.
"""
import json
import sys

import numpy as np
import zarr


def halve(a):
    z, y, x = a.shape
    pad = np.full(((z + 1) // 2 * 2, (y + 1) // 2 * 2, (x + 1) // 2 * 2), np.nan)
    pad[:z, :y, :x] = a
    blocks = pad.reshape(pad.shape[0] // 2, 2, pad.shape[1] // 2, 2, pad.shape[2] // 2, 2)
    return np.nanmean(blocks, axis=(1, 3, 5))


def to_type(m, dtype):
    if np.dtype(dtype).kind == "f":
        return m.astype(dtype)
    info = np.iinfo(dtype)
    r = np.where(m >= 0, np.floor(m + 0.5), np.ceil(m - 0.5))
    return np.clip(r, info.min, info.max).astype(dtype)


def main(argv):
    store, source, dtype = argv[1], argv[2], argv[3]
    dims = [int(v) for v in argv[4:7]]
    spacing = [float(v) for v in argv[7:10]]
    origin = [float(v) for v in argv[10:13]]
    problems = []
    g = zarr.open_group(store, mode="r")
    ms = g.attrs["multiscales"]
    if len(ms) != 1 or ms[0].get("version") != "0.4":
        problems.append("multiscales: %r" % ms)
    ms = ms[0]
    axes = ms["axes"]
    if [a["name"] for a in axes] != ["z", "y", "x"] or any(
            a.get("type") != "space" or a.get("unit") != "millimeter" for a in axes):
        problems.append("axes: %r" % axes)
    want = np.fromfile(source, dtype=dtype).reshape(dims[2], dims[1], dims[0])
    level = want.astype(np.float64)
    datasets = ms["datasets"]
    for l, ds in enumerate(datasets):
        if ds["path"] != str(l):
            problems.append("dataset %d path %r" % (l, ds["path"]))
        t = ds["coordinateTransformations"]
        f = 2.0 ** l
        scale = [spacing[2] * f, spacing[1] * f, spacing[0] * f]
        trans = [origin[2] + spacing[2] * (f - 1) / 2, origin[1] + spacing[1] * (f - 1) / 2,
                 origin[0] + spacing[0] * (f - 1) / 2]
        if t[0]["type"] != "scale" or not np.allclose(t[0]["scale"], scale):
            problems.append("level %d scale %r, expected %r" % (l, t[0], scale))
        if t[1]["type"] != "translation" or not np.allclose(t[1]["translation"], trans):
            problems.append("level %d translation %r, expected %r" % (l, t[1], trans))
        got = g[ds["path"]][:]
        if got.dtype != np.dtype(dtype).newbyteorder("=") and got.dtype != np.dtype(dtype):
            problems.append("level %d dtype %s" % (l, got.dtype))
        expect = want if l == 0 else to_type(level, dtype)
        if got.shape != expect.shape:
            problems.append("level %d shape %r, expected %r" % (l, got.shape, expect.shape))
        elif not np.array_equal(got, expect, equal_nan=np.dtype(dtype).kind == "f"):
            diff = np.abs(got.astype(np.float64) - expect.astype(np.float64))
            problems.append("level %d: %d voxels differ, max %g" % (
                l, int(np.count_nonzero(diff)), float(np.nanmax(diff))))
        level = halve(level if l == 0 else expect.astype(np.float64))
    last = g[datasets[-1]["path"]]
    print(json.dumps({"levels": len(datasets), "last_shape": list(last.shape),
                      "last_chunks": list(last.chunks), "problems": problems}))
    return 0 if not problems else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
