#!/usr/bin/python3
"""Re-encodes a folder of uncompressed single-frame DICOM files (as
`tessera convert X out/ --format dicom` writes them) for the DICOMweb tests
and benchmark, with Debian's encoders:

  jpeg-lossless  DCMTK's dcmcjpeg (JPEG lossless, process 14 SV1: 1.2.840.10008.1.2.4.70)
  j2k-lossless   OpenJPEG's opj_compress (reversible 5/3), wrapped by pydicom
                 (JPEG 2000 lossless only: 1.2.840.10008.1.2.4.90)
  jpeg-ls        DCMTK's dcmcjpls (JPEG-LS lossless: 1.2.840.10008.1.2.4.80)
  htj2k-lossless OpenJPH's ojph_compress (reversible), wrapped by pydicom
                 (HTJ2K lossless only: 1.2.840.10008.1.2.4.201)

Every file gets a new Series Instance UID (the old one's first 50
characters + "." + SUFFIX) and SOP Instance UID (derived from the old one
and SUFFIX), so that one archive can hold the same slices in several
syntaxes.

usage: DicomWebEncode.py IN_FOLDER OUT_FOLDER KIND SUFFIX
"""
import os
import subprocess
import sys
import tempfile

import numpy as np
import pydicom
from pydicom.encaps import encapsulate
from pydicom._uid_dict import UID_dictionary
from pydicom.uid import generate_uid

# pydicom 2.3 predates HTJ2K: its lossless syntax is made known to it.
UID_dictionary.setdefault("1.2.840.10008.1.2.4.201",
                          ("HTJ2KLossless", "Transfer Syntax", "", "", "HTJ2KLossless"))

src, dst, kind, suffix = sys.argv[1:5]
os.makedirs(dst, exist_ok=True)
work = tempfile.mkdtemp()


def reuid(d, name):
    d.SeriesInstanceUID = d.SeriesInstanceUID[:50] + "." + suffix
    # Derived from the old one (generate_uid hashes its sources): distinct
    # per file and per suffix, as long UIDs that share a prefix stay.
    d.SOPInstanceUID = generate_uid(None, [d.SOPInstanceUID, suffix])
    d.file_meta.MediaStorageSOPInstanceUID = d.SOPInstanceUID
    d.save_as(name, write_like_original=False)


for name in sorted(os.listdir(src)):
    inp, out = os.path.join(src, name), os.path.join(dst, name)
    if kind in ("jpeg-lossless", "jpeg-ls"):
        tool = ["dcmcjpeg"] if kind == "jpeg-lossless" else ["dcmcjpls"]
        tmp = os.path.join(work, name)
        subprocess.run(tool + [inp, tmp], check=True)
        reuid(pydicom.dcmread(tmp), out)
        continue
    d = pydicom.dcmread(inp)
    a = d.pixel_array
    rows, cols = a.shape
    signed = d.PixelRepresentation == 1
    bits = d.BitsAllocated
    raw = os.path.join(work, "frame.raw")
    if kind == "htj2k-lossless":
        # ojph_compress 0.9 reads raw samples unsigned: signed ones go in
        # DC-level shifted (ISO 15444-1 G.1.2) and SIZ is then marked signed.
        shift = 1 << (d.BitsStored - 1) if signed else 0
        (a.astype(np.int64) + shift).astype("<u" + str(bits // 8)).tofile(raw)
        stream = os.path.join(work, "frame.j2c")
        subprocess.run(["ojph_compress", "-i", raw, "-o", stream, "-dims", "{%d,%d}" % (cols, rows),
                        "-num_comps", "1", "-signed", "false",
                        "-bit_depth", str(d.BitsStored), "-downsamp", "{1,1}",
                        "-reversible", "true"],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if signed:
            data = bytearray(open(stream, "rb").read())
            data[42] |= 0x80  # Ssiz of component 0 (A.5.1): signed
            open(stream, "wb").write(data)
        d.file_meta.TransferSyntaxUID = "1.2.840.10008.1.2.4.201"
    else:
        a.astype((">i" if signed else ">u") + str(bits // 8)).tofile(raw)
        stream = os.path.join(work, "frame.j2k")
        subprocess.run(["opj_compress", "-i", raw, "-o", stream, "-F",
                        "%d,%d,1,%d,%s" % (cols, rows, d.BitsStored, "s" if signed else "u")],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        d.file_meta.TransferSyntaxUID = "1.2.840.10008.1.2.4.90"
    d.is_little_endian, d.is_implicit_VR = True, False
    d.PixelData = encapsulate([open(stream, "rb").read()])
    d["PixelData"].VR = "OB"
    d["PixelData"].is_undefined_length = True
    reuid(d, out)
