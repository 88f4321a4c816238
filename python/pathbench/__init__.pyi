# Types of the `pathbench` package (its functions live in the C++ extension _core).
# tests/python/test_package.py checks that this names every public function, method,
# property and argument of the built module, with the same defaults.
import os
from typing import Literal, overload

import numpy as np
import numpy.typing as npt

__version__: str
git_revision: str
NO_HIT: int

_Floats = npt.ArrayLike  # any array-like of real numbers (float or int dtype); complex/bool/object: TypeError

class Scene:
    @property
    def name(self) -> str: ...
    @property
    def positions(self) -> npt.NDArray[np.float32]: ...
    @property
    def triangles(self) -> npt.NDArray[np.uint32]: ...
    @property
    def material_ids(self) -> npt.NDArray[np.uint32]: ...
    @property
    def bounds(self) -> npt.NDArray[np.float32]: ...
    @property
    def extent(self) -> float: ...
    @property
    def num_triangles(self) -> int: ...
    @property
    def dropped_triangles(self) -> int: ...
    def intersect(self, origins: _Floats, directions: _Floats, tnear: _Floats = 0.0, tfar: _Floats = ...,
                  *, backend: Literal["embree", "bvh"] = "embree", watertight: bool = True
                  ) -> dict[str, npt.NDArray[np.bool_] | npt.NDArray[np.uint32] | npt.NDArray[np.float32]]: ...
    def occluded(self, origins: _Floats, directions: _Floats, tnear: _Floats = 0.0, tfar: _Floats = ...,
                 *, backend: Literal["embree", "bvh"] = "embree", watertight: bool = True
                 ) -> npt.NDArray[np.bool_]: ...

def load_scene(name_or_path: str | bytes | os.PathLike[str] | os.PathLike[bytes], scale: float = 1.0,
               offset: tuple[float, float, float] | list[float] = (0.0, 0.0, 0.0),
               embree_layout: _Layout = "auto", strict: bool = False) -> Scene: ...
def builtin_scenes() -> list[tuple[str, str]]: ...
def export_mitsuba(scene: Scene, folder: str | bytes | os.PathLike[str] | os.PathLike[bytes], width: int, height: int,
                   *, bounces: int | None = None, converged: bool = False) -> str: ...
def gpu_available() -> tuple[bool, str]: ...

_Sampling = Literal["uniform", "cosine", "nee"]
_Strategy = Literal["pixel", "wavefront", "paper-queue"]
_Device = Literal["cpu", "gpu"]
_Precision = Literal["float", "double"]
_Layout = Literal["auto", "triangles", "quads"]
_Isa = Literal["auto", "avx512", "avx2", "scalar"]
_Instancing = Literal["auto", "on", "off"]
_Image = npt.NDArray[np.float32]

@overload
def render(scene: Scene, width: int, height: int, spp: int, *, bounces: int | None = None,
           converged: bool = False, rr: bool = False, sampling: _Sampling = "nee", strategy: _Strategy = "pixel",
           device: _Device = "cpu", precision: _Precision = "float", embree_layout: _Layout = "auto",
           isa: _Isa = "auto", instancing: _Instancing = "auto", seed: int = 0, paths_in_flight: int = 0, threads: int = 0, watertight: bool = True,
           variance: Literal[False] = False, profile: bool = False) -> tuple[_Image, dict[str, object]]: ...
@overload
def render(scene: Scene, width: int, height: int, spp: int, *, bounces: int | None = None,
           converged: bool = False, rr: bool = False, sampling: _Sampling = "nee", strategy: _Strategy = "pixel",
           device: _Device = "cpu", precision: _Precision = "float", embree_layout: _Layout = "auto",
           isa: _Isa = "auto", instancing: _Instancing = "auto", seed: int = 0, paths_in_flight: int = 0, threads: int = 0, watertight: bool = True,
           variance: Literal[True], profile: bool = False) -> tuple[_Image, dict[str, object], _Image]: ...
