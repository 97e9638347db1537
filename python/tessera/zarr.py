"""OME-Zarr pyramids of numpy and dask arrays, built by dask (on a cluster too).

``write_pyramid(array, url)`` writes the store ``tessera convert`` writes for the
same voxels: OME-NGFF 0.4 multiscales on Zarr v2, a factor-2 mean pyramid down
to one chunk, the same ``.zarray``/``.zattrs``/``.zgroup`` and the same chunk
files byte for byte. Each level is computed chunk-parallel by dask from the
level above: a task per block of 2^k x 2^k x 2^k chunks (about 16 MiB) halves
its block, the halves are merged into blocks again, and the task that computed
a block compresses and writes its chunks, on a worker when a
``distributed.Client`` runs the graph. The client writes only the metadata and
gathers a few numbers per chunk-deep slab of a block. No level is ever held
whole anywhere.

The reduction is ``lod::downsample(v, 2)`` of the C++ library: the mean of the
voxels present in each 2x2x2 block (partial blocks at odd edges average what
they have; non-finite values are skipped; a block of none is NaN), summed in
double in z, y, x order, integer types rounded half away from zero
(``std::lround``), float32 rounded from the double mean. Codecs: zstd level 3,
blosc lz4 level 5 with byte shuffle and automatic block size, zlib/gzip level 6,
or none, through the same system libraries (Debian's numcodecs links libzstd and
libblosc) and Python's zlib. All-zero chunks are not stored (they read as
``fill_value`` 0), as the C++ writer does.

The store is built in a hidden sibling folder (``.tessera-<pid>-<id>-NAME``) and
renamed into place when every chunk is written: a worker that dies mid-write
leaves no store at ``url`` (the temporary folder is removed when the client
sees the failure), and the same call run again completes. An existing OME-Zarr
store at ``url`` is replaced; any other existing path is refused.

Pure Python (numpy, numcodecs, dask); it does not need the compiled module.
Workers need numpy, numcodecs and dask, and ``url`` must name a folder that
every worker and the client see at the same path (a shared filesystem).
"""

from __future__ import annotations

import json
import math
import os
import shutil
import time
import uuid
from dataclasses import dataclass, field
from typing import Optional, Sequence, Tuple, Union

import numpy as np

__all__ = ["write_pyramid", "PyramidResult", "auto_levels"]

# numpy dtype (little-endian) -> Zarr dtype string, as io::zarrayJson writes it.
_ZARR_DTYPES = {
    np.dtype("uint8"): "|u1",
    np.dtype("<u2"): "<u2",
    np.dtype("<i2"): "<i2",
    np.dtype("<f4"): "<f4",
}

# The .zarray "compressor" objects of io::zarrayJson, by the names convert takes.
_COMPRESSORS = {
    "none": None,
    "zlib": {"id": "zlib", "level": 6},
    "gzip": {"id": "gzip", "level": 6},
    "zstd": {"id": "zstd", "level": 3},
    "blosc": {"id": "blosc", "cname": "lz4", "clevel": 5, "shuffle": 1, "blocksize": 0},
}

# The C++ writer's text for its default factors (io/ZarrWriter.cpp: the
# factors, z by y by x); this writer halves every axis.
_METHOD = (
    "tessera convert: 2x2x2 (z by y by x) mean (lod::downsample), partial edge blocks "
    "average the voxels present"
)


@dataclass
class PyramidResult:
    """What ``write_pyramid`` wrote: per level shapes (z, y, x) and chunk counts."""

    path: str
    level_shapes: list = field(default_factory=list)
    chunks: list = field(default_factory=list)  # per level chunk shape (z, y, x)
    chunks_written: int = 0
    chunks_skipped: int = 0  # all zero (= fill_value): not stored
    bytes_written: int = 0
    value_range: Tuple[float, float] = (0.0, 0.0)
    seconds: float = 0.0


# ---------------------------------------------------------------- metadata


def _number_text(x: float) -> str:
    """A double as nlohmann::json::dump writes it (shortest round trip, '.0' on
    integers, exponent from 1e15 up and below 1e-4, NaN and inf as null)."""
    x = float(x)
    if not math.isfinite(x):
        return "null"
    text = repr(x)
    if "e" not in text and 1e15 <= abs(x) < 1e16:
        # Python prints these in full, nlohmann switches to an exponent at 16 digits.
        mantissa, exponent = f"{x:.16e}".split("e")
        digits = mantissa.rstrip("0").rstrip(".")
        text = f"{digits}e+{int(exponent):02d}"
    return text


def _json_text(value, indent: int = 0) -> str:
    """nlohmann::json::dump(2): keys sorted, two-space indent, UTF-8 as is."""
    pad, inner = " " * indent, " " * (indent + 2)
    if isinstance(value, dict):
        if not value:
            return "{}"
        items = [
            f"{inner}{json.dumps(k, ensure_ascii=False)}: {_json_text(value[k], indent + 2)}"
            for k in sorted(value)
        ]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(value, (list, tuple)):
        if not value:
            return "[]"
        items = [inner + _json_text(v, indent + 2) for v in value]
        return "[\n" + ",\n".join(items) + "\n" + pad + "]"
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return _number_text(value)
    return json.dumps(value, ensure_ascii=False)


def _zarray_text(shape, chunks, dtype: np.dtype, compressor: str) -> str:
    return _json_text(
        {
            "zarr_format": 2,
            "shape": [int(s) for s in shape],
            "chunks": [int(c) for c in chunks],
            "dtype": _ZARR_DTYPES[dtype],
            "order": "C",
            "fill_value": 0,
            "filters": None,
            "dimension_separator": "/",
            "compressor": _COMPRESSORS[compressor],
        }
    )


def _zattrs_text(name, spacing, origin, direction, levels, value_range, window) -> str:
    """The .zattrs of ZarrWriter.cpp's attributes(): spacing, origin (x, y, z)
    and direction (3x3, rows = world axes) of the finest level."""
    axes = [{"name": a, "type": "space", "unit": "millimeter"} for a in ("z", "y", "x")]
    datasets = []
    for level in range(levels):
        f = math.ldexp(1.0, level)
        scale = [spacing[a] * f for a in range(3)]
        # A level-l voxel is the mean of 2^l finer voxels per axis: its centre
        # lies (2^l - 1)/2 finest voxels past the first of them, a shift in
        # the array's own axes (NGFF has no direction; a reader applies
        # tessera.direction to it: "translations": "array axes").
        moved = [origin[a] + spacing[a] * (0.5 * (f - 1.0)) for a in range(3)]
        datasets.append(
            {
                "path": str(level),
                "coordinateTransformations": [
                    {"type": "scale", "scale": scale[::-1]},
                    {"type": "translation", "translation": moved[::-1]},
                ],
            }
        )
    multiscale = {
        "version": "0.4",
        "name": name,
        "axes": axes,
        "datasets": datasets,
        "type": "mean",
        "metadata": {
            "method": _METHOD,
            "world_frame": "RAS+ millimetres; x->R, y->A, z->S when direction is identity",
        },
    }
    # glm is column-major: the C++ writes direction()[c] (column c) as row c.
    tessera = {
        "world_frame": "RAS",
        "translations": "array axes",
        "direction": [[float(direction[r][c]) for r in range(3)] for c in range(3)],
    }
    if value_range is not None and value_range[1] >= value_range[0]:
        tessera["value_range"] = [float(value_range[0]), float(value_range[1])]
    if window is not None:
        tessera["window"] = [float(window[0]), float(window[1])]
    return _json_text({"multiscales": [multiscale], "tessera": tessera})


_ZGROUP_TEXT = '{\n  "zarr_format": 2\n}'


# ---------------------------------------------------------------- geometry


def auto_levels(shape_zyx: Sequence[int], chunks_zyx: Sequence[int]) -> int:
    """Levels ``"auto"`` gives: halve (rounding up) until one chunk holds a level."""
    dims, levels = [int(s) for s in shape_zyx], 1
    while any(d > c for d, c in zip(dims, chunks_zyx)):
        dims = [(d + 1) // 2 for d in dims]
        levels += 1
    return levels


def _level_shapes(shape_zyx, chunks_zyx, levels) -> list:
    count = auto_levels(shape_zyx, chunks_zyx) if levels == "auto" else levels
    shapes, dims = [], tuple(int(s) for s in shape_zyx)
    for _ in range(count):
        shapes.append(dims)
        if dims == (1, 1, 1):
            break
        dims = tuple((d + 1) // 2 for d in dims)
    return shapes


def _geometry(spacing, affine):
    """(spacing, origin, direction) of the finest level in x, y, z; direction
    as rows of world axes, columns of index axes (RAS+ mm)."""
    if affine is None:
        s = [float(v) for v in spacing]
        if len(s) != 3 or not all(math.isfinite(v) and v > 0 for v in s):
            raise ValueError(f"spacing {tuple(spacing)}: expected three positive sizes in mm")
        return s, [0.0, 0.0, 0.0], [[1.0 if r == c else 0.0 for c in range(3)] for r in range(3)]
    a = np.asarray(affine, dtype=np.float64)
    if a.shape != (4, 4) or not np.all(np.isfinite(a)):
        raise ValueError(f"affine of shape {a.shape}: expected a finite 4x4 matrix")
    s = [float(np.linalg.norm(a[:3, c])) for c in range(3)]
    if not all(v > 0 for v in s):
        raise ValueError("affine: an index axis has zero length")
    direction = [[float(a[r, c] / s[c]) for c in range(3)] for r in range(3)]
    return s, [float(v) for v in a[:3, 3]], direction


# ---------------------------------------------------------------- chunk work


def _mean_2x2x2(block: np.ndarray) -> np.ndarray:
    """lod::downsample(v, 2) of a block that starts on an even voxel: the mean
    of the voxels present (non-finite ones skipped), summed in double in z, y,
    x order, integers rounded half away from zero (std::lround)."""
    dz, dy, dx = block.shape
    out = ((dz + 1) // 2, (dy + 1) // 2, (dx + 1) // 2)
    parts = [block[z::2, y::2, x::2] for z in range(2) for y in range(2) for x in range(2)]
    if block.dtype.kind in "ui":
        # Integer sums are exact in any order: sum in int32 (8 x 65535 fits).
        total = np.zeros(out, dtype=np.int32)
        for p in parts:
            total[: p.shape[0], : p.shape[1], : p.shape[2]] += p
        per_axis = [np.minimum(2, n - 2 * np.arange(o)) for n, o in zip(block.shape, out)]
        count = per_axis[0][:, None, None] * per_axis[1][None, :, None] * per_axis[2][None, None, :]
        mean = total / count
        info = np.iinfo(block.dtype)
        # std::lround: halves away from zero (numpy's round is half to even).
        rounded = np.copysign(np.floor(np.abs(mean) + 0.5), mean)
        return np.clip(rounded, info.min, info.max).astype(block.dtype)
    total = np.zeros(out, dtype=np.float64)
    count = np.zeros(out, dtype=np.int32)
    for p in parts:  # in the C++ loop's order: float sums depend on it
        v = p.astype(np.float64)
        finite = np.isfinite(v)
        total[: p.shape[0], : p.shape[1], : p.shape[2]] += np.where(finite, v, 0.0)
        count[: p.shape[0], : p.shape[1], : p.shape[2]] += finite
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = total / count
    # A block of no finite voxel is std::numeric_limits<double>::quiet_NaN()
    # (sign bit clear); x86's 0/0 would set it, and the chunk bytes differ.
    mean[count == 0] = np.nan
    return mean.astype(block.dtype)


def _encode(raw: np.ndarray, compressor: str) -> bytes:
    data = raw.tobytes()
    if compressor == "none":
        return data
    if compressor in ("zlib", "gzip"):
        import zlib

        wbits = 15 + 16 if compressor == "gzip" else 15
        c = zlib.compressobj(6, zlib.DEFLATED, wbits, 8, zlib.Z_DEFAULT_STRATEGY)
        return c.compress(data) + c.flush()
    if compressor == "zstd":
        from numcodecs import Zstd

        return bytes(Zstd(level=3).encode(data))
    from numcodecs import Blosc

    codec = Blosc(cname="lz4", clevel=5, shuffle=Blosc.SHUFFLE, blocksize=0)
    return bytes(codec.encode(raw))


def _mkdir(path: str) -> None:
    # Only below the level folder the client made: a task still running after
    # the client gave up (and removed the temporary store) fails here instead
    # of recreating it.
    try:
        os.mkdir(path)
    except FileExistsError:
        pass


def _write_one(sub, root, level, index, chunk_zyx, compressor):
    """Stores one chunk (sub = its voxels); returns the stored size, or None
    when it is all zero (it reads as fill_value: nothing to store)."""
    raw = np.zeros(chunk_zyx, dtype=sub.dtype)
    raw[: sub.shape[0], : sub.shape[1], : sub.shape[2]] = sub
    if not raw.view(np.uint8).any():
        return None
    stored = _encode(raw, compressor)
    zdir = os.path.join(root, str(level), str(index[0]))
    _mkdir(zdir)
    _mkdir(os.path.join(zdir, str(index[1])))
    with open(os.path.join(zdir, str(index[1]), str(index[2])), "wb") as f:
        f.write(stored)
    return len(stored)


def _write_block(block, root, level, chunk_zyx, compressor, track_range, block_info=None):
    """Writes the chunks of one block (a whole number of chunks, starting on
    one) and returns per chunk-deep slab of it: [written, skipped, stored
    bytes, finite min, finite max, finite count]."""
    starts = [a for a, _ in block_info[0]["array-location"]]
    first = [s // c for s, c in zip(starts, chunk_zyx)]
    counts = [-(-n // c) for n, c in zip(block.shape, chunk_zyx)]
    stats = np.zeros((counts[0], 1, 1, 6), dtype=np.float64)
    stats[:, 0, 0, 3] = np.inf
    stats[:, 0, 0, 4] = -np.inf
    cz, cy, cx = chunk_zyx
    for iz in range(counts[0]):
        row = stats[iz, 0, 0]
        for iy in range(counts[1]):
            for ix in range(counts[2]):
                sub = block[iz * cz : (iz + 1) * cz, iy * cy : (iy + 1) * cy, ix * cx : (ix + 1) * cx]
                index = (first[0] + iz, first[1] + iy, first[2] + ix)
                size = _write_one(sub, root, level, index, chunk_zyx, compressor)
                row[0 if size is not None else 1] += 1
                row[2] += size or 0
                if track_range:
                    finite = sub[np.isfinite(sub)] if sub.dtype.kind == "f" else sub
                    if finite.size:
                        row[3] = min(row[3], float(finite.min()))
                        row[4] = max(row[4], float(finite.max()))
                        row[5] += finite.size
    return stats


def _block_shape(chunk_zyx, itemsize, target=16 << 20) -> Tuple[int, int, int]:
    """A dask block: 2^k chunks per axis, the largest of at most `target`
    bytes. A task per block, not per chunk, keeps the graph and the
    scheduler small (a 1024^3 u8 level 0 is 64 tasks, not 4096)."""
    k, voxels = 1, int(np.prod(chunk_zyx)) * itemsize
    while (2 * k) ** 3 * voxels <= target:
        k *= 2
    return tuple(k * c for c in chunk_zyx)


def _level0_blocks(a, chunk_zyx, block_zyx):
    """The input in blocks that hold whole chunks: its own when every block
    boundary is on a chunk boundary (no data moves between workers), else
    rechunked."""
    chunk = [min(c, d) for c, d in zip(chunk_zyx, a.shape)]
    aligned = all(all(b % c == 0 for b in axis[:-1]) for axis, c in zip(a.chunks, chunk))
    largest = a.dtype.itemsize * int(np.prod([max(axis) for axis in a.chunks]))
    if aligned and largest <= 64 << 20:
        return a
    return a.rechunk(tuple(min(b, d) for b, d in zip(block_zyx, a.shape)))


# ---------------------------------------------------------------- the store


def _checked_dtype(dtype) -> np.dtype:
    d = np.dtype(dtype)
    little = d.newbyteorder("<") if d.itemsize > 1 else d
    if little not in _ZARR_DTYPES:
        raise ValueError(
            f"dtype {d}: expected uint8, uint16, int16 or float32 (the types Tessera renders)"
        )
    return little


def _checked_chunks(chunks) -> Tuple[int, int, int]:
    c = (int(chunks),) * 3 if np.isscalar(chunks) else tuple(int(v) for v in chunks)
    if len(c) != 3 or any(v < 8 or v > 1024 or v % 2 for v in c):
        raise ValueError(
            f"chunks {chunks}: expected an even size in 8..1024, or three (z, y, x)"
        )
    return c


def _checked_levels(levels):
    if levels == "auto":
        return levels
    if isinstance(levels, (int, np.integer)) and not isinstance(levels, bool):
        if 1 <= levels <= 30:
            return int(levels)
    raise ValueError(f"levels {levels!r}: expected 'auto' or a count in 1..30")


def _local_path(url: str) -> str:
    if url.startswith("file://"):
        url = url[len("file://") :]
    elif "://" in url:
        scheme = url.split("://", 1)[0]
        raise ValueError(
            f"{url}: {scheme}:// is not written directly (no atomic rename there); write to a "
            "folder every worker sees (a shared filesystem) and copy it to object storage"
        )
    path = os.path.abspath(url.rstrip("/") or "/")
    if not path.endswith(".zarr"):
        raise ValueError(f"{url}: expected a store name ending in .zarr (NAME.ome.zarr)")
    return path


def _is_zarr_store(path: str) -> bool:
    return os.path.isdir(path) and any(
        os.path.exists(os.path.join(path, n)) for n in (".zgroup", ".zarray", ".zattrs")
    )


def _remove_tree(path: str) -> None:
    # Tasks still finishing elsewhere may add a file while this removes: retry.
    for _ in range(20):
        shutil.rmtree(path, ignore_errors=True)
        if not os.path.exists(path):
            return
        time.sleep(0.1)


def _as_dask(array, axes: str, dtype: np.dtype, block_zyx):
    import dask.array as da

    if axes not in ("xyz", "zyx"):
        raise ValueError(f"axes {axes!r}: expected 'xyz' (a[i, j, k], nibabel's) or 'zyx'")
    a = array if isinstance(array, da.Array) else np.asarray(array)
    if a.ndim != 3:
        raise ValueError(f"array of {a.ndim} dimensions {a.shape}: expected 3")
    if any(isinstance(s, float) and math.isnan(s) for s in a.shape):
        raise ValueError("array has unknown chunk sizes: call compute_chunk_sizes() first")
    if not isinstance(a, da.Array):
        a = da.from_array(a if axes == "zyx" else a.transpose(2, 1, 0), chunks=block_zyx)
    elif axes == "xyz":
        a = a.transpose(2, 1, 0)
    if a.dtype != dtype:
        a = a.astype(dtype)
    return a


def write_pyramid(
    array,
    url: str,
    *,
    chunks: Union[int, Sequence[int]] = 64,
    levels: Union[str, int] = "auto",
    compressor: str = "zstd",
    client=None,
    axes: str = "xyz",
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    affine=None,
    window: Optional[Tuple[float, float]] = None,
) -> PyramidResult:
    """Write ``array`` as the OME-Zarr store ``tessera convert`` writes.

    array: a numpy or dask array, uint8, uint16, int16 or float32 (any byte
        order; stored little-endian). ``axes="xyz"`` (default) indexes it as
        nibabel does, ``a[i, j, k]`` with i along x; ``axes="zyx"`` for arrays
        in Zarr's (z, y, x) order. A dask array is never computed in the
        client: each chunk is made, reduced and written by a task.
    url: the store folder (``NAME.ome.zarr``, or ``file://``), seen at the same
        path by the client and every worker.
    chunks: chunk edge (even, 8..1024) or (z, y, x), as ``convert --chunk``.
    levels: ``"auto"`` (halve until one chunk holds a level) or a count.
    compressor: ``"zstd"`` (level 3), ``"blosc"`` (lz4, byte shuffle),
        ``"zlib"``, ``"gzip"`` or ``"none"``.
    client: a ``distributed.Client`` to run on; None uses dask's default
        scheduler (a default Client if one is active, else threads).
    spacing / affine: voxel size in mm along i, j, k, or a 4x4 index->RAS+ mm
        affine (as ``tessera.from_array``); window: (low, high) to store.

    Returns a ``PyramidResult``. Raises ValueError for bad arguments and
    OSError for a path it cannot write; on any failure nothing is left at
    ``url`` (a store that was there stays).
    """
    import dask

    started = time.perf_counter()
    chunks_zyx = _checked_chunks(chunks)
    levels = _checked_levels(levels)
    if compressor not in _COMPRESSORS:
        raise ValueError(
            f"compressor {compressor!r}: expected zstd, blosc, zlib, gzip or none"
        )
    path = _local_path(str(url))
    if not hasattr(array, "dtype"):
        array = np.asarray(array)
    dtype = _checked_dtype(array.dtype)
    spacing_xyz, origin_xyz, direction = _geometry(spacing, affine)
    if window is not None and not (len(window) == 2 and window[1] > window[0]):
        raise ValueError(f"window {window}: expected (low, high) with low < high")
    parent = os.path.dirname(path)
    if not os.path.isdir(parent):
        raise FileNotFoundError(f"{path}: cannot write, folder {parent} does not exist")
    replace = os.path.exists(path)
    if replace and not _is_zarr_store(path):
        raise FileExistsError(f"{path}: exists and is not an OME-Zarr store; not replacing it")

    level0 = _as_dask(array, axes, dtype, _block_shape(chunks_zyx, dtype.itemsize))
    shapes = _level_shapes(level0.shape, chunks_zyx, levels)
    level_chunks = [tuple(min(d, c) for d, c in zip(s, chunks_zyx)) for s in shapes]

    base = os.path.basename(path)
    name = base[: base.index(".")] if base.find(".") > 0 else base
    temp = os.path.join(parent, f".tessera-{os.getpid()}-{uuid.uuid4().hex[:8]}-{base}")
    os.mkdir(temp)
    try:
        stats = []
        block = _block_shape(chunks_zyx, dtype.itemsize)
        level = _level0_blocks(level0, chunks_zyx, block)
        for index, (shape, chunk) in enumerate(zip(shapes, level_chunks)):
            os.mkdir(os.path.join(temp, str(index)))
            with open(os.path.join(temp, str(index), ".zarray"), "w", encoding="utf-8") as f:
                f.write(_zarray_text(shape, chunk, dtype, compressor))
            if index > 0:
                level = _halved(level, block)
            _, ny, nx = level.numblocks
            slabs = tuple(-(-b // chunk[0]) for b in level.chunks[0])
            stats.append(
                level.map_blocks(
                    _write_block, temp, index, chunk, compressor, index == 0,
                    chunks=(slabs, (1,) * ny, (1,) * nx, (6,)), new_axis=3,
                    dtype=np.float64, name=f"tessera-write-{index}-{uuid.uuid4().hex}",
                )
            )
        numbers = _run(stats, client, dask)
        result = _summary(path, shapes, level_chunks, numbers, dtype)
        with open(os.path.join(temp, ".zgroup"), "w", encoding="utf-8") as f:
            f.write(_ZGROUP_TEXT)
        with open(os.path.join(temp, ".zattrs"), "w", encoding="utf-8") as f:
            f.write(
                _zattrs_text(name, spacing_xyz, origin_xyz, direction, len(shapes),
                             result.value_range, window)
            )
        old = f"{path}.old-{os.getpid()}"
        if replace:
            os.rename(path, old)
        try:
            os.rename(temp, path)
        except BaseException:
            if replace:
                os.rename(old, path)  # the store that was there stays
            raise
    except BaseException:
        _remove_tree(temp)
        raise
    if replace:
        _remove_tree(old)
    result.seconds = time.perf_counter() - started
    return result


def _halved(level, block):
    """The next level: each block of `level` (whole chunks, so it starts on an
    even voxel) reduced by one task, then merged into blocks of `block` again
    (the data that moves between workers is the smaller level's)."""
    halves = tuple(tuple((b + 1) // 2 for b in axis) for axis in level.chunks)
    half = level.map_blocks(_mean_2x2x2, chunks=halves, dtype=level.dtype)
    return half.rechunk(tuple(min(b, d) for b, d in zip(block, half.shape)))


def _run(stats, client, dask):
    """Computes the per-chunk numbers (a few bytes each: the voxels stay on the
    workers) on ``client`` or dask's default scheduler."""
    if client is None:
        return dask.compute(*stats)
    futures = client.compute(stats)
    try:
        return client.gather(futures)
    except BaseException:
        client.cancel(futures)
        raise


def _summary(path, shapes, level_chunks, numbers, dtype) -> PyramidResult:
    r = PyramidResult(path=path, level_shapes=list(shapes), chunks=list(level_chunks))
    for n in numbers:
        r.chunks_written += int(n[..., 0].sum())
        r.chunks_skipped += int(n[..., 1].sum())
        r.bytes_written += int(n[..., 2].sum())
    # Volume::valueRange per chunk-deep slab of level 0, merged as the C++
    # writer merges them: a float slab with no finite voxel counts as [0, 0].
    lo, hi = math.inf, -math.inf
    for slab in numbers[0]:
        seen = slab[..., 5] > 0
        s_lo, s_hi = (slab[..., 3][seen].min(), slab[..., 4][seen].max()) if seen.any() else (0, 0)
        lo, hi = min(lo, float(s_lo)), max(hi, float(s_hi))
    r.value_range = (lo, hi)
    return r
