"""tessera.widget(volume): a Jupyter viewer that renders on the kernel side.

The volume is rendered by a :class:`tessera.Session` in the kernel and each
frame is sent to the page as a PNG. Dragging on the image rotates the view
(tessera/drag_view.py: a custom ipywidgets view for the classic notebook
that sends pointer drags, one in flight, the moves made meanwhile summed
into the next); the kernel turns each drag into an orbit through the
library's camera controller (``Session.orbit``, the desktop and web viewers'
``viewer::CameraController``: 0.4 degrees per pixel) and answers with the
new frame. The azimuth/elevation sliders follow the drag and rotate too;
where the drag view cannot load (JupyterLab, a headless nbclient run) the
viewer shows a plain ``ipywidgets.Image`` and the sliders. Controls: TF
preset, window, shading, mode, and three slice views (axial/coronal/sagittal
storage axes) with index sliders.
"""
from __future__ import annotations

import sys
import time
import types
from typing import Any

import ipywidgets as widgets

import tessera

from .drag_view import DragImage, javascript


class Viewer:
    """The widget (``viewer.widget`` is the ipywidgets box; a notebook cell
    showing the Viewer shows it). ``last_ms``: the last frame's round trip on
    the kernel side (render + PNG + hand-over to the widget);
    ``last_drag_ms``: the last drag's (orbit + sliders + frame); ``drags``
    and ``drag_moves``: drag messages handled and the pointer moves they
    carried (more moves than messages: coalesced while a frame was drawn)."""

    def __init__(self, volume: Any, *, size: int = 384, slice_size: int = 192, **settings: Any):
        self.session = tessera.Session(volume, **settings)
        self.size = int(size)
        self.last_ms = 0.0
        self.last_drag_ms = 0.0
        self.drags = 0
        self.drag_moves = 0
        self._syncing = False
        s = self.session.settings
        info = tessera.info(self.session.volume) if self.session.volume.in_core else None
        lo = info["value_min"] if info else 0.0
        hi = info["value_max"] if info else 1.0
        if hi <= lo:
            hi = lo + 1.0
        cam = s["camera"]
        # Steps of 0.1 degree: a drag sets the angles to tenths (0.4 per pixel).
        slider = dict(continuous_update=True)
        angle = dict(step=0.1, readout_format=".1f", **slider)
        self.azimuth = widgets.FloatSlider(
            value=cam["azimuth"], min=-180, max=180, description="azimuth", **angle
        )
        self.elevation = widgets.FloatSlider(
            value=cam["elevation"], min=-89, max=89, description="elevation", **angle
        )
        self.zoom = widgets.FloatSlider(
            value=cam["zoom"], min=0.25, max=8, step=0.05, description="zoom", **slider
        )
        presets = tessera.tf_presets()
        tf_name = s["tf"].get("name", presets[0]) if isinstance(s["tf"], dict) else s["tf"]
        self.tf = widgets.Dropdown(
            options=presets, value=tf_name if tf_name in presets else presets[0], description="tf"
        )
        self.window = widgets.FloatRangeSlider(
            value=tuple(s["window"]) if s["window"] else (lo, hi),
            min=lo,
            max=hi,
            step=(hi - lo) / 200.0,
            description="window",
            continuous_update=False,
        )
        self.shade = widgets.Checkbox(value=bool(s["shading"]["enabled"]), description="shade")
        self.mode = widgets.Dropdown(
            options=["composite", "mip", "minip", "average"], value=s["mode"], description="mode"
        )
        self.image = widgets.Image(format="png", width=self.size, height=self.size)
        # Hidden until its view says it is on the page; then it replaces the image.
        self.drag_image = DragImage(
            format="png", width=self.size, height=self.size, layout=widgets.Layout(display="none")
        )
        self.drag_image.drag_handlers.append(self.drag)
        self.drag_image.ready_handlers.append(self._on_drag_ready)
        self.status = widgets.Label(value="")
        for w in (self.azimuth, self.elevation, self.zoom):
            w.observe(self._on_camera, names="value")
        for w in (self.tf, self.window, self.shade, self.mode):
            w.observe(self._on_settings, names="value")

        self.slice_images = []
        self.slice_indices = []
        boxes = []
        dims = self.session.volume.shape if self.session.volume.in_core else None
        if dims is not None:
            for axis in range(3):
                idx = widgets.IntSlider(
                    value=dims[axis] // 2,
                    min=0,
                    max=dims[axis] - 1,
                    description=f"axis {axis}",
                    continuous_update=True,
                )
                img = widgets.Image(format="png", width=slice_size, height=slice_size)
                idx.observe(lambda change, a=axis: self._draw_slice(a), names="value")
                self.slice_indices.append(idx)
                self.slice_images.append(img)
                boxes.append(widgets.VBox([img, idx]))
        controls = widgets.VBox(
            [self.azimuth, self.elevation, self.zoom, self.tf, self.window, self.shade, self.mode,
             self.status]
        )
        frame = widgets.VBox([self.drag_image, self.image])
        self.widget = widgets.VBox([widgets.HBox([frame, controls]), widgets.HBox(boxes)])
        self.draw()
        for axis in range(len(self.slice_images)):
            self._draw_slice(axis)

    def _on_drag_ready(self) -> None:
        self.drag_image.layout.display = None
        self.image.layout.display = "none"
        self.draw()

    def drag(self, dx: float, dy: float, moves: int = 1) -> bytes:
        """A drag of (dx, dy) pixels on the image (y down; what the page
        sends, ``moves`` pointer moves summed): orbits the camera as the
        viewers do (``Session.orbit``), moves the sliders to it without a
        second frame, draws, and returns the frame's PNG."""
        t0 = time.perf_counter()
        self.session.orbit(dx, dy)
        cam = self.session.settings["camera"]
        self._syncing = True
        try:
            self.azimuth.value = cam["azimuth"]
            self.elevation.value = cam["elevation"]
        finally:
            self._syncing = False
        png = self.draw()
        self.drags += 1
        self.drag_moves += int(moves)
        self.last_drag_ms = (time.perf_counter() - t0) * 1000.0
        return png

    def draw(self) -> bytes:
        """Renders the current view into the image shown (the kernel-side
        round trip) and returns its PNG."""
        t0 = time.perf_counter()
        frame = self.session.render(self.size, self.size)
        png = tessera._png(frame, level=1)  # the frame's bytes cross a local socket
        if self.drag_image.ready:
            self.drag_image.set_frame(png)
        else:
            self.image.value = png
        self.last_ms = (time.perf_counter() - t0) * 1000.0
        self.status.value = f"{self.last_ms:.0f} ms per frame"
        return png

    def _draw_slice(self, axis: int) -> None:
        tf_name = self.tf.value
        img = self.session.slice(
            axis, self.slice_indices[axis].value, window=self.window.value, tf=tf_name
        )
        self.slice_images[axis].value = tessera._png(img)

    def _on_camera(self, change: dict) -> None:
        if self._syncing:
            return
        self.session.update(
            azimuth=self.azimuth.value, elevation=self.elevation.value, zoom=self.zoom.value
        )
        self.draw()

    def _on_settings(self, change: dict) -> None:
        try:
            self.session.update(
                tf=self.tf.value,
                window=self.window.value,
                shade=self.shade.value,
                mode=self.mode.value,
            )
        except tessera.InputError as e:
            self.status.value = str(e)
            return
        self.draw()
        for axis in range(len(self.slice_images)):
            self._draw_slice(axis)

    def _ipython_display_(self) -> None:
        from IPython.display import display

        display(javascript())
        display(self.widget)


class _CallableModule(types.ModuleType):
    """Importing this module binds it as ``tessera.widget`` over the
    package's function of that name (Python sets a package's attribute to
    each submodule it imports); calling the module does what the function
    does, so ``tessera.widget(volume)`` works before and after."""

    def __call__(self, volume: Any, **settings: Any) -> Viewer:
        return Viewer(volume, **settings)


sys.modules[__name__].__class__ = _CallableModule
