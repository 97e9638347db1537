# Type hints of the package `tessera` (python/tessera/__init__.py).
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from ._tessera import BudgetError as BudgetError
from ._tessera import Error as Error
from ._tessera import GpuError as GpuError
from ._tessera import InputError as InputError

PathLike = Union[str, os.PathLike[str]]
TFSpec = Union[str, Dict[str, Any]]

class StorageError(OSError): ...

class Volume:
    copied: bool
    @property
    def spec(self) -> str: ...
    @property
    def name(self) -> str: ...
    @property
    def in_core(self) -> bool: ...
    def load(self) -> Volume: ...
    @property
    def dims(self) -> Tuple[int, int, int]: ...
    @property
    def shape(self) -> Tuple[int, int, int]: ...
    @property
    def dtype(self) -> str: ...
    @property
    def affine(self) -> np.ndarray: ...
    @property
    def voxel_address(self) -> int: ...
    @property
    def borrowed(self) -> bool: ...

def open(
    path_or_url: PathLike,
    *,
    series: Optional[str] = ...,
    channel: Optional[int] = ...,
    time: Optional[int] = ...,
) -> Volume: ...
def from_array(
    a: Any,
    *,
    spacing: Sequence[float] = ...,
    affine: Optional[Any] = ...,
    window: Optional[Tuple[float, float]] = ...,
    axes: str = ...,
    name: str = ...,
) -> Volume: ...
def tf(spec: TFSpec) -> Dict[str, Any]: ...
def tf_presets() -> List[str]: ...
def info(x: Any) -> Dict[str, Any]: ...
def convert(
    src: Any,
    dst: PathLike,
    *,
    chunks: Union[int, Sequence[int]] = ...,
    levels: Union[str, int] = ...,
    compressor: str = ...,
    crop: Optional[Sequence[Sequence[int]]] = ...,
    downsample: Union[None, int, Sequence[int]] = ...,
    zarr_format: int = ...,
    shard: int = ...,
) -> List[str]: ...

class Session:
    tf: Dict[str, Any]
    window: Optional[Tuple[float, float]]
    camera: Dict[str, Any]
    step: float
    shade: Dict[str, Any]
    clip: Dict[str, Any]
    mode: str
    labels: bool
    technique: str
    layout: str
    azimuth: float
    elevation: float
    zoom: float
    def __init__(
        self,
        volume: Any,
        *,
        profile: Optional[str] = ...,
        layout: str = ...,
        technique: str = ...,
        region: Optional[str] = ...,
        level: Optional[Union[str, int]] = ...,
        **settings: Any,
    ) -> None: ...
    @property
    def volume(self) -> Volume: ...
    @property
    def settings(self) -> Dict[str, Any]: ...
    def update(self, **settings: Any) -> Session: ...
    @property
    def default_note(self) -> str: ...
    def state(self) -> Dict[str, Any]: ...
    def render(self, width: int = ..., height: int = ..., **camera: Any) -> np.ndarray: ...
    def run(
        self,
        width: int = ...,
        height: int = ...,
        *,
        repeat: int = ...,
        rotate: float = ...,
        reference: bool = ...,
    ) -> Tuple[np.ndarray, Dict[str, Any]]: ...
    def render_reference(self, width: int = ..., height: int = ..., **camera: Any) -> np.ndarray: ...
    def orbit(self, dx: float, dy: float) -> Session: ...
    def slice(
        self,
        axis: int,
        index: Optional[int] = ...,
        *,
        window: Optional[Tuple[float, float]] = ...,
        tf: Optional[TFSpec] = ...,
    ) -> np.ndarray: ...
    def _repr_png_(self) -> bytes: ...

def widget(volume: Any, **settings: Any) -> Any: ...
