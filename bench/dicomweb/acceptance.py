#!/usr/bin/python3
"""DICOMweb acceptance run (not a test): a generated 512x512x300 CT series
with a marker, stored in Orthanc (started here on a free loopback port,
DICOMweb plugin only) uncompressed, as JPEG lossless and as JPEG 2000
lossless; for each syntax, `tessera info URL` (time to open, bytes
transferred) and `tessera render URL` against `tessera render FOLDER`.

usage: bench/dicomweb/acceptance.py [TESSERA] [--size 512x512x300]
Prints a Markdown table.
"""
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time

import nibabel as nib
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TESSERA = os.path.join(ROOT, "build", "tessera")
if len(sys.argv) > 1 and not sys.argv[1].startswith("--"):
    TESSERA = sys.argv[1]
SIZE = "512x512x300"
if "--size" in sys.argv:
    SIZE = sys.argv[sys.argv.index("--size") + 1]
NX, NY, NZ = (int(v) for v in SIZE.split("x"))
ENCODE = os.path.join(ROOT, "tests", "io", "DicomWebEncode.py")
MARKER = (NX // 4, NY // 3, NZ // 5)  # voxel index of the bright marker


def ct_volume():
    """Air around an elliptic body of soft tissue with noise, a spine-like
    bone cylinder and a 5-voxel bright cube (the marker) off centre."""
    z, y, x = np.meshgrid(np.arange(NZ), np.arange(NY), np.arange(NX), indexing="ij")
    rng = np.random.default_rng(3)
    body = ((x - NX / 2) / (0.42 * NX)) ** 2 + ((y - NY / 2) / (0.34 * NY)) ** 2 < 1
    v = np.full((NZ, NY, NX), -1000, np.int16)
    v[body] = 40 + rng.integers(-20, 20, size=int(body.sum()), dtype=np.int16)
    bone = (x - NX / 2) ** 2 + (y - 0.7 * NY) ** 2 < (0.05 * NX) ** 2
    v[bone] = 900
    mx, my, mz = MARKER
    v[mz - 2:mz + 3, my - 2:my + 3, mx - 2:mx + 3] = 3000
    return v


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def run(args, **kw):
    return subprocess.run(args, check=True, capture_output=True, text=True, **kw)


def main():
    work = tempfile.mkdtemp(prefix="tessera-dicomweb-bench-")
    orthanc = None
    try:
        v = ct_volume()
        img = nib.Nifti1Image(np.transpose(v, (2, 1, 0)), np.diag([0.7, 0.7, 1.25, 1]))
        nib.save(img, os.path.join(work, "ct.nii.gz"))
        plain = os.path.join(work, "plain")
        run([TESSERA, "convert", os.path.join(work, "ct.nii.gz"), plain + "/", "--quiet"])
        t = time.time()
        for kind, suffix in (("jpeg-lossless", "2"), ("j2k-lossless", "3")):
            run(["/usr/bin/python3", ENCODE, plain, os.path.join(work, kind), kind, suffix])
        encode_s = time.time() - t
        port = free_port()
        store = os.path.join(work, "orthanc")
        os.makedirs(store)
        cfg = os.path.join(work, "orthanc.json")
        json.dump({"Name": "bench", "StorageDirectory": store, "IndexDirectory": store,
                   "HttpPort": port, "DicomServerEnabled": False, "RemoteAccessAllowed": False,
                   "HttpCompressionEnabled": False, "AuthenticationEnabled": False,
                   "Plugins": ["/usr/share/orthanc/plugins/libOrthancDicomWeb.so"],
                   "DicomWeb": {"Enable": True, "Root": "/dicom-web/"}}, open(cfg, "w"))
        orthanc = subprocess.Popen(["/usr/sbin/Orthanc", cfg], stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
        base = "http://127.0.0.1:%d" % port
        for _ in range(100):
            if subprocess.run(["curl", "-sf", "-o", "/dev/null", base + "/system"]).returncode == 0:
                break
            time.sleep(0.1)
        sizes = {}
        for kind in ("plain", "jpeg-lossless", "j2k-lossless"):
            folder = os.path.join(work, kind)
            files = sorted(os.listdir(folder))
            sizes[kind] = sum(os.path.getsize(os.path.join(folder, f)) for f in files)
            for i in range(0, len(files), 50):
                args = ["curl"]
                for f in files[i:i + 50]:
                    # --next: each file its own request (data options are per request).
                    args += ["-sf", "-X", "POST", "--data-binary", "@" + os.path.join(folder, f),
                             base + "/instances", "-o", "/dev/null", "--next"]
                args.pop()
                run(args)
        listing = json.loads(run([TESSERA, "dicomweb", base + "/dicom-web", "--json"]).stdout)
        urls = {s["uid"]: s["url"] for st in listing["studies"] for s in st["series"]}
        view = ["--size", "512x512", "--azimuth", "30", "--elevation", "20"]
        folder_png = os.path.join(work, "folder.png")
        t = time.time()
        folder_info = json.loads(run([TESSERA, "info", plain, "--json"]).stdout)
        folder_open = time.time() - t
        run([TESSERA, "render", plain, "--out", folder_png] + view)
        folder_pixels = open(folder_png, "rb").read()
        rows = []
        for kind, name in (("plain", "uncompressed"), ("jpeg-lossless", "JPEG lossless"),
                           ("j2k-lossless", "JPEG 2000 lossless")):
            plain_uid = folder_info["dicom_series"][0]["series_instance_uid"]
            uid = plain_uid if kind == "plain" else plain_uid[:50] + (
                ".2" if kind == "jpeg-lossless" else ".3")
            url = urls[uid]
            t = time.time()
            info = json.loads(run([TESSERA, "info", url, "--json"]).stdout)
            open_s = time.time() - t
            desc = info["description"]
            fetched = desc[desc.rfind("; ") + 2:]
            png = os.path.join(work, kind + ".png")
            run([TESSERA, "render", url, "--out", png] + view)
            same_png = open(png, "rb").read() == folder_pixels
            same_geometry = info["affine"] == folder_info["affine"] and \
                info["dims"] == folder_info["dims"]
            same_range = (info["value_min"], info["value_max"]) == \
                (folder_info["value_min"], folder_info["value_max"])
            rows.append((name, "%.1f MiB" % (sizes[kind] / 2**20), "%.2f s" % open_s, fetched,
                         "yes" if same_geometry and same_range else "NO",
                         "identical" if same_png else "DIFFERENT"))
        print("%s CT, marker at voxel %s; folder open %.2f s; encoding %.0f s\n" %
              (SIZE, MARKER, folder_open, encode_s))
        print("| stored as | in Orthanc (files) | `tessera info URL` | transferred "
              "| dims, affine, range = folder | `render URL` vs `render FOLDER` PNG |")
        print("|---|---|---|---|---|---|")
        for r in rows:
            print("| " + " | ".join(r) + " |")
    finally:
        if orthanc:
            orthanc.terminate()
            orthanc.wait()
        shutil.rmtree(work, ignore_errors=True)


main()
