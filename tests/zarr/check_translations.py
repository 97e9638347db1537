#!/usr/bin/python3
"""Reads every level of an OME-Zarr (NGFF 0.4, Zarr v2) store with
zarr-python the way an NGFF reader does (world = scale * index +
translation per array axis, no direction) and prints, per level, where its
centre lies against level 0's (mm, z y x) and how far its voxels are from
the mean of the level-0 voxels they cover (the block centre the translation
claims).

usage: check_translations.py STORE         -> one JSON line per level
       check_translations.py --lps OUT.nrrd -> writes a 64x48x40 u8 LPS NRRD
"""
import json
import sys

import numpy as np
import zarr


def write_lps(path):
    z, y, x = np.mgrid[0:40, 0:48, 0:64]
    v = ((x * 3 + y * 5 + z * 7) % 251).astype(np.uint8)
    with open(path, "wb") as f:
        f.write(b"NRRD0004\ntype: uint8\ndimension: 3\nspace: left-posterior-superior\n"
                b"sizes: 64 48 40\nspace directions: (0.7,0,0) (0,0.7,0) (0,0,2)\n"
                b"space origin: (10,20,30)\nencoding: raw\n\n")
        f.write(v.tobytes())


def main(store):
    g = zarr.open_group(store, mode="r")
    ms = g.attrs["multiscales"][0]
    levels = []
    for d in ms["datasets"]:
        a = g[d["path"]]
        s = t = None
        for c in d["coordinateTransformations"]:
            if c["type"] == "scale":
                s = np.array(c["scale"], float)
            if c["type"] == "translation":
                t = np.array(c["translation"], float)
        levels.append((np.asarray(a[...]), s, t if t is not None else np.zeros(3)))
    base, s0, t0 = levels[0]
    c0 = t0 + s0 * (np.array(base.shape) - 1) / 2
    for l, (data, s, t) in enumerate(levels):
        centre = t + s * (np.array(data.shape) - 1) / 2
        f = 2 ** l
        # Level-l voxels whose 2^l block lies whole inside level 0.
        n = np.array(base.shape) // f
        block = base[:n[0] * f, :n[1] * f, :n[2] * f].astype(float)
        mean = block.reshape(n[0], f, n[1], f, n[2], f).mean(axis=(1, 3, 5))
        diff = np.abs(data[:n[0], :n[1], :n[2]].astype(float) - mean).max()
        # Where the first voxel's block centre is, per the level's translation.
        first = t - (t0 + s0 * (f - 1) / 2)
        print(json.dumps({"level": l, "shape": list(data.shape),
                          "centre_minus_level0_mm": [round(v, 6) for v in (centre - c0)],
                          "first_voxel_vs_block_centre_mm": [round(v, 6) for v in first],
                          "max_abs_value_vs_block_mean": round(float(diff), 3)}))


if __name__ == "__main__":
    if sys.argv[1] == "--lps":
        write_lps(sys.argv[2])
    else:
        main(sys.argv[1])
