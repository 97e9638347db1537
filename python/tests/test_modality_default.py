"""A Session given no ``tf`` gets its volume's modality default, as
`tessera render` does (session/ModalityDefault.h): a CT series opens with
ct-soft-tissue over -160..240 HU, and its frame is the CLI's default render
and the render with tf="ct-soft-tissue"; a tf the user gives stays."""
import os

import numpy as np
import pytest

import tessera
from conftest import psnr, read_png, run_cli

pydicom = pytest.importorskip("pydicom")

NOTE = ("CT: default transfer function ct-soft-tissue (modality CT), window -160..240 HU of "
        "the preset; --tf to change")


def ct_series(folder, n=12, size=24):
    """A CT series (stored = HU + 1024, intercept -1024): air around a
    water-and-bone cylinder, no Window Center/Width of its own."""
    from pydicom.dataset import Dataset, FileMetaDataset
    from pydicom.uid import ExplicitVRLittleEndian, generate_uid

    os.makedirs(folder, exist_ok=True)
    series, study = generate_uid(), generate_uid()
    y, x = np.mgrid[0:size, 0:size]
    r = np.hypot(x - size / 2 + 0.5, y - size / 2 + 0.5)
    for k in range(n):
        hu = np.where(r < size * 0.4, 40, -1000)
        hu = np.where(r < size * 0.15, 900 if 3 <= k < n - 3 else 40, hu)
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = "1.2.840.10008.5.1.4.1.1.2"
        meta.MediaStorageSOPInstanceUID = generate_uid()
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        ds = Dataset()
        ds.file_meta = meta
        ds.is_little_endian, ds.is_implicit_VR = True, False
        ds.SOPClassUID, ds.SOPInstanceUID = meta.MediaStorageSOPClassUID, meta.MediaStorageSOPInstanceUID
        ds.StudyInstanceUID, ds.SeriesInstanceUID, ds.Modality = study, series, "CT"
        ds.InstanceNumber = k + 1
        ds.ImagePositionPatient = [0, 0, 2.0 * k]
        ds.ImageOrientationPatient = [1, 0, 0, 0, 1, 0]
        ds.PixelSpacing = [1, 1]
        ds.SliceThickness = 2
        ds.RescaleIntercept, ds.RescaleSlope = -1024, 1
        ds.Rows = ds.Columns = size
        ds.SamplesPerPixel, ds.PhotometricInterpretation = 1, "MONOCHROME2"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 0
        ds.PixelData = (hu + 1024).astype("<u2").tobytes()
        ds.save_as(os.path.join(folder, f"s{k:03d}.dcm"), write_like_original=False)
    return folder


def test_a_session_without_tf_gets_the_modality_default_and_renders_as_the_cli(tmp_path, cli):
    folder = ct_series(str(tmp_path / "ct"))
    s = tessera.Session(folder, azimuth=30, elevation=20)
    assert s.settings["tf"]["name"] == "ct-soft-tissue"
    assert s.default_note == NOTE
    frame = s.render(64, 64)
    # The same frame as with the preset named, and as the CLI's default.
    named = tessera.Session(folder, tf="ct-soft-tissue", azimuth=30, elevation=20)
    assert named.default_note == ""
    assert np.array_equal(frame, named.render(64, 64))
    png = str(tmp_path / "cli.png")
    run_cli(cli, "render", folder, "--azimuth", "30", "--elevation", "20", "--size", "64x64",
            "--out", png)
    assert frame[..., :3].max() > 50, "the frame shows the volume"
    assert psnr(frame, read_png(png)) >= 60.0
    # Not the front end's default TF.
    assert not np.array_equal(frame, tessera.Session(folder, tf="mr-default", azimuth=30,
                                                     elevation=20).render(64, 64))
    # Settings changed later keep the default (the user still named no tf).
    s.update(azimuth=60)
    assert s.settings["tf"]["name"] == "ct-soft-tissue"
    assert np.array_equal(s.render(64, 64), named.render(64, 64, azimuth=60))


def test_a_tf_the_user_gives_stays_and_ct_bone_on_a_ct_gets_a_note(tmp_path):
    folder = ct_series(str(tmp_path / "ct"))
    grey = tessera.Session(folder, tf="grey")
    assert grey.settings["tf"]["name"] == "grey"
    assert grey.default_note == ""
    bone = tessera.Session(folder, tf="ct-bone")
    assert bone.settings["tf"]["name"] == "ct-bone"
    assert bone.default_note == ("CT: ct-bone is the bone ramp over the volume's own window; the "
                                 "bone preset in Hounsfield units, the same on every CT, is "
                                 "ct-bone-hu")
    # An array has no modality: the front end's default stays.
    a = tessera.Session(tessera.from_array(np.zeros((8, 8, 8), np.uint8)))
    assert a.settings["tf"]["name"] == "mr-default"
    assert a.default_note == ""
