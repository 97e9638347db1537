#!/usr/bin/python3
"""The marked head of the patient-geometry tests, stored every way a user meets it.

    marked_head.py make OUTDIR     writes the storages and OUTDIR/truth.json
    marked_head.py marker FILE...  prints {file: marker centre (RAS mm)} as JSON

A head (ch2 from mricron-data, halved, or a synthetic ellipsoid head) gets a
bright block on the patient's right-anterior-superior side. It is written
with independent tools -- nibabel for NIfTI, pydicom for DICOM, hand-written
NRRD/MetaImage headers -- in different storage orders, each with the
geometry that says so. `marker` finds the block (voxels at the marker value)
and returns its centre in RAS+ millimetres, reading NIfTI with nibabel,
DICOM with pydicom and NRRD/MHA/VTI/raw+JSON by their specs, never with
Tessera, so a conversion that moves the patient shows up.

Needs Debian's python3-numpy, python3-nibabel and python3-pydicom.
"""
import base64
import gzip
import json
import os
import sys
import zlib

import numpy as np
import nibabel as nib
import pydicom
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.uid import ExplicitVRLittleEndian, generate_uid

MARKER = 255  # brighter than anything in the head (ch2 tops out at 254)
CH2 = "/usr/share/mricron/templates/ch2.nii.gz"
LPS = np.diag([-1.0, -1.0, 1.0])  # RAS <-> LPS


def head():
    """RAS-stored head (uint8, x fastest when written) and its affine."""
    if os.path.exists(CH2):
        img = nib.load(CH2)
        data = np.asarray(img.dataobj).astype(np.float64)
        # Halve by 2x2x2 box averaging (keeps the test quick).
        n = (np.array(data.shape) // 2) * 2
        d = data[: n[0], : n[1], : n[2]]
        d = d.reshape(n[0] // 2, 2, n[1] // 2, 2, n[2] // 2, 2).mean(axis=(1, 3, 5))
        affine = img.affine.copy()
        affine[:3, :3] = affine[:3, :3] * 2.0
        affine[:3, 3] = img.affine[:3, :3] @ np.array([0.5, 0.5, 0.5]) + img.affine[:3, 3]
        data = np.clip(np.rint(d), 0, 254).astype(np.uint8)
    else:
        shape = (80, 96, 80)
        idx = np.indices(shape).astype(np.float64)
        c = (np.array(shape)[:, None, None, None] - 1) / 2.0
        r = np.sqrt(sum(((idx[a] - c[a]) / (0.42 * shape[a])) ** 2 for a in range(3)))
        data = np.where(r < 1.0, 60 + 120 * (1.0 - r), 0).astype(np.uint8)
        data[(r < 0.6) & (idx[1] > c[1])] = 200  # a front-back asymmetry
        affine = np.diag([2.0, 2.0, 2.0, 1.0])
        affine[:3, 3] = -np.array(shape) + 1.0
    if affine[0, 0] < 0 or affine[1, 1] < 0 or affine[2, 2] < 0:
        raise SystemExit(f"{CH2}: expected RAS storage")
    # The marker: right (+x), anterior (+y), superior (+z) of the centre.
    s = np.array(data.shape)
    x0, y0, z0 = (s * np.array([0.72, 0.70, 0.62])).astype(int)
    data[x0 : x0 + 8, y0 : y0 + 6, z0 : z0 + 5] = MARKER
    return data, affine


def marker_centre_ras(data, affine):
    idx = np.argwhere(data == MARKER)
    if len(idx) == 0:
        raise SystemExit("no marker voxels found")
    centre = idx.mean(axis=0)
    return (affine[:3, :3] @ centre + affine[:3, 3]).tolist()


def reorient(data, affine, axes, flips):
    """Store `data` with new index axis a = old axis axes[a], reversed where flips[a]."""
    out = np.transpose(data, axes)
    new = np.eye(4)
    shape = np.array(data.shape)
    for a, (old, flip) in enumerate(zip(axes, flips)):
        col = affine[:3, old]
        if flip:
            out = np.flip(out, axis=a)
            new[:3, a] = -col
        else:
            new[:3, a] = col
    # Voxel (0,0,0) of the new storage sits at the old index:
    start = np.zeros(3)
    for a, (old, flip) in enumerate(zip(axes, flips)):
        start[old] = shape[old] - 1 if flip else 0
    new[:3, 3] = affine[:3, :3] @ start + affine[:3, 3]
    return np.ascontiguousarray(out), new


# ------------------------------------------------------------------ writers


def write_nifti(path, data, affine):
    img = nib.Nifti1Image(data, affine)
    img.set_sform(affine, code=1)
    img.set_qform(affine, code=1)
    nib.save(img, path)


def write_nrrd_lps(path, data, affine):
    lps = LPS @ affine[:3, :3]
    origin = LPS @ affine[:3, 3]
    vec = lambda v: "(" + ",".join(f"{x:.10g}" for x in v) + ")"
    header = (
        "NRRD0004\ntype: uint8\ndimension: 3\nspace: left-posterior-superior\n"
        f"sizes: {data.shape[0]} {data.shape[1]} {data.shape[2]}\n"
        f"space directions: {vec(lps[:, 0])} {vec(lps[:, 1])} {vec(lps[:, 2])}\n"
        "kinds: domain domain domain\nendian: little\nencoding: raw\n"
        f"space origin: {vec(origin)}\n\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(np.asfortranarray(data).tobytes(order="F"))


def write_mha(path, data, affine):
    # MetaIO/ITK: LPS; TransformMatrix lists the direction of index axis 0,
    # then 1, then 2 (ITK MetaImageIO reads direction(i) from entries 3i..3i+2).
    lps = LPS @ affine[:3, :3]
    spacing = np.linalg.norm(lps, axis=0)
    dirs = lps / spacing
    origin = LPS @ affine[:3, 3]
    tm = " ".join(f"{x:.10g}" for a in range(3) for x in dirs[:, a])
    header = (
        "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
        f"TransformMatrix = {tm}\nOffset = {' '.join(f'{x:.10g}' for x in origin)}\n"
        f"ElementSpacing = {' '.join(f'{x:.10g}' for x in spacing)}\n"
        f"DimSize = {data.shape[0]} {data.shape[1]} {data.shape[2]}\n"
        "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(np.asfortranarray(data).tobytes(order="F"))


def write_dicom(folder, data, affine):
    """Slices along index axis 2; rows along axis 0 (IOP row direction)."""
    os.makedirs(folder, exist_ok=True)
    lps = LPS @ affine[:3, :3]
    spacing = np.linalg.norm(lps, axis=0)
    row_dir, col_dir = lps[:, 0] / spacing[0], lps[:, 1] / spacing[1]
    study, series, frame = generate_uid(), generate_uid(), generate_uid()
    n = data.shape[2]
    for k in range(n):
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = "1.2.840.10008.5.1.4.1.1.4"  # MR Image Storage
        meta.MediaStorageSOPInstanceUID = generate_uid()
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        ds = Dataset()
        ds.file_meta = meta
        ds.is_little_endian = True
        ds.is_implicit_VR = False
        ds.SOPClassUID = meta.MediaStorageSOPClassUID
        ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
        ds.StudyInstanceUID, ds.SeriesInstanceUID, ds.FrameOfReferenceUID = study, series, frame
        ds.Modality = "MR"
        ds.PatientName = "Marked^Head"
        ds.PatientID = "MARKED"
        ds.InstanceNumber = k + 1
        ds.ImageOrientationPatient = [f"{x:.8f}" for x in (*row_dir, *col_dir)]
        ipp = lps @ np.array([0.0, 0.0, float(k)]) + LPS @ affine[:3, 3]
        ds.ImagePositionPatient = [f"{x:.6f}" for x in ipp]
        ds.PixelSpacing = [f"{spacing[1]:.8f}", f"{spacing[0]:.8f}"]  # row spacing, column spacing
        ds.SliceThickness = f"{spacing[2]:.8f}"
        ds.Rows, ds.Columns = data.shape[1], data.shape[0]
        ds.SamplesPerPixel = 1
        ds.PhotometricInterpretation = "MONOCHROME2"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 0
        ds.PixelData = np.ascontiguousarray(data[:, :, k].T.astype("<u2")).tobytes()
        ds.save_as(os.path.join(folder, f"slice{k:04d}.dcm"), write_like_original=False)


def resample_oblique(data, affine, rotation, grow=1.25):
    """The head on a grid turned by `rotation` (RAS) about its centre, trilinear;
    the grid is `grow` times larger so that no part of the head is cut off."""
    shape = np.array(data.shape)
    target = np.ceil(shape * grow).astype(int)
    centre = affine[:3, :3] @ ((shape - 1) / 2.0) + affine[:3, 3]
    new_lin = rotation @ affine[:3, :3]
    new = np.eye(4)
    new[:3, :3] = new_lin
    new[:3, 3] = centre - new_lin @ ((target - 1) / 2.0)
    # Source index of every target voxel.
    idx = np.indices(tuple(target)).reshape(3, -1).astype(np.float64)
    world = new_lin @ idx + new[:3, 3:4]
    src = np.linalg.solve(affine[:3, :3], world - affine[:3, 3:4])
    f = np.floor(src).astype(int)
    w = src - f
    out = np.zeros(idx.shape[1])
    for corner in range(8):
        o = np.array([(corner >> a) & 1 for a in range(3)])[:, None]
        i = f + o
        ok = np.all((i >= 0) & (i < shape[:, None]), axis=0)
        wt = np.prod(np.where(o == 1, w, 1 - w), axis=0)
        vals = np.zeros(idx.shape[1])
        vals[ok] = data[i[0, ok], i[1, ok], i[2, ok]]
        out += wt * vals
    out = np.rint(out).reshape(tuple(target))
    # Keep the marker recognisable: only voxels that were wholly marker stay 255.
    out = np.clip(out, 0, 254)
    full = np.isclose(
        sum(
            np.prod(np.where(np.array([(c >> a) & 1 for a in range(3)])[:, None] == 1, w, 1 - w), axis=0)
            * (data[tuple(np.clip(f + np.array([(c >> a) & 1 for a in range(3)])[:, None], 0, shape[:, None] - 1))] == MARKER)
            for c in range(8)
        ).reshape(tuple(target)),
        1.0,
    )
    out[full] = MARKER
    return out.astype(np.uint8), new


def rotation(axis, deg):
    t = np.radians(deg)
    c, s = np.cos(t), np.sin(t)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    r = np.eye(3)
    r[i, i], r[i, j], r[j, i], r[j, j] = c, -s, s, c
    return r


def make(out):
    os.makedirs(out, exist_ok=True)
    data, affine = head()
    truth = {"marker_ras": marker_centre_ras(data, affine), "storages": {}}

    def record(name, kind, d, a, spacing_check=True):
        truth["storages"][name] = {
            "kind": kind,
            "orientation": "".join(nib.aff2axcodes(a)),
            "marker_ras": marker_centre_ras(d, a),
            "dims": list(d.shape),
        }

    write_nifti(os.path.join(out, "ras.nii.gz"), data, affine)
    record("ras.nii.gz", "nifti", data, affine)
    d, a = reorient(data, affine, (0, 1, 2), (True, False, False))
    write_nifti(os.path.join(out, "las.nii.gz"), d, a)
    record("las.nii.gz", "nifti", d, a)
    d, a = reorient(data, affine, (0, 1, 2), (True, True, False))
    write_nrrd_lps(os.path.join(out, "lps.nrrd"), d, a)
    record("lps.nrrd", "nrrd", d, a)
    d, a = reorient(data, affine, (0, 2, 1), (False, True, True))  # coronal-like: R I P
    write_mha(os.path.join(out, "rip.mha"), d, a)
    record("rip.mha", "mha", d, a)
    # DICOM (LPS): axial IOP 1\0\0\0\1\0 -> storage L P S.
    d, a = reorient(data, affine, (0, 1, 2), (True, True, False))
    write_dicom(os.path.join(out, "axial.dcm.d"), d, a)
    record("axial.dcm.d", "dicom", d, a)
    # The other slice order: acquired head first, Instance Number 1 at the top
    # of the head and growing towards the feet (read as LPI, z following the
    # instances).
    d2, a2 = reorient(data, affine, (0, 1, 2), (True, True, True))
    write_dicom(os.path.join(out, "axial-reversed.dcm.d"), d2, a2)
    record("axial-reversed.dcm.d", "dicom", d2, a2)
    # Sagittal, IOP 0\1\0\0\0\-1: rows run posterior, columns inferior, slices left.
    d, a = reorient(data, affine, (1, 2, 0), (True, True, True))
    write_dicom(os.path.join(out, "sagittal.dcm.d"), d, a)
    record("sagittal.dcm.d", "dicom", d, a)
    # Coronal, IOP 1\0\0\0\0\-1: rows run left, columns inferior, slices anterior.
    d, a = reorient(data, affine, (0, 2, 1), (True, True, False))
    write_dicom(os.path.join(out, "coronal.dcm.d"), d, a)
    record("coronal.dcm.d", "dicom", d, a)
    # Oblique: the axial grid turned 20 deg about S and 15 deg about R.
    d, a = reorient(data, affine, (0, 1, 2), (True, True, False))
    d, a = resample_oblique(d, a, rotation(2, 20.0) @ rotation(0, 15.0))
    write_dicom(os.path.join(out, "oblique.dcm.d"), d, a)
    record("oblique.dcm.d", "dicom", d, a)
    with open(os.path.join(out, "truth.json"), "w") as f:
        json.dump(truth, f, indent=1)


# ------------------------------------------------------------------ readers


def read_text_header(path):
    with open(path, "rb") as f:
        raw = f.read()
    return raw


def read_nrrd(path):
    raw = read_text_header(path)
    end = raw.index(b"\n\n")
    fields = {}
    for line in raw[:end].decode().splitlines()[1:]:
        if line.startswith("#") or ":" not in line:
            continue
        k, v = line.split(":", 1)
        fields[k.strip()] = v.strip().lstrip("=").strip()
    sizes = [int(x) for x in fields["sizes"].split()]
    types = {"uint8": "u1", "uchar": "u1", "unsigned char": "u1", "uint16": "u2", "ushort": "u2",
             "unsigned short": "u2", "int16": "i2", "short": "i2", "float": "f4"}
    endian = "<" if fields.get("endian", "little") == "little" else ">"
    dtype = np.dtype(endian + types[fields["type"]])
    payload = raw[end + 2 :]
    if fields.get("encoding") in ("gzip", "gz"):
        payload = gzip.decompress(payload)
    data = np.frombuffer(payload, dtype=dtype, count=int(np.prod(sizes))).reshape(sizes, order="F")
    vecs = [np.array([float(x) for x in v.strip("()").split(",")]) for v in
            fields["space directions"].replace(") (", ")|(").split("|")]
    origin = np.array([float(x) for x in fields["space origin"].strip("()").split(",")])
    space = fields["space"].lower()
    flip = {"left-posterior-superior": LPS, "lps": LPS, "right-anterior-superior": np.eye(3),
            "ras": np.eye(3)}[space]
    affine = np.eye(4)
    affine[:3, :3] = flip @ np.stack(vecs, axis=1)
    affine[:3, 3] = flip @ origin
    return data, affine


def read_mha(path):
    raw = read_text_header(path)
    fields, offset = {}, 0
    for line in raw.split(b"\n"):
        offset += len(line) + 1
        k, v = [t.strip() for t in line.decode().split("=", 1)]
        fields[k] = v
        if k == "ElementDataFile":
            break
    dims = [int(x) for x in fields["DimSize"].split()]
    dtype = {"MET_UCHAR": "u1", "MET_USHORT": "<u2", "MET_SHORT": "<i2", "MET_FLOAT": "<f4"}[fields["ElementType"]]
    payload = raw[offset:]
    if fields.get("CompressedData", "False") == "True":
        payload = zlib.decompress(payload)
    data = np.frombuffer(payload, dtype=dtype, count=int(np.prod(dims))).reshape(dims, order="F")
    tm = np.array([float(x) for x in fields.get("TransformMatrix", "1 0 0 0 1 0 0 0 1").split()]).reshape(3, 3)
    spacing = np.array([float(x) for x in fields.get("ElementSpacing", "1 1 1").split()])
    origin = np.array([float(x) for x in fields.get("Offset", fields.get("Origin", "0 0 0")).split()])
    affine = np.eye(4)
    affine[:3, :3] = LPS @ (tm.T * spacing)  # rows of tm are the axis directions
    affine[:3, 3] = LPS @ origin
    return data, affine


def read_vti(path):
    import re

    raw = open(path, "rb").read()
    cut = raw.find(b"<AppendedData")
    text = raw[: cut if cut >= 0 else len(raw)].decode("latin-1")
    attr = lambda tag, name, default=None: (
        re.search(rf"<{tag}\b[^>]*\b{name}=\"([^\"]*)\"", text) or [None, default]
    )[1]
    ext = [int(x) for x in attr("ImageData", "WholeExtent").split()]
    dims = [ext[1] - ext[0] + 1, ext[3] - ext[2] + 1, ext[5] - ext[4] + 1]
    origin = np.array([float(x) for x in attr("ImageData", "Origin", "0 0 0").split()])
    spacing = np.array([float(x) for x in attr("ImageData", "Spacing", "1 1 1").split()])
    direction = np.array(
        [float(x) for x in attr("ImageData", "Direction", "1 0 0 0 1 0 0 0 1").split()]
    ).reshape(3, 3)
    dtype = {"UInt8": "u1", "UInt16": "<u2", "Int16": "<i2", "Float32": "<f4"}[attr("DataArray", "type")]
    fmt = attr("DataArray", "format")
    hsize = 8 if attr("VTKFile", "header_type", "UInt32") == "UInt64" else 4
    compressed = attr("VTKFile", "compressor") is not None
    if fmt == "appended":
        start = raw.index(b"_", cut) + 1 + int(attr("DataArray", "offset", "0"))
        data = decode_vtk_blocks(raw[start:], hsize, compressed, dtype)
    elif fmt == "binary":
        body = re.search(r"<DataArray[^>]*>([^<]*)</DataArray>", text).group(1)
        data = decode_vtk_blocks(base64.b64decode("".join(body.split())), hsize, compressed, dtype)
    else:
        body = re.search(r"<DataArray[^>]*>([^<]*)</DataArray>", text).group(1)
        data = np.array(body.split(), dtype=dtype)
    data = data[: int(np.prod(dims))].reshape(dims, order="F")
    affine = np.eye(4)
    # VTK: Direction is row-major and its columns are the index axes; the
    # world of extent index e is Origin + Direction * (Spacing * e). VTK has no
    # patient frame: Tessera reads and writes VTI coordinates as RAS.
    affine[:3, :3] = direction * spacing
    affine[:3, 3] = origin + affine[:3, :3] @ np.array([ext[0], ext[2], ext[4]], dtype=float)
    return data, affine


def decode_vtk_blocks(blob, hsize, compressed, dtype):
    it = "<u8" if hsize == 8 else "<u4"
    if not compressed:
        n = int(np.frombuffer(blob[:hsize], it)[0])
        return np.frombuffer(blob[hsize : hsize + n], dtype)
    nblocks = int(np.frombuffer(blob[:hsize], it)[0])
    head = np.frombuffer(blob[: hsize * (3 + nblocks)], it)
    sizes = head[3:]
    pos, parts = hsize * (3 + nblocks), []
    for s in sizes:
        parts.append(zlib.decompress(blob[pos : pos + int(s)]))
        pos += int(s)
    return np.frombuffer(b"".join(parts), dtype)


def read_dicom_folder(folder):
    slices = []
    for name in sorted(os.listdir(folder)):
        try:
            ds = pydicom.dcmread(os.path.join(folder, name))
        except Exception:
            continue
        if "PixelData" not in ds:
            continue
        slices.append(ds)
    iop = np.array([float(x) for x in slices[0].ImageOrientationPatient])
    row, col = iop[:3], iop[3:]
    normal = np.cross(row, col)
    slices.sort(key=lambda ds: float(np.dot(normal, [float(x) for x in ds.ImagePositionPatient])))
    vol = np.stack([ds.pixel_array.T.astype(np.float64) * float(getattr(ds, "RescaleSlope", 1))
                    + float(getattr(ds, "RescaleIntercept", 0)) for ds in slices], axis=2)
    ps = [float(x) for x in slices[0].PixelSpacing]
    p0 = np.array([float(x) for x in slices[0].ImagePositionPatient])
    p1 = np.array([float(x) for x in slices[1].ImagePositionPatient]) if len(slices) > 1 else p0 + normal
    lps = np.eye(4)
    lps[:3, 0] = row * ps[1]
    lps[:3, 1] = col * ps[0]
    lps[:3, 2] = p1 - p0
    lps[:3, 3] = p0
    affine = np.eye(4)
    affine[:3, :] = LPS @ lps[:3, :]
    return np.rint(vol), affine


def read_any(path):
    p = path.rstrip("/")
    if os.path.isdir(p):
        return read_dicom_folder(p)
    if p.endswith(".nii") or p.endswith(".nii.gz"):
        img = nib.load(p)
        return np.asarray(img.dataobj), img.affine
    if p.endswith(".nrrd"):
        return read_nrrd(p)
    if p.endswith(".mha"):
        return read_mha(p)
    if p.endswith(".vti"):
        return read_vti(p)
    raise SystemExit(f"{path}: no independent reader for this format")


def main():
    if len(sys.argv) >= 3 and sys.argv[1] == "make":
        make(sys.argv[2])
    elif len(sys.argv) >= 3 and sys.argv[1] == "marker":
        result = {}
        for path in sys.argv[2:]:
            data, affine = read_any(path)
            result[path] = marker_centre_ras(np.rint(data), affine)
        print(json.dumps(result))
    else:
        raise SystemExit(__doc__)


if __name__ == "__main__":
    main()
