#!/usr/bin/env python3
"""Writes the bad-input corpus (tests/data/bad/) and the fuzz seed corpora
(fuzz/corpus/<target>/).

Every case in tests/data/bad/ is a file (or, for DICOM, a folder) that
readVolume() must reject with tessera::InputError or tessera::BudgetError,
quickly and without allocating what the file cannot justify
(tests/io/BadCorpusTest.cpp). MANIFEST.json lists each case:

  file        path relative to tests/data/bad/, what readVolume() is given
  format      the reader it exercises
  problem     what is wrong with it
  expect      text the error message must contain (case-insensitive);
              "a|b" accepts either a or b
  companions  other files the case needs (detached data, sidecars)

The fuzz seeds are small valid files, one folder per fuzz target. Seeds
written here are rewritten; other files in fuzz/corpus/ (seeds encoded by
other tools: DICOMweb answers, HTJ2K codestreams, DICOM files from pydicom,
fuzz finds) are kept, and --check compares only the seeds written here.

Standard library only, deterministic: running it twice gives the same bytes
(with the same zlib). Files in tests/data/bad/fuzz-regressions/ are crash
inputs found by scripts/fuzz.sh, copied by hand; they are kept, and listed
through FUZZ_REGRESSIONS below.

Usage: scripts/make_bad_corpus.py [--check]   (--check: only verify the
committed corpus matches what this script writes)
"""

import gzip
import json
import os
import shutil
import struct
import sys
import tempfile
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

MiB = 1 << 20
# A real decompression bomb: 50 MiB of zeros deflate to ~50 KB (zlib's best
# ratio is close to deflate's bound of 1032:1, zlib FAQ). Files stay < 64 KiB.
BOMB_INFLATED = 50 * MiB - 64 * 1024
BOMB_CLAIMED_DIMS = (320, 320, 512)  # u8: exactly 50 MiB, 64 KiB more than the stream holds

# Crash inputs found by fuzzing, copied into fuzz-regressions/<target>/ by
# hand: (file, format, problem, expect). scripts/fuzz.sh also replays them as
# seeds. device_profile cases are not volumes: BadCorpusTest skips them (test_io
# does not link the gpu layer) and fuzz_device_profile replays them.
DICOM_HUGE_LENGTH = "length|ends|truncat|corrupt|readable|larger than|exceeds"
FUZZ_REGRESSIONS = [
    ("fuzz-regressions/nrrd/empty-space-directions-crash-9483.nrrd", "nrrd",
     "fuzz_nrrd: empty 'space directions:' line indexed an empty vector (UBSan)",
     "'space directions' has no values"),
    ("fuzz-regressions/dicom/huge-meta-element-length-oom", "dicom",
     "fuzz_dicom: a 160-byte file whose meta Transfer Syntax UID element (VR mutated to 'UM') "
     "declares gigabytes; reading the UID makes DCMTK allocate them (OOM)", DICOM_HUGE_LENGTH),
    ("fuzz-regressions/dicom/huge-element-length-oom", "dicom",
     "fuzz_dicom: a dataset element declaring gigabytes in a 717-byte file; reading it as a "
     "string makes DCMTK allocate them (OOM)", DICOM_HUGE_LENGTH),
    ("fuzz-regressions/dicom/htj2k-zero-tile-size-fpe.dcm", "dicom",
     "fuzz_dicom_basic: an HTJ2K frame whose SIZ marker declares a zero tile size; OpenJPH's "
     "pre-allocation divided by it (SIGFPE); the tiling is checked before OpenJPH sizes anything",
     "HTJ2K frame"),
    ("fuzz-regressions/dicom/htj2k-corrupt-codeblocks-overflow.dcm", "dicom",
     "fuzz_dicom_basic: an HTJ2K frame with sane headers and corrupt code-block data; Debian 12's "
     "OpenJPH 0.9 wrote past its buffers (heap overflow; its own ojph_expand crashes too); now "
     "the claim runs into io/Htj2kFrame's guard bytes and is refused before OpenJPH writes",
     "HTJ2K frame"),
    ("fuzz-regressions/device_profile/number-overflow-crash.json", "device_profile",
     "fuzz_device_profile: a number too large for a double made nlohmann::json throw "
     "out_of_range.406, which escaped DeviceProfile::fromJson", "device profile"),
    ("fuzz-regressions/dicom/htj2k-mel-assert-abort.dcm", "dicom",
     "fuzz_dicom_basic: an HTJ2K frame whose MEL segment starts past 0x8F; Debian 12's OpenJPEG "
     "2.5.0, tried as HTJ2K's decoder, aborted on an assertion in ht_dec.c (mel_init); HTJ2K now "
     "goes to OpenJPH, which rejects the code-block", "HTJ2K frame"),
    ("fuzz-regressions/dicom/htj2k-terminate-assert-abort.dcm", "dicom",
     "fuzz_htj2k: a packet header ending in two 0xFF bytes; Debian 12's OpenJPH 0.9 (assertions "
     "on) aborted in bb_terminate (unstuff == false); marker codes in packet data are now refused "
     "before OpenJPH reads them (and OpenJPH decodes in a child process)", "HTJ2K frame"),
]


def noise(n, seed=1):
    """Deterministic bytes that deflate cannot shrink (xorshift32)."""
    x = seed or 1
    out = bytearray(n)
    for i in range(n):
        x ^= (x << 13) & 0xFFFFFFFF
        x ^= x >> 17
        x ^= (x << 5) & 0xFFFFFFFF
        out[i] = x & 0xFF
    return bytes(out)


def gz(data):
    return gzip.compress(data, compresslevel=9, mtime=0)


def zl(data):
    return zlib.compress(data, 9)


class Corpus:
    def __init__(self, root):
        self.root = root
        self.cases = []

    def write(self, rel, data):
        path = os.path.join(self.root, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        if isinstance(data, str):
            data = data.encode("latin-1")
        with open(path, "wb") as f:
            f.write(data)

    def case(self, rel, fmt, problem, expect, data=None, companions=None):
        """One case; `companions` maps relative paths to their bytes."""
        if data is not None:
            self.write(rel, data)
        entry = {"file": rel, "format": fmt, "problem": problem, "expect": expect}
        if companions:
            for crel, cdata in companions.items():
                self.write(crel, cdata)
            entry["companions"] = sorted(companions)
        self.cases.append(entry)


# --------------------------------------------------------------------- NIfTI

NIFTI_DT = {"u8": (2, 8), "i16": (4, 16), "i32": (8, 32), "f32": (16, 32), "complex64": (32, 64),
            "u16": (512, 16), "rgb24": (128, 24)}


def nifti_header(dims=(4, 3, 2), ndim=3, dtype="u8", pixdim=(1.0, 1.0, 1.0), vox_offset=None,
                 magic=None, version=1, sizeof_hdr=None, big=False, extra_dims=(1, 1, 1, 1),
                 scl=(0.0, 0.0)):
    """Header plus the 4-byte extension flag (offsets from nifti1.h / nifti2.h)."""
    e = ">" if big else "<"
    code, bitpix = NIFTI_DT[dtype]
    dim = [ndim, dims[0], dims[1], dims[2]] + list(extra_dims)
    pd = [1.0, pixdim[0], pixdim[1], pixdim[2], 1.0, 1.0, 1.0, 1.0]
    if version == 1:
        h = bytearray(352)
        struct.pack_into(e + "i", h, 0, sizeof_hdr if sizeof_hdr is not None else 348)
        struct.pack_into(e + "8h", h, 40, *dim)
        struct.pack_into(e + "hh", h, 70, code, bitpix)
        struct.pack_into(e + "8f", h, 76, *pd)
        struct.pack_into(e + "f", h, 108, 352.0 if vox_offset is None else vox_offset)
        struct.pack_into(e + "ff", h, 112, *scl)
        h[344:348] = magic if magic is not None else b"n+1\0"
        return bytes(h)
    h = bytearray(544)
    struct.pack_into(e + "i", h, 0, sizeof_hdr if sizeof_hdr is not None else 540)
    h[4:12] = magic if magic is not None else b"n+2\0\r\n\x1a\n"
    struct.pack_into(e + "hh", h, 12, code, bitpix)
    struct.pack_into(e + "8q", h, 16, *dim)
    struct.pack_into(e + "8d", h, 104, *pd)
    struct.pack_into(e + "q", h, 168, 544 if vox_offset is None else int(vox_offset))
    struct.pack_into(e + "dd", h, 176, *scl)
    return bytes(h)


def make_nifti(c):
    f = "nifti"
    nan, inf = float("nan"), float("inf")
    c.case("nifti/truncated-data.nii", f, "header says 16x16x16 u8 (4096 bytes), file holds 1000",
           "file has", nifti_header((16, 16, 16)) + bytes(1000))
    c.case("nifti/dims-exceed-file.nii", f, "header says 256x256x256 i16 = 32 MiB, file has 24 bytes",
           "header says 256x256x256", nifti_header((256, 256, 256), dtype="i16") + bytes(24))
    c.case("nifti/truncated-header.nii", f, "file ends inside the 348-byte header",
           "ends after 100 of the 348 bytes", nifti_header()[:100])
    c.case("nifti/tiny-file.nii", f, "three bytes, not even sizeof_hdr", "too short", b"\x5c\x01\x00")
    c.case("nifti/empty.nii", f, "zero-byte file", "too short", b"")
    c.case("nifti/zero-spacing.nii", f, "pixdim[2] = 0", "pixdim[2]",
           nifti_header(pixdim=(1.0, 0.0, 1.0)) + bytes(24))
    c.case("nifti/nan-spacing.nii", f, "pixdim[1] = NaN", "pixdim[1] is nan",
           nifti_header(pixdim=(nan, 1.0, 1.0)) + bytes(24))
    c.case("nifti/inf-spacing.nii", f, "pixdim[3] = +inf", "pixdim[3] is inf",
           nifti_header(pixdim=(1.0, 1.0, inf)) + bytes(24))
    c.case("nifti/zero-dim.nii", f, "dim[2] = 0", "dim[2] is 0",
           nifti_header((4, 0, 2)) + bytes(24))
    c.case("nifti/negative-dim.nii", f, "dim[1] = -5", "dim[1] is -5",
           nifti_header((-5, 3, 2)) + bytes(24))
    c.case("nifti/dim-2pow31.nii", f, "NIfTI-2 dim[1] = 2^31", "dim[1] is 2147483648",
           nifti_header((1 << 31, 1, 1), version=2) + bytes(64))
    c.case("nifti/dim-2pow31-big-endian.nii", f, "NIfTI-2, big endian, dim[3] = 2^31",
           "dim[3] is 2147483648", nifti_header((1, 1, 1 << 31), version=2, big=True) + bytes(64))
    c.case("nifti/2d-image.nii", f, "dim[0] = 2", "dim[0] is 2",
           nifti_header((4, 3, 1), ndim=2) + bytes(12))
    c.case("nifti/vector-image.nii", f, "dim[0] = 5 with 3 vector components", "dim[5] is 3",
           nifti_header((2, 2, 2), ndim=5, extra_dims=(1, 3, 1, 1)) + bytes(24))
    c.case("nifti/time-series-short.nii", f, "5 time points declared, data for 2",
           "past the end|file has|truncated|beyond",
           nifti_header((2, 2, 2), ndim=4, extra_dims=(5, 1, 1, 1)) + bytes(16))
    c.case("nifti/bad-magic.nii", f, "magic 'xyz' instead of 'n+1'", "magic",
           nifti_header(magic=b"xyz\0") + bytes(24))
    c.case("nifti/bad-sizeof-hdr.nii", f, "sizeof_hdr 349", "sizeof_hdr is 349",
           nifti_header(sizeof_hdr=349) + bytes(24))
    c.case("nifti/not-nifti.nii", f, "a PNG file named .nii", "not a NIfTI file",
           b"\x89PNG\r\n\x1a\n" + bytes(400))
    c.case("nifti/complex-datatype.nii", f, "datatype 32 (complex64)", "datatype 32",
           nifti_header(dtype="complex64") + bytes(24 * 8))
    c.case("nifti/rgb-datatype.nii", f, "datatype 128 (RGB24)", "datatype 128",
           nifti_header(dtype="rgb24") + bytes(24 * 3))
    c.case("nifti/vox-offset-beyond-file.nii", f, "vox_offset 1e9 in a 376-byte file",
           "vox_offset", nifti_header(vox_offset=1e9) + bytes(24))
    c.case("nifti/vox-offset-nan.nii", f, "vox_offset NaN", "vox_offset is nan",
           nifti_header(vox_offset=nan) + bytes(24))
    c.case("nifti/negative-vox-offset-nifti2.nii", f, "NIfTI-2 vox_offset -4096", "vox_offset is -4096",
           nifti_header(vox_offset=-4096, version=2) + bytes(24))
    c.case("nifti/analyze-without-img.hdr", f, "ANALYZE .hdr whose .img is missing", "image file",
           nifti_header(magic=b"\0\0\0\0")[:348])
    # gzip
    c.case("nifti/gzip-bomb-claimed.nii.gz", f,
           "gzip; header claims 1024^3 i16 (2 GiB), stream holds 24 bytes: over the host budget",
           "budget", gz(nifti_header((1024, 1024, 1024), dtype="i16") + bytes(24)))
    c.case("nifti/gzip-claim-beyond-deflate-bound.nii.gz", f,
           "gzip; header claims 256^3 u8 (16 MiB) from ~100 bytes of gzip (1032:1 allows ~100 KiB)",
           "can inflate to at most", gz(nifti_header((256, 256, 256)) + bytes(24)))
    data = nifti_header(BOMB_CLAIMED_DIMS) + bytes(BOMB_INFLATED)
    c.case("nifti/gzip-bomb-real.nii.gz", f,
           "real ~1030:1 bomb: 51 KB inflating to 50 MiB, 64 KiB short of the 320x320x512 u8 claimed",
           "gzip data ends after", gz(data))
    body = nifti_header((32, 32, 32)) + noise(32 * 32 * 32)
    c.case("nifti/gzip-truncated.nii.gz", f, "gzip stream cut in half (incompressible voxels)",
           "gzip data ends after", gz(body)[: len(body) // 2])
    c.case("nifti/gzip-corrupt.nii.gz", f, "deflate stream with a corrupted block after the header",
           "corrupt", corrupt_deflate(nifti_header((64, 64, 16)) + pattern(64 * 64 * 16)))


def pattern(n):
    """Compressible but not constant, so deflate uses Huffman-coded blocks."""
    return bytes((i * 7 + (i >> 9)) & 0x3F for i in range(n))


def corrupt_deflate(raw):
    """gzip of `raw` with two bytes in the middle of the deflate stream damaged
    so that inflation fails with a data error after the header but before
    len(raw) bytes come out (checked here, so the case cannot silently turn
    into a valid file or into a truncated header)."""
    good = gz(raw)
    for pos in range(len(good) // 2, len(good) - 16):
        bad = bytearray(good)
        bad[pos] ^= 0xFF
        bad[pos + 1] ^= 0x5A
        d = zlib.decompressobj(16 + 15)
        produced = 0
        try:
            for i in range(0, len(bad), 16):
                produced += len(d.decompress(bytes(bad[i:i + 16])))
        except zlib.error:
            if 544 <= produced < len(raw):
                return bytes(bad)
    raise RuntimeError("no corruption found that zlib rejects")


# ---------------------------------------------------------------------- NRRD

def nrrd_header(fields, magic="NRRD0004"):
    return magic + "\n" + "".join(f"{k}: {v}\n" for k, v in fields) + "\n"


def nrrd3(type_="uchar", sizes="4 4 4", encoding="raw", extra=(), endian="little"):
    fields = [("type", type_), ("dimension", "3"), ("sizes", sizes)]
    if endian:
        fields.append(("endian", endian))
    fields.append(("encoding", encoding))
    fields += list(extra)
    return nrrd_header(fields)


def make_nrrd(c):
    f = "nrrd"
    c.case("nrrd/truncated-data.nrrd", f, "header says 16x16x16 u8, file holds 1000 bytes", "file has",
           nrrd3(sizes="16 16 16") + "\0" * 1000)
    c.case("nrrd/dims-exceed-file.nrrd", f, "header says 256x256x100 u16 = 12.5 MiB, file has 40 bytes",
           "header says 256x256x100 u16", nrrd3("ushort", "256 256 100") + "\0" * 40)
    c.case("nrrd/zero-spacing.nrrd", f, "spacings 1 0 1", "spacing of axis 1 is 0",
           nrrd3(extra=[("spacings", "1 0 1")]) + "\0" * 64)
    c.case("nrrd/negative-spacing.nrrd", f, "spacings 1 1 -2", "spacing of axis 2 is -2",
           nrrd3(extra=[("spacings", "1 1 -2")]) + "\0" * 64)
    c.case("nrrd/nan-spacing.nrrd", f, "spacings nan 1 1", "spacing of axis 0 is nan",
           nrrd3(extra=[("spacings", "nan 1 1")]) + "\0" * 64)
    c.case("nrrd/zero-space-direction.nrrd", f, "space direction (0,0,0)",
           "length of space direction of axis 2 is 0",
           nrrd3(extra=[("space dimension", "3"),
                        ("space directions", "(1,0,0) (0,1,0) (0,0,0)")]) + "\0" * 64)
    c.case("nrrd/none-space-direction.nrrd", f, "space direction 'none' on a spatial axis", "'none'",
           nrrd3(extra=[("space dimension", "3"),
                        ("space directions", "(1,0,0) none (0,0,1)")]) + "\0" * 64)
    c.case("nrrd/zero-size.nrrd", f, "sizes 4 0 4", "size of axis 1 is 0",
           nrrd3(sizes="4 0 4") + "\0" * 16)
    c.case("nrrd/negative-size.nrrd", f, "sizes 4 4 -7", "size of axis 2 is -7",
           nrrd3(sizes="4 4 -7") + "\0" * 16)
    c.case("nrrd/size-2pow31.nrrd", f, "sizes 2147483648 1 1", "2147483648",
           nrrd3(sizes="2147483648 1 1") + "\0" * 16)
    c.case("nrrd/size-not-integer.nrrd", f, "sizes with a 20-digit number", "not an integer",
           nrrd3(sizes="4 99999999999999999999 4") + "\0" * 16)
    c.case("nrrd/bad-magic.nrrd", f, "starts with 'NRRX0004'", "not a NRRD file",
           "NRRX0004\ntype: uchar\n\n")
    c.case("nrrd/unknown-version.nrrd", f, "magic NRRD0009", "NRRD0009", "NRRD0009\ntype: uchar\n\n")
    c.case("nrrd/binary-junk.nrrd", f, "binary bytes, no magic", "not a NRRD file", noise(512, 7))
    c.case("nrrd/unsupported-type.nrrd", f, "type longlong", "type 'longlong' is not supported",
           nrrd3("longlong") + "\0" * 512)
    c.case("nrrd/unsupported-encoding.nrrd", f, "encoding bzip2", "bzip2",
           nrrd3(encoding="bzip2") + "\0" * 64)
    c.case("nrrd/missing-endian.nrrd", f, "type short without an endian field", "'endian'",
           nrrd3("short", endian=None) + "\0" * 128)
    c.case("nrrd/missing-sizes.nrrd", f, "no sizes field", "'sizes'",
           nrrd_header([("type", "uchar"), ("dimension", "3"), ("encoding", "raw")]) + "\0" * 64)
    c.case("nrrd/sizes-count-mismatch.nrrd", f, "dimension 3 with 2 sizes", "'sizes' has 2 values",
           nrrd3(sizes="4 4") + "\0" * 64)
    c.case("nrrd/2d-image.nrrd", f, "dimension 2", "dimension is 2",
           nrrd_header([("type", "uchar"), ("dimension", "2"), ("sizes", "4 4"),
                        ("encoding", "raw")]) + "\0" * 16)
    c.case("nrrd/empty-space-directions.nrrd", f, "'space directions:' with no vectors",
           "'space directions' has no values",
           nrrd3(extra=[("space dimension", "3"), ("space directions", "")]) + "\0" * 64)
    c.case("nrrd/not-field-value.nrrd", f, "a header line without ': '", "not a 'field: value' line",
           "NRRD0004\ntype uchar\n\n")
    c.case("nrrd/byte-skip-minus-two.nrrd", f, "byte skip -2", "byte skip is -2",
           nrrd3(extra=[("byte skip", "-2")]) + "\0" * 64)
    c.case("nrrd/byte-skip-beyond-file.nrrd", f, "byte skip 1000000 in a small file", "file has",
           nrrd3(extra=[("byte skip", "1000000")]) + "\0" * 64)
    c.case("nrrd/line-skip-beyond-file.nrrd", f, "line skip 50 with no newlines after the header",
           "line skip is 50", nrrd3(extra=[("line skip", "50")]) + "\0" * 64)
    c.case("nrrd/several-data-files.nhdr", f, "data file: LIST", "several files",
           nrrd3(extra=[("data file", "LIST")]) + "a.raw\nb.raw\n")
    c.case("nrrd/missing-data-file.nhdr", f, "detached data file that does not exist",
           "no-such-data.raw", nrrd3(extra=[("data file", "no-such-data.raw")]))
    c.case("nrrd/detached-truncated.nhdr", f, "detached data holds 100 of 4096 bytes", "file has",
           nrrd3(sizes="16 16 16", extra=[("data file", "detached-truncated.raw")]),
           companions={"nrrd/detached-truncated.raw": bytes(100)})
    c.case("nrrd/gzip-bomb-claimed.nrrd", f,
           "gzip; sizes 1024^3 ushort (2 GiB) from a 20-byte stream: over the host budget", "budget",
           nrrd3("ushort", "1024 1024 1024", "gzip").encode() + gz(bytes(64)))
    c.case("nrrd/gzip-claim-beyond-deflate-bound.nrrd", f,
           "gzip; 256^3 uchar (16 MiB) claimed from ~30 bytes of gzip", "can inflate to at most",
           nrrd3("uchar", "256 256 256", "gzip").encode() + gz(bytes(64)))
    c.case("nrrd/gzip-bomb-real.nrrd", f,
           "real ~1030:1 bomb: 51 KB inflating to 50 MiB, 64 KiB short of the 320x320x512 claimed",
           "gzip data ends after",
           nrrd3("uchar", "%d %d %d" % BOMB_CLAIMED_DIMS, "gzip").encode() + gz(bytes(BOMB_INFLATED)))
    c.case("nrrd/gzip-truncated.nrrd", f, "gzip stream cut in half", "gzip data ends after",
           nrrd3("uchar", "32 32 32", "gzip").encode() + gz(noise(32 * 32 * 32, 3))[:16384])
    c.case("nrrd/gzip-not-gzip.nrrd", f, "encoding gzip, but the data is raw", "gzip magic",
           nrrd3("uchar", "4 4 4", "gzip") + "\1" * 64)
    c.case("nrrd/gzip-byte-skip-minus-one.nrrd", f, "byte skip -1 with gzip encoding", "byte skip -1",
           nrrd3("uchar", "4 4 4", "gzip", extra=[("byte skip", "-1")]).encode() + gz(bytes(64)))


# ----------------------------------------------------------------- MetaImage

def mha(fields, data=b""):
    return ("".join(f"{k} = {v}\n" for k, v in fields)).encode() + data


def meta_fields(dims="4 4 4", etype="MET_UCHAR", spacing="1 1 1", datafile="LOCAL", extra=(),
                ndims="3"):
    fields = [("ObjectType", "Image"), ("NDims", ndims), ("BinaryData", "True"),
              ("BinaryDataByteOrderMSB", "False")]
    fields += list(extra)
    fields += [("ElementSpacing", spacing), ("DimSize", dims), ("ElementType", etype),
               ("ElementDataFile", datafile)]
    return fields


def make_metaimage(c):
    f = "metaimage"
    short = "ends|file has|truncat|short|needs|too few"
    c.case("metaimage/truncated-data.mha", f, "DimSize 16 16 16 MET_UCHAR, 1000 bytes of data", short,
           mha(meta_fields("16 16 16"), bytes(1000)))
    c.case("metaimage/dims-exceed-file.mha", f, "DimSize 256 256 256 MET_SHORT (32 MiB), 40 bytes",
           short + "|header says", mha(meta_fields("256 256 256", "MET_SHORT"), bytes(40)))
    c.case("metaimage/detached-truncated.mhd", f, "detached raw holds 100 of 4096 bytes", short,
           mha(meta_fields("16 16 16", datafile="detached-truncated.raw")),
           companions={"metaimage/detached-truncated.raw": bytes(100)})
    c.case("metaimage/missing-data-file.mhd", f, "ElementDataFile names a file that does not exist",
           "no-such-data.raw", mha(meta_fields(datafile="no-such-data.raw")))
    c.case("metaimage/zero-spacing.mha", f, "ElementSpacing 1 0 1", "spacing",
           mha(meta_fields(spacing="1 0 1"), bytes(64)))
    c.case("metaimage/negative-spacing.mha", f, "ElementSpacing -1 1 1", "spacing",
           mha(meta_fields(spacing="-1 1 1"), bytes(64)))
    c.case("metaimage/nan-spacing.mha", f, "ElementSpacing 1 1 nan", "spacing",
           mha(meta_fields(spacing="1 1 nan"), bytes(64)))
    c.case("metaimage/zero-dim.mha", f, "DimSize 4 0 4", "DimSize",
           mha(meta_fields("4 0 4"), bytes(16)))
    c.case("metaimage/dim-2pow31.mha", f, "DimSize 2147483648 1 1", "DimSize|2147483648",
           mha(meta_fields("2147483648 1 1"), bytes(16)))
    c.case("metaimage/2d-image.mha", f, "NDims 2", "NDims",
           mha(meta_fields("4 4", ndims="2", spacing="1 1"), bytes(16)))
    c.case("metaimage/unsupported-type.mha", f, "ElementType MET_LONG_LONG", "MET_LONG_LONG",
           mha(meta_fields(etype="MET_LONG_LONG"), bytes(512)))
    c.case("metaimage/three-channels.mha", f, "ElementNumberOfChannels 3 (RGB)",
           "ElementNumberOfChannels|channel|component",
           mha(meta_fields(extra=[("ElementNumberOfChannels", "3")]), bytes(192)))
    c.case("metaimage/not-metaimage.mha", f, "binary bytes with no 'Key = Value' header",
           "MetaImage|header|ObjectType|NDims", noise(512, 11))
    c.case("metaimage/not-an-image.mha", f, "ObjectType = Mesh", "ObjectType|Mesh",
           mha([("ObjectType", "Mesh"), ("NDims", "3")] + meta_fields()[2:], bytes(64)))
    c.case("metaimage/zraw-bomb-claimed.mha", f,
           "CompressedData; DimSize 1024^3 MET_USHORT (2 GiB) from a tiny stream: over the budget",
           "budget|1032", mha(meta_fields("1024 1024 1024", "MET_USHORT",
                                     extra=[("CompressedData", "True"),
                                            ("CompressedDataSize", str(len(zl(bytes(64)))))]),
                         zl(bytes(64))))
    c.case("metaimage/zraw-claim-beyond-deflate-bound.mha", f,
           "CompressedData; 256^3 MET_UCHAR (16 MiB) from ~12 bytes of zlib",
           "1032|at most|inflate|compress",
           mha(meta_fields("256 256 256", extra=[("CompressedData", "True"),
                                                ("CompressedDataSize", str(len(zl(bytes(64)))))]),
               zl(bytes(64))))
    bomb = zl(bytes(BOMB_INFLATED))
    c.case("metaimage/zraw-bomb-real.mha", f,
           "real ~1030:1 zlib bomb: 51 KB inflating to 50 MiB, 64 KiB short of 320x320x512 claimed",
           "ends|short|truncat|inflate|compress",
           mha(meta_fields("%d %d %d" % BOMB_CLAIMED_DIMS,
                           extra=[("CompressedData", "True"),
                                  ("CompressedDataSize", str(len(bomb)))]), bomb))
    c.case("metaimage/zraw-corrupt.mhd", f, "detached .zraw that is not zlib data",
           "zlib|corrupt|compress|inflate",
           mha(meta_fields("8 8 8", extra=[("CompressedData", "True")],
                           datafile="zraw-corrupt.zraw")),
           companions={"metaimage/zraw-corrupt.zraw": noise(300, 5)})


# ----------------------------------------------------------------------- VTI

def vti(extent="0 3 0 3 0 3", spacing="1 1 1", type_="UInt8", body=b"", fmt="appended",
        compressor=None, header_type="UInt32", vtk_type="ImageData", extra_attrs="",
        inline=None):
    comp = f' compressor="{compressor}"' if compressor else ""
    head = (f'<?xml version="1.0"?>\n'
            f'<VTKFile type="{vtk_type}" version="1.0" byte_order="LittleEndian" '
            f'header_type="{header_type}"{comp}>\n'
            f'  <ImageData WholeExtent="{extent}" Origin="0 0 0" Spacing="{spacing}">\n'
            f'    <Piece Extent="{extent}">\n'
            f'      <PointData Scalars="density">\n')
    if fmt == "appended":
        head += (f'        <DataArray type="{type_}" Name="density" format="appended" '
                 f'offset="0"{extra_attrs}/>\n')
    else:
        head += (f'        <DataArray type="{type_}" Name="density" format="{fmt}"{extra_attrs}>'
                 f'{inline}</DataArray>\n')
    head += '      </PointData>\n    </Piece>\n  </ImageData>\n'
    if fmt != "appended":
        return (head + '</VTKFile>\n').encode()
    return (head + '  <AppendedData encoding="raw">\n   _').encode() + body + \
        b'\n  </AppendedData>\n</VTKFile>\n'


def u32(n):
    return struct.pack("<I", n)


def u64(n):
    return struct.pack("<Q", n)


def make_vti(c):
    f = "vti"
    short = "ends|file has|truncat|short|needs|too few|size"
    c.case("vti/truncated-appended.vti", f, "extent 0..15 x3 UInt8, appended block holds 1000 bytes",
           short, vti("0 15 0 15 0 15", body=u32(4096) + bytes(1000)))
    c.case("vti/extent-exceeds-data.vti", f, "extent 0..255 x3 UInt16 (32 MiB), block holds 64 bytes",
           short + "|header says|extent", vti("0 255 0 255 0 255", type_="UInt16", body=u32(64) + bytes(64)))
    c.case("vti/zero-spacing.vti", f, "Spacing 1 0 1", "spacing",
           vti(spacing="1 0 1", body=u32(64) + bytes(64)))
    c.case("vti/negative-spacing.vti", f, "Spacing 1 1 -0.5", "spacing",
           vti(spacing="1 1 -0.5", body=u32(64) + bytes(64)))
    c.case("vti/nan-spacing.vti", f, "Spacing nan 1 1", "spacing",
           vti(spacing="nan 1 1", body=u32(64) + bytes(64)))
    c.case("vti/empty-extent.vti", f, "WholeExtent 0 -1 0 3 0 3 (zero points along x)", "extent",
           vti("0 -1 0 3 0 3", body=u32(0)))
    c.case("vti/extent-2pow31.vti", f, "WholeExtent 0 2147483647 0 0 0 0 (2^31 points)",
           "extent|2147483648|2147483647", vti("0 2147483647 0 0 0 0", body=u32(16) + bytes(16)))
    c.case("vti/unsupported-type.vti", f, "DataArray type Int64", "Int64",
           vti(type_="Int64", body=u32(512) + bytes(512)))
    c.case("vti/three-components.vti", f, "NumberOfComponents 3", "NumberOfComponents|component",
           vti(body=u32(192) + bytes(192), extra_attrs=' NumberOfComponents="3"'))
    c.case("vti/not-xml.vti", f, "binary bytes", "XML|VTKFile|ImageData", noise(400, 13))
    c.case("vti/polydata.vti", f, "VTKFile type PolyData", "PolyData|ImageData",
           vti(vtk_type="PolyData", body=u32(64) + bytes(64)))
    c.case("vti/unclosed-xml.vti", f, "XML cut off inside the ImageData element",
           "XML|VTKFile|ImageData|unexpected|ends|truncat", vti(body=u32(64) + bytes(64))[:200])
    c.case("vti/bad-base64.vti", f, "inline binary with characters outside base64", "base64",
           vti(fmt="binary", inline="QUJD$$$***!!!"))
    c.case("vti/ascii-too-few-values.vti", f, "ascii array with 5 of 64 values",
           "ascii|values|short|expected", vti(fmt="ascii", inline="1 2 3 4 5"))
    c.case("vti/lz4-compressor.vti", f, "compressor vtkLZ4DataCompressor", "LZ4|compressor",
           vti(compressor="vtkLZ4DataCompressor", body=u32(1) + u32(64) + u32(0) + u32(10) + bytes(10)))
    small = zl(bytes(64))
    c.case("vti/zlib-bomb-claimed.vti", f,
           "zlib; extent 1024^3 UInt16 (2 GiB), one block said to be 2 GiB, tiny stream: over the budget",
           "budget|1032", vti("0 1023 0 1023 0 1023", type_="UInt16", compressor="vtkZLibDataCompressor",
                         header_type="UInt64",
                         body=u64(1) + u64(1 << 31) + u64(0) + u64(len(small)) + small))
    c.case("vti/zlib-claim-beyond-deflate-bound.vti", f,
           "zlib; extent 256^3 UInt8 (16 MiB) in one block from ~12 bytes of zlib",
           "1032|at most|inflate|compress",
           vti("0 255 0 255 0 255", compressor="vtkZLibDataCompressor",
               body=u32(1) + u32(1 << 24) + u32(0) + u32(len(small)) + small))
    bomb = zl(bytes(BOMB_INFLATED))
    x, y, z = BOMB_CLAIMED_DIMS
    c.case("vti/zlib-bomb-real.vti", f,
           "real ~1030:1 zlib bomb: 51 KB inflating to 50 MiB, 64 KiB short of the 50 MiB block claimed",
           "ends|short|truncat|inflate|compress|block",
           vti(f"0 {x - 1} 0 {y - 1} 0 {z - 1}", compressor="vtkZLibDataCompressor",
               body=u32(1) + u32(x * y * z) + u32(0) + u32(len(bomb)) + bomb))
    c.case("vti/zlib-corrupt.vti", f, "zlib block that is not zlib data",
           "zlib|corrupt|compress|inflate",
           vti("0 7 0 7 0 7", compressor="vtkZLibDataCompressor",
               body=u32(1) + u32(512) + u32(0) + u32(300) + noise(300, 17)))


# ----------------------------------------------------------------------- PVM

def make_pvm(c):
    f = "pvm"
    short = "ends|file has|truncat|short|needs|too few"
    c.case("pvm/truncated-data.pvm", f, "PVM 16x16x16 u8, 1000 bytes of data", short,
           b"PVM\n16 16 16\n1\n" + bytes(1000))
    c.case("pvm/dims-exceed-file.pvm", f, "PVM2 256x256x256 u16 (32 MiB), 40 bytes of data",
           short + "|header says", b"PVM2\n256 256 256\n1 1 1\n2\n" + bytes(40))
    c.case("pvm/zero-spacing.pvm", f, "PVM2 scale 1 0 1", "spacing|scale",
           b"PVM2\n4 4 4\n1 0 1\n1\n" + bytes(64))
    c.case("pvm/negative-spacing.pvm", f, "PVM3 scale 1 1 -1", "spacing|scale",
           b"PVM3\n4 4 4\n1 1 -1\n1\n" + bytes(64) + b"\0\0\0\0")
    c.case("pvm/nan-spacing.pvm", f, "PVM2 scale nan 1 1", "spacing|scale",
           b"PVM2\n4 4 4\nnan 1 1\n1\n" + bytes(64))
    c.case("pvm/zero-dim.pvm", f, "PVM 4x0x4", "size|dim|width|height|depth",
           b"PVM\n4 0 4\n1\n" + bytes(16))
    c.case("pvm/dim-2pow31.pvm", f, "PVM 2147483648x1x1", "2147483648|size|dim|width",
           b"PVM\n2147483648 1 1\n1\n" + bytes(16))
    c.case("pvm/three-components.pvm", f, "3 components (RGB)", "component",
           b"PVM\n4 4 4\n3\n" + bytes(192))
    c.case("pvm/zero-components.pvm", f, "0 components", "component", b"PVM\n4 4 4\n0\n" + bytes(64))
    c.case("pvm/bad-magic.pvm", f, "starts with 'PVX'", "magic|not a PVM", b"PVX\n4 4 4\n1\n" + bytes(64))
    c.case("pvm/binary-junk.pvm", f, "binary bytes", "magic|not a PVM", noise(300, 19))
    c.case("pvm/non-numeric-header.pvm", f, "dims 'four 4 4'", "four|dim|size|width|header|number",
           b"PVM\nfour 4 4\n1\n" + bytes(64))
    c.case("pvm/dds-garbage.pvm", f, "DDS v3e magic followed by junk", "DDS",
           b"DDS v3e\n" + noise(200, 23))


# -------------------------------------------------------- raw + JSON sidecar

def make_raw(c):
    f = "raw"

    def raw_case(name, problem, expect, meta, data=bytes(64), sidecar=True):
        rel = f"raw/{name}.raw"
        comp = {}
        if sidecar:
            comp[rel + ".json"] = meta if isinstance(meta, (str, bytes)) else json.dumps(meta)
        c.case(rel, f, problem, expect, data, comp)

    base = {"dims": [4, 4, 4], "type": "u8", "spacing": [1, 1, 1], "origin": [0, 0, 0],
            "endian": "little"}

    def m(**kw):
        d = dict(base)
        d.update(kw)
        return d

    raw_case("truncated", "dims 16x16x16 u8, 1000 bytes of data", "ends|file has|truncat|short|needs|too few",
             m(dims=[16, 16, 16]), bytes(1000))
    raw_case("dims-exceed-file", "dims 256^3 u16 (32 MiB), 64 bytes", "ends|file has|truncat|short|needs|too few",
             m(dims=[256, 256, 256], type="u16"))
    raw_case("no-sidecar", "no .json sidecar next to the raw file", "json|sidecar", None, sidecar=False)
    raw_case("invalid-json", "sidecar is not JSON", "json", "{\"dims\": [4, 4, 4], \"type\": ")
    raw_case("zero-spacing", "spacing [1, 0, 1]", "spacing", m(spacing=[1, 0, 1]))
    raw_case("negative-spacing", "spacing [-1, 1, 1]", "spacing", m(spacing=[-1, 1, 1]))
    # JSON has no NaN; 1e999 parses as infinity.
    raw_case("infinite-spacing", "spacing [1, 1, 1e999]", "spacing",
             json.dumps(base).replace('"spacing": [1, 1, 1]', '"spacing": [1, 1, 1e999]'))
    raw_case("zero-dim", "dims [4, 0, 4]", "dims", m(dims=[4, 0, 4]))
    raw_case("dim-2pow31", "dims [2147483648, 1, 1]", "dims|2147483648", m(dims=[2147483648, 1, 1]))
    raw_case("two-dims", "dims [4, 4]", "dims", m(dims=[4, 4]))
    raw_case("dims-not-numbers", "dims [\"4\", 4, 4]", "dims", m(dims=["4", 4, 4]))
    raw_case("unsupported-type", "type u64", "u64", m(type="u64"))
    raw_case("bad-endian", "endian middle", "endian", m(endian="middle"))
    raw_case("negative-offset", "offset -16", "offset", m(offset=-16))
    raw_case("offset-beyond-file", "offset 1000000 in a 64-byte file", "offset|ends|file has|needs|too few",
             m(offset=1000000))


# --------------------------------------------------------------------- DICOM

LONG_VRS = {"OB", "OW", "OF", "SQ", "UT", "UN"}
EXPLICIT_LE = "1.2.840.10008.1.2.1"
CT_IMAGE_STORAGE = "1.2.840.10008.5.1.4.1.1.2"
UID_ROOT = "1.2.826.0.1.3680043.10.1234"  # example root: these UIDs name nothing real


def dcm_el(group, elem, vr, value):
    if isinstance(value, str):
        value = value.encode("ascii")
        if len(value) % 2:
            value += b"\0" if vr == "UI" else b" "
    elif len(value) % 2:
        value += b"\0"
    if vr in LONG_VRS:
        return struct.pack("<HH2sHI", group, elem, vr.encode(), 0, len(value)) + value
    return struct.pack("<HH2sH", group, elem, vr.encode(), len(value)) + value


def ds(*values):
    return "\\".join(f"{v:g}" if isinstance(v, float) else str(v) for v in values)


def dicom_slice(z, rows=8, cols=8, series=UID_ROOT + ".1", orientation=(1, 0, 0, 0, 1, 0),
                spacing="0.5\\0.5", bits=16, samples=1, photometric="MONOCHROME2",
                transfer_syntax=EXPLICIT_LE, pixel=None, claimed_pixel_len=None, magic=b"DICM",
                position=None, instance=1, encapsulated=False, nested=0, fragment=None):
    sop = f"{UID_ROOT}.2.{instance}.{int(z * 10) & 0xFFFF}"
    meta = (dcm_el(0x0002, 0x0001, "OB", b"\0\1") +
            dcm_el(0x0002, 0x0002, "UI", CT_IMAGE_STORAGE) +
            dcm_el(0x0002, 0x0003, "UI", sop) +
            dcm_el(0x0002, 0x0010, "UI", transfer_syntax) +
            dcm_el(0x0002, 0x0012, "UI", UID_ROOT + ".99"))
    meta = dcm_el(0x0002, 0x0000, "UL", struct.pack("<I", len(meta))) + meta
    pos = position if position is not None else (0.0, 0.0, float(z))
    body = (dcm_el(0x0008, 0x0016, "UI", CT_IMAGE_STORAGE) +
            dcm_el(0x0008, 0x0018, "UI", sop) +
            dcm_el(0x0008, 0x0060, "CS", "CT") +
            (nested_sequences(nested) if nested else b"") +
            dcm_el(0x0020, 0x000D, "UI", UID_ROOT + ".3") +
            dcm_el(0x0020, 0x000E, "UI", series) +
            dcm_el(0x0020, 0x0013, "IS", str(instance)) +
            dcm_el(0x0020, 0x0032, "DS", ds(*pos)) +
            dcm_el(0x0020, 0x0037, "DS", ds(*orientation)) +
            dcm_el(0x0028, 0x0002, "US", struct.pack("<H", samples)) +
            dcm_el(0x0028, 0x0004, "CS", photometric) +
            dcm_el(0x0028, 0x0010, "US", struct.pack("<H", rows)) +
            dcm_el(0x0028, 0x0011, "US", struct.pack("<H", cols)) +
            dcm_el(0x0028, 0x0030, "DS", spacing) +
            dcm_el(0x0028, 0x0100, "US", struct.pack("<H", bits)) +
            dcm_el(0x0028, 0x0101, "US", struct.pack("<H", bits)) +
            dcm_el(0x0028, 0x0102, "US", struct.pack("<H", bits - 1)) +
            dcm_el(0x0028, 0x0103, "US", struct.pack("<H", 0)))
    if encapsulated:
        # Undefined length, an empty offset table item, one fragment, delimiter.
        frag = fragment if fragment is not None else noise(64, 29)
        body += (struct.pack("<HH2sHI", 0x7FE0, 0x0010, b"OB", 0, 0xFFFFFFFF) +
                 struct.pack("<HHI", 0xFFFE, 0xE000, 0) +
                 struct.pack("<HHI", 0xFFFE, 0xE000, len(frag)) + frag +
                 struct.pack("<HHI", 0xFFFE, 0xE0DD, 0))
    else:
        if pixel is None:
            pixel = bytes((i * 3 + int(z)) & 0xFF for i in range(rows * cols * samples * (bits // 8)))
        n = claimed_pixel_len if claimed_pixel_len is not None else len(pixel)
        body += struct.pack("<HH2sHI", 0x7FE0, 0x0010, b"OW", 0, n) + pixel
    return bytes(128) + magic + meta + body


def nested_sequences(depth):
    """`depth` Referenced Series Sequences (0008,1115) one inside another, each
    of undefined length with one undefined-length item (PS3.5 7.5): 36 bytes a
    level. DCMTK 3.6.7 reads them by recursion; thousands of levels overflow
    its stack."""
    seq = struct.pack("<HH2sHI", 0x0008, 0x1115, b"SQ", 0, 0xFFFFFFFF)
    item = struct.pack("<HHI", 0xFFFE, 0xE000, 0xFFFFFFFF)
    item_end = struct.pack("<HHI", 0xFFFE, 0xE00D, 0)
    seq_end = struct.pack("<HHI", 0xFFFE, 0xE0DD, 0)
    inner = dcm_el(0x0020, 0x000E, "UI", UID_ROOT + ".78")
    return (seq + item) * depth + inner + (item_end + seq_end) * depth


def dcm_sq(group, elem, *items):
    """A sequence of defined length whose items (element bytes) have defined
    lengths (PS3.5 7.5)."""
    body = b"".join(struct.pack("<HHI", 0xFFFE, 0xE000, len(i)) + i for i in items)
    return struct.pack("<HH2sHI", group, elem, b"SQ", 0, len(body)) + body


def enhanced_ct(frames=3, items=3, missing_position=None):
    """An Enhanced CT Image Storage object (PS3.3 C.7.6.16) of 8x8 u16
    frames: orientation and pixel measures shared, a position per frame
    (frame `missing_position`, counted from 1, without one); `items`
    per-frame functional-group items for `frames` frames of pixels."""
    sop_class = "1.2.840.10008.5.1.4.1.1.2.1"
    sop = f"{UID_ROOT}.2.77.{frames}.{items}.{missing_position or 0}"
    meta = (dcm_el(0x0002, 0x0001, "OB", b"\0\1") + dcm_el(0x0002, 0x0002, "UI", sop_class) +
            dcm_el(0x0002, 0x0003, "UI", sop) + dcm_el(0x0002, 0x0010, "UI", EXPLICIT_LE) +
            dcm_el(0x0002, 0x0012, "UI", UID_ROOT + ".99"))
    meta = dcm_el(0x0002, 0x0000, "UL", struct.pack("<I", len(meta))) + meta
    shared = (dcm_sq(0x0020, 0x9116, dcm_el(0x0020, 0x0037, "DS", ds(1, 0, 0, 0, 1, 0))) +
              dcm_sq(0x0028, 0x9110, dcm_el(0x0018, 0x0050, "DS", "2") +
                     dcm_el(0x0028, 0x0030, "DS", "0.5\\0.5")))
    per_frame = [b"" if k + 1 == missing_position else
                 dcm_sq(0x0020, 0x9113, dcm_el(0x0020, 0x0032, "DS", ds(0.0, 0.0, 2.0 * k)))
                 for k in range(items)]
    pixels = bytes((i * 5 + k) & 0xFF for k in range(frames) for i in range(128))
    body = (dcm_el(0x0008, 0x0016, "UI", sop_class) + dcm_el(0x0008, 0x0018, "UI", sop) +
            dcm_el(0x0008, 0x0060, "CS", "CT") + dcm_el(0x0020, 0x000D, "UI", UID_ROOT + ".3") +
            dcm_el(0x0020, 0x000E, "UI", f"{UID_ROOT}.76.{frames}.{items}") +
            dcm_el(0x0020, 0x0013, "IS", "1") +
            dcm_el(0x0028, 0x0002, "US", struct.pack("<H", 1)) +
            dcm_el(0x0028, 0x0004, "CS", "MONOCHROME2") + dcm_el(0x0028, 0x0008, "IS", str(frames)) +
            dcm_el(0x0028, 0x0010, "US", struct.pack("<H", 8)) +
            dcm_el(0x0028, 0x0011, "US", struct.pack("<H", 8)) +
            dcm_el(0x0028, 0x0100, "US", struct.pack("<H", 16)) +
            dcm_el(0x0028, 0x0101, "US", struct.pack("<H", 16)) +
            dcm_el(0x0028, 0x0102, "US", struct.pack("<H", 15)) +
            dcm_el(0x0028, 0x0103, "US", struct.pack("<H", 0)) +
            dcm_sq(0x5200, 0x9229, shared) + dcm_sq(0x5200, 0x9230, *per_frame) +
            struct.pack("<HH2sHI", 0x7FE0, 0x0010, b"OW", 0, len(pixels)) + pixels)
    return bytes(128) + b"DICM" + meta + body


def make_dicom(c):
    f = "dicom"

    def series(name, problem, expect, slices):
        folder = f"dicom/{name}"
        for fname, data in slices.items():
            c.write(f"{folder}/{fname}", data)
        c.case(folder, f, problem, expect)

    def ordinary(zs, **kw):
        # File names unrelated to position, as scanners write them.
        return {f"IM{(i * 7919) % 10000:04d}.dcm": dicom_slice(z, instance=i + 1, **kw)
                for i, z in enumerate(zs)}

    series("gap", "slices at z = 0 1 2 4 5: slice 3 is missing", "gap|spacing|missing|uneven|irregular",
           ordinary([0, 1, 2, 4, 5]))
    s = ordinary([0, 1, 2, 3])
    s["IM9999.dcm"] = dicom_slice(4, rows=6, instance=5)
    series("mismatched-rows", "one slice has 6 rows, the others 8", "rows|8x6|6x8|size", s)
    s = ordinary([0, 1, 2, 3])
    s["IM9998.dcm"] = dicom_slice(2, instance=5)
    series("duplicate-position", "two slices at z = 2", "duplicate|same position", s)
    s = ordinary([0, 1, 2, 3])
    s["IM9997.dcm"] = dicom_slice(4, orientation=(0, 1, 0, 0, 0, 1), instance=5)
    series("mixed-orientation", "one slice is sagittal, the others axial", "orientation", s)
    full = dicom_slice(0)
    series("truncated-file", "the only slice ends inside its pixel data",
           "truncat|ends|pixel data|short|incomplete|premature|read", {"IM0001.dcm": full[:-60]})
    s = ordinary([0, 1, 2, 3])
    first = sorted(s)[1]
    s[first] = s[first][:-60]
    series("truncated-slice-in-series", "one of four slices ends inside its pixel data",
           "truncat|ends|pixel data|short|incomplete|premature|read|gap", s)
    series("pixel-length-exceeds-file", "PixelData element claims 1 GiB, file holds 128 bytes",
           "pixel data|truncat|ends|short|length|read", {"IM0001.dcm": dicom_slice(0, claimed_pixel_len=1 << 30)})
    series("zero-rows", "Rows 0", "rows|0x|empty|zero|size",
           {k: v for k, v in ordinary([0, 1, 2], rows=0, pixel=b"").items()})
    series("huge-rows-columns", "Rows = Columns = 65535 u16 (8 GiB a slice), 128 bytes of pixels",
           "pixel data|rows|size|budget|short|length",
           ordinary([0, 1, 2], rows=65535, cols=65535, pixel=bytes(128)))
    series("zero-spacing", "PixelSpacing 0\\0", "spacing", ordinary([0, 1, 2], spacing="0\\0"))
    series("negative-spacing", "PixelSpacing -0.5\\0.5", "spacing",
           ordinary([0, 1, 2], spacing="-0.5\\0.5"))
    series("nan-spacing", "PixelSpacing NaN\\NaN", "spacing", ordinary([0, 1, 2], spacing="NaN\\NaN"))
    series("bits-allocated-32", "BitsAllocated 32", "bits|32", ordinary([0, 1, 2], bits=32))
    series("rgb", "SamplesPerPixel 3, PhotometricInterpretation RGB",
           "samples|rgb|colo|component|photometric", ordinary([0, 1, 2], samples=3, photometric="RGB"))
    series("jpeg2000", "transfer syntax JPEG 2000 (1.2.840.10008.1.2.4.90), not decodable by DCMTK",
           "1.2.840.10008.1.2.4.90|JPEG 2000|JPEG2000|transfer syntax",
           ordinary([0, 1, 2], transfer_syntax="1.2.840.10008.1.2.4.90", encapsulated=True))
    # SOI, a JFIF APP0, then TEM (FF01) where the frame header belongs.
    tem = (bytes.fromhex("ffd8ffe000104a46494600010100000100010000ff01") +
           bytes.fromhex("ffc3000b10000800080101") + noise(42, 37))
    series("jpeg-tem-marker",
           "JPEG Lossless slices whose frame has a TEM marker (FF01) before its frame header; "
           "DCMTK 3.6.7's JPEG decoder never returned on it (found by fuzz_dicomweb)",
           "TEM marker (FF01)",
           ordinary([0, 1, 2], transfer_syntax="1.2.840.10008.1.2.4.70", encapsulated=True,
                    fragment=tem))
    series("no-dicom-files", "a folder holding only a text file", "DICOM",
           {"notes.txt": b"not a DICOM file\n"})
    series("nested-sequences", "sequences nested 100 levels deep (the readers accept 64)",
           "sequences nested deeper than 64 levels; refused", {"IM0001.dcm": dicom_slice(0, nested=100)})
    series("bad-magic", "128-byte preamble followed by 'DICX' and junk", "DICOM|magic|read|parse",
           {"IM0001.dcm": bytes(128) + b"DICX" + noise(200, 31)})
    series("enhanced-frame-without-position",
           "an Enhanced CT object of 3 frames whose frame 2 has no Plane Position (Patient) in its "
           "per-frame functional groups, nor the shared ones",
           "frame 2 has no Plane Position (Patient) (0020,9113)",
           {"enhanced.dcm": enhanced_ct(missing_position=2)})
    series("enhanced-per-frame-items-lie",
           "an Enhanced CT object of 3 frames of pixels whose Per-frame Functional Groups "
           "Sequence has 2 items",
           "Number of Frames (0028,0008) is 3, but the Per-frame Functional Groups Sequence "
           "(5200,9230) has 2 items", {"enhanced.dcm": enhanced_ct(items=2)})


# --------------------------------------------------------------- fuzz seeds


# ------------------------------------------------------------------ OME-Zarr
# Stores are folders; chunks are built with the standard library only (zlib,
# gzip; blosc and zstd frames in their uncompressed forms) so that the
# corpus is the same wherever the script runs.

ZATTRS = json.dumps({"multiscales": [{"version": "0.4", "axes": [
    {"name": a, "type": "space", "unit": "millimeter"} for a in "zyx"],
    "datasets": [{"path": "0", "coordinateTransformations": [
        {"type": "scale", "scale": [1.0, 1.0, 1.0]}]}]}]})


def zarray(shape=(4, 4, 4), chunks=(4, 4, 4), dtype="|u1", compressor=None, order="C", **extra):
    d = {"zarr_format": 2, "shape": list(shape), "chunks": list(chunks), "dtype": dtype,
         "order": order, "fill_value": 0, "filters": None, "compressor": compressor}
    d.update(extra)
    return json.dumps(d)


def blosc_memcpy(raw, typesize=1):
    """A blosc frame holding `raw` uncompressed (flags: memcpyed)."""
    return struct.pack("<BBBBIII", 2, 1, 0x02, typesize, len(raw), len(raw), len(raw) + 16) + raw


def zstd_raw(raw):
    """A zstd frame of one raw block with its content size (single segment)."""
    header = struct.pack("<IB", 0xFD2FB528, 0xE0) + struct.pack("<Q", len(raw))
    block = (len(raw) << 3) | 1  # last block, type raw
    return header + struct.pack("<I", block)[:3] + raw


def make_zarr(c):
    f = "zarr"

    def store(name, problem, expect, files):
        folder = f"zarr/{name}.zarr"
        base = {".zgroup": '{"zarr_format": 2}', ".zattrs": ZATTRS}
        base.update(files)
        for rel, data in base.items():
            if data is not None:
                c.write(f"{folder}/{rel}", data)
        c.case(folder, f, problem, expect)

    raw = bytes(range(64))
    store("bad-json-zattrs", ".zattrs is cut off mid-list", "not valid JSON",
          {".zattrs": '{"multiscales": [{"version": "0.4", "datasets": ['})
    store("bad-json-zarray", "0/.zarray is not JSON", "not valid JSON", {"0/.zarray": "shape=4,4,4"})
    store("no-metadata", "a folder with .zgroup only: no multiscales and no .zarray",
          "not an OME-Zarr store", {".zattrs": "{}"})
    store("missing-zarray", "multiscales names dataset 0, which has no .zarray", "missing", {})
    store("dims-beyond-budget", "65536^3 u16 (512 TiB) in 64^3 chunks", "host budget",
          {"0/.zarray": zarray((65536,) * 3, (64,) * 3, "<u2")})
    store("huge-chunk", "one chunk of 2^40 x 2^40 x 2^40 f8", "larger than any host",
          {"0/.zarray": zarray((8,) * 3, (1 << 40,) * 3, "<f8")})
    store("chunk-too-big-for-budget", "one chunk of 65536^3 u8 (256 TiB)", "one chunk",
          {"0/.zarray": zarray((65536,) * 3, (65536,) * 3)})
    store("zero-chunk", "chunks [0, 4, 4]", "positive integer",
          {"0/.zarray": zarray(chunks=(0, 4, 4))})
    store("negative-chunk", "chunks [-4, 4, 4]", "positive integer",
          {"0/.zarray": zarray(chunks=(-4, 4, 4))})
    store("negative-shape", "shape [4, -4, 4]", "positive integer",
          {"0/.zarray": zarray(shape=(4, -4, 4))})
    store("two-axes", "a 2D array", "axes", {"0/.zarray": zarray((4, 4), (4, 4))})
    store("fortran-order", "order F", "order", {"0/.zarray": zarray(order="F")})
    store("complex-dtype", "dtype <c8", "not supported", {"0/.zarray": zarray(dtype="<c8")})
    store("unknown-compressor", "compressor lzma", "not supported",
          {"0/.zarray": zarray(compressor={"id": "lzma"})})
    store("bad-separator", 'dimension_separator "-"', "dimension_separator",
          {"0/.zarray": zarray(dimension_separator="-")})
    store("wrong-size-raw-chunk", "uncompressed chunk of 60 bytes where 64 belong", "expected 64",
          {"0/.zarray": zarray(), "0/0.0.0": raw[:60]})
    store("truncated-zlib-chunk", "zlib chunk cut in half", "truncated|corrupt",
          {"0/.zarray": zarray(compressor={"id": "zlib", "level": 1}),
           "0/0.0.0": zl(noise(64))[:30]})
    store("wrong-size-zlib-chunk", "zlib chunk that inflates to 32 of the 64 bytes", "expected 64",
          {"0/.zarray": zarray(compressor={"id": "zlib", "level": 1}), "0/0.0.0": zl(raw[:32])})
    store("zlib-chunk-too-long", "zlib chunk that inflates to 128 bytes where 64 belong",
          "more than",
          {"0/.zarray": zarray(compressor={"id": "zlib", "level": 1}), "0/0.0.0": zl(raw * 2)})
    store("garbage-gzip-chunk", "gzip chunk of random bytes", "corrupt|truncated",
          {"0/.zarray": zarray(compressor={"id": "gzip", "level": 1}), "0/0.0.0": noise(50)})
    store("truncated-blosc-chunk", "blosc chunk cut after 40 of its 80 bytes", "truncated",
          {"0/.zarray": zarray(compressor={"id": "blosc", "cname": "lz4", "shuffle": 1}),
           "0/0.0.0": blosc_memcpy(raw)[:40]})
    store("wrong-size-blosc-chunk", "blosc chunk holding 32 bytes where 64 belong", "expected 64",
          {"0/.zarray": zarray(compressor={"id": "blosc", "cname": "lz4", "shuffle": 1}),
           "0/0.0.0": blosc_memcpy(raw[:32])})
    store("short-blosc-header", "blosc chunk of 9 bytes", "16-byte header",
          {"0/.zarray": zarray(compressor={"id": "blosc", "cname": "lz4", "shuffle": 1}),
           "0/0.0.0": blosc_memcpy(raw)[:9]})
    store("truncated-zstd-chunk", "zstd chunk cut after 30 bytes", "zstd",
          {"0/.zarray": zarray(compressor={"id": "zstd", "level": 1}),
           "0/0.0.0": zstd_raw(raw)[:30]})
    store("wrong-size-zstd-chunk", "zstd frame declaring 32 bytes where 64 belong", "expected 64",
          {"0/.zarray": zarray(compressor={"id": "zstd", "level": 1}),
           "0/0.0.0": zstd_raw(raw[:32])})
    store("oversized-chunk", "a 200 KiB file where a 64-byte chunk belongs", "more than",
          {"0/.zarray": zarray(compressor={"id": "zlib", "level": 1}),
           "0/0.0.0": None})
    c.write("zarr/oversized-chunk.zarr/0/0.0.0", b"\x78" * (63 * 1024))


# ------------------------------------------------------- OME-Zarr 0.5 (Zarr v3)
# A group zarr.json with NGFF 0.5 metadata under "ome", an array zarr.json
# and shards built from the sharding spec (inner chunks, then an index of
# (offset, nbytes) uint64 pairs and its crc32c).

def crc32c(data):
    c = 0xFFFFFFFF
    for b in data:
        c ^= b
        for _ in range(8):
            c = (0x82F63B78 ^ (c >> 1)) if c & 1 else c >> 1
    return c ^ 0xFFFFFFFF


V3_GROUP = json.dumps({"zarr_format": 3, "node_type": "group", "attributes": {"ome": {
    "version": "0.5", "multiscales": [{"axes": [
        {"name": a, "type": "space", "unit": "millimeter"} for a in "zyx"],
        "datasets": [{"path": "0", "coordinateTransformations": [
            {"type": "scale", "scale": [1.0, 1.0, 1.0]}]}]}]}}})


def v3_array(dtype="uint8", shard=(4, 4, 4), inner=(2, 2, 2), inner_codecs=None, **extra):
    inner_codecs = inner_codecs or [{"name": "bytes", "configuration": {"endian": "little"}}]
    d = {"zarr_format": 3, "node_type": "array", "shape": [4, 4, 4], "data_type": dtype,
         "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": list(shard)}},
         "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
         "fill_value": 0,
         "codecs": [{"name": "sharding_indexed", "configuration": {
             "chunk_shape": list(inner), "codecs": inner_codecs,
             "index_codecs": [{"name": "bytes", "configuration": {"endian": "little"}},
                              {"name": "crc32c"}],
             "index_location": "end"}}]}
    d.update(extra)
    return json.dumps(d)


def v3_shard(chunks, entries=None, spoil_index_crc=False):
    """Inner chunks back to back, then the index (entries override the real
    (offset, nbytes) pairs) and its crc32c."""
    body, real, at = b"", [], 0
    for ch in chunks:
        real.append((at, len(ch)))
        body += ch
        at += len(ch)
    index = b"".join(struct.pack("<QQ", o, n) for o, n in (entries or real))
    crc = crc32c(index) ^ (1 if spoil_index_crc else 0)
    return body + index + struct.pack("<I", crc)


def make_zarr_v3(c):
    f = "zarr"

    def store(name, problem, expect, array, shard):
        folder = f"zarr/v3-{name}.zarr"
        c.write(f"{folder}/zarr.json", V3_GROUP)
        c.write(f"{folder}/0/zarr.json", array)
        if shard is not None:
            c.write(f"{folder}/0/c/0/0/0", shard)
        c.case(folder, f, problem, expect)

    chunk = bytes(range(8))
    eight = [bytes(range(8 * i, 8 * i + 8)) for i in range(8)]
    good = v3_array()
    store("offset-past-end", "shard index entry 0 at offset 2^30 in a 204-byte shard",
          "lies outside the shard", good,
          v3_shard(eight, [(1 << 30, 8)] + [(8 * i, 8) for i in range(1, 8)]))
    store("overlapping-entries", "shard index entries 0 and 1 both at bytes 0..8",
          "overlap", good, v3_shard(eight, [(0, 8), (4, 8)] + [(8 * i, 8) for i in range(2, 8)]))
    store("lying-length", "shard index entry 3 claims 2^40 bytes for an 8-byte chunk",
          "an inner chunk holds", good,
          v3_shard(eight, [(8 * i, 8) for i in range(3)] + [(24, 1 << 40)] +
                   [(8 * i, 8) for i in range(4, 8)]))
    store("index-crc-mismatch", "the shard index's crc32c is off by one bit",
          "crc32c mismatch", good, v3_shard(eight, spoil_index_crc=True))
    crc_codecs = [{"name": "bytes", "configuration": {"endian": "little"}}, {"name": "crc32c"}]
    bad_crc = [ch + struct.pack("<I", crc32c(ch) ^ 0x10) for ch in eight]
    store("chunk-crc-mismatch", "every inner chunk's crc32c is wrong", "crc32c mismatch",
          v3_array(inner_codecs=crc_codecs), v3_shard(bad_crc))
    store("unknown-codec", "inner codec lz4hc", "codec \"lz4hc\" is not supported",
          v3_array(inner_codecs=[{"name": "lz4hc"}]), v3_shard(eight))
    store("dtype-mismatch", "data_type uint32 where the inner chunks hold 8 one-byte values",
          "expected 32", v3_array(dtype="uint32"), v3_shard(eight))
    store("nested-sharding", "a sharding_indexed inside a shard", "nested sharding_indexed",
          v3_array(inner_codecs=[{"name": "sharding_indexed", "configuration": {
              "chunk_shape": [1, 1, 1], "codecs": [{"name": "bytes"}]}}]), None)
    store("short-shard", "a 20-byte shard whose index alone is 132 bytes", "asked of a value of 20",
          good, bytes(20))
    store("too-many-inner-chunks", "a 2^30-voxel shard of 1-voxel inner chunks",
          "inner chunks per shard",
          v3_array(shard=(1024, 1024, 1024), inner=(1, 1, 1)), None)
    store("unknown-data-type", "data_type complex64", "data_type \"complex64\" is not supported",
          v3_array(dtype="complex64"), None)
    store("bad-chunk-grid", "chunk_grid rectilinear", "only the \"regular\" chunk grid",
          v3_array(chunk_grid={"name": "rectilinear"}), None)


def fuzz_seeds(root):
    def put(target, name, data):
        path = os.path.join(root, target, name)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "wb") as fh:
            fh.write(data if isinstance(data, bytes) else data.encode())

    voxels = bytes(range(24))
    put("nifti", "u8.nii", nifti_header() + voxels)
    put("nifti", "i16-big.nii", nifti_header(dtype="i16", big=True) + bytes(48))
    put("nifti", "f32-scaled.nii", nifti_header(dtype="f32", scl=(2.0, 1.0)) + bytes(96))
    put("nifti", "nifti2.nii", nifti_header(version=2) + voxels)
    put("nifti", "u8.nii.gz", gz(nifti_header() + voxels))
    put("nrrd", "raw.nrrd", nrrd3(sizes="2 3 4") + "\0" * 24)
    put("nrrd", "gzip.nrrd", nrrd3("short", "2 3 4", "gzip").encode() + gz(bytes(48)))
    put("nrrd", "directions.nrrd",
        nrrd_header([("type", "float"), ("dimension", "4"), ("space", "right-anterior-superior"),
                     ("sizes", "1 2 2 2"), ("space directions", "none (0.5,0,0) (0,0.5,0) (0,0,2)"),
                     ("space origin", "(1,2,3)"), ("endian", "big"), ("encoding", "raw"),
                     ("byte skip", "-1")]) + "\0" * 32)
    put("metaimage", "raw.mha", mha(meta_fields("2 3 4"), voxels))
    put("metaimage", "short-msb.mha",
        mha([("ObjectType", "Image"), ("NDims", "3"), ("BinaryData", "True"),
             ("BinaryDataByteOrderMSB", "True"), ("Offset", "1 2 3"), ("ElementSpacing", "0.5 0.5 2"),
             ("DimSize", "2 3 4"), ("ElementType", "MET_SHORT"), ("ElementDataFile", "LOCAL")],
            bytes(48)))
    put("metaimage", "zlib.mha",
        mha(meta_fields("2 3 4", "MET_FLOAT", extra=[("CompressedData", "True"),
                                                     ("CompressedDataSize", str(len(zl(bytes(96)))))]),
            zl(bytes(96))))
    put("vti", "appended.vti", vti("0 1 0 2 0 3", body=u32(24) + voxels))
    put("vti", "binary.vti", vti("0 1 0 2 0 3", type_="Int16", fmt="binary",
                                 inline=__import__("base64").b64encode(u32(48) + bytes(48)).decode()))
    put("vti", "ascii.vti", vti("0 1 0 2 0 3", type_="Float32", fmt="ascii",
                                inline=" ".join(str(i) for i in range(24))))
    block = zl(bytes(range(24)))
    put("vti", "zlib.vti", vti("0 1 0 2 0 3", compressor="vtkZLibDataCompressor",
                               body=u32(1) + u32(24) + u32(24) + u32(len(block)) + block))
    put("pvm", "v1.pvm", b"PVM\n2 3 4\n1\n" + voxels)
    put("pvm", "v2.pvm", b"PVM2\n2 3 4\n0.5 0.5 2\n2\n" + bytes(48))
    put("pvm", "v3.pvm", b"PVM3\n2 3 4\n1 1 1\n1\n" + voxels + b"desc\0courtesy\0param\0comment\0")
    # fuzz_raw_sidecar reads the fuzzed JSON with a fixed 512-byte data file.
    put("raw_sidecar", "u8.json", json.dumps({"dims": [8, 8, 8], "type": "u8"}))
    put("raw_sidecar", "full.json", json.dumps({"dims": [4, 4, 8], "type": "u16", "spacing": [0.5, 0.5, 2],
                                                "origin": [1, 2, 3], "endian": "big", "offset": 256}))
    put("raw_sidecar", "f32.json", json.dumps({"dims": [2, 4, 16], "type": "f32"}))
    put("dicom", "slice.dcm", dicom_slice(0))
    put("dicom", "slice-u8.dcm", dicom_slice(3, bits=8, spacing="0.7\\0.7"))
    put("dicom", "nested-10.dcm", dicom_slice(0, nested=10))
    put("transfer_function", "grey.json", json.dumps(
        {"name": "grey", "opacity_unit_length": 1.0,
         "color": [{"x": 0, "rgb": [0, 0, 0]}, {"x": 1, "rgb": [1, 1, 1]}],
         "opacity": [{"x": 0, "alpha": 0}, {"x": 1, "alpha": 1}]}))
    put("transfer_function", "ramp.json", json.dumps(
        {"color": [{"x": 0.2, "rgb": [1, 0.5, 0]}],
         "opacity": [{"x": 0, "alpha": 0}, {"x": 0.3, "alpha": 0.1}, {"x": 0.9, "alpha": 0.8}]}))
    put("device_profile", "phone.json", json.dumps(
        {"name": "phone", "note": "a phone", "api": "gles3", "max_2d_texture_size": 4096,
         "max_3d_texture_size": 256, "texture_units": 16, "texture_budget_mb": 256,
         "host_budget_mb": 1024, "float_render_targets": True}))
    put("device_profile", "es2.json", json.dumps(
        {"name": "es2", "api": "gles2", "max_2d_texture_size": "unlimited", "texture_units": 8}))
    # fuzz_zarr: a .zarray, a NUL byte, then the array's one chunk.
    u16 = b"".join(struct.pack("<H", i * 7) for i in range(120))
    for name, comp, chunk in [
            ("none.bin", None, u16),
            ("zlib.bin", {"id": "zlib", "level": 1}, zl(u16)),
            ("gzip.bin", {"id": "gzip", "level": 1}, gz(u16)),
            ("blosc.bin", {"id": "blosc", "cname": "lz4", "shuffle": 1}, blosc_memcpy(u16, 2)),
            ("zstd.bin", {"id": "zstd", "level": 1}, zstd_raw(u16))]:
        put("zarr", name, zarray((4, 5, 6), (4, 5, 6), "<u2", comp).encode() + b"\0" + chunk)
    put("zarr", "big-endian-slash.bin",
        zarray((4, 5, 6), (4, 5, 6), ">i2", None, dimension_separator="/").encode() + b"\0" +
        b"".join(struct.pack(">h", i - 60) for i in range(120)))
    # fuzz_zarr_v3: an array zarr.json, a NUL byte, then chunk 0/c/0/0/0.
    eight = [bytes(range(8 * i, 8 * i + 8)) for i in range(8)]
    crc_codecs = [{"name": "bytes", "configuration": {"endian": "little"}}, {"name": "crc32c"}]
    put("zarr_v3", "sharded.bin", v3_array().encode() + b"\0" + v3_shard(eight))
    put("zarr_v3", "sharded-crc.bin", v3_array(inner_codecs=crc_codecs).encode() + b"\0" +
        v3_shard([ch + struct.pack("<I", crc32c(ch)) for ch in eight]))
    plain = json.loads(v3_array())
    plain["chunk_grid"]["configuration"]["chunk_shape"] = [4, 5, 6]
    plain["shape"] = [4, 5, 6]
    plain["data_type"] = "int16"
    plain["codecs"] = [{"name": "transpose", "configuration": {"order": [2, 1, 0]}},
                       {"name": "bytes", "configuration": {"endian": "big"}},
                       {"name": "gzip", "configuration": {"level": 1}}, {"name": "crc32c"}]
    big = gz(b"".join(struct.pack(">h", i - 60) for i in range(120)))
    put("zarr_v3", "transpose-big-gzip-crc.bin",
        json.dumps(plain).encode() + b"\0" + big + struct.pack("<I", crc32c(big)))
    # fuzz_zarr_shard_index: 2 layout bytes, the shard size, the index.
    index = v3_shard(eight)[64:]
    put("zarr_shard_index", "2x2x2-end-crc.bin", bytes([0x09, 0x19]) + struct.pack("<Q", 64 + 132) +
        index)
    put("zarr_shard_index", "2x2x2-start.bin", bytes([0x09, 0x01]) + struct.pack("<Q", 64 + 128) +
        b"".join(struct.pack("<QQ", 128 + 8 * i, 8) for i in range(8)))
    # fuzz_functional_groups: multi-frame headers as DICOM JSON (WADO-RS metadata).
    for name, datasets in functional_group_seeds():
        put("functional_groups", name, json.dumps(datasets, indent=None, sort_keys=True))
    # Found by fuzz_functional_groups: nlohmann's out_of_range escaped parseDicomJson.
    put("functional_groups", "number-overflow-crash.json",
        '[{"00280008": {"vr": "IS", "Value": [1e999]}}]')


def dj(vr, *values):
    """One DICOM JSON element (PS3.18 F.2.2)."""
    return {"vr": vr, "Value": list(values)} if values else {"vr": vr}


def sq(*items):
    return dj("SQ", *items)


def multiframe_header(frames, sop_class, modality, **extra):
    d = {"00080016": dj("UI", sop_class), "00080018": dj("UI", UID_ROOT + ".70." + modality),
         "00080060": dj("CS", modality), "0020000E": dj("UI", UID_ROOT + ".71"),
         "00280002": dj("US", 1), "00280004": dj("CS", "MONOCHROME2"),
         "00280008": dj("IS", str(frames)), "00280010": dj("US", 8), "00280011": dj("US", 8),
         "00280100": dj("US", 16), "00280101": dj("US", 12), "00280102": dj("US", 11),
         "00280103": dj("US", 0), "7FE00010": {"vr": "OW", "BulkDataURI": "http://h/bulk"}}
    d.update(extra)
    return d


def functional_group_seeds():
    """Enhanced CT of one stack (the plane shared, positions per frame, the
    frames in reverse order), an Enhanced MR of two stacks (each frame its own
    measures and orientation), classic RT Dose (Grid Frame Offset Vector) and
    classic NM (the plane in the Detector Information Sequence)."""
    axial = ["1", "0", "0", "0", "1", "0"]
    sagittal = ["0", "1", "0", "0", "0", "-1"]
    shared = {"00289110": sq({"00280030": dj("DS", "0.5", "0.5"), "00180050": dj("DS", "2")}),
              "00209116": sq({"00200037": dj("DS", *axial)}),
              "00289145": sq({"00281052": dj("DS", "-1024"), "00281053": dj("DS", "1")}),
              "00289132": sq({"00281050": dj("DS", "40"), "00281051": dj("DS", "400")})}

    def frame(position, stack, number, own=None):
        f = {"00209113": sq({"00200032": dj("DS", *position)}),
             "00209111": sq({"00209056": dj("SH", stack), "00209057": dj("UL", number)})}
        f.update(own or {})
        return f

    ct = multiframe_header(3, "1.2.840.10008.5.1.4.1.1.2.1", "CT",
                           **{"52009229": sq(shared),
                              "52009230": sq(*[frame(["-2", "-2", str(2.0 * k)], "1", k + 1)
                                               for k in (2, 1, 0)])})
    planes = []
    for stack, iop in (("1", axial), ("2", sagittal)):
        own = {"00289110": sq({"00280030": dj("DS", "0.8", "0.8"), "00180050": dj("DS", "1.5")}),
               "00209116": sq({"00200037": dj("DS", *iop)})}
        planes += [frame([str(1.5 * k), "0", "0"] if stack == "2" else ["0", "0", str(1.5 * k)],
                         stack, k + 1, own) for k in range(2)]
    mr = multiframe_header(4, "1.2.840.10008.5.1.4.1.1.4.1", "MR",
                           **{"52009229": sq({}), "52009230": sq(*planes)})
    dose = multiframe_header(3, "1.2.840.10008.5.1.4.1.1.481.2", "RTDOSE",
                             **{"00200032": dj("DS", "0", "0", "10"),
                                "00200037": dj("DS", *axial), "00280030": dj("DS", "2", "2"),
                                "3004000C": dj("DS", "10", "12.5", "15")})
    nm = multiframe_header(2, "1.2.840.10008.5.1.4.1.1.20", "NM",
                           **{"00180088": dj("DS", "3.5"), "00280030": dj("DS", "2", "2.5"),
                              "00540022": sq({"00200032": dj("DS", "10", "-20", "30"),
                                              "00200037": dj("DS", *axial)})})
    return [("enhanced-ct.json", [ct]), ("enhanced-mr-two-stacks.json", [mr]),
            ("rtdose-grid-offsets.json", [dose]), ("nm-detector.json", [nm])]


# ---------------------------------------------------------------------- main

def generate(bad_root, seed_root):
    keep = os.path.join(bad_root, "fuzz-regressions")
    if os.path.isdir(bad_root):
        for name in os.listdir(bad_root):
            p = os.path.join(bad_root, name)
            if p == keep:
                continue
            if os.path.isdir(p):
                shutil.rmtree(p)
            else:
                os.remove(p)
    c = Corpus(bad_root)
    for make in (make_nifti, make_nrrd, make_metaimage, make_vti, make_pvm, make_raw, make_dicom,
                 make_zarr, make_zarr_v3):
        make(c)
    for rel, fmt, problem, expect in FUZZ_REGRESSIONS:
        if not os.path.exists(os.path.join(bad_root, rel)):
            raise SystemExit(f"fuzz regression {rel} is listed but missing")
        c.case(rel, fmt, problem, expect)
    manifest = {
        "about": "Inputs every reader must reject with InputError or BudgetError, naming the file, "
                 "within 1 s, without allocating what the file cannot justify. Generated by "
                 "scripts/make_bad_corpus.py; checked by tests/io/BadCorpusTest.cpp. 'expect' is "
                 "text the message must contain (case-insensitive, 'a|b' = either).",
        "cases": c.cases,
    }
    with open(os.path.join(bad_root, "MANIFEST.json"), "w") as fh:
        json.dump(manifest, fh, indent=1)
        fh.write("\n")
    fuzz_seeds(seed_root)
    return c.cases


def tree(root):
    out = {}
    for dirpath, _, files in os.walk(root):
        for name in files:
            p = os.path.join(dirpath, name)
            with open(p, "rb") as fh:
                out[os.path.relpath(p, root)] = fh.read()
    return out


def main():
    bad_root = os.path.join(ROOT, "tests", "data", "bad")
    seed_root = os.path.join(ROOT, "fuzz", "corpus")
    if "--check" in sys.argv[1:]:
        with tempfile.TemporaryDirectory() as tmp:
            tb, ts = os.path.join(tmp, "bad"), os.path.join(tmp, "corpus")
            if os.path.isdir(os.path.join(bad_root, "fuzz-regressions")):
                shutil.copytree(os.path.join(bad_root, "fuzz-regressions"),
                                os.path.join(tb, "fuzz-regressions"))
            generate(tb, ts)
            committed = tree(seed_root)
            ok = tree(tb) == tree(bad_root) and all(
                committed.get(p) == d for p, d in tree(ts).items())
        print("corpus is up to date" if ok else "corpus differs from scripts/make_bad_corpus.py")
        return 0 if ok else 1
    cases = generate(bad_root, seed_root)
    files = tree(bad_root)
    big = [(p, len(d)) for p, d in files.items() if len(d) >= 64 * 1024]
    total = sum(len(d) for d in files.values())
    if big:
        raise SystemExit(f"files of 64 KiB or more: {big}")
    if total >= 2 * MiB:
        raise SystemExit(f"corpus is {total} bytes, over 2 MiB")
    counts = {}
    for case in cases:
        counts[case["format"]] = counts.get(case["format"], 0) + 1
    print(f"{len(cases)} cases in {len(files)} files, {total} bytes: " +
          ", ".join(f"{k} {v}" for k, v in counts.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
