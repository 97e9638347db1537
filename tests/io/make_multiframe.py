#!/usr/bin/python3
"""Multi-frame DICOM objects for the multi-frame tests, written with pydicom.

    make_multiframe.py OUTDIR    writes the files below and OUTDIR/truth.json

- single/slice_NNNN.dcm  the marked head (tests/geometry/marked_head.py) as a
  single-frame CT series: stored = value + 1024, Rescale Intercept -1024;
- enhanced.dcm           the same anatomy as one Enhanced CT Image Storage
  object: Pixel Measures, Plane Orientation and Pixel Value Transformation in
  the shared functional groups, Plane Position and Frame Content (Stack ID,
  In-Stack Position Number) per frame; the frames stored in reverse order;
- enhanced-rle.dcm       the same, RLE Lossless, two fragments per frame and a
  Basic Offset Table;
- twostack.dcm           an Enhanced MR object of two stacks, axial (stack "1",
  24 frames, values 100 + k) and sagittal (stack "2", 20 frames, 200 + k);
- twostack-rle.dcm       the same, RLE Lossless, one fragment per frame;
- classic-nm.dcm         classic NM multi-frame: the plane in the Detector
  Information Sequence, Spacing Between Slices the step; frame k = 10 + k;
- bad/no-position.dcm    enhanced, frame 5 without Plane Position (Patient);
- bad/frames-lie.dcm     enhanced, Number of Frames 26 for 24 frames of pixels
  (and 26 per-frame items).

Needs Debian's python3-numpy, python3-nibabel and python3-pydicom (2.x).
"""
import copy
import json
import os
import sys

import numpy as np
import pydicom
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.encaps import encapsulate
from pydicom.sequence import Sequence
from pydicom.uid import ExplicitVRLittleEndian, RLELossless, generate_uid

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "geometry"))
import marked_head  # noqa: E402  (the head, its marker and reorientation)

LPS = marked_head.LPS
CT = "1.2.840.10008.5.1.4.1.1.2"
ENHANCED_CT = "1.2.840.10008.5.1.4.1.1.2.1"
ENHANCED_MR = "1.2.840.10008.5.1.4.1.1.4.1"
NM = "1.2.840.10008.5.1.4.1.1.20"


def base(sop_class, series, modality):
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = sop_class
    meta.MediaStorageSOPInstanceUID = generate_uid()
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = Dataset()
    ds.file_meta = meta
    ds.is_little_endian = True
    ds.is_implicit_VR = False
    ds.SOPClassUID = sop_class
    ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
    ds.StudyInstanceUID = generate_uid()
    ds.SeriesInstanceUID = series
    ds.FrameOfReferenceUID = generate_uid()
    ds.Modality = modality
    ds.PatientName = "Multi^Frame"
    ds.PatientID = "MULTIFRAME"
    ds.SamplesPerPixel = 1
    ds.PhotometricInterpretation = "MONOCHROME2"
    ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 0
    return ds


def ds_text(values, fmt):
    return [fmt.format(x) for x in values]


def plane(affine):
    """IOP (row, column direction), pixel spacing (row, column) and the LPS
    position of voxel (0, 0, k) of an index -> RAS affine."""
    lps = LPS @ affine[:3, :3]
    spacing = np.linalg.norm(lps, axis=0)
    iop = [*(lps[:, 0] / spacing[0]), *(lps[:, 1] / spacing[1])]
    position = lambda k: lps @ np.array([0.0, 0.0, float(k)]) + LPS @ affine[:3, 3]
    return iop, spacing, position


def item(**attributes):
    d = Dataset()
    for k, v in attributes.items():
        setattr(d, k, v)
    return d


def enhanced(sop_class, series, modality, stacks, rows, cols, rescale=None):
    """One enhanced object; `stacks` is [(stack_id, frames (k, rows, cols) u16,
    affine)], written in that order, frames within a stack as given."""
    ds = base(sop_class, series, modality)
    ds.Rows, ds.Columns = rows, cols
    shared = Dataset()
    if rescale is not None:
        shared.PixelValueTransformationSequence = Sequence(
            [item(RescaleIntercept=str(rescale), RescaleSlope="1", RescaleType="HU")])
    per_frame, pixels = [], []
    one_plane = len(stacks) == 1
    for stack_id, frames, affine, order in stacks:
        iop, spacing, position = plane(affine)
        measures = item(PixelSpacing=ds_text((spacing[1], spacing[0]), "{:.8f}"),
                        SliceThickness=f"{spacing[2]:.8f}")
        orientation = item(ImageOrientationPatient=ds_text(iop, "{:.8f}"))
        if one_plane:
            shared.PixelMeasuresSequence = Sequence([measures])
            shared.PlaneOrientationSequence = Sequence([orientation])
        for k in order:
            fg = Dataset()
            if not one_plane:
                fg.PixelMeasuresSequence = Sequence([copy.deepcopy(measures)])
                fg.PlaneOrientationSequence = Sequence([copy.deepcopy(orientation)])
            fg.PlanePositionSequence = Sequence(
                [item(ImagePositionPatient=ds_text(position(k), "{:.6f}"))])
            fg.FrameContentSequence = Sequence(
                [item(StackID=stack_id, InStackPositionNumber=int(k) + 1,
                      DimensionIndexValues=[int(stack_id), int(k) + 1])])
            per_frame.append(fg)
            pixels.append(np.ascontiguousarray(frames[k]).astype("<u2"))
    ds.SharedFunctionalGroupsSequence = Sequence([shared])
    ds.PerFrameFunctionalGroupsSequence = Sequence(per_frame)
    ds.NumberOfFrames = len(pixels)
    ds.PixelData = b"".join(p.tobytes() for p in pixels)
    return ds, pixels


def renamed(ds):
    """A copy of `ds` as another instance of another series."""
    out = copy.deepcopy(ds)
    out.SeriesInstanceUID = generate_uid()
    out.SOPInstanceUID = out.file_meta.MediaStorageSOPInstanceUID = generate_uid()
    return out


def rle(ds, pixels, fragments_per_frame):
    """`ds` re-encoded as RLE Lossless (PS3.5 G), frames split into fragments."""
    from pydicom.pixel_data_handlers.rle_handler import rle_encode_frame

    out = renamed(ds)
    frames = [rle_encode_frame(p) for p in pixels]
    out.PixelData = encapsulate(frames, fragments_per_frame=fragments_per_frame, has_bot=True)
    out["PixelData"].is_undefined_length = True
    out["PixelData"].VR = "OB"
    out.file_meta.TransferSyntaxUID = RLELossless
    return out


def save(ds, path):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    ds.save_as(path, write_like_original=False)


def head_files(out, truth):
    data, affine = marked_head.head()
    # Axial storage, LPS as a scanner writes it (marked_head's axial.dcm.d).
    d, a = marked_head.reorient(data, affine, (0, 1, 2), (True, True, False))
    truth["marker_ras"] = marked_head.marker_centre_ras(d, a)
    truth["head_dims"] = list(d.shape)
    stored = d.astype(np.uint16) + 1024  # stored = HU + 1024
    frames = [stored[:, :, k].T for k in range(d.shape[2])]  # (rows = y, columns = x)
    iop, spacing, position = plane(a)
    series = generate_uid()
    for k in range(d.shape[2]):
        ds = base(CT, series, "CT")
        ds.InstanceNumber = k + 1
        ds.ImageOrientationPatient = ds_text(iop, "{:.8f}")
        ds.ImagePositionPatient = ds_text(position(k), "{:.6f}")
        ds.PixelSpacing = ds_text((spacing[1], spacing[0]), "{:.8f}")
        ds.SliceThickness = f"{spacing[2]:.8f}"
        ds.RescaleIntercept, ds.RescaleSlope = "-1024", "1"
        ds.Rows, ds.Columns = frames[k].shape
        ds.PixelData = np.ascontiguousarray(frames[k]).astype("<u2").tobytes()
        save(ds, os.path.join(out, "single", f"slice_{k:04d}.dcm"))
    order = list(reversed(range(len(frames))))  # the file's frame order is not z
    ds, pixels = enhanced(ENHANCED_CT, generate_uid(), "CT", [("1", frames, a, order)],
                          frames[0].shape[0], frames[0].shape[1], rescale=-1024)
    save(ds, os.path.join(out, "enhanced.dcm"))
    save(rle(ds, pixels, 2), os.path.join(out, "enhanced-rle.dcm"))
    return ds


def two_stacks(out, truth):
    n = 32
    axial = [np.full((n, n), 100 + k, np.uint16) for k in range(24)]
    sagittal = [np.full((n, n), 200 + k, np.uint16) for k in range(20)]
    axial_affine = np.diag([0.8, 0.8, 2.0, 1.0])
    axial_affine[:3, 3] = [-12.0, -12.0, -20.0]
    # Sagittal: rows run anterior (RAS +y), columns inferior, slices right.
    sag_affine = np.eye(4)
    sag_affine[:3, 0] = [0, 0.8, 0]
    sag_affine[:3, 1] = [0, 0, -0.8]
    sag_affine[:3, 2] = [1.5, 0, 0]
    sag_affine[:3, 3] = [-15.0, -12.0, 12.0]
    ds, pixels = enhanced(ENHANCED_MR, generate_uid(), "MR",
                          [("1", axial, axial_affine, range(24)),
                           ("2", sagittal, sag_affine, range(20))], n, n)
    save(ds, os.path.join(out, "twostack.dcm"))
    save(rle(ds, pixels, 1), os.path.join(out, "twostack-rle.dcm"))
    truth["twostack"] = {"series": ds.SeriesInstanceUID,
                         "stacks": {"1": {"frames": 24, "affine": axial_affine.tolist()},
                                    "2": {"frames": 20, "affine": sag_affine.tolist()}}}
    # A frame without its position; Number of Frames that lies.
    bad = renamed(ds)
    del bad.PerFrameFunctionalGroupsSequence[4].PlanePositionSequence
    save(bad, os.path.join(out, "bad", "no-position.dcm"))
    lie, _ = enhanced(ENHANCED_MR, generate_uid(), "MR", [("1", axial, axial_affine, range(24))],
                      n, n)
    lie.PerFrameFunctionalGroupsSequence.extend(
        [copy.deepcopy(lie.PerFrameFunctionalGroupsSequence[-1]) for _ in range(2)])
    lie.NumberOfFrames = 26
    save(lie, os.path.join(out, "bad", "frames-lie.dcm"))


def classic_nm(out, truth):
    ds = base(NM, generate_uid(), "NM")
    ds.Rows, ds.Columns = 16, 20
    ds.NumberOfFrames = 12
    ds.SpacingBetweenSlices = "3.5"
    ds.PixelSpacing = ["2.0", "2.5"]
    ds.DetectorInformationSequence = Sequence(
        [item(ImagePositionPatient=["10.0", "-20.0", "30.0"],
              ImageOrientationPatient=["1", "0", "0", "0", "1", "0"])])
    frames = [np.full((16, 20), 10 + k, np.uint16) for k in range(12)]
    ds.PixelData = b"".join(f.astype("<u2").tobytes() for f in frames)
    save(ds, os.path.join(out, "classic-nm.dcm"))


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    truth = {"pydicom": pydicom.__version__}
    head_files(out, truth)
    two_stacks(out, truth)
    classic_nm(out, truth)
    with open(os.path.join(out, "truth.json"), "w") as f:
        json.dump(truth, f, indent=1)


if __name__ == "__main__":
    main()
