"""tessera.zarr.write_pyramid against `tessera convert`: the same store, file for file.

Run: /usr/bin/python3 -m pytest python/tests/test_zarr_pyramid.py
Needs build/tessera (target tessera_cli; TESSERA_CLI overrides the path).
"""

import os
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python"))

from tessera.zarr import write_pyramid  # noqa: E402

CLI = Path(os.environ.get("TESSERA_CLI", ROOT / "build" / "tessera"))
needs_cli = pytest.mark.skipif(
    not CLI.is_file(), reason=f"{CLI} is missing (build the tessera_cli target)"
)
pytestmark = needs_cli


# ------------------------------------------------------------------ data


def voxels(z0, z1, y0, y1, x0, x1, n):
    """A deterministic u8 test volume of n^3 voxels, any box of it, (z, y, x):
    a textured ellipsoid in zeros (so some chunks are all zero and skipped)."""
    z, y, x = (np.arange(a, b, dtype=np.int32) for a, b in ((z0, z1), (y0, y1), (x0, x1)))
    c = (n - 1) / 2.0
    rz, ry, rx = (((v - c) / (f * n)) ** 2 for v, f in ((z, 0.42), (y, 0.40), (x, 0.45)))
    inside = (rz[:, None, None] + (ry[:, None] + rx[None, :])[None]) < 1.0
    zy = (z * 3)[:, None] + (y * 13)[None, :]
    v = (zy[:, :, None] + (x * 7)[None, None, :]) ^ ((y[:, None] * x[None, :]) >> 4)[None]
    return np.where(inside, v & 0xFF, 0).astype(np.uint8)


def lazy_volume(n, chunk, kill=None):
    """The volume as a dask array whose blocks are computed where they are
    needed (never in the client). `kill` = (block index, folder, marker): that
    block's task waits until the store being written in `folder` holds chunks,
    notes how many in `marker`, and kills its worker process."""
    import dask.array as da

    def block(block_info=None):
        info = block_info[None]
        (z0, z1), (y0, y1), (x0, x1) = info["array-location"]
        if kill and tuple(info["chunk-location"]) == kill[0] and not os.path.exists(kill[2]):
            wait_for_chunks_then_die(kill[1], kill[2])
        return voxels(z0, z1, y0, y1, x0, x1, n)

    sizes = tuple(min(chunk, n - i) for i in range(0, n, chunk))
    return da.map_blocks(block, dtype=np.uint8, chunks=(sizes, sizes, sizes))


def wait_for_chunks_then_die(folder, marker):
    import time

    for _ in range(400):
        written = [
            f
            for d in Path(folder).glob(".tessera-*")
            for f in d.rglob("*")
            if f.is_file() and not f.name.startswith(".")
        ]
        if len(written) >= 8:
            break
        time.sleep(0.025)
    Path(marker).write_text(str(len(written)))
    os._exit(1)


def write_nifti(path, n, affine):
    """The same volume as NIfTI (x fastest), streamed slab by slab."""
    import nibabel as nib

    hdr = nib.Nifti1Header()
    hdr.set_data_shape((n, n, n))
    hdr.set_data_dtype(np.uint8)
    hdr.set_sform(affine, code=1)
    hdr.set_qform(affine, code=1)
    hdr["vox_offset"] = 352
    with open(path, "wb") as f:
        f.write(hdr.binaryblock + b"\0" * 4)
        for z0 in range(0, n, 32):
            f.write(voxels(z0, min(n, z0 + 32), 0, n, 0, n, n).tobytes())


def convert(src, dst, *args):
    subprocess.run([str(CLI), "convert", str(src), str(dst), *args], check=True,
                   capture_output=True, timeout=120)


def store_files(root):
    root = Path(root)
    return {str(p.relative_to(root)): p.read_bytes() for p in root.rglob("*") if p.is_file()}


def assert_same_store(expected, actual):
    a, b = store_files(expected), store_files(actual)
    assert sorted(a) == sorted(b), f"files differ: {sorted(set(a) ^ set(b))[:8]}"
    different = [k for k in a if a[k] != b[k]]
    assert not different, f"{len(different)} of {len(a)} files differ: {different[:8]}"
    return len(a)


def render(*stores):
    """Renders each store (at once, one process each) to STORE.png; the images."""
    from PIL import Image

    runs = [subprocess.Popen([str(CLI), "render", str(s), "--size", "96x96", "--out",
                              f"{s}.png"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
            for s in stores]
    for s, run in zip(stores, runs):
        out = run.communicate(timeout=120)[0]
        assert run.returncode == 0, f"render {s}: {out.decode(errors='replace')}"
    return [np.asarray(Image.open(f"{s}.png").convert("RGBA")).astype(np.float64) for s in stores]


def psnr(a, b):
    mse = np.mean((a - b) ** 2)
    return float("inf") if mse == 0 else 10 * np.log10(255.0**2 / mse)


class PeakRss:
    """This process's peak resident set while the block runs (sampled every 5 ms)."""

    def __enter__(self):
        import psutil

        self._proc = psutil.Process()
        self.start = self.peak = self._proc.memory_info().rss
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._sample, daemon=True)
        self._thread.start()
        return self

    def _sample(self):
        while not self._stop.wait(0.005):
            self.peak = max(self.peak, self._proc.memory_info().rss)

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()
        self.peak = max(self.peak, self._proc.memory_info().rss)

    @property
    def growth_mib(self):
        return (self.peak - self.start) / 2**20


@pytest.fixture(scope="module")
def cluster():
    """A LocalCluster of two worker processes. A task whose worker dies is not
    retried (allowed-failures 0), so a killed worker fails the write at once."""
    import dask
    from distributed import Client, LocalCluster

    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                          dashboard_address=None, silence_logs=40) as lc:
            with Client(lc) as client:
                yield client


# ------------------------------------------------------------------ tests


def test_lazy_512_on_a_local_cluster_is_the_convert_store(cluster, tmp_path):
    import zarr

    n = 512
    affine = np.diag([0.5, 0.75, 1.25, 1.0])
    affine[:3, 3] = (-100.0, 40.5, 7.0)
    write_nifti(tmp_path / "head.nii", n, affine)
    (tmp_path / "cli").mkdir()
    (tmp_path / "dask").mkdir()
    # Converted by the CLI while dask writes (another process: not in the RSS).
    cli = subprocess.Popen([str(CLI), "convert", str(tmp_path / "head.nii"),
                            str(tmp_path / "cli" / "head.ome.zarr")],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT)

    volume = lazy_volume(n, 128)  # chunks unlike the store's: rechunked by dask
    # Once small first: what the first call costs (imports, the workers'
    # connections) is not what the volume's size costs.
    write_pyramid(lazy_volume(64, 32), tmp_path / "warm.ome.zarr", axes="zyx", client=cluster)
    with PeakRss() as rss:
        r = write_pyramid(volume, tmp_path / "dask" / "head.ome.zarr", axes="zyx",
                          affine=affine, client=cluster)
    print(f"512^3 on 2 workers: {r.seconds:.1f} s, client RSS +{rss.growth_mib:.1f} MiB, "
          f"{r.chunks_written} chunks written, {r.chunks_skipped} skipped")
    # A level is 128 MiB; the client holds only the graph and per-chunk numbers.
    assert rss.growth_mib < 32, f"client RSS grew {rss.growth_mib:.1f} MiB"
    assert r.level_shapes == [(512,) * 3, (256,) * 3, (128,) * 3, (64,) * 3]
    assert r.chunks_written + r.chunks_skipped == 512 + 64 + 8 + 1
    assert r.chunks_skipped > 0
    out = cli.communicate(timeout=300)[0]
    assert cli.returncode == 0, out.decode(errors="replace")
    files = assert_same_store(tmp_path / "cli" / "head.ome.zarr", tmp_path / "dask" / "head.ome.zarr")
    assert files == r.chunks_written + 4 + 2  # chunks, 4 .zarray, .zgroup, .zattrs

    # zarr-python reads it: a box of level 0 and of level 1 (numpy's mean).
    group = zarr.open_group(str(tmp_path / "dask" / "head.ome.zarr"), mode="r")
    assert group.attrs["multiscales"][0]["version"] == "0.4"
    box = voxels(200, 264, 100, 164, 300, 364, n)
    assert np.array_equal(group["0"][200:264, 100:164, 300:364], box)
    mean = box.reshape(32, 2, 32, 2, 32, 2).astype(np.int64).sum(axis=(1, 3, 5))
    assert np.array_equal(group["1"][100:132, 50:82, 150:182], (mean + 4) // 8)

    # Tessera renders it, as it renders the convert store.
    a, b = render(tmp_path / "dask" / "head.ome.zarr", tmp_path / "cli" / "head.ome.zarr")
    assert a[..., 3].max() > 0, "the render is empty"
    assert psnr(a, b) == float("inf")


@pytest.mark.parametrize(
    "dtype,shape,chunks,compressor",
    [
        ("uint8", (97, 130, 61), 32, "zstd"),
        ("uint8", (97, 130, 61), 64, "blosc"),
        ("uint16", (40, 33, 70), 16, "zlib"),
        ("int16", (33, 17, 9), 8, "gzip"),
        ("float32", (31, 40, 23), 16, "none"),
        ("float32", (31, 40, 23), 8, "blosc"),
    ],
)
def test_odd_sizes_and_every_type_are_the_convert_store(tmp_path, dtype, shape, chunks, compressor):
    import nibabel as nib

    rng = np.random.default_rng(7)
    if dtype == "float32":
        a = rng.normal(0.0, 100.0, size=shape).astype(np.float32)
        a[a > 150] = np.nan  # skipped by the mean; all-NaN blocks stay NaN
        a[:8, :8, :] = np.nan
    elif dtype == "int16":
        a = rng.integers(-3000, 3000, size=shape).astype(np.int16)
    else:
        a = rng.integers(0, np.iinfo(dtype).max, size=shape).astype(dtype)
    if dtype != "float32":
        a[:40, :40, :] = 0  # all-zero chunks, not stored
    affine = np.diag([0.5, 1.25, 2.0, 1.0])
    affine[:3, 3] = (-10.0, 20.5, 3.0)
    nib.save(nib.Nifti1Image(a, affine), tmp_path / "in.nii")
    (tmp_path / "cli").mkdir()
    (tmp_path / "dask").mkdir()
    chunk_arg = str(chunks) if chunks in (64, 128) else f"{chunks},{chunks},{chunks}"
    convert(tmp_path / "in.nii", tmp_path / "cli" / "v.ome.zarr", "--chunk", chunk_arg,
            "--compressor", compressor)
    # Big-endian input is stored little-endian, as convert stores it.
    r = write_pyramid(a.astype(a.dtype.newbyteorder(">")), tmp_path / "dask" / "v.ome.zarr",
                      chunks=chunks, compressor=compressor, affine=affine)
    files = assert_same_store(tmp_path / "cli" / "v.ome.zarr", tmp_path / "dask" / "v.ome.zarr")
    assert files == r.chunks_written + len(r.level_shapes) + 2
    assert r.level_shapes[0] == shape[::-1]


def test_odd_size_store_renders_as_the_convert_store(tmp_path):
    import nibabel as nib

    n = (97, 130, 61)
    a = np.ascontiguousarray(voxels(0, n[2], 0, n[1], 0, n[0], 100).transpose(2, 1, 0))
    affine = np.diag([1.0, 1.0, 1.5, 1.0])
    nib.save(nib.Nifti1Image(a, affine), tmp_path / "odd.nii")
    (tmp_path / "cli").mkdir()
    (tmp_path / "dask").mkdir()
    convert(tmp_path / "odd.nii", tmp_path / "cli" / "odd.ome.zarr", "--chunk", "16,16,16",
            "--levels", "3")
    write_pyramid(a, tmp_path / "dask" / "odd.ome.zarr", chunks=16, levels=3, affine=affine)
    assert_same_store(tmp_path / "cli" / "odd.ome.zarr", tmp_path / "dask" / "odd.ome.zarr")
    a_png, b_png = render(tmp_path / "dask" / "odd.ome.zarr", tmp_path / "cli" / "odd.ome.zarr")
    assert a_png[..., 3].max() > 0
    assert psnr(a_png, b_png) == float("inf")


def test_a_worker_killed_mid_write_leaves_no_store_and_a_rerun_completes(cluster, tmp_path):
    from distributed import KilledWorker

    n, chunk = 96, 16
    out = tmp_path / "v.ome.zarr"
    marker = tmp_path / "killed"
    write_nifti(tmp_path / "v.nii", n, np.eye(4))
    (tmp_path / "cli").mkdir()
    convert(tmp_path / "v.nii", tmp_path / "cli" / "v.ome.zarr", "--chunk", "16,16,16")

    # No store yet: a killed worker leaves none, and no temporary folder.
    killing = lazy_volume(n, chunk, kill=((5, 5, 5), tmp_path, marker))
    with pytest.raises(KilledWorker):
        write_pyramid(killing, out, axes="zyx", chunks=chunk, client=cluster)
    assert int(marker.read_text()) >= 8, "the worker died before any chunk was written"
    assert not out.exists()
    assert not list(tmp_path.glob(".tessera-*")), "the temporary store was left behind"

    # The rerun completes, and is the convert store.
    r = write_pyramid(lazy_volume(n, chunk), out, axes="zyx", chunks=chunk, client=cluster)
    assert_same_store(tmp_path / "cli" / "v.ome.zarr", out)

    # Killed while replacing that store: the complete one stays as it was.
    marker.unlink()
    before = store_files(out)
    other = lazy_volume(n, chunk, kill=((5, 5, 5), tmp_path, marker))[::-1]
    with pytest.raises(KilledWorker):
        write_pyramid(other, out, axes="zyx", chunks=chunk, client=cluster)
    assert store_files(out) == before
    assert not list(tmp_path.glob(".tessera-*")) and not list(tmp_path.glob("*.old-*"))
    assert r.chunks_written == len(before) - len(r.level_shapes) - 2


def test_bad_arguments_raise_with_the_reason(tmp_path):
    a = np.zeros((8, 8, 8), np.uint8)
    with pytest.raises(ValueError, match="dtype int32: expected uint8, uint16, int16 or float32"):
        write_pyramid(a.astype(np.int32), tmp_path / "a.ome.zarr")
    with pytest.raises(ValueError, match=r"chunks 9: expected an even size in 8\.\.1024"):
        write_pyramid(a, tmp_path / "a.ome.zarr", chunks=9)
    with pytest.raises(ValueError, match="levels 0: expected 'auto' or a count in 1..30"):
        write_pyramid(a, tmp_path / "a.ome.zarr", levels=0)
    with pytest.raises(ValueError, match="compressor 'lzma'"):
        write_pyramid(a, tmp_path / "a.ome.zarr", compressor="lzma")
    with pytest.raises(ValueError, match="s3:// is not written directly"):
        write_pyramid(a, "s3://bucket/a.ome.zarr")
    with pytest.raises(ValueError, match="array of 2 dimensions"):
        write_pyramid(a[0], tmp_path / "a.ome.zarr")
    (tmp_path / "notes.zarr").mkdir()
    (tmp_path / "notes.zarr" / "keep.txt").write_text("mine")
    with pytest.raises(FileExistsError, match="notes.zarr: exists and is not an OME-Zarr store"):
        write_pyramid(a, tmp_path / "notes.zarr")
    assert (tmp_path / "notes.zarr" / "keep.txt").read_text() == "mine"
    with pytest.raises(FileNotFoundError, match="folder .*missing does not exist"):
        write_pyramid(a, tmp_path / "missing" / "a.ome.zarr")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.zarr"]
