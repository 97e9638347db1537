#!/usr/bin/python3
"""Benchmark: tessera.zarr.write_pyramid of a lazily generated N^3 u8 volume on a
LocalCluster of 2 worker processes against 1, in one run; the client's peak RSS;
and chunk identity with `tessera convert` of the same voxels (as NIfTI).

    /usr/bin/python3 bench/dask_pyramid.py                 # 1024^3, chunks 64
    /usr/bin/python3 bench/dask_pyramid.py --size 512 --workers 1 2 4

Not a test: it prints figures (docs/large-data.md quotes them). The work folder
(default: a temporary one) holds the NIfTI (N^3 bytes) and three stores.
"""

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python"))

from tessera.zarr import write_pyramid  # noqa: E402


def voxels(z0, z1, y0, y1, x0, x1, n):
    """A textured ellipsoid in zeros, u8, any (z, y, x) box of an n^3 volume."""
    z, y, x = (np.arange(a, b, dtype=np.int32) for a, b in ((z0, z1), (y0, y1), (x0, x1)))
    c = (n - 1) / 2.0
    rz, ry, rx = (((v - c) / (f * n)) ** 2 for v, f in ((z, 0.42), (y, 0.40), (x, 0.45)))
    inside = (rz[:, None, None] + (ry[:, None] + rx[None, :])[None]) < 1.0
    zy = (z * 3)[:, None] + (y * 13)[None, :]
    v = (zy[:, :, None] + (x * 7)[None, None, :]) ^ ((y[:, None] * x[None, :]) >> 4)[None]
    return np.where(inside, v & 0xFF, 0).astype(np.uint8)


def lazy_volume(n, chunk):
    import dask.array as da

    def block(block_info=None):
        (z0, z1), (y0, y1), (x0, x1) = block_info[None]["array-location"]
        return voxels(z0, z1, y0, y1, x0, x1, n)

    sizes = tuple(min(chunk, n - i) for i in range(0, n, chunk))
    return da.map_blocks(block, dtype=np.uint8, chunks=(sizes,) * 3)


def write_nifti(path, n):
    import nibabel as nib

    hdr = nib.Nifti1Header()
    hdr.set_data_shape((n, n, n))
    hdr.set_data_dtype(np.uint8)
    hdr.set_sform(np.eye(4), code=1)
    hdr.set_qform(np.eye(4), code=1)
    hdr["vox_offset"] = 352
    with open(path, "wb") as f:
        f.write(hdr.binaryblock + b"\0" * 4)
        for z0 in range(0, n, 32):
            f.write(voxels(z0, min(n, z0 + 32), 0, n, 0, n, n).tobytes())


class PeakRss:
    def __enter__(self):
        import psutil

        self._proc = psutil.Process()
        self.start = self.peak = self._proc.memory_info().rss
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._sample, daemon=True)
        self._thread.start()
        return self

    def _sample(self):
        while not self._stop.wait(0.01):
            self.peak = max(self.peak, self._proc.memory_info().rss)

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()


def store_files(root):
    root = Path(root)
    return {str(p.relative_to(root)): p for p in root.rglob("*") if p.is_file()}


def identical(a, b):
    fa, fb = store_files(a), store_files(b)
    same = sorted(fa) == sorted(fb) and all(
        fa[k].read_bytes() == fb[k].read_bytes() for k in fa
    )
    return same, len(fa)


def worker_peak_rss():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def mib(b):
    return b / 2**20


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--chunks", type=int, default=64)
    ap.add_argument("--workers", type=int, nargs="+", default=[2, 1])
    ap.add_argument("--cli", default=str(ROOT / "build" / "tessera"))
    ap.add_argument("--workdir", default=None)
    ap.add_argument("--convert-store", default=None,
                    help="a `tessera convert` store of this volume from an earlier run: "
                    "compare with it instead of writing the NIfTI and converting again")
    args = ap.parse_args()

    from distributed import Client, LocalCluster

    n = args.size
    work = Path(args.workdir or tempfile.mkdtemp(prefix="tessera-dask-bench-"))
    work.mkdir(parents=True, exist_ok=True)
    print(f"{n}^3 u8 ({mib(n**3):.0f} MiB), chunks {args.chunks}^3, zstd; work folder {work}")
    print(f"machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}")

    if args.convert_store:
        reference = Path(args.convert_store)
        print(f"tessera convert: the store of an earlier run, {reference}")
        convert_s = convert_rss = None
    else:
        reference = work / "cli" / "vol.ome.zarr"
        t = time.perf_counter()
        write_nifti(work / "vol.nii", n)
        print(f"NIfTI written in {time.perf_counter() - t:.1f} s")
        reference.parent.mkdir(exist_ok=True)
        shutil.rmtree(reference, ignore_errors=True)
        t = time.perf_counter()
        subprocess.run([args.cli, "convert", str(work / "vol.nii"), str(reference),
                        "--chunk", str(args.chunks)], check=True, capture_output=True)
        convert_s = time.perf_counter() - t
        convert_rss = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024
        print(f"tessera convert: {convert_s:.1f} s, peak RSS {mib(convert_rss):.0f} MiB")
        os.remove(work / "vol.nii")

    rows = []
    volume = lazy_volume(n, 128)
    for workers in args.workers:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=40)
        client = Client(cluster)
        out = work / f"w{workers}" / "vol.ome.zarr"
        out.parent.mkdir(exist_ok=True)
        with PeakRss() as rss:
            r = write_pyramid(volume, out, axes="zyx", chunks=args.chunks, client=client)
        worker_rss = max(client.run(worker_peak_rss).values())
        client.close()
        cluster.close()
        same, files = identical(reference, out)
        rows.append((workers, r.seconds, mib(rss.peak - rss.start), mib(rss.peak),
                     mib(worker_rss), same, files))
        print(f"{workers} worker(s): {r.seconds:.1f} s, client RSS +{mib(rss.peak - rss.start):.1f}"
              f" MiB (peak {mib(rss.peak):.0f} MiB), worker peak {mib(worker_rss):.0f} MiB, "
              f"{r.chunks_written} chunks written, {r.chunks_skipped} skipped, "
              f"{'identical to' if same else 'DIFFERENT from'} convert ({files} files)")
        shutil.rmtree(out)

    print()
    print("| workers | seconds | speed-up | client RSS growth | worker peak RSS | = convert |")
    print("|---|---|---|---|---|---|")
    base = next((s for w, s, *_ in rows if w == 1), rows[0][1])
    for workers, seconds, growth, _, worker_rss, same, files in rows:
        print(f"| {workers} | {seconds:.1f} | {base / seconds:.2f}x | {growth:.1f} MiB "
              f"| {worker_rss:.0f} MiB | {'identical' if same else 'DIFFERENT'} ({files} files) |")
    if convert_s is not None:
        print(f"| convert | {convert_s:.1f} | | | {mib(convert_rss):.0f} MiB (one process) | |")
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    if not args.workdir:
        shutil.rmtree(work)
    return 0 if all(r[5] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
