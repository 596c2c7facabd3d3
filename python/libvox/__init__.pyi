# Type stub of the libvox package (the compiled module libvox._libvox, re-exported). Kept in step with the binding by
# tests/python/test_stub.py, which compares every name, parameter and default here with the module's.
import os
from typing import Any, Callable, Iterable, Optional, Sequence, SupportsIndex, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

_Path = Union[str, bytes, os.PathLike]
_Array = npt.ArrayLike
_Source = Union[_Path, Tuple[_Array, _Array], Any]
_Progress = Union[bool, None, Callable[[float], None]]
# What the conversion layer takes (python/src/convert.h): an integer is anything with __index__ (numpy's too), a
# number any real number (numbers.Real); a bool is neither.
_Int = SupportsIndex
_Float = Union[float, int, np.floating, np.integer]

class InputError(ValueError): ...
class UsageError(ValueError): ...
class LimitError(MemoryError): ...

class Grid:
    @property
    def dims(self) -> Tuple[int, int, int]: ...
    @property
    def bounds(self) -> npt.NDArray[np.float64]: ...
    @property
    def pitch(self) -> npt.NDArray[np.float64]: ...
    @property
    def transform(self) -> npt.NDArray[np.float64]: ...
    @property
    def method(self) -> str: ...
    @property
    def occupied_count(self) -> int: ...
    @property
    def solid_count(self) -> int: ...
    @property
    def primitive_count(self) -> int: ...
    @property
    def indices(self) -> npt.NDArray[np.int32]: ...
    @property
    def fractions(self) -> npt.NDArray[np.float64]: ...
    @property
    def sdf(self) -> Tuple[npt.NDArray[np.int32], npt.NDArray[np.float64]]: ...
    @property
    def sdf_half_width(self) -> float: ...
    @property
    def solid_indices(self) -> npt.NDArray[np.int32]: ...
    def dense(self, solid: bool = True) -> npt.NDArray[np.bool_]: ...
    def distance(
        self, points: _Array, signed: bool = True, threads: Optional[_Int] = None
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], npt.NDArray[np.float64]]: ...
    @property
    def points(self) -> npt.NDArray[np.float64]: ...
    @property
    def counts(self) -> npt.NDArray[np.int32]: ...
    @property
    def cell_primitives(self) -> Tuple[npt.NDArray[np.int64], npt.NDArray[np.uint32]]: ...
    def contains(self, points: _Array) -> npt.NDArray[np.bool_]: ...
    @property
    def source(self) -> str: ...
    def save(
        self,
        path: _Path,
        *,
        faces: str = "exposed",
        color: str = "count",
        ascii: bool = False,
        bricks: Union[None, _Int, Sequence[_Int]] = None,
        threads: Optional[_Int] = None,
        progress: _Progress = False,
    ) -> None: ...
    def mesh(
        self, faces: str = "merged", color: str = "none", *, threads: Optional[_Int] = None
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int32], Optional[npt.NDArray[np.uint8]]]: ...
    def colors(self, mode: str = "material") -> npt.NDArray[np.uint8]: ...
    def surface(
        self, level: _Float = 0.0, *, threads: Optional[_Int] = None
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]: ...
    def intersect(
        self,
        origins: _Array,
        directions: _Array,
        tmax: Union[float, _Array] = ...,
        threads: Optional[_Int] = None,
        *,
        accel: str = "grid",
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], npt.NDArray[np.float64]]: ...
    def occluded(
        self,
        origins: _Array,
        directions: _Array,
        tmax: Union[float, _Array] = ...,
        threads: Optional[_Int] = None,
        *,
        accel: str = "grid",
    ) -> npt.NDArray[np.bool_]: ...

def load(path: _Path) -> Grid: ...
def voxelize(
    source: _Source,
    *,
    resolution: Optional[_Int] = None,
    dims: Union[None, _Int, Sequence[_Int]] = None,
    pitch: Union[None, _Float, Sequence[_Float]] = None,
    bounds: Optional[_Array] = None,
    method: str = "exact",
    fill: Optional[bool] = None,
    sdf: Optional[_Float] = None,
    fraction: bool = False,
    threads: Optional[_Int] = None,
    progress: _Progress = False,
) -> Grid: ...
def sdf(
    source: _Source,
    *,
    resolution: Optional[_Int] = None,
    dims: Union[None, _Int, Sequence[_Int]] = None,
    pitch: Union[None, _Float, Sequence[_Float]] = None,
    bounds: Optional[_Array] = None,
    threads: Optional[_Int] = None,
    progress: _Progress = False,
) -> npt.NDArray[np.float64]: ...
def surface(
    source: _Source,
    *,
    resolution: Optional[_Int] = None,
    dims: Union[None, _Int, Sequence[_Int]] = None,
    pitch: Union[None, _Float, Sequence[_Float]] = None,
    bounds: Optional[_Array] = None,
    level: _Float = 0.0,
    half_width: Optional[_Float] = None,
    threads: Optional[_Int] = None,
    progress: _Progress = False,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]: ...
def voxelize_batch(
    sources: Iterable[_Source],
    resolution: _Int = 64,
    *,
    fill: Optional[bool] = None,
    method: str = "exact",
    threads: Optional[_Int] = None,
    dense: bool = True,
    progress: _Progress = False,
) -> Union[npt.NDArray[np.bool_], list[Grid]]: ...
def render(
    grid: Grid,
    size: Sequence[_Int] = (512, 512),
    mode: str = "shade",
    *,
    samples: _Int = 1,
    bounces: _Int = 0,
    weight: _Float = 0.01,
    shade_back: bool = False,
    shadows: bool = True,
    filter: Optional[Tuple[str, _Float]] = None,
    eye: Optional[_Array] = None,
    look_at: Optional[_Array] = None,
    up: Optional[_Array] = None,
    fov: Optional[_Float] = None,
    accel: str = "grid",
    threads: Optional[_Int] = None,
    progress: _Progress = False,
) -> npt.NDArray[np.float32]: ...
def save_image(path: _Path, image: _Array) -> None: ...
