"""The widget's draggable frame: an ipywidgets DOMWidget whose front end is a
small requirejs module, the way ipywidgets 6 documents custom widgets for the
classic notebook (Debian 12: python3-ipywidgets 6.0, notebook 6.4; no
ipyevents, ipycanvas or anywidget).

The page shows the frame (``_b64value``, as ``ipywidgets.Image`` keeps it)
and sends pointer drags to the kernel as custom messages
``{"event": "drag", "dx", "dy", "moves", "seq"}`` (pixels, y down). At most
one drag is in flight: moves made while the kernel draws are summed into the
next message (``moves`` counts them), sent when the kernel answers
``{"event": "frame", "seq"}`` after the new frame. The view says
``{"event": "ready"}`` when it is on the page (and keeps the last 100
round trips, drag sent to answer received, in ms on the image element as
``roundTripsMs``); where the module cannot load
(JupyterLab, a headless nbclient run) it never does, and the viewer keeps
its plain ``ipywidgets.Image`` and sliders.

The JavaScript is text here rather than a .js file so that it travels with
the package's .py files (the CMake link step and setup.py copy those)."""
from __future__ import annotations

import base64
from typing import Any, Callable, List, Optional

import ipywidgets as widgets
from traitlets import CUnicode, Unicode

MODULE = "tessera-drag"

# Guarded so that a front end without requirejs (JupyterLab renders the
# output but has no define) shows nothing instead of an error.
JAVASCRIPT = r"""
if (typeof define === 'function' && define.amd) {
  if (typeof require !== 'undefined' && require.undef) require.undef('%(module)s');
  define('%(module)s', ['jupyter-js-widgets'], function (widgets) {
    var DragImageView = widgets.DOMWidgetView.extend({
      render: function () {
        var img = this.img = document.createElement('img');
        img.className = 'tessera-drag';
        img.draggable = false;
        img.style.cursor = 'grab';
        img.style.touchAction = 'none';
        img.style.userSelect = 'none';
        this.el.appendChild(img);
        this.pending = { dx: 0, dy: 0, moves: 0 };
        this.seq = 0;
        this.inFlight = false;
        this.from = null;
        this.showFrame();
        this.model.on('change:_b64value change:format change:width change:height',
                      this.showFrame, this);
        this.model.on('msg:custom', this.onMessage, this);
        var self = this;
        img.addEventListener('pointerdown', function (e) {
          if (e.button !== 0) return;
          img.setPointerCapture(e.pointerId);
          self.from = [e.clientX, e.clientY];
          img.style.cursor = 'grabbing';
          e.preventDefault();
        });
        img.addEventListener('pointermove', function (e) {
          if (!self.from) return;
          self.pending.dx += e.clientX - self.from[0];
          self.pending.dy += e.clientY - self.from[1];
          self.pending.moves += 1;
          self.from = [e.clientX, e.clientY];
          self.flush();
        });
        var end = function () { self.from = null; img.style.cursor = 'grab'; };
        img.addEventListener('pointerup', end);
        img.addEventListener('pointercancel', end);
        this.send({ event: 'ready' });
      },
      showFrame: function () {
        var w = this.model.get('width'), h = this.model.get('height');
        if (w) this.img.width = w;
        if (h) this.img.height = h;
        var b64 = this.model.get('_b64value');
        if (b64) this.img.src = 'data:image/' + this.model.get('format') + ';base64,' + b64;
      },
      // One drag in flight: the rest waits in `pending` for the answer.
      flush: function () {
        var p = this.pending;
        if (this.inFlight || (p.dx === 0 && p.dy === 0)) return;
        this.inFlight = true;
        this.seq += 1;
        this.send({ event: 'drag', dx: p.dx, dy: p.dy, moves: p.moves, seq: this.seq });
        this.sentAt = performance.now();
        this.pending = { dx: 0, dy: 0, moves: 0 };
        var self = this, seq = this.seq;
        // A kernel that never answers (an error, a restart) must not stop the drag.
        setTimeout(function () {
          if (self.seq === seq && self.inFlight) { self.inFlight = false; self.flush(); }
        }, 5000);
      },
      onMessage: function (content) {
        if (content.event === 'frame' && content.seq === this.seq) {
          // What a drag costs seen from the page (message out, frame and answer in).
          var trips = this.img.roundTripsMs = this.img.roundTripsMs || [];
          trips.push(performance.now() - this.sentAt);
          if (trips.length > 100) trips.shift();
          this.inFlight = false;
          this.flush();
        }
      }
    });
    return { DragImageView: DragImageView };
  });
}
""" % {"module": MODULE}


class DragImage(widgets.DOMWidget):
    """The frame, draggable. Its model is ipywidgets' own DOMWidgetModel (so
    that a front end without the view module still makes the model and the
    rest of the widget shows); its view is DragImageView of ``tessera-drag``.
    ``on_drag(dx, dy, moves)`` is called per drag message and returns once
    the new frame is set; ``ready`` is True once a view said it is on the
    page."""

    _view_name = Unicode("DragImageView").tag(sync=True)
    _view_module = Unicode(MODULE).tag(sync=True)
    format = Unicode("png").tag(sync=True)
    width = CUnicode().tag(sync=True)
    height = CUnicode().tag(sync=True)
    _b64value = Unicode().tag(sync=True)

    def __init__(self, **kwargs: Any):
        super().__init__(**kwargs)
        self.ready = False
        self.drag_handlers: List[Callable[[float, float, int], None]] = []
        self.ready_handlers: List[Callable[[], None]] = []
        self.on_msg(self._on_message)

    def set_frame(self, data: bytes, fmt: Optional[str] = None) -> None:
        if fmt:
            self.format = fmt
        self._b64value = base64.b64encode(data).decode("ascii")

    def _on_message(self, _widget: Any, content: dict, _buffers: Any = None) -> None:
        event = content.get("event")
        if event == "ready":
            self.ready = True
            for f in self.ready_handlers:
                f()
        elif event == "drag":
            try:
                for f in self.drag_handlers:
                    f(float(content.get("dx", 0)), float(content.get("dy", 0)),
                      int(content.get("moves", 1)))
            finally:
                # The answer frees the page's next (coalesced) drag.
                self.send({"event": "frame", "seq": content.get("seq")})


def javascript() -> Any:
    """The view's module, as an IPython display object (shown before the
    widget so that requirejs knows ``tessera-drag`` when the view is made)."""
    from IPython.display import Javascript

    return Javascript(JAVASCRIPT)
