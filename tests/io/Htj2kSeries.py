#!/usr/bin/python3
"""Writes the DICOM series the HTJ2K tests read (tests/io/Htj2kDicomTest.cpp):
for each case a folder of three 48x40 slices of a synthetic phantom (a smooth
pattern with noise, as many bits as the case says), uncompressed in
OUT/CASE/plain/ and encoded by Debian's ojph_compress in OUT/CASE/coded/,
wrapped by pydicom. The slices' header is pydicom's MR_small.dcm's with the
pixel module, geometry and UIDs rewritten.

A case is KIND-BITS-SIGN[-VARIANT]:
  KIND     lossless (.201, LRCP), rpcl (.202), lossy (.203, 9/7 wavelet),
           in-j2k (a lossless HTJ2K stream in a file saying JPEG 2000, .90)
  BITS     8, 12 or 16 (Bits Stored; Bits Allocated 8 or 16)
  SIGN     u or s (Pixel Representation 0 or 1)
  VARIANT  tiles: 16x16 tiles; truncated: the codestream cut to a third;
           rows: the header declares half the rows; garbage: a fragment of
           random bytes; sign: Pixel Representation says the other sign;
           colour: a three-component stream with Samples per Pixel 1;
           cut90: the codestream cut to 90%; nosoc: SOC marker missing

usage: Htj2kSeries.py OUT CASE...
"""
import copy
import os
import subprocess
import sys

import numpy as np
import pydicom
from pydicom._uid_dict import UID_dictionary
from pydicom.encaps import encapsulate
from pydicom.uid import generate_uid

# pydicom 2.3 predates HTJ2K: its transfer syntaxes are made known to it.
for uid, name in (("1.2.840.10008.1.2.4.201", "HTJ2KLossless"),
                  ("1.2.840.10008.1.2.4.202", "HTJ2KLosslessRPCL"),
                  ("1.2.840.10008.1.2.4.203", "HTJ2K")):
    UID_dictionary.setdefault(uid, (name, "Transfer Syntax", "", "", name))

TEMPLATE = "/usr/lib/python3/dist-packages/pydicom/data/test_files/MR_small.dcm"
ROWS, COLS, SLICES = 40, 48, 3
SYNTAX = {"lossless": "1.2.840.10008.1.2.4.201", "rpcl": "1.2.840.10008.1.2.4.202",
          "lossy": "1.2.840.10008.1.2.4.203", "in-j2k": "1.2.840.10008.1.2.4.90"}


def phantom(bits, signed, z, seed):
    lo, hi = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)
    y, x = np.mgrid[0:ROWS, 0:COLS]
    rng = np.random.default_rng(seed + z)
    a = lo + (hi - lo) * (0.5 + 0.45 * np.sin(x / 6.0 + z) * np.cos(y / 5.0))
    a = a + rng.integers(-(1 << max(bits - 8, 1)), 1 << max(bits - 8, 1), (ROWS, COLS))
    a = np.clip(np.rint(a), lo, hi).astype(np.int64)
    a[3, 4] = hi  # the extremes, so every bit is exercised
    a[5, 6] = lo
    return a


def encode(a, bits, signed, kind, variant, work):
    raw, stream = os.path.join(work, "frame.raw"), os.path.join(work, "frame.j2c")
    comps = 3 if variant == "colour" else 1
    # ojph_compress 0.9 reads raw samples as unsigned (never sign-extends),
    # so signed data is encoded as unsigned after the DC level shift
    # (ISO 15444-1 G.1.2: u = s + 2^(B-1)) and SIZ then says signed: a
    # decoder skips the inverse shift and gives s back, exactly.
    if signed:
        a = a + (1 << (bits - 1))
    dt = "u1" if bits <= 8 else "<u2"
    np.stack([a] * comps).astype(dt).tofile(raw)
    args = ["ojph_compress", "-i", raw, "-o", stream, "-dims", "{%d,%d}" % (COLS, ROWS),
            "-num_comps", str(comps), "-signed", ",".join(["false"] * comps),
            "-bit_depth", ",".join([str(bits)] * comps),
            "-downsamp", ",".join(["{1,1}"] * comps)]
    if kind == "lossy":
        args += ["-qstep", "0.0005"]
    else:
        args += ["-reversible", "true"]
    args += ["-prog_order", "RPCL" if kind == "rpcl" else "LRCP"]
    if variant == "tiles":
        args += ["-tile_size", "{16,16}"]
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    data = bytearray(open(stream, "rb").read())
    if signed:  # Ssiz of each component (A.5.1): byte 42 + 3c, bit 7 the sign
        for c in range(comps):
            data[42 + 3 * c] |= 0x80
    data = bytes(data)
    if variant == "truncated":
        data = data[:len(data) // 3]
    elif variant == "cut90":
        data = data[:len(data) * 9 // 10]
    elif variant == "garbage":
        data = bytes(np.random.default_rng(7).integers(0, 256, len(data), dtype=np.uint8))
    elif variant == "nosoc":
        data = data[2:]
    return data


def write(template, a, bits, signed, z, series, out, pixels=None, syntax=None, extra=None):
    d = copy.deepcopy(template)
    d.Rows, d.Columns = ROWS, COLS
    d.BitsAllocated = 8 if bits <= 8 else 16
    d.BitsStored, d.HighBit = bits, bits - 1
    d.PixelRepresentation = 1 if signed else 0
    d.SamplesPerPixel = 1
    d.PhotometricInterpretation = "MONOCHROME2"
    d.SeriesInstanceUID = series
    d.SOPInstanceUID = generate_uid(None, [series, str(z)])
    d.file_meta.MediaStorageSOPInstanceUID = d.SOPInstanceUID
    d.InstanceNumber = z + 1
    d.ImagePositionPatient = [-20.0, -15.0, 4.0 * z]
    d.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
    d.PixelSpacing = [0.5, 0.75]
    d.SliceThickness = 4.0
    for tag in ("RescaleSlope", "RescaleIntercept", "WindowCenter", "WindowWidth"):
        if tag in d:
            delattr(d, tag)
    d.is_little_endian, d.is_implicit_VR = True, False
    if pixels is None:
        d.file_meta.TransferSyntaxUID = "1.2.840.10008.1.2.1"
        dt = ("i1" if signed else "u1") if bits <= 8 else ("<i2" if signed else "<u2")
        d.PixelData = a.astype(dt).tobytes()
        d["PixelData"].VR = "OB" if bits <= 8 else "OW"
    else:
        d.file_meta.TransferSyntaxUID = syntax
        d.PixelData = encapsulate([pixels])
        d["PixelData"].VR = "OB"
        d["PixelData"].is_undefined_length = True
    for key, value in (extra or {}).items():
        setattr(d, key, value)
    os.makedirs(os.path.dirname(out), exist_ok=True)
    d.save_as(out, write_like_original=False)


def make(root, case):
    parts = case.split("-")
    if parts[0] == "in" and parts[1] == "j2k":
        parts = ["in-j2k"] + parts[2:]
    kind, bits, sign = parts[0], int(parts[1]), parts[2]
    variant = parts[3] if len(parts) > 3 else ""
    signed = sign == "s"
    template = pydicom.dcmread(TEMPLATE)
    work = os.path.join(root, case)
    os.makedirs(work, exist_ok=True)
    series = generate_uid(None, [case])
    for z in range(SLICES):
        a = phantom(bits, signed, z, bits * 2 + signed)
        name = "slice%d.dcm" % z
        write(template, a, bits, signed, z, series + ".1", os.path.join(work, "plain", name))
        data = encode(a, bits, signed, kind, variant, work)
        extra = {}
        if variant == "rows":
            extra["Rows"] = ROWS // 2
        if variant == "sign":
            extra["PixelRepresentation"] = 0 if signed else 1
        write(template, a, bits, signed, z, series + ".2", os.path.join(work, "coded", name),
              data, SYNTAX[kind], extra)


for c in sys.argv[2:]:
    make(sys.argv[1], c)
