"""tessera.widget: the kernel-side viewer draws a new frame for each camera
change, the same frame a session renders at those settings."""
import numpy as np
import pytest

import tessera
from conftest import psnr

pytest.importorskip("ipywidgets")


def png_pixels(png):
    import io

    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"))


def test_the_widget_renders_each_camera_change_as_a_session_would():
    a = np.zeros((40, 40, 40), np.uint8)
    a[10:30, 5:35, 15:25] = 200
    v = tessera.widget(tessera.from_array(a), tf="ct-bone", size=96)
    first = bytes(v.image.value)
    v.azimuth.value = 60
    assert bytes(v.image.value) != first and v.last_ms > 0
    s = tessera.Session(tessera.from_array(a), tf="ct-bone", azimuth=60)
    assert psnr(png_pixels(v.image.value), s.render(96, 96)) >= 60.0
    v.tf.value = "grey"
    v.mode.value = "mip"
    s.update(tf="grey", mode="mip")
    assert psnr(png_pixels(v.image.value), s.render(96, 96)) >= 60.0
    assert [len(i.value) > 100 for i in v.slice_images] == [True] * 3
    before = bytes(v.slice_images[2].value)
    v.slice_indices[2].value = 5  # a[:, :, 5], outside the box
    assert bytes(v.slice_images[2].value) != before


def box_volume():
    a = np.zeros((40, 40, 40), np.uint8)
    a[10:30, 5:35, 15:25] = 200
    return a


def camera_after(az, el, drags):
    """The orbit viewer::CameraController makes of pointer drags: azimuth -=
    dx * k (wrapped to [-180, 180]), elevation += dy * k within +-89."""
    k = tessera._tessera.orbit_degrees_per_pixel
    for dx, dy in drags:
        az = float(np.remainder(az - dx * k + 180.0, 360.0) - 180.0)
        el = min(89.0, max(-89.0, el + dy * k))
    return az, el


def test_a_drag_orbits_by_the_documented_angle_and_draws_exactly_the_session_frame():
    assert tessera._tessera.orbit_degrees_per_pixel == 0.4
    v = tessera.widget(tessera.from_array(box_volume()), tf="ct-bone", size=96)
    cam = v.session.settings["camera"]
    renders = []
    real_render = v.session.render
    v.session.render = lambda *a, **k: renders.append(a) or real_render(*a, **k)
    png = v.drag(25, -10)
    az, el = camera_after(cam["azimuth"], cam["elevation"], [(25, -10)])
    got = v.session.settings["camera"]
    assert (got["azimuth"], got["elevation"]) == pytest.approx((az, el), abs=1e-9)
    assert (v.azimuth.value, v.elevation.value) == pytest.approx((az, el), abs=1e-9)
    assert len(renders) == 1, "the sliders' sync must not draw a second frame"
    assert bytes(v.image.value) == png and v.drags == 1 and v.last_drag_ms > 0
    s = tessera.Session(tessera.from_array(box_volume()), tf="ct-bone", azimuth=az, elevation=el)
    assert np.array_equal(png_pixels(png), s.render(96, 96))
    v.drag(0, 1000)  # elevation stops at 89, as in the viewers
    assert v.elevation.value == 89.0 and v.session.settings["camera"]["elevation"] == 89.0


def drag_message(viewer, dx, dy, moves, seq):
    sent = []
    viewer.drag_image.send = sent.append
    viewer.drag_image._on_message(
        viewer.drag_image, {"event": "drag", "dx": dx, "dy": dy, "moves": moves, "seq": seq}
    )
    return sent


def test_coalesced_drag_messages_reach_the_camera_and_frame_of_the_separate_moves():
    moves = [(10, 0), (15, 5), (-3, 2), (7, -4)]
    one_by_one = tessera.widget(tessera.from_array(box_volume()), size=64)
    cam = one_by_one.session.settings["camera"]
    for seq, (dx, dy) in enumerate(moves, 1):
        assert drag_message(one_by_one, dx, dy, 1, seq) == [{"event": "frame", "seq": seq}]
    coalesced = tessera.widget(tessera.from_array(box_volume()), size=64)
    total = (sum(m[0] for m in moves), sum(m[1] for m in moves))
    assert drag_message(coalesced, *total, len(moves), 1) == [{"event": "frame", "seq": 1}]
    az, el = camera_after(cam["azimuth"], cam["elevation"], moves)
    for v in (one_by_one, coalesced):
        got = v.session.settings["camera"]
        assert (got["azimuth"], got["elevation"]) == pytest.approx((az, el), abs=1e-9)
        assert v.drag_moves == len(moves)
    assert (one_by_one.drags, coalesced.drags) == (4, 1)
    assert np.array_equal(png_pixels(one_by_one.image.value), png_pixels(coalesced.image.value))


def test_frames_go_to_the_drag_view_once_it_is_on_the_page_and_the_sliders_still_rotate():
    v = tessera.widget(tessera.from_array(box_volume()), size=64)
    assert v.drag_image.layout.display == "none" and v.image.layout.display != "none"
    v.drag_image._on_message(v.drag_image, {"event": "ready"})
    assert v.drag_image.layout.display is None and v.image.layout.display == "none"
    shown = v.drag_image._b64value
    v.azimuth.value = 40
    assert v.drag_image._b64value != shown
    s = tessera.Session(tessera.from_array(box_volume()), azimuth=40)
    import base64

    assert np.array_equal(png_pixels(base64.b64decode(v.drag_image._b64value)), s.render(64, 64))
    assert "define('tessera-drag'" in tessera.drag_view.JAVASCRIPT


def test_session_orbit_wraps_the_azimuth_and_keeps_the_elevation_inside_89_degrees():
    s = tessera.Session(tessera.from_array(box_volume()), azimuth=170, elevation=80)
    s.orbit(-50, 30)  # the eye goes left by -20 degrees: 190 is -170; 80 + 12 stops at 89
    assert (s.azimuth, s.elevation) == pytest.approx((-170.0, 89.0), abs=1e-9)
    assert (s.azimuth, s.elevation) == pytest.approx(camera_after(170, 80, [(-50, 30)]), abs=1e-9)
