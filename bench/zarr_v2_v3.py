#!/usr/bin/python3
"""Zarr v2 against Zarr v3 sharded, the same volume served by nginx (issue 30).

    /usr/bin/python3 bench/zarr_v2_v3.py [--size 1024] [--chunk 64] [--shard 4]
        [--image 512x512] [--rounds 2] [--work /tmp/zarr_v2_v3] [--tessera build/tessera]

Writes a SIZE^3 u8 head-like volume (an ellipsoid shell of "bone" around a
textured "brain", air in the corners; numpy alone, streamed as an
uncompressed NGFF 0.4 store of 128^3 chunks), converts it with `tessera
convert` to NGFF 0.4 on Zarr v2 (CHUNK^3 zstd chunks) and to NGFF 0.5 on
Zarr v3 sharded (the same chunks, SHARD^3 of them per shard file), serves
both from one nginx on 127.0.0.1 with an access log, and renders each with

    tessera render http://127.0.0.1:PORT/NAME.ome.zarr --layout bricks --size 512x512 --json

until the frame is refined (every brick at the level the 512^2 frame
needs). The stores alternate (v2, v3, v2, v3 ...) in one run, so a busy
machine loads both alike. Per render: requests and body bytes from nginx's
access log (by status: 206 ranges, 200 whole files, 404 absent chunks),
the client's own count, the wall time of the command and the renderer's
time to the refined frame, and the 1-minute load average before it (the
machine is shared). Prints a Markdown table (docs/large-data.md).
"""
import argparse
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
from collections import Counter

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def head_block(z0, y0, n, size, rng):
    """Voxels [z0, z0+n) x [y0, y0+n) x [0, size) of the head, u8 (z, y, x)."""
    c = (np.arange(size, dtype=np.float32) + 0.5) / size * 2.0 - 1.0
    z = c[z0:z0 + n, None, None]
    y = c[None, y0:y0 + n, None]
    x = c[None, None, :]
    r = np.sqrt((x / 0.78) ** 2 + (y / 0.92) ** 2 + (z / 0.85) ** 2)
    tex = (np.sin(23.0 * x + 3.0 * np.sin(7.0 * z)) * np.sin(19.0 * y + 2.0 * np.cos(9.0 * x))
           * np.sin(17.0 * z + 2.5 * np.sin(5.0 * y)))
    brain = 90.0 + 35.0 * tex
    v = np.where(r < 0.86, brain, 0.0)
    v = np.where((r >= 0.86) & (r < 0.95), 220.0, v)  # bone
    v = np.where((r >= 0.95) & (r < 1.0), 60.0, v)  # skin
    noise = rng.integers(-6, 7, size=v.shape, dtype=np.int16)
    v = np.where(r < 1.0, v + noise, 0.0)
    return np.clip(v, 0, 255).astype(np.uint8)


def write_source(path, size):
    """An uncompressed NGFF 0.4 / Zarr v2 store, 128^3 chunks, written block by block."""
    n = 128
    if os.path.exists(path):
        shutil.rmtree(path)
    os.makedirs(os.path.join(path, "0"))
    with open(os.path.join(path, ".zgroup"), "w") as f:
        json.dump({"zarr_format": 2}, f)
    with open(os.path.join(path, ".zattrs"), "w") as f:
        json.dump({"multiscales": [{
            "version": "0.4", "name": "head",
            "axes": [{"name": a, "type": "space", "unit": "millimeter"} for a in "zyx"],
            "datasets": [{"path": "0", "coordinateTransformations": [
                {"type": "scale", "scale": [0.25, 0.25, 0.25]}]}]}]}, f)
    with open(os.path.join(path, "0", ".zarray"), "w") as f:
        json.dump({"zarr_format": 2, "shape": [size] * 3, "chunks": [n] * 3, "dtype": "|u1",
                   "compressor": None, "fill_value": 0, "order": "C", "filters": None,
                   "dimension_separator": "/"}, f)
    rng = np.random.default_rng(30)
    for zi in range(size // n):
        for yi in range(size // n):
            block = head_block(zi * n, yi * n, n, size, rng)
            for xi in range(size // n):
                d = os.path.join(path, "0", str(zi), str(yi))
                os.makedirs(d, exist_ok=True)
                with open(os.path.join(d, str(xi)), "wb") as f:
                    f.write(np.ascontiguousarray(block[:, :, xi * n:(xi + 1) * n]).tobytes())


def store_stats(path):
    files = 0
    total = 0
    for dirpath, _, names in os.walk(path):
        for name in names:
            files += 1
            total += os.path.getsize(os.path.join(dirpath, name))
    return files, total


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Nginx:
    """nginx on loopback serving ROOT, one access-log line per request."""

    def __init__(self, root, prefix):
        os.makedirs(os.path.join(prefix, "tmp"), exist_ok=True)
        self.port = free_port()
        self.log = os.path.join(prefix, "access.log")
        conf = os.path.join(prefix, "nginx.conf")
        temps = "".join(f" {k}_temp_path {prefix}/tmp;\n"
                        for k in ("client_body", "proxy", "fastcgi", "uwsgi", "scgi"))
        with open(conf, "w") as f:
            f.write(f"daemon off;\nworker_processes 1;\npid {prefix}/nginx.pid;\n"
                    f"error_log {prefix}/error.log;\nevents {{ worker_connections 256; }}\n"
                    "http {\n log_format bench '$status $body_bytes_sent $request_method "
                    "$uri \"$http_range\"';\n"
                    f" access_log {self.log} bench;\n{temps}"
                    f" server {{ listen 127.0.0.1:{self.port}; root {root}; location / {{ }} }}\n}}\n")
        open(self.log, "w").close()
        self.proc = subprocess.Popen(["/usr/sbin/nginx", "-p", prefix, "-c", conf])
        for _ in range(100):
            try:
                socket.create_connection(("127.0.0.1", self.port), 0.1).close()
                return
            except OSError:
                time.sleep(0.1)
        raise RuntimeError("nginx did not start")

    def url(self, name):
        return f"http://127.0.0.1:{self.port}/{name}"

    def stop(self):
        self.proc.send_signal(signal.SIGQUIT)
        self.proc.wait(10)


LINE = re.compile(r'^(\d+) (\d+) (\S+) (\S+) "(.*)"$')


def read_log(path, offset):
    with open(path) as f:
        f.seek(offset)
        lines = f.read().splitlines()
    status = Counter()
    body = 0
    for line in lines:
        m = LINE.match(line)
        if not m:
            continue
        status[int(m.group(1))] += 1
        body += int(m.group(2))
    return len(lines), status, body


def mib(n):
    return f"{n / 2**20:.2f} MiB"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=1024, help="volume edge (multiple of 128)")
    ap.add_argument("--chunk", type=int, default=64)
    ap.add_argument("--shard", type=int, default=4, help="chunks per shard edge (v3)")
    ap.add_argument("--image", default="512x512")
    ap.add_argument("--rounds", type=int, default=2, help="v2, v3 pairs")
    ap.add_argument("--work", default="/tmp/zarr_v2_v3")
    ap.add_argument("--tessera", default=os.path.join(ROOT, "build", "tessera"))
    ap.add_argument("--reuse", action="store_true", help="keep stores already in --work")
    ap.add_argument("--extra", default="", help="more `tessera render` options")
    a = ap.parse_args()
    if a.size % 128:
        sys.exit("--size must be a multiple of 128")
    www = os.path.join(a.work, "www")
    os.makedirs(www, exist_ok=True)
    source = os.path.join(a.work, "source.ome.zarr")
    v2 = os.path.join(www, "v2.ome.zarr")
    v3 = os.path.join(www, "v3.ome.zarr")
    if not (a.reuse and os.path.exists(source)):
        t = time.time()
        write_source(source, a.size)
        print(f"source {a.size}^3 u8 written in {time.time() - t:.1f} s", file=sys.stderr)
    for out, extra in ((v2, []), (v3, ["--zarr-format", "3", "--shard", str(a.shard)])):
        if a.reuse and os.path.exists(out):
            continue
        t = time.time()
        subprocess.run([a.tessera, "convert", source, out, "--chunk", str(a.chunk), "--quiet"]
                       + extra, check=True)
        print(f"{os.path.basename(out)} converted in {time.time() - t:.1f} s", file=sys.stderr)

    nginx = Nginx(www, os.path.join(a.work, "nginx"))
    rows = []
    try:
        for _ in range(a.rounds):
            for name in ("v2.ome.zarr", "v3.ome.zarr"):
                offset = os.path.getsize(nginx.log)
                cmd = [a.tessera, "render", nginx.url(name), "--layout", "bricks", "--size",
                       a.image, "--json", "--out", os.path.join(a.work, name + ".png")]
                cmd += a.extra.split()
                load = os.getloadavg()[0]
                t = time.time()
                p = subprocess.run(cmd, capture_output=True, text=True)
                wall = time.time() - t
                if p.returncode:
                    sys.exit(f"{' '.join(cmd)} failed:\n{p.stderr}")
                j = json.loads(p.stdout)
                time.sleep(0.2)  # nginx writes its log line after the response
                n, status, body = read_log(nginx.log, offset)
                b = j.get("bricks", {})
                rows.append({"store": name, "requests": n, "status": dict(status), "body": body,
                             "client_requests": j.get("http", {}).get("requests"),
                             "client_bytes": j.get("http", {}).get("bytes_fetched"),
                             "wall_s": wall, "load": load, "complete_ms": b.get("complete_ms"),
                             "complete": b.get("complete"), "frames": b.get("refine_frames"),
                             "wanted_per_level": b.get("wanted_per_level")})
                print(json.dumps(rows[-1]), file=sys.stderr)
    finally:
        nginx.stop()

    print(f"{a.size}^3 u8 head, {a.chunk}^3 zstd chunks, v3 with --shard {a.shard}; "
          f"`tessera render URL --layout bricks --size {a.image}`, nginx on 127.0.0.1\n")
    print("| store | files | stored | bricks wanted per level | requests (206 / 200 / 404) "
          "| body bytes | to the refined frame | wall | load before |")
    print("|---|---|---|---|---|---|---|---|---|")
    stats = {n: store_stats(os.path.join(www, n)) for n in ("v2.ome.zarr", "v3.ome.zarr")}
    for r in rows:
        files, total = stats[r["store"]]
        s = r["status"]
        label = "v2" if r["store"].startswith("v2") else f"v3, shards of {a.shard}³ chunks"
        print(f"| {label} | {files} | {mib(total)} | {r['wanted_per_level']} | {r['requests']} "
              f"({s.get(206, 0)} / {s.get(200, 0)} / {s.get(404, 0)}) | {mib(r['body'])} | "
              f"{r['complete_ms'] / 1000:.2f} s{'' if r['complete'] else ' (not refined)'} | "
              f"{r['wall_s']:.2f} s | {r['load']:.1f} |")


if __name__ == "__main__":
    main()
