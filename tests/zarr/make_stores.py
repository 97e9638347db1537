#!/usr/bin/python3
"""Writes Zarr v2 / OME-NGFF 0.4 stores with zarr-python (the independent
writer of tests/io/ZarrInteropTest.cpp) and, beside each, the voxels
Tessera must read: the selected time point and channel of level 0 as raw
little-endian bytes of the type Tessera holds (x fastest).

usage: make_stores.py OUT_DIR      -> OUT_DIR/cases.json
"""
import json
import os
import sys

import numcodecs
import numpy as np
import zarr


def multiscales(axes, levels, unit="millimeter"):
    """NGFF 0.4 multiscales: levels = [(path, scale, translation)]."""
    ax = []
    for a in axes:
        kind = {"t": "time", "c": "channel"}.get(a, "space")
        entry = {"name": a, "type": kind}
        if kind == "space" and unit:
            entry["unit"] = unit
        ax.append(entry)
    return [{
        "version": "0.4",
        "axes": ax,
        "datasets": [{
            "path": p,
            "coordinateTransformations": [{"type": "scale", "scale": s},
                                          {"type": "translation", "translation": t}],
        } for p, s, t in levels],
    }]


def values(shape, dtype, seed):
    rng = np.random.default_rng(seed)
    if np.dtype(dtype).kind == "f":
        return (rng.standard_normal(shape) * 100).astype(dtype)
    info = np.iinfo(np.dtype(dtype))
    return rng.integers(info.min, info.max, size=shape, endpoint=True, dtype=np.int64).astype(dtype)


def remove_chunk(store_dir, path, key):
    os.remove(os.path.join(store_dir, path, key))


def main(out):
    os.makedirs(out, exist_ok=True)
    cases = []

    def case(name, data3d, target, spacing, origin, fill_missing=None, time=0, channel=0,
             levels=1, note=""):
        """data3d: (z, y, x) voxels Tessera must return."""
        expected = os.path.join(out, name + ".bin")
        as_target = {"u8": "<u1", "u16": "<u2", "i16": "<i2", "f32": "<f4"}[target]
        arr = np.ascontiguousarray(data3d.astype(as_target))
        arr.tofile(expected)
        cases.append({"name": name, "store": os.path.join(out, name + ".zarr"),
                      "expected": expected, "type": target,
                      "dims": [int(data3d.shape[2]), int(data3d.shape[1]), int(data3d.shape[0])],
                      "spacing": spacing, "origin": origin, "time": time, "channel": channel,
                      "levels": levels, "note": note})

    # 1. u8, blosc lz4 + byte shuffle, "/" separator, chunks that do not
    #    divide the shape, a missing chunk read as fill_value 7.
    name = "u8_blosc_lz4_slash"
    path = os.path.join(out, name + ".zarr")
    g = zarr.open_group(zarr.NestedDirectoryStore(path), mode="w")
    d = values((37, 50, 45), "u1", 1)
    a = g.create_dataset("0", data=d, chunks=(16, 16, 16), fill_value=7,
                         compressor=numcodecs.Blosc("lz4", 5, numcodecs.Blosc.SHUFFLE))
    g.attrs["multiscales"] = multiscales("zyx", [("0", [2.0, 0.5, 0.75], [10.0, -3.0, 4.5])])
    assert a._dimension_separator == "/" or a._store._dimension_separator == "/"
    remove_chunk(path, "0", "1/2/0")
    d[16:32, 32:48, 0:16] = 7
    case(name, d, "u8", [0.75, 0.5, 2.0], [4.5, -3.0, 10.0])

    # 2. u16, zlib, "." separator, two levels (the second written as a
    #    plain 2x subsample: Tessera must read whatever the store holds).
    name = "u16_zlib_dot"
    path = os.path.join(out, name + ".zarr")
    g = zarr.open_group(zarr.DirectoryStore(path), mode="w")
    d = values((20, 33, 41), "<u2", 2)
    g.create_dataset("0", data=d, chunks=(7, 10, 12), compressor=numcodecs.Zlib(level=3))
    g.create_dataset("1", data=d[::2, ::2, ::2].copy(), chunks=(7, 10, 12),
                     compressor=numcodecs.Zlib(level=3))
    g.attrs["multiscales"] = multiscales(
        "zyx", [("0", [1.0, 1.0, 1.0], [0.0, 0.0, 0.0]), ("1", [2.0, 2.0, 2.0], [0.5, 0.5, 0.5])])
    assert os.path.exists(os.path.join(path, "0", "0.0.0"))
    case(name, d, "u16", [1, 1, 1], [0, 0, 0], levels=2)

    # 3. big-endian i16, blosc zstd + bitshuffle, "/" separator, unit micrometer.
    name = "i16_big_blosc_zstd"
    path = os.path.join(out, name + ".zarr")
    g = zarr.open_group(zarr.NestedDirectoryStore(path), mode="w")
    d = values((17, 19, 23), ">i2", 3)
    g.create_dataset("0", data=d, chunks=(8, 8, 8),
                     compressor=numcodecs.Blosc("zstd", 3, numcodecs.Blosc.BITSHUFFLE))
    g.attrs["multiscales"] = multiscales("zyx", [("0", [500.0, 250.0, 250.0], [0.0, 0.0, 0.0])],
                                         unit="micrometer")
    case(name, d, "i16", [0.25, 0.25, 0.5], [0, 0, 0])

    # 4. f32, gzip, fill NaN, a missing chunk.
    name = "f32_gzip_nan"
    path = os.path.join(out, name + ".zarr")
    g = zarr.open_group(zarr.DirectoryStore(path), mode="w")
    d = values((12, 13, 14), "<f4", 4)
    g.create_dataset("0", data=d, chunks=(5, 5, 5), fill_value=float("nan"),
                     compressor=numcodecs.GZip(level=5))
    g.attrs["multiscales"] = multiscales("zyx", [("0", [1.0, 1.0, 1.0], [0.0, 0.0, 0.0])])
    remove_chunk(path, "0", "2.1.0")
    d[10:12, 5:10, 0:5] = np.nan
    case(name, d, "f32", [1, 1, 1], [0, 0, 0])

    # 5. t, c, z, y, x u16 with zstd: time 1, channel 2.
    name = "tczyx_u16_zstd"
    path = os.path.join(out, name + ".zarr")
    g = zarr.open_group(zarr.NestedDirectoryStore(path), mode="w")
    d = values((2, 3, 10, 11, 12), "<u2", 5)
    g.create_dataset("0", data=d, chunks=(1, 2, 4, 4, 4), compressor=numcodecs.Zstd(level=1))
    g.attrs["multiscales"] = multiscales(
        "tczyx", [("0", [1.0, 1.0, 3.0, 2.0, 1.0], [0.0, 0.0, 0.0, 0.0, 0.0])])
    case(name, d[1, 2], "u16", [1, 2, 3], [0, 0, 0], time=1, channel=2)

    # 6. i4, no compressor: read as f32 with a note.
    name = "i32_raw"
    path = os.path.join(out, name + ".zarr")
    g = zarr.open_group(zarr.DirectoryStore(path), mode="w")
    d = values((6, 7, 8), "<i4", 6)
    g.create_dataset("0", data=d, chunks=(4, 4, 4), compressor=None)
    g.attrs["multiscales"] = multiscales("zyx", [("0", [1.0, 1.0, 1.0], [0.0, 0.0, 0.0])])
    case(name, d, "f32", [1, 1, 1], [0, 0, 0], note="read as f32")

    with open(os.path.join(out, "cases.json"), "w") as f:
        json.dump(cases, f, indent=1)


if __name__ == "__main__":
    main(sys.argv[1])
