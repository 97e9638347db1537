"""Tessera from Python: render volumes (numpy arrays, files, DICOM folders,
OME-Zarr stores and URLs) headless, images back as numpy arrays.

    import tessera
    s = tessera.Session(tessera.open("/usr/share/mricron/templates/ch2.nii.gz"),
                        tf="ct-bone", shade=True)
    rgba = s.render(512, 512, azimuth=60)      # (512, 512, 4) uint8

The module wraps the library's ``session::Session``: every setting is checked
by the library (one range, one message), every frame is its frame. See
docs/python.md.

Errors: bad input raises :class:`InputError` (a ``ValueError``), a file,
folder or URL that cannot be read or written :class:`StorageError` (an
``OSError``), a host or GPU budget :class:`BudgetError` (a ``MemoryError``),
the GL driver :class:`GpuError` (a ``RuntimeError``); each carries the
library's message.

Threads: the GIL is released while a session renders and while volumes are
read. A :class:`Session` belongs to the thread that made it (its GL context
is current there): a call from another thread raises :class:`GpuError`;
sessions made on different threads render in parallel, and calls to one
session are serialised. :class:`Volume` objects are immutable once made and
may be shared between threads and sessions.
"""
from __future__ import annotations

import errno as _errno
import json as _json
import os as _os
import struct as _struct
import zlib as _zlib
from typing import Any, Dict, Optional, Sequence, Tuple, Union

import numpy as _np


def _load_native():
    """The extension: installed beside this file (pip install .), or built by
    CMake into BUILD/python/tessera (a source checkout with PYTHONPATH=python;
    BUILD is $TESSERA_BUILD_DIR or the checkout's build/)."""
    try:
        from . import _tessera  # noqa: F401

        return _tessera
    except ImportError:
        here = _os.path.dirname(_os.path.abspath(__file__))
        build = _os.environ.get("TESSERA_BUILD_DIR") or _os.path.join(here, "..", "..", "build")
        candidate = _os.path.normpath(_os.path.join(build, "python", "tessera"))
        if not _os.path.isdir(candidate):
            raise ImportError(
                "tessera: the native module _tessera is neither installed beside "
                f"{here} nor built in {candidate}; build it (scripts/build.sh, CMake "
                "option TESSERA_PYTHON) or `pip install .` (docs/python.md)"
            ) from None
        __path__.append(candidate)  # type: ignore[name-defined]
        from . import _tessera  # noqa: F811

        return _tessera


_tessera = _load_native()

InputError = _tessera.InputError
BudgetError = _tessera.BudgetError
GpuError = _tessera.GpuError
Error = _tessera.Error


class StorageError(OSError):
    """A file, folder or URL could not be read or written (the library's
    message; ``filename`` names it)."""


__all__ = [
    "open",
    "from_array",
    "Session",
    "Volume",
    "info",
    "convert",
    "tf",
    "tf_presets",
    "widget",
    "InputError",
    "StorageError",
    "BudgetError",
    "GpuError",
    "Error",
]

PathLike = Union[str, "_os.PathLike[str]"]


def _is_remote(spec: str) -> bool:
    return spec.startswith(("http://", "https://"))


def _is_generated(spec: str) -> bool:
    return spec.startswith(("gen:", "head:"))


def _storage_error(err: Exception, spec: str, writing: bool = False) -> Optional[StorageError]:
    """The library's InputError as a StorageError when the path is what failed:
    it does not exist (reading), its folder cannot be written (writing), or a
    URL could not be fetched."""
    msg = str(err)
    if not spec or _is_generated(spec):
        return None
    if _is_remote(spec):
        e = StorageError(_errno.EIO, msg)
    elif writing:
        parent = _os.path.dirname(_os.path.abspath(spec))
        if _os.path.isdir(parent) and _os.access(parent, _os.W_OK):
            return None
        e = StorageError(_errno.EACCES if _os.path.isdir(parent) else _errno.ENOENT, msg)
    elif not _os.path.exists(spec):
        e = StorageError(_errno.ENOENT, msg)
    elif not _os.access(spec, _os.R_OK):
        e = StorageError(_errno.EACCES, msg)
    else:
        return None
    e.filename = spec
    return e


def _reraising(spec: str, call, *args, writing: bool = False):
    try:
        return call(*args)
    except InputError as err:
        io = _storage_error(err, spec, writing)
        if io is None:
            raise
        raise io from None


class Volume:
    """A volume: a file, DICOM folder, OME-Zarr store or URL (read lazily: by
    the session that renders it, or by :meth:`load`), or voxels in memory (a
    numpy array borrowed without a copy, see :func:`from_array`).

    Geometry is the storage's: ``dims`` (x fastest in memory), ``affine``
    mapping storage indices (x, y, z) to RAS+ millimetres. Immutable once made
    and safe to share between threads and sessions."""

    __slots__ = ("_handle", "_array", "_storage_axis", "copied")

    def __init__(self, handle, array=None, copied=False, storage_axis=(0, 1, 2)):
        self._handle = handle
        self._array = array
        self._storage_axis = tuple(storage_axis)  # the storage axis of each index axis
        self.copied = copied

    @property
    def spec(self) -> str:
        """The path, URL or generator it was opened from ('' for an array)."""
        return self._handle.spec

    @property
    def name(self) -> str:
        return self._handle.name

    @property
    def in_core(self) -> bool:
        """Its voxels are in memory (an array, or a file after :meth:`load`)."""
        return self._handle.in_core

    def load(self) -> "Volume":
        """Reads the voxels in core (the GIL released); returns self."""
        _reraising(self.spec, self._handle.load)
        return self

    @property
    def dims(self) -> Tuple[int, int, int]:
        """Storage dims (x, y, z), x fastest in memory (reads the volume)."""
        return _reraising(self.spec, lambda: self._handle.dims)

    @property
    def shape(self) -> Tuple[int, int, int]:
        """The dims in the index order the volume was given in: an array's
        shape; a file's storage dims."""
        d = self.dims
        return tuple(d[a] for a in self._storage_axis)

    @property
    def dtype(self) -> str:
        """'u8', 'u16', 'i16' or 'f32'."""
        return _reraising(self.spec, lambda: self._handle.dtype)

    @property
    def affine(self) -> _np.ndarray:
        """4x4 storage index (x, y, z) -> RAS+ mm."""
        return _np.array(_reraising(self.spec, lambda: self._handle.affine))

    @property
    def voxel_address(self) -> int:
        """Address of the first voxel in memory: for an array passed without a
        copy, the array's own data pointer."""
        return _reraising(self.spec, lambda: self._handle.voxel_address)

    @property
    def borrowed(self) -> bool:
        """The voxels are a numpy array's memory, not a copy."""
        return self._handle.borrowed

    def __repr__(self) -> str:
        if self.in_core:
            return f"tessera.Volume({self.name!r}, dims={self.dims}, dtype={self.dtype!r})"
        return f"tessera.Volume({self.spec!r}, not read yet)"


def open(  # noqa: A001 - the module's verb, as in tessera.open(path)
    path_or_url: PathLike,
    *,
    series: Optional[str] = None,
    channel: Optional[int] = None,
    time: Optional[int] = None,
) -> Volume:
    """A file (NIfTI, NRRD, MetaImage, VTI, PVM, raw+JSON), DICOM folder,
    OME-Zarr store (folder or http(s) URL) or generated volume
    ('gen:shepp-logan:128', 'head:1024x1024x512'). Lazy: nothing is read
    until a session renders it (a store too large for the device streams
    brick by brick) or :meth:`Volume.load`. ``series``: a DICOM Series
    Instance UID; ``time``, ``channel``: an OME-Zarr store's."""
    spec = _os.fspath(path_or_url)
    return Volume(_tessera.open_spec(spec, series or "", int(time or 0), int(channel or 0)))


_DTYPES = {"uint8": "u8", "uint16": "u16", "int16": "i16", "float32": "f32"}
# q (array index order z, y, x) -> (x, y, z), and storage order reversal.
_REVERSE = _np.array([[0, 0, 1, 0], [0, 1, 0, 0], [1, 0, 0, 0], [0, 0, 0, 1]], dtype=float)


def from_array(
    a: Any,
    *,
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    affine: Optional[Any] = None,
    window: Optional[Tuple[float, float]] = None,
    axes: str = "ijk",
    name: str = "array",
) -> Volume:
    """A 3D numpy array as a volume, **without a copy** when it is C- or
    Fortran-contiguous in native byte order (the volume's voxels are the
    array's memory; the array is kept alive by the volume, and must not be
    resized; writing to it changes what later renders show).

    dtypes: uint8, uint16, int16, float32 (others: InputError naming the
    dtype; convert with ``a.astype(numpy.float32)``). A non-contiguous or
    byte-swapped array is copied once (``volume.copied`` is then True).

    ``axes="ijk"`` (default, nibabel's convention): ``a[i, j, k]`` is voxel
    (i, j, k) and ``affine`` maps (i, j, k, 1) to RAS+ mm (default:
    ``diag(spacing)``, spacing per array axis). ``axes="zyx"`` (zarr's and
    tifffile's order): ``a[z, y, x]``, ``spacing`` given per array axis
    (z, y, x), ``affine`` mapping (x, y, z, 1) to RAS+ mm.

    ``window``: raw values (lo, hi) mapped to the transfer function's [0, 1]
    (default: the value range)."""
    arr = _np.asarray(a)
    if arr.ndim != 3:
        raise InputError(f"{name}: expected a 3D array, got shape {arr.shape}")
    base = arr.dtype.newbyteorder("=") if arr.dtype.byteorder not in "=|" else arr.dtype
    kind = _DTYPES.get(base.name)
    if kind is None:
        raise InputError(
            f"{name}: dtype {arr.dtype} is not rendered; Tessera takes uint8, uint16, int16 "
            "and float32 (convert with a.astype(numpy.float32))"
        )
    if axes not in ("ijk", "zyx"):
        raise InputError(f"{name}: axes {axes!r}: expected 'ijk' (nibabel) or 'zyx' (zarr)")
    copied = False
    if not arr.dtype.isnative:
        arr = arr.astype(base)
        copied = True
    if not (arr.flags.c_contiguous or arr.flags.f_contiguous):
        arr = _np.ascontiguousarray(arr)
        copied = True
    sp = [float(s) for s in spacing]
    if len(sp) != 3:
        raise InputError(f"{name}: spacing {tuple(spacing)}: expected 3 numbers")
    if affine is None:
        user = _np.diag(sp[::-1] + [1.0]) if axes == "zyx" else _np.diag(sp + [1.0])
    else:
        if tuple(sp) != (1.0, 1.0, 1.0):
            raise InputError(f"{name}: give spacing or affine, not both (the affine holds it)")
        user = _np.asarray(affine, dtype=float)
        if user.shape != (4, 4):
            raise InputError(f"{name}: affine of shape {user.shape}: expected 4x4")
    # Array index order q -> world; then storage index t -> world: C order
    # stores the last array axis fastest (t = reversed q), Fortran the first.
    per_q = user @ _REVERSE if axes == "zyx" else user
    if arr.flags.c_contiguous:
        storage = per_q @ _REVERSE
        dims = tuple(int(n) for n in arr.shape[::-1])
    else:
        storage = per_q
        dims = tuple(int(n) for n in arr.shape)
    handle = _tessera.borrow_array(arr, dims, kind, storage.tolist(), name)
    if window is not None:
        lo, hi = window
        handle.set_window(float(lo), float(hi))
    return Volume(handle, arr, copied, (2, 1, 0) if arr.flags.c_contiguous else (0, 1, 2))


def _as_volume(x: Any) -> Volume:
    if isinstance(x, Volume):
        return x
    if isinstance(x, Session):
        return x.volume
    if isinstance(x, _np.ndarray):
        return from_array(x)
    if isinstance(x, (str, _os.PathLike)):
        return open(x)
    raise InputError(f"expected a path, URL, numpy array or tessera.Volume, got {type(x).__name__}")


def tf(spec: Union[str, Dict[str, Any]]) -> Dict[str, Any]:
    """A transfer function as the library's JSON dict, checked by it: a preset
    name (:func:`tf_presets`), a JSON file, JSON text or a dict
    ``{"name": "red", "color": [{"x": 0, "rgb": [1, 0, 0]}, ...],
    "opacity": [{"x": 0, "alpha": 0}, {"x": 1, "alpha": 0.5}, ...]}``
    (x in [0, 1] over the window)."""
    if isinstance(spec, dict):
        spec = _json.dumps(spec)
    return _json.loads(_tessera.tf_json(str(spec)))


def tf_presets() -> list:
    """The built-in transfer functions' names."""
    return list(_tessera.tf_presets())


def info(x: Any) -> Dict[str, Any]:
    """What ``tessera info --json`` prints, as a dict: dims, spacing, affine,
    type, value range, percentiles, bytes, a store's levels, a DICOM folder's
    series. ``x``: a path or URL, a :class:`Volume`, an array or a session."""
    v = _as_volume(x)
    return _json.loads(_reraising(v.spec, _tessera.info, v._handle))


def convert(
    src: Any,
    dst: PathLike,
    *,
    chunks: Union[int, Sequence[int]] = 64,
    levels: Union[str, int] = "auto",
    compressor: str = "zstd",
    crop: Optional[Sequence[Sequence[int]]] = None,
    downsample: Union[None, int, Sequence[int]] = None,
    zarr_format: int = 2,
    shard: int = 0,
    pyramid_factors: Sequence[int] = (2, 2, 2),
) -> list:
    """Writes ``src`` (a path, URL, :class:`Volume` or array) to ``dst`` in the
    format its name says (``.nii.gz``, ``.nrrd``, ``.mha``, ``.ome.zarr``…),
    as ``tessera convert`` does, with the same options:

    - ``crop``: ``((x0, x1), (y0, y1), (z0, z1))`` voxels to keep, ends
      exclusive (``--crop x0:x1,y0:y1,z0:z1``);
    - ``downsample``: a box-filter factor N or ``(a, b, c)`` per x, y, z
      (``--downsample``), after the crop;
    - OME-Zarr output: ``chunks`` (64, 128 or ``(z, y, x)``), ``levels``
      (``"auto"`` or a count), ``compressor`` (zstd, blosc, zlib, none),
      ``zarr_format`` (2: NGFF 0.4; 3: NGFF 0.5), ``shard`` (chunks per
      shard edge with ``zarr_format=3``) and ``pyramid_factors`` (each
      level's factor against the one before, ``(z, y, x)``, each 1 or 2:
      ``(1, 2, 2)`` keeps z, as microscopy pyramids do;
      ``--pyramid-factors``).

    Returns what the format could not hold (notes). Bad options raise
    :class:`InputError` naming the option as the CLI spells it."""
    v = _as_volume(src)
    out = _os.fspath(dst)
    chunk = str(chunks) if isinstance(chunks, int) else ",".join(str(int(c)) for c in chunks)
    crop_text = ""
    if crop is not None:
        try:
            crop_text = ",".join(f"{int(a)}:{int(b)}" for a, b in crop)
        except (TypeError, ValueError):
            raise InputError(f"crop {crop!r}: expected ((x0, x1), (y0, y1), (z0, z1))") from None
    if downsample is None:
        factors = ""
    elif isinstance(downsample, int):
        factors = str(downsample)
    else:
        factors = "x".join(str(int(f)) for f in downsample)
    _reraising(v.spec, v._handle.load)
    return list(
        _reraising(out, _tessera.convert, v._handle, out, chunk, str(levels), compressor,
                   crop_text, factors, int(zarr_format), int(shard),
                   ",".join(str(int(f)) for f in pyramid_factors), writing=True)
    )


_CAMERA_KEYS = ("azimuth", "elevation", "zoom", "fov", "projection", "target")


def _merge(into: dict, patch: dict) -> None:
    for k, v in patch.items():
        if isinstance(v, dict) and isinstance(into.get(k), dict):
            _merge(into[k], v)
        else:
            into[k] = v


def _apply_setting(j: dict, key: str, value: Any) -> None:
    """One keyword argument into the settings' JSON (session::Settings)."""
    if key == "tf":
        j["tf"] = tf(value)
    elif key == "window":
        j["window"] = None if value is None else [float(value[0]), float(value[1])]
    elif key == "camera":
        _merge(j["camera"], dict(value))
    elif key in _CAMERA_KEYS:
        j["camera"][key] = value
    elif key == "ortho":
        j["camera"]["projection"] = "orthographic" if value else "perspective"
    elif key == "shade":
        if isinstance(value, dict):
            _merge(j["shading"], value)
        else:
            j["shading"]["enabled"] = bool(value)
    elif key == "clip":
        if isinstance(value, dict):
            _merge(j["clipping"], value)
        else:
            j["clipping"]["planes"] = list(value)
    elif key in j and key != "version":
        if isinstance(value, dict) and isinstance(j[key], dict):
            _merge(j[key], value)
        else:
            j[key] = value
    else:
        names = sorted(k for k in j if k != "version")
        raise InputError(
            f"setting {key!r} is unknown; settings: tf, window, camera ({', '.join(_CAMERA_KEYS)}"
            f", ortho), step, shade, clip, mode, labels, region, {', '.join(names)}"
        )


def _png(rgba: _np.ndarray, level: int = 6) -> bytes:
    """An 8-bit RGBA PNG of an (H, W, 4) array (no imaging library needed);
    ``level``: zlib's (1 is twice as fast as 6 for a frame, 40 % larger)."""
    h, w, _ = rgba.shape
    raw = b"".join(b"\x00" + rgba[y].tobytes() for y in range(h))

    def chunk(tag: bytes, data: bytes) -> bytes:
        c = _struct.pack(">I", len(data)) + tag + data
        return c + _struct.pack(">I", _zlib.crc32(tag + data) & 0xFFFFFFFF)

    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", _struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0))
        + chunk(b"IDAT", _zlib.compress(raw, level))
        + chunk(b"IEND", b"")
    )


class Session:
    """A rendering session (the library's ``session::Session``) on its own
    headless device (EGL; Mesa llvmpipe without a GPU).

    ``volume``: a :class:`Volume`, a path/URL or a numpy array.
    ``profile``: a device profile name or JSON file ('native', 'webgl1',
    'ipad2', ...). ``layout`` ('auto', 'texture3d', 'mosaic', 'bricks', ...)
    and ``technique`` ('raycast', 'slice3d', 'slice2d') are wishes the
    planner honours. ``region`` ('x0:x1,y0:y1,z0:z1') and ``level`` render one
    box of a file or store's level (read as one box).

    Settings, as keyword arguments, with :meth:`update` or as properties,
    all checked by the library (session::Settings: one range, one message):

    - ``tf``: preset name, JSON file/text or dict (:func:`tf`);
    - ``window``: (lo, hi) raw values, or None for the volume's own;
    - ``camera``: dict of azimuth, elevation (degrees; azimuth 0 looks at
      the face), zoom, fov, projection ('perspective'/'orthographic'),
      target; or those keys directly, and ``ortho=True``;
    - ``step``: sample distance in voxels, in (0, 8];
    - ``shade``: bool, or a dict of shading (enabled, ambient, diffuse,
      specular, shininess, headlight, light_direction, gradient_opacity…);
    - ``clip``: dict of clipping (planes, crop_min, crop_max), or a list of
      planes;
    - ``mode``: 'composite', 'mip', 'minip', 'average';
    - ``labels``: True renders a label volume (nearest, categorical colours);
    - and the rest of the schema: background, max_steps, opacity_scale, ert,
      jitter, sampling, skip_block, lut, slices, classify, gradient.

    Threads: a session is used from the thread that made it (another
    thread's call raises GpuError; make one session per thread, they render
    in parallel); the GIL is released while it renders or reads."""

    def __init__(
        self,
        volume: Any,
        *,
        profile: Optional[str] = None,
        layout: str = "auto",
        technique: str = "raycast",
        region: Optional[str] = None,
        level: Optional[Union[str, int]] = None,
        **settings: Any,
    ):
        self._volume = _as_volume(volume)
        self._core = _tessera.SessionCore(profile or "native")
        # No tf given: the volume's modality picks it (CT ct-soft-tissue over
        # its HU window, MR mr-percentile), as `tessera render` does.
        self._tf_default = "tf" not in settings
        self.update(layout=layout, technique=technique, **settings)
        _reraising(
            self._volume.spec,
            self._core.open,
            self._volume._handle,
            region or "",
            "" if level is None else str(level),
        )

    @property
    def volume(self) -> Volume:
        return self._volume

    @property
    def settings(self) -> Dict[str, Any]:
        """Every setting as the session's JSON (what state files hold)."""
        return _json.loads(self._core.settings())

    def update(self, **settings: Any) -> "Session":
        """Changes settings (keyword arguments as in the class docstring);
        all or none: on an InputError the session keeps its settings."""
        j = self.settings
        for key, value in settings.items():
            _apply_setting(j, key, value)
        tf_default = getattr(self, "_tf_default", False) and "tf" not in settings
        self._core.set_settings(_json.dumps(j), tf_default)
        self._tf_default = tf_default
        return self

    @property
    def default_note(self) -> str:
        """What the session chose because no ``tf`` was given ("CT: default
        transfer function ct-soft-tissue (modality CT), window -160..240 HU
        of the preset; ..."), or a note on the ``tf`` given; "" when none."""
        return self._core.default_note

    def state(self) -> Dict[str, Any]:
        """The session's state (version, volume, settings), as `tessera render
        --save-state` writes it."""
        return _json.loads(self._core.state())

    def render(self, width: int = 512, height: int = 512, **camera: Any) -> _np.ndarray:
        """A frame, (height, width, 4) uint8 RGBA, row 0 at the top. Camera
        keywords (azimuth, elevation, zoom, fov, ortho…) update the
        session's camera first."""
        if camera:
            self.update(**camera)
        return self._core.render(int(width), int(height))

    def run(
        self,
        width: int = 512,
        height: int = 512,
        *,
        repeat: int = 1,
        rotate: float = 0.0,
        reference: bool = False,
    ) -> Tuple[_np.ndarray, Dict[str, Any]]:
        """A run as ``tessera render --repeat N --rotate D [--reference]``
        makes it: the volume uploaded once, ``repeat`` frames rotating by
        ``rotate`` degrees. Returns the first frame and what the run measured
        (frame_ms, prepare_ms, layout, texture_bytes, psnr_db and ssim against
        the CPU reference)."""
        image, report = self._core.run(int(width), int(height), int(repeat), float(rotate),
                                       bool(reference))
        return image, dict(report)

    def render_reference(self, width: int = 256, height: int = 256, **camera: Any) -> _np.ndarray:
        """The double-precision CPU reference of the same view (slow; in-core
        volumes only), (height, width, 4) uint8."""
        if camera:
            self.update(**camera)
        return self._core.render_reference(int(width), int(height))

    def orbit(self, dx: float, dy: float) -> "Session":
        """Turns the camera as a pointer drag of (dx, dy) pixels (y down) on
        the frame does in the viewers (viewer::CameraController: azimuth
        -= dx * orbit_degrees_per_pixel, elevation += dy * it, clamped to
        +-89)."""
        self._core.orbit(float(dx), float(dy))
        return self

    def slice(
        self,
        axis: int,
        index: Optional[int] = None,
        *,
        window: Optional[Tuple[float, float]] = None,
        tf: Optional[Union[str, Dict[str, Any]]] = None,
    ) -> _np.ndarray:
        """Slice ``index`` (default: the middle) normal to index axis
        ``axis`` (0, 1, 2 in the order the volume was given: an array's axes,
        ``a[:, :, index]`` for axis 2; a file's storage axes), as `tessera
        slice` draws it (nearest voxel, radiological convention, square
        pixels): (H, W) uint8 grey over ``window``, or (H, W, 4) RGBA in the
        colours of ``tf``."""
        storage = self._volume._storage_axis[axis] if axis in (0, 1, 2) else axis
        if index is None:
            index = self._volume.shape[axis] // 2 if axis in (0, 1, 2) else 0
        w = None if window is None else (float(window[0]), float(window[1]))
        tf_text = "" if tf is None else _json.dumps(globals()["tf"](tf))
        img = self._core.slice(int(storage), int(index), w, tf_text)
        return img if tf is not None else img[:, :, 0]

    def _repr_png_(self) -> bytes:
        return _png(self.render(512, 512))

    def __repr__(self) -> str:
        return f"tessera.Session({self._core.volume_name!r}, device {self._core.device})"


def _settings_property(key: str, doc: str):
    def get(self):
        j = self.settings
        if key in _CAMERA_KEYS:
            return j["camera"][key]
        return {"shade": j["shading"], "clip": j["clipping"], "step": j.get("step")}.get(
            key, j.get(key)
        )

    def put(self, value):
        self.update(**{key: value})

    return property(get, put, doc=doc)


for _key, _doc in {
    "tf": "The transfer function (JSON dict); set a preset name, file, JSON or dict.",
    "window": "Raw values (lo, hi) mapped to the TF, or None (the volume's own).",
    "camera": "The camera dict (azimuth, elevation, zoom, fov, projection, target).",
    "step": "Sample distance in voxels, (0, 8].",
    "shade": "Shading dict; set True/False or a dict.",
    "clip": "Clipping dict (planes, crop_min, crop_max).",
    "mode": "'composite', 'mip', 'minip' or 'average'.",
    "labels": "A label volume (nearest sampling, categorical colours).",
    "technique": "'raycast', 'slice3d' or 'slice2d'.",
    "layout": "The layout wish ('auto' lets the planner choose).",
    "azimuth": "Camera azimuth in degrees (0: looking at the face).",
    "elevation": "Camera elevation in degrees (90: from superior).",
    "zoom": "Camera zoom (>1 magnifies).",
}.items():
    setattr(Session, _key, _settings_property(_key, _doc))


def widget(volume: Any, **settings: Any):
    """An ipywidgets viewer rendering on the kernel side (tessera/widget.py):
    drag on the frame or move the sliders to rotate."""
    from .widget import Viewer

    return Viewer(volume, **settings)
