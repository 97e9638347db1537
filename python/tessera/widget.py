"""tessera.widget(volume): a Jupyter viewer that renders on the kernel side.

The volume is rendered by a :class:`tessera.Session` in the kernel and each
frame is sent to the page as a PNG in an ``ipywidgets.Image``. Debian's
python3-ipywidgets (6.0) has no pointer events and ipyevents is not packaged,
so rotating is by azimuth/elevation sliders (``continuous_update``: every
slider step is a frame, as a drag would be); with ipyevents installed a drag
on the image rotates too. Controls: TF preset, window, shading, mode, and
three slice views (axial/coronal/sagittal storage axes) with index sliders.
"""
from __future__ import annotations

import time
from typing import Any, Optional

import ipywidgets as widgets

import tessera


class Viewer:
    """The widget (``viewer.widget`` is the ipywidgets box; a notebook cell
    showing the Viewer shows it). ``last_ms``: the last frame's round trip on
    the kernel side (render + PNG + hand-over to the widget)."""

    def __init__(self, volume: Any, *, size: int = 384, slice_size: int = 192, **settings: Any):
        self.session = tessera.Session(volume, **settings)
        self.size = int(size)
        self.last_ms = 0.0
        s = self.session.settings
        info = tessera.info(self.session.volume) if self.session.volume.in_core else None
        lo = info["value_min"] if info else 0.0
        hi = info["value_max"] if info else 1.0
        if hi <= lo:
            hi = lo + 1.0
        cam = s["camera"]
        slider = dict(continuous_update=True)
        self.azimuth = widgets.FloatSlider(
            value=cam["azimuth"], min=-180, max=180, step=2, description="azimuth", **slider
        )
        self.elevation = widgets.FloatSlider(
            value=cam["elevation"], min=-89, max=89, step=2, description="elevation", **slider
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
        self._attach_drag()
        controls = widgets.VBox(
            [self.azimuth, self.elevation, self.zoom, self.tf, self.window, self.shade, self.mode,
             self.status]
        )
        self.widget = widgets.VBox([widgets.HBox([self.image, controls]), widgets.HBox(boxes)])
        self.draw()
        for axis in range(len(self.slice_images)):
            self._draw_slice(axis)

    def _attach_drag(self) -> None:
        try:
            from ipyevents import Event  # optional; not packaged by Debian
        except ImportError:
            self._events = None
            return
        self._events = Event(source=self.image, watched_events=["drag", "mousemove"])
        self._drag_from: Optional[tuple] = None

        def on_event(e: dict) -> None:
            if e.get("type") == "mousemove" and e.get("buttons", 0) & 1:
                x, y = e["relativeX"], e["relativeY"]
                if self._drag_from is not None:
                    dx, dy = x - self._drag_from[0], y - self._drag_from[1]
                    self.azimuth.value = (self.azimuth.value - dx * 0.5 + 180) % 360 - 180
                    self.elevation.value = max(-89, min(89, self.elevation.value + dy * 0.5))
                self._drag_from = (x, y)
            else:
                self._drag_from = None

        self._events.on_dom_event(on_event)

    def draw(self) -> None:
        """Renders the current view into the image (the kernel-side round trip)."""
        t0 = time.perf_counter()
        frame = self.session.render(self.size, self.size)
        self.image.value = tessera._png(frame)
        self.last_ms = (time.perf_counter() - t0) * 1000.0
        self.status.value = f"{self.last_ms:.0f} ms per frame"

    def _draw_slice(self, axis: int) -> None:
        tf_name = self.tf.value
        img = self.session.slice(
            axis, self.slice_indices[axis].value, window=self.window.value, tf=tf_name
        )
        self.slice_images[axis].value = tessera._png(img)

    def _on_camera(self, change: dict) -> None:
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

        display(self.widget)
