"""Fixtures of the Python module's tests: the package from python/ (its
extension from the CMake build, $TESSERA_BUILD_DIR or build/), the CLI beside
it for comparisons, and PNG and PSNR helpers."""
import json
import os
import subprocess
import sys
import zlib

import numpy as np
import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
BUILD = os.environ.get("TESSERA_BUILD_DIR") or os.path.join(ROOT, "build")
sys.path.insert(0, os.path.join(ROOT, "python"))

CH2 = "/usr/share/mricron/templates/ch2.nii.gz"


@pytest.fixture(scope="session")
def root():
    return ROOT


@pytest.fixture(scope="session")
def cli():
    path = os.path.join(BUILD, "tessera")
    if not os.path.exists(path):
        pytest.skip(f"{path} is not built")
    return path


@pytest.fixture(scope="session")
def ch2():
    if not os.path.exists(CH2):
        pytest.skip(f"{CH2} (mricron-data) is not installed")
    return CH2


def run_cli(cli, *args):
    out = subprocess.run([cli, *args], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return out.stdout


def run_cli_json(cli, *args):
    return json.loads(run_cli(cli, *args, "--json"))


def read_png(path):
    """RGBA uint8 (H, W, 4) of an 8-bit RGBA, non-interlaced PNG (what the
    library writes), without an imaging library."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    at, idat, width, height = 8, b"", 0, 0
    while at < len(data):
        n = int.from_bytes(data[at : at + 4], "big")
        tag, body = data[at + 4 : at + 8], data[at + 8 : at + 8 + n]
        if tag == b"IHDR":
            width, height = int.from_bytes(body[:4], "big"), int.from_bytes(body[4:8], "big")
            assert body[8] == 8 and body[9] == 6, "expected 8-bit RGBA"
        elif tag == b"IDAT":
            idat += body
        at += 12 + n
    raw = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(height, 1 + width * 4)
    out = np.zeros((height, width * 4), np.int32)
    prev = np.zeros(width * 4, np.int32)
    for y in range(height):
        f, line = raw[y, 0], raw[y, 1:].astype(np.int32)
        cur = np.zeros(width * 4, np.int32)
        for x in range(width * 4):
            a = cur[x - 4] if x >= 4 else 0
            b = prev[x]
            c = prev[x - 4] if x >= 4 else 0
            if f == 0:
                p = 0
            elif f == 1:
                p = a
            elif f == 2:
                p = b
            elif f == 3:
                p = (a + b) // 2
            else:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            cur[x] = (line[x] + p) & 255
        out[y], prev = cur, cur
    return out.reshape(height, width, 4).astype(np.uint8)


def psnr(a, b):
    """PSNR in dB over RGB (inf when identical)."""
    d = a[..., :3].astype(np.float64) - b[..., :3].astype(np.float64)
    mse = float(np.mean(d * d))
    return float("inf") if mse == 0 else 10.0 * np.log10(255.0 * 255.0 / mse)
