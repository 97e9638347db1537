"""Frames from numpy equal the CLI's frames of the same voxels read from a
NIfTI file; arrays are wrapped without a copy; settings reach the session."""
import os
import threading
import time

import numpy as np
import pytest

import tessera
from conftest import psnr, read_png, run_cli

SIZE = 128
SETTINGS_CLI = ["--tf", "ct-bone", "--azimuth", "30", "--elevation", "15", "--size", f"{SIZE}x{SIZE}"]
SETTINGS_PY = dict(tf="ct-bone", azimuth=30, elevation=15)


def blob(shape, dtype):
    """A smooth anisotropic blob with a bright shell: structure at every scale."""
    z, y, x = np.meshgrid(*[np.linspace(-1, 1, n) for n in shape], indexing="ij")
    r = np.sqrt(x * x + 1.5 * y * y + 0.7 * z * z)
    v = np.exp(-3 * r * r) + 0.8 * np.exp(-80 * (r - 0.6) ** 2)
    scale = {np.uint8: 250, np.uint16: 4000, np.int16: 3000, np.float32: 1.0}[dtype]
    return (v * scale).astype(dtype)


AFFINE = np.array([[1.2, 0, 0, -20], [0, 0.9, 0, 5], [0, 0, 1.5, 10], [0, 0, 0, 1]])


def cli_render(cli, tmp_path, data, affine, name):
    import nibabel as nib

    path = str(tmp_path / f"{name}.nii.gz")
    nib.save(nib.Nifti1Image(np.asfortranarray(data), affine), path)
    out = str(tmp_path / f"{name}.png")
    run_cli(cli, "render", path, *SETTINGS_CLI, "--out", out)
    return read_png(out)


@pytest.mark.parametrize("order", ["F", "C"])
def test_from_array_render_equals_cli_render_of_the_nifti(cli, tmp_path, order):
    data = blob((40, 48, 36), np.uint16)
    expected = cli_render(cli, tmp_path, data, AFFINE, "blob")
    a = np.asfortranarray(data) if order == "F" else np.ascontiguousarray(data)
    v = tessera.from_array(a, affine=AFFINE)
    assert v.borrowed and not v.copied
    got = tessera.Session(v, **SETTINGS_PY).render(SIZE, SIZE)
    assert got.shape == (SIZE, SIZE, 4) and got.dtype == np.uint8
    assert got[..., :3].max() > 50, "the frame shows the volume"
    db = psnr(got, expected)
    print(f"from_array ({order} order) vs CLI render of the NIfTI: PSNR {db:.2f} dB")
    assert db >= 60.0


def test_zyx_axes_render_equals_ijk_of_the_transposed_array(tmp_path):
    data = blob((40, 48, 36), np.uint8)  # a[i, j, k]
    zyx = np.ascontiguousarray(data.transpose(2, 1, 0))  # a[z, y, x]
    a = tessera.Session(tessera.from_array(data, spacing=(1.0, 2.0, 1.5)), **SETTINGS_PY)
    b = tessera.Session(tessera.from_array(zyx, spacing=(1.5, 2.0, 1.0), axes="zyx"),
                        **SETTINGS_PY)
    assert np.array_equal(a.volume.affine[:3, :3] @ [1, 1, 1], [1.0, 2.0, 1.5])
    assert psnr(a.render(SIZE, SIZE), b.render(SIZE, SIZE)) >= 60.0


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_a_512_cubed_u16_array_is_wrapped_without_a_copy():
    a = np.ones((512, 512, 512), np.uint16)  # 256 MiB, every page touched
    a[100:400, 100:400, 100:400] = 3000
    before = rss_bytes()
    v = tessera.from_array(a, spacing=(0.5, 0.5, 0.5))
    wrapped = rss_bytes()
    s = tessera.Session(v)
    opened = rss_bytes()
    print(f"RSS delta wrapping a 512^3 u16 array (256 MiB): {(wrapped - before) / 2**20:.2f} MiB; "
          f"opening a session on it: {(opened - wrapped) / 2**20:.2f} MiB")
    assert v.voxel_address == a.ctypes.data
    assert v.borrowed and not v.copied
    assert v.dims == (512, 512, 512) and v.dtype == "u16"
    assert wrapped - before < 4 * 2**20
    assert opened - wrapped < 64 * 2**20
    assert s.volume is v


def test_the_array_stays_alive_while_the_volume_lives():
    v = tessera.from_array(blob((24, 24, 24), np.float32))
    import gc

    gc.collect()
    assert tessera.Session(v).render(32, 32).shape == (32, 32, 4)


def test_non_contiguous_and_byte_swapped_arrays_are_copied_once():
    base = blob((20, 20, 20), np.uint16)
    v = tessera.from_array(base[::2])
    assert v.copied and v.dims == (20, 20, 10)
    w = tessera.from_array(base.astype(">u2"))
    assert w.copied and w.dtype == "u16"


def test_window_and_tf_from_a_dict_reach_the_render():
    v = tessera.from_array(blob((32, 32, 32), np.uint8), window=(0, 255))
    s = tessera.Session(v, tf="grey")
    grey = s.render(64, 64)
    custom = tessera.tf({"name": "red", "color": [{"x": 0, "rgb": [1, 0, 0]},
                                                  {"x": 1, "rgb": [1, 0, 0]}],
                         "opacity": [{"x": 0, "alpha": 0}, {"x": 1, "alpha": 1}]})
    assert custom["name"] == "red"
    red = s.update(tf=custom).render(64, 64)
    assert red[..., 1].max() == 0 and red[..., 0].max() > 100
    assert grey[..., 1].max() > 50
    assert s.tf["name"] == "red"
    s.window = (0, 1000)
    assert s.window == [0.0, 1000.0]
    darker = s.render(64, 64)
    assert darker[..., 0].astype(int).sum() < red[..., 0].astype(int).sum()


def test_render_reference_agrees_with_the_gpu_frame():
    s = tessera.Session(tessera.from_array(blob((32, 32, 32), np.uint8)), tf="ct-bone")
    db = psnr(s.render(64, 64), s.render_reference(64, 64))
    print(f"render vs render_reference: {db:.1f} dB")
    assert db >= 35.0


def test_slice_shows_the_voxels_of_the_index():
    a = np.zeros((16, 20, 24), np.uint8)
    for k in range(24):
        a[:, :, k] = 10 * k
    s = tessera.Session(tessera.from_array(a, window=(0, 255)))
    img = s.slice(2, 7)  # a[:, :, 7]: axial (the affine's k is superior)
    assert img.ndim == 2 and img.shape == (20, 16)
    assert np.all(img == 70)
    assert s.slice(2, 7, tf="ct-bone").shape == (20, 16, 4)
    assert s.slice(0, 3).shape == (24, 20)  # a[3]: sagittal
    f = tessera.Session(tessera.from_array(np.asfortranarray(a), window=(0, 255)))
    assert np.array_equal(f.slice(2, 7), img) and np.array_equal(f.slice(0, 3), s.slice(0, 3))


def test_the_gil_is_released_while_rendering():
    s = tessera.Session(tessera.from_array(blob((64, 64, 64), np.uint8)), tf="ct-bone")
    s.render(32, 32)
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(1)
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    t0 = time.perf_counter()
    s.render(384, 384)
    ms = (time.perf_counter() - t0) * 1000
    done.set()
    t.join()
    assert len(ticks) >= max(3, ms / 10), (len(ticks), ms)


def test_render_camera_keywords_and_repr_png():
    s = tessera.Session(tessera.from_array(blob((32, 32, 32), np.uint8)))
    front = s.render(64, 64)
    side = s.render(64, 64, azimuth=90)
    assert s.azimuth == 90 and s.camera["azimuth"] == 90
    assert not np.array_equal(front, side)
    png = s._repr_png_()
    assert png.startswith(b"\x89PNG") and len(png) > 1000


def test_render_keeps_the_technique_and_draws_what_a_fresh_run_draws():
    s = tessera.Session(tessera.from_array(blob((48, 40, 32), np.uint16)), tf="ct-bone")
    s.render(96, 96)
    t0 = time.perf_counter()
    for azimuth, tf, shade in [(30, "ct-bone", False), (75, "mr-default", False),
                               (120, "grey", True), (200, "ct-bone", True)]:
        s.update(azimuth=azimuth, tf=tf, shade=shade)
        kept = s.render(96, 96)
        fresh, report = s.run(96, 96)  # uploads and prepares anew (runRender)
        assert np.array_equal(kept, fresh), (azimuth, tf, shade, psnr(kept, fresh))
        assert report["frame_ms"] and report["layout"]
    assert (time.perf_counter() - t0) < 30


def test_a_session_belongs_to_its_thread_and_sessions_on_threads_render_in_parallel():
    v = tessera.from_array(blob((32, 32, 32), np.uint8))
    s = tessera.Session(v, tf="ct-bone")
    mine = s.render(48, 48)
    out = {}

    def elsewhere():
        try:
            s.render(48, 48)
        except tessera.GpuError as e:
            out["error"] = str(e)
        own = tessera.Session(v, tf="ct-bone")  # the same volume, shared
        out["frame"] = own.render(48, 48)

    threads = [threading.Thread(target=elsewhere) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert "thread that made it" in out["error"]
    assert np.array_equal(out["frame"], mine)
    assert np.array_equal(s.render(48, 48), mine)  # still usable on its own thread
