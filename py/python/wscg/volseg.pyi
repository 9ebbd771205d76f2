from dataclasses import dataclass
from typing import List, Literal, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

_ArrayLike = npt.ArrayLike
_F32 = npt.NDArray[np.float32]
_U16 = npt.NDArray[np.uint16]
_Bool = npt.NDArray[np.bool_]
_Norm = Union[Literal["window", "minmax", "none"], Tuple[Literal["window"], float, float]]
_Solver = Literal["block", "per_label"]
_Precision = Literal["f32", "f64"]
_Preset = Literal["default", "paper"]

__all__ = ["random_walker_bone", "RandomWalkerSession", "nearest_seed", "dice", "bone_mask",
           "smooth", "local_grow_edit", "remove_small_components",
           "make_fractured_shell_phantom", "SolveReport"]

@dataclass(frozen=True)
class SolveReport:
    labels: List[int]
    n_iter: List[int]
    residuals: List[float]
    converged: List[bool]
    seconds: List[float]
    n_unreached: int
    n_labels: int
    n_nodes: int
    n_seeds: int

DEFAULT_WINDOW: Tuple[float, float]

@overload
def random_walker_bone(ct: _ArrayLike, seeds: _ArrayLike, *, t_bone: float = ...,
                       beta: Optional[float] = ..., eps: Optional[float] = ...,
                       kappa: Optional[float] = ..., preset: _Preset = ..., tol: float = ...,
                       max_iter: int = ...,
                       spacing: Sequence[float] = ..., n_smooth_passes: int = ...,
                       norm: _Norm = ...,
                       spacing_in_weights: bool = ..., solver: _Solver = ...,
                       precision: _Precision = ..., jacobi: bool = ...,
                       n_threads: Optional[int] = ..., return_prob: Literal[False] = ...,
                       return_report: Literal[False] = ...) -> _U16: ...
@overload
def random_walker_bone(ct: _ArrayLike, seeds: _ArrayLike, *, t_bone: float = ...,
                       beta: Optional[float] = ..., eps: Optional[float] = ...,
                       kappa: Optional[float] = ..., preset: _Preset = ..., tol: float = ...,
                       max_iter: int = ...,
                       spacing: Sequence[float] = ..., n_smooth_passes: int = ...,
                       norm: _Norm = ...,
                       spacing_in_weights: bool = ..., solver: _Solver = ...,
                       precision: _Precision = ..., jacobi: bool = ...,
                       n_threads: Optional[int] = ..., return_prob: Literal[True],
                       return_report: Literal[False] = ...) -> Tuple[_U16, _F32]: ...
@overload
def random_walker_bone(ct: _ArrayLike, seeds: _ArrayLike, *, t_bone: float = ...,
                       beta: Optional[float] = ..., eps: Optional[float] = ...,
                       kappa: Optional[float] = ..., preset: _Preset = ..., tol: float = ...,
                       max_iter: int = ...,
                       spacing: Sequence[float] = ..., n_smooth_passes: int = ...,
                       norm: _Norm = ...,
                       spacing_in_weights: bool = ..., solver: _Solver = ...,
                       precision: _Precision = ..., jacobi: bool = ...,
                       n_threads: Optional[int] = ..., return_prob: Literal[False] = ...,
                       return_report: Literal[True]) -> Tuple[_U16, SolveReport]: ...
@overload
def random_walker_bone(ct: _ArrayLike, seeds: _ArrayLike, *, t_bone: float = ...,
                       beta: Optional[float] = ..., eps: Optional[float] = ...,
                       kappa: Optional[float] = ..., preset: _Preset = ..., tol: float = ...,
                       max_iter: int = ...,
                       spacing: Sequence[float] = ..., n_smooth_passes: int = ...,
                       norm: _Norm = ...,
                       spacing_in_weights: bool = ..., solver: _Solver = ...,
                       precision: _Precision = ..., jacobi: bool = ...,
                       n_threads: Optional[int] = ..., return_prob: Literal[True],
                       return_report: Literal[True]) -> Tuple[_U16, _F32, SolveReport]: ...

class RandomWalkerSession:
    def __init__(self, ct: _ArrayLike, mask: Optional[_ArrayLike] = None, *, t_bone: float = ...,
                 beta: Optional[float] = ..., eps: Optional[float] = ...,
                 kappa: Optional[float] = ..., preset: _Preset = ..., tol: float = ...,
                 max_iter: int = ..., spacing: Sequence[float] = ..., n_smooth_passes: int = ...,
                 norm: _Norm = ..., spacing_in_weights: bool = ..., solver: _Solver = ...,
                 precision: _Precision = ..., jacobi: bool = ...,
                 n_threads: Optional[int] = ...) -> None: ...
    def set_seeds(self, seeds: _ArrayLike) -> int: ...
    def add_seeds(self, zyx_indices: _ArrayLike, label: int) -> int: ...
    def solve(self, warm_start: bool = True) -> SolveReport: ...
    def report(self) -> Optional[SolveReport]: ...
    def labels(self) -> _U16: ...
    def probabilities(self, label: Optional[int] = None) -> _F32: ...
    def seeds(self) -> _U16: ...
    def nearest_seed(self) -> _U16: ...
    @property
    def n_nodes(self) -> int: ...
    @property
    def n_edges(self) -> int: ...
    @property
    def n_labels(self) -> int: ...
    @property
    def shape(self) -> Tuple[int, int, int]: ...
    @property
    def graph_bytes(self) -> int: ...

def nearest_seed(ct: _ArrayLike, seeds: _ArrayLike, t_bone: float = 300.0, *,
                 mask: Optional[_ArrayLike] = None) -> _U16: ...
def dice(a: _ArrayLike, b: _ArrayLike) -> float: ...
def bone_mask(ct: _ArrayLike, t_bone: float = 300.0, *, n_smooth_passes: int = 0,
              spacing: Sequence[float] = (1.0, 1.0, 1.0)) -> _Bool: ...
def smooth(ct: _ArrayLike, n_passes: int = 1, *,
           spacing: Sequence[float] = (1.0, 1.0, 1.0)) -> _F32: ...
def local_grow_edit(labels: _ArrayLike, ct: _ArrayLike, center_zyx: Sequence[float], radius: float,
                    active: int, t_bone: float = 300.0, *, norm: _Norm = "window",
                    ratio: float = 0.5, gradient: float = 0.3, distance: float = 0.2,
                    gradient_scale: float = 0.05, tau: float = 0.5,
                    max_sweeps: int = 10) -> Tuple[_U16, int]: ...
def remove_small_components(labels: _ArrayLike, min_voxels: int) -> Tuple[_U16, int]: ...
@overload
def make_fractured_shell_phantom(shape: Sequence[int] = (128, 128, 128), n_fragments: int = 6,
                                 seed: int = 0, *, return_distance: Literal[False] = ...,
                                 shell: Tuple[float, float] = (0.60, 0.68),
                                 bone_hu: float = 1200.0, gap_hu: float = 450.0,
                                 gap_width: float = 0.75, blur_sigma: float = 0.8,
                                 noise_hu: float = 30.0, t_bone: float = 300.0,
                                 stroke_radius: float = 2.0, stroke_margin: float = 4.0,
                                 surface_strokes: bool = False) -> Tuple[_F32, _U16, _U16]: ...
@overload
def make_fractured_shell_phantom(shape: Sequence[int] = (128, 128, 128), n_fragments: int = 6,
                                 seed: int = 0, *, return_distance: Literal[True],
                                 shell: Tuple[float, float] = (0.60, 0.68),
                                 bone_hu: float = 1200.0, gap_hu: float = 450.0,
                                 gap_width: float = 0.75, blur_sigma: float = 0.8,
                                 noise_hu: float = 30.0, t_bone: float = 300.0,
                                 stroke_radius: float = 2.0, stroke_margin: float = 4.0,
                                 surface_strokes: bool = False) -> Tuple[_F32, _U16, _U16, _F32]: ...
