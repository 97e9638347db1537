#!/usr/bin/python3
"""Writes the acceptance's 3-channel u16 OME-Zarr store (issue 30, item 5).

    /usr/bin/python3 bench/channels_store.py OUT.ome.zarr [--dims 512x512x200]

NGFF 0.4 on Zarr v2, uncompressed chunks of 1 x 50 x 256 x 256, written with
numpy alone (no zarr package needed). One known structure per channel on a
background of 100, the same as tests/support/ChannelStore.h: channel 0 a
sphere (3000), channel 1 a slab across x and z (2000), channel 2 a rod along
y (4000); omero colours red, green, azure and windows per channel. Render:

    build/tessera render OUT.ome.zarr --channels 0,1,2 --reference --size 512x512
    build/tessera render OUT.ome.zarr --channel-mode max --reference
    build/tessera render OUT.ome.zarr --channels 0,2 --profile webgl1-desktop-2012 --reference
    build/tessera render OUT.ome.zarr --channels 0,1,2 --layout bricks --size 256x256 --ortho \
        --azimuth 30 --elevation 20 --tf grey --opacity-scale 20 --reference --json

The last one mixes levels (the atlas holds 528 of the 1792 level-0 bricks);
its reference reads each brick cell's level as the GPU does
(docs/channels.md "Bricks").
"""
import argparse
import json
import os
import shutil

import numpy as np


def channel(c, dims):
    x, y, z = dims
    fx = (np.arange(x) + 0.5) / x
    fy = (np.arange(y) + 0.5) / y
    fz = (np.arange(z) + 0.5) / z
    Z, Y, X = np.meshgrid(fz, fy, fx, indexing="ij")
    if c == 0:
        inside = (X - 0.35) ** 2 + (Y - 0.4) ** 2 + (Z - 0.5) ** 2 < 0.22**2
    elif c == 1:
        inside = (Y > 0.62) & (Y < 0.78)
    else:
        inside = (X - 0.72) ** 2 + (Z - 0.45) ** 2 < 0.08**2
    return np.where(inside, [3000, 2000, 4000][c], 100).astype("<u2")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--dims", default="512x512x200", help="XxYxZ voxels")
    a = ap.parse_args()
    dims = tuple(int(v) for v in a.dims.split("x"))
    x, y, z = dims
    chunk = (1, min(z, 50), min(y, 256), min(x, 256))
    if os.path.exists(a.out):
        shutil.rmtree(a.out)
    os.makedirs(os.path.join(a.out, "0"))
    axes = [{"name": "c", "type": "channel"}] + [
        {"name": n, "type": "space", "unit": "micrometer"} for n in "zyx"
    ]
    windows = [(100, 3000, 100, 3000), (100, 2000, 50, 2500), (100, 4000, 100, 4000)]
    attrs = {
        "multiscales": [{
            "version": "0.4", "name": "channels", "axes": axes,
            "datasets": [{"path": "0", "coordinateTransformations": [
                {"type": "scale", "scale": [1.0, 2.0, 1.0, 1.0]}]}]}],
        "omero": {"channels": [
            {"label": label, "color": color, "active": True,
             "window": {"min": w[0], "max": w[1], "start": w[2], "end": w[3]}}
            for label, color, w in zip(["sphere", "slab", "rod"],
                                       ["FF0000", "00FF00", "0080FF"], windows)]},
    }
    with open(os.path.join(a.out, ".zgroup"), "w") as f:
        json.dump({"zarr_format": 2}, f)
    with open(os.path.join(a.out, ".zattrs"), "w") as f:
        json.dump(attrs, f, indent=1)
    with open(os.path.join(a.out, "0", ".zarray"), "w") as f:
        json.dump({"zarr_format": 2, "shape": [3, z, y, x], "chunks": list(chunk),
                   "dtype": "<u2", "compressor": None, "fill_value": 0, "order": "C",
                   "filters": None, "dimension_separator": "/"}, f)
    for c in range(3):
        data = channel(c, dims)
        for k in range(0, z, chunk[1]):
            for j in range(0, y, chunk[2]):
                for i in range(0, x, chunk[3]):
                    block = np.zeros(chunk[1:], dtype="<u2")
                    part = data[k:k + chunk[1], j:j + chunk[2], i:i + chunk[3]]
                    block[:part.shape[0], :part.shape[1], :part.shape[2]] = part
                    d = os.path.join(a.out, "0", str(c), str(k // chunk[1]), str(j // chunk[2]))
                    os.makedirs(d, exist_ok=True)
                    block.tofile(os.path.join(d, str(i // chunk[3])))
    print(f"wrote {a.out}: 3 channels of {x}x{y}x{z} u16")


if __name__ == "__main__":
    main()
