from dataclasses import dataclass
from typing import NamedTuple, Optional, Tuple

import numpy as np
import numpy.typing as npt

_F32 = npt.NDArray[np.float32]
_I64 = npt.NDArray[np.int64]

__all__ = ["marching_cubes", "estimate_normals", "sparsify", "random_dropouts",
           "angular_errors", "angular_rms", "rotation_class", "at_risk_configurations",
           "study_full_cd", "study_exact", "fields", "MeshInfo", "NormalStats", "AngularRms",
           "SparseComparison", "ExactComparison"]

@dataclass(frozen=True)
class NormalStats:
    n_undefined: int
    n_fallback: int
    n_skipped_cells: int

@dataclass(frozen=True)
class MeshInfo:
    n_undefined: int
    n_fallback: int
    n_skipped_cells: int
    edges: _I64
    cells: _I64

class AngularRms(NamedTuple):
    rms: float
    n_defined: int
    n_undefined: int

@dataclass(frozen=True)
class SparseComparison:
    n_vertices: int
    n_triangles: int
    kept_fraction: float
    cd_defined_on_sparse: float
    n_reference_undefined: int
    spline: AngularRms
    lsn: AngularRms
    n_spline_undefined: int
    n_lsn_undefined: int

@dataclass(frozen=True)
class ExactComparison:
    n_vertices: int
    central: AngularRms
    spline: AngularRms
    lsn: AngularRms
    level: float

def marching_cubes(volume: npt.ArrayLike, level: float,
                   spacing: Tuple[float, float, float] = (1.0, 1.0, 1.0),
                   normals: Optional[str] = "spline", side_hint: Optional[npt.ArrayLike] = None,
                   selection: str = "mesh", eq8_literal: bool = False,
                   normalize_before_mean: bool = False,
                   ambiguous_face: str = "inside",
                   origin: Tuple[float, float, float] = (0.0, 0.0, 0.0)
                   ) -> Tuple[_F32, _I64, _F32, MeshInfo]: ...
def estimate_normals(volume: npt.ArrayLike, level: float, edges: npt.ArrayLike,
                     spacing: Tuple[float, float, float] = (1.0, 1.0, 1.0),
                     normals: str = "spline", side_hint: Optional[npt.ArrayLike] = None,
                     selection: str = "mesh", eq8_literal: bool = False,
                     normalize_before_mean: bool = False,
                     ambiguous_face: str = "inside") -> Tuple[_F32, NormalStats]: ...
def sparsify(volume: npt.ArrayLike, level: float) -> Tuple[_F32, npt.NDArray[np.bool_]]: ...
def random_dropouts(volume: npt.ArrayLike, rate: float, seed: int = 0) -> _F32: ...
def angular_errors(a: npt.ArrayLike, b: npt.ArrayLike) -> _F32: ...
def angular_rms(a: npt.ArrayLike, b: npt.ArrayLike) -> AngularRms: ...
def rotation_class(config: int) -> int: ...
def at_risk_configurations(threshold: float = ..., ambiguous_face: str = "inside") -> list[int]: ...
def study_full_cd(volume: npt.ArrayLike, level: float,
                  spacing: Tuple[float, float, float] = (1.0, 1.0, 1.0)) -> SparseComparison: ...
def study_exact(name: str, n: int = 64) -> ExactComparison: ...

class fields:
    NAMES: Tuple[str, ...]
    @staticmethod
    def sample(name: str, n: int = 64) -> Tuple[_F32, Tuple[float, float, float],
                                                 Tuple[float, float, float]]: ...
    @staticmethod
    def exact_normals(name: str, n: int, vertices: npt.ArrayLike) -> _F32: ...
    @staticmethod
    def make_marschner_lobb(n: int = 64) -> _F32: ...
    @staticmethod
    def make_noisy_sphere(n: int = 64, radius: float = 20.0, width: float = 1.5,
                          noise: float = 3.0, seed: int = 0) -> _F32: ...
