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
