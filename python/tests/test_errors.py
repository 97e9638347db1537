"""Every error path raises the right exception carrying the library's message
(the same text the CLI prints), never a crash of the interpreter."""
import json
import os
import subprocess

import numpy as np
import pytest

import tessera
from conftest import ROOT

BAD = os.path.join(ROOT, "tests", "data", "bad")


def cli_error(cli, *args):
    out = subprocess.run([cli, *args], capture_output=True, text=True, timeout=60)
    assert out.returncode != 0
    return out.stderr.strip()


def small():
    return tessera.from_array(np.zeros((8, 8, 8), np.uint8))


@pytest.mark.parametrize("dtype", [np.int32, np.float64, np.uint32, np.int8, np.bool_])
def test_a_dtype_the_gpu_path_does_not_take_is_rejected_naming_it(dtype):
    with pytest.raises(tessera.InputError, match=f"dtype {np.dtype(dtype).name}"):
        tessera.from_array(np.zeros((4, 4, 4), dtype))


def test_input_errors_are_value_errors_and_storage_errors_os_errors():
    assert issubclass(tessera.InputError, ValueError)
    assert issubclass(tessera.StorageError, OSError)
    assert issubclass(tessera.BudgetError, MemoryError)
    assert issubclass(tessera.GpuError, RuntimeError)


def test_a_2d_array_and_bad_axes_are_rejected():
    with pytest.raises(tessera.InputError, match=r"expected a 3D array, got shape \(4, 4\)"):
        tessera.from_array(np.zeros((4, 4), np.uint8))
    with pytest.raises(tessera.InputError, match="axes 'xyz'"):
        tessera.from_array(np.zeros((4, 4, 4), np.uint8), axes="xyz")
    with pytest.raises(tessera.InputError, match="spacing along axis 0 is 0"):
        tessera.from_array(np.zeros((4, 4, 4), np.uint8), affine=np.zeros((4, 4)))


def test_a_missing_file_is_a_storage_error_with_the_library_message(cli):
    path = "/nonexistent/head.nii.gz"
    expected = cli_error(cli, "info", path).removeprefix("tessera: error: ")
    with pytest.raises(tessera.StorageError) as e:
        tessera.Session(tessera.open(path))
    assert e.value.filename == path
    assert e.value.strerror == expected  # the library's message, as the CLI prints it
    with pytest.raises(tessera.StorageError):
        tessera.info(path)


@pytest.mark.parametrize("case", ["nifti/truncated-data.nii", "nifti/bad-magic.nii",
                                  "nrrd/zero-spacing.nrrd", "nifti/gzip-corrupt.nii.gz"])
def test_a_bad_file_is_an_input_error_naming_it(cli, case):
    manifest = json.load(open(os.path.join(BAD, "MANIFEST.json")))
    expect = next(c["expect"] for c in manifest["cases"] if c["file"] == case)
    path = os.path.join(BAD, case)
    with pytest.raises(tessera.InputError) as e:
        tessera.info(path)
    msg = str(e.value)
    assert msg == cli_error(cli, "info", path).removeprefix("tessera: error: ")
    assert os.path.basename(path) in msg
    assert any(x.lower() in msg.lower() for x in expect.split("|")), msg
    with pytest.raises(tessera.InputError):
        tessera.Session(tessera.open(path))


def test_settings_out_of_range_raise_the_session_message():
    with pytest.raises(tessera.InputError, match=r"step 0: expected voxels in \(0, 8\]"):
        tessera.Session(small(), step=0)
    s = tessera.Session(small())
    with pytest.raises(tessera.InputError, match="bogus"):
        s.update(mode="bogus")
    with pytest.raises(tessera.InputError, match="no-such-tf"):
        s.tf = "no-such-tf"
    with pytest.raises(tessera.InputError, match="setting 'colour' is unknown"):
        s.update(colour="red")
    with pytest.raises(tessera.InputError, match="fov"):
        s.update(fov=400)
    # All or none: the session keeps its settings after an error.
    assert s.settings["mode"] == "composite" and s.settings["camera"]["fov"] == 30


def test_a_slice_outside_the_volume_and_a_bad_axis_raise():
    s = tessera.Session(small())
    with pytest.raises(tessera.InputError, match="12"):
        s.slice(2, 12)
    with pytest.raises(tessera.InputError, match="axis 5"):
        s.slice(5, 0)


def test_bad_sizes_raise_instead_of_crashing():
    s = tessera.Session(small())
    for w, h in [(0, 64), (64, -1), (100000, 64)]:
        with pytest.raises(tessera.InputError, match="size"):
            s.render(w, h)


def test_convert_into_an_unwritable_folder_is_a_storage_error(tmp_path):
    with pytest.raises(tessera.StorageError):
        tessera.convert(small(), "/proc/no/such/folder/out.nii.gz")
    with pytest.raises(tessera.InputError, match="levels 'x'"):
        tessera.convert(small(), str(tmp_path / "a.ome.zarr"), levels="x")


def test_a_region_of_an_array_is_refused():
    with pytest.raises(tessera.InputError, match="slice the array"):
        tessera.Session(small(), region="0:4,0:4,0:4")


def test_unknown_profile_and_layout_raise():
    with pytest.raises(tessera.InputError, match="nope"):
        tessera.Session(small(), profile="nope")
    with pytest.raises(tessera.InputError, match="nope"):
        tessera.Session(small(), layout="nope").render(16, 16)
