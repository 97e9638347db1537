"""The package imports headless from a source checkout, info() is the CLI's
`info --json`, convert() writes what the CLI reads, `pip install .` works."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest


import tessera
from conftest import BUILD, ROOT, psnr, run_cli_json


def test_the_package_imports_and_renders_headless_in_a_fresh_interpreter():
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["PYTHONPATH"] = os.path.join(ROOT, "python")
    env["TESSERA_BUILD_DIR"] = BUILD
    code = ("import tessera; s = tessera.Session(tessera.open('gen:shepp-logan:32')); "
            "print(s.render(48, 40).shape, tessera.__file__)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, timeout=120, cwd="/")
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("(40, 48, 4) " + os.path.join(ROOT, "python", "tessera"))


def test_info_equals_the_cli_info_json(cli, ch2):
    assert tessera.info(ch2) == run_cli_json(cli, "info", ch2)
    assert tessera.info(tessera.open(ch2).load()) == run_cli_json(cli, "info", ch2)


def test_info_of_an_array_describes_its_storage():
    a = np.zeros((10, 12, 14), np.int16)
    a[2:5, 3:7, 1:2] = -7
    i = tessera.info(tessera.from_array(a, spacing=(1, 2, 3)))
    assert i["dims"] == [14, 12, 10] and i["type"] == "i16"  # C order: k fastest
    assert i["value_min"] == -7 and i["value_max"] == 0
    assert i["bytes"] == a.nbytes
    # Storage (x, y, z) = array (k, j, i): the affine's columns are permuted.
    assert np.allclose(np.array(i["affine"])[:3, :3], [[0, 0, 1], [0, 2, 0], [3, 0, 0]])


def test_convert_writes_what_the_cli_renders_like_the_array(cli, tmp_path):
    a = np.zeros((24, 24, 24), np.uint8)
    a[6:18, 4:20, 8:16] = 200
    out = str(tmp_path / "box.nrrd")
    notes = tessera.convert(tessera.from_array(a, spacing=(1, 1, 2)), out)
    assert isinstance(notes, list)
    assert run_cli_json(cli, "info", out)["dims"] == [24, 24, 24]
    zarr = str(tmp_path / "box.ome.zarr")
    tessera.convert(out, zarr, chunks=64, levels=2)
    assert len(tessera.info(zarr)["zarr"]["levels"]) == 2
    s = tessera.Session(tessera.from_array(a, spacing=(1, 1, 2)), tf="ct-bone")
    t = tessera.Session(tessera.open(zarr), tf="ct-bone")
    assert psnr(s.render(64, 64), t.render(64, 64)) >= 60.0


def test_convert_takes_the_clis_crop_downsample_and_zarr_options(cli, tmp_path):
    """convert()'s crop, downsample, chunks, zarr_format and shard are the
    CLI's (session/Convert.h): the files written are byte-identical to
    `tessera convert`'s, and bad options name the option as the CLI does."""
    rng = np.random.default_rng(5)
    a = rng.integers(0, 4000, size=(30, 28, 26), dtype=np.uint16)
    src = str(tmp_path / "in.nii")
    tessera.convert(tessera.from_array(a, spacing=(0.5, 1.0, 2.0)), src)
    ours = str(tmp_path / "py.nrrd")
    theirs = str(tmp_path / "cli.nrrd")
    tessera.convert(src, ours, crop=((2, 22), (3, 27), (0, 25)), downsample=(2, 1, 3))
    subprocess.run([cli, "convert", src, theirs, "--crop", "2:22,3:27,0:25",
                    "--downsample", "2x1x3", "--quiet"], check=True, capture_output=True)
    assert tessera.info(ours)["dims"] == [10, 24, 9]
    assert open(ours, "rb").read() == open(theirs, "rb").read()
    zpy = tmp_path / "py" / "v.ome.zarr"  # the same name: the multiscales name is the file's
    zcli = tmp_path / "cli" / "v.ome.zarr"
    zpy.parent.mkdir()
    zcli.parent.mkdir()
    tessera.convert(src, str(zpy), chunks=(8, 16, 16), zarr_format=3, shard=2, downsample=2,
                    pyramid_factors=(1, 2, 2))
    subprocess.run([cli, "convert", src, str(zcli), "--chunk", "8,16,16", "--zarr-format", "3",
                    "--shard", "2", "--downsample", "2", "--pyramid-factors", "1,2,2",
                    "--quiet"], check=True, capture_output=True)
    files = sorted(p.relative_to(zpy) for p in zpy.rglob("*") if p.is_file())
    assert files == sorted(p.relative_to(zcli) for p in zcli.rglob("*") if p.is_file())
    assert any(str(f).endswith("zarr.json") for f in files)
    for f in files:
        assert (zpy / f).read_bytes() == (zcli / f).read_bytes(), f
    with pytest.raises(tessera.InputError, match="--crop '0:99,0:28,0:26'"):
        tessera.convert(src, str(tmp_path / "x.nii"), crop=((0, 99), (0, 28), (0, 26)))
    with pytest.raises(tessera.InputError, match="--downsample '0'"):
        tessera.convert(src, str(tmp_path / "x.nii"), downsample=0)
    with pytest.raises(tessera.InputError, match="--chunk '7,16,16'"):
        tessera.convert(src, str(tmp_path / "x.ome.zarr"), chunks=(7, 16, 16))
    with pytest.raises(tessera.InputError, match="crop"):
        tessera.convert(src, str(tmp_path / "x.nii"), crop=(1, 2))
    with pytest.raises(tessera.InputError, match="--pyramid-factors"):
        tessera.convert(src, str(tmp_path / "x.ome.zarr"), pyramid_factors=(3, 2, 2))


def test_tf_presets_and_json():
    names = tessera.tf_presets()
    assert {"grey", "mr-default", "ct-bone"} <= set(names)
    bone = tessera.tf("ct-bone")
    assert bone["name"] == "ct-bone"
    assert tessera.tf(json.dumps(bone)) == bone


def test_pip_install_into_a_folder_imports_from_there(tmp_path):
    target = str(tmp_path / "site")
    env = dict(os.environ, TESSERA_BUILD_DIR=BUILD)
    out = subprocess.run(
        [sys.executable, "-m", "pip", "install", "--no-build-isolation", "--no-deps", "--no-index",
         "--quiet", "--target", target, ROOT],
        capture_output=True, text=True, env=env, timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    env = {k: v for k, v in os.environ.items() if k != "TESSERA_BUILD_DIR"}
    env["PYTHONPATH"] = target
    code = ("import tessera, os; print(tessera.Session(tessera.open('gen:sphere:16'))"
            ".render(8, 8).shape, os.path.dirname(tessera._tessera.__file__))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                         timeout=120, cwd="/")
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == f"(8, 8, 4) {os.path.join(target, 'tessera')}"
    assert os.path.exists(os.path.join(target, "tessera", "py.typed"))
    assert os.path.exists(os.path.join(target, "tessera", "__init__.pyi"))
