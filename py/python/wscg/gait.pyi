from dataclasses import dataclass
from typing import (Any, Dict, Hashable, List, Literal, NamedTuple, Optional, Sequence, Tuple,
                    Union, overload)

import numpy as np
import numpy.typing as npt
from ._estimator import Estimator

_ArrayLike = npt.ArrayLike
_F64 = npt.NDArray[np.float64]
_I64 = npt.NDArray[np.int64]
_Joint = Union[str, int]
_Pairs = Union[_ArrayLike, Sequence[Tuple[_Joint, _Joint]]]
_Cycle = Union[Tuple[int, int, int], "CycleDetails", Dict[str, Any]]
_Sample = Union[_ArrayLike, Sequence[_ArrayLike]]
_Cost = Literal["abs", "squared"]
_Multivariate = Literal["independent", "dependent"]

__all__ = ["JOINT_NAMES", "N_PAIRS", "all_pairs", "jra", "detect_cycle", "jra_sequences",
           "relevance_matrix", "occupied_bins", "select_pairs", "dtw", "dtw_path",
           "dtw_kernel", "dissimilarity_matrix", "nearest", "load_ts", "load_skeleton",
           "save_skeleton_csv", "ball_features", "preis_features", "GaitRecognizer",
           "make_walkers", "evaluate_synthetic", "GaitCycle", "CycleDetails", "SyntheticWalks",
           "GaitEvaluation", "KINECT_V1_NAMES", "load_ntu_bodies", "NtuBody"]

JOINT_NAMES: List[str]
KINECT_V1_NAMES: List[str]
N_PAIRS: int

@dataclass(frozen=True)
class NtuBody:
    id: int
    n_frames: int
    n_tracked: int

class GaitCycle(NamedTuple):
    start: int
    mid: int
    end: int

@dataclass(frozen=True)
class CycleDetails:
    start: int
    mid: int
    end: int
    ankle_dist: _F64
    minima: _I64
    first_step: Optional[str]
    @property
    def cycle(self) -> GaitCycle: ...

@dataclass(frozen=True)
class SyntheticWalks:
    frames: List[_F64]
    labels: _I64
    sessions: _I64
    minima: List[_I64]
    walk_frames: _I64
    sit_tail: List[bool]

@dataclass(frozen=True)
class GaitEvaluation:
    decisions: int
    jra_nearest: float
    jra_paper_vote: float
    jra_majority: float
    jra_fixed: float
    jra_normalized: float
    jra_resampled: float
    raw_dtw: float
    ball_nn: float
    preis_nb: float
    preis_nn: float
    chosen_t: List[float]
    curve: _F64
    relevance: _F64

def all_pairs(reference: _Joint = "SpineBase") -> _I64: ...
def jra(p1: _ArrayLike, p2: _ArrayLike, r: _ArrayLike) -> float: ...
@overload
def detect_cycle(frames: _ArrayLike, fps: float = 30.0, smooth_window: int = 5,
                 min_step_s: float = 0.25, min_prominence: float = 0.2,
                 up: Union[Literal["estimate", "y"], _ArrayLike] = "estimate",
                 choice: Literal["first", "most_regular"] = "first",
                 start_leg: Literal["left", "right", "any"] = "left",
                 return_details: Literal[False] = False) -> GaitCycle: ...
@overload
def detect_cycle(frames: _ArrayLike, fps: float = 30.0, smooth_window: int = 5,
                 min_step_s: float = 0.25, min_prominence: float = 0.2,
                 up: Union[Literal["estimate", "y"], _ArrayLike] = "estimate",
                 choice: Literal["first", "most_regular"] = "first",
                 start_leg: Literal["left", "right", "any"] = "left", *,
                 return_details: Literal[True]) -> CycleDetails: ...
def jra_sequences(frames: _ArrayLike, cycle: Optional[_Cycle] = None,
                  pairs: Optional[_Pairs] = None, reference: _Joint = "SpineBase",
                  fps: float = 30.0) -> _F64: ...
def occupied_bins(theta_rad: _ArrayLike, bin_deg: float = 1.0, lo_deg: float = 0.0,
                  hi_deg: float = 180.0) -> int: ...
def relevance_matrix(samples: Sequence[_ArrayLike], bin_deg: float = 1.0, lo_deg: float = 0.0,
                     hi_deg: float = 180.0, reference: _Joint = "SpineBase") -> _F64: ...
def select_pairs(relevance: _ArrayLike, min_bins: float = 20.0) -> _I64: ...
def dtw(a: _ArrayLike, b: _ArrayLike, cost: _Cost = "abs", window: Optional[int] = None,
        normalize: bool = False) -> float: ...
def dtw_path(a: _ArrayLike, b: _ArrayLike, cost: _Cost = "abs", window: Optional[int] = None,
             normalize: bool = False) -> Tuple[float, _I64]: ...
def dtw_kernel(A: _Sample, B: _Sample, cost: _Cost = "abs", window: Optional[int] = None,
               normalize: bool = False,
               multivariate: _Multivariate = "independent") -> float: ...
def dissimilarity_matrix(As: Sequence[_Sample], Bs: Optional[Sequence[_Sample]] = None,
                         cost: _Cost = "abs", window: Optional[int] = None,
                         normalize: bool = False,
                         multivariate: _Multivariate = "independent") -> _F64: ...
def nearest(query: _Sample, gallery: Sequence[_Sample], cost: _Cost = "abs",
            window: Optional[int] = None, normalize: bool = False,
            multivariate: _Multivariate = "independent") -> Tuple[int, float]: ...
def load_ts(path: Any) -> Tuple[List[List[_F64]], List[str]]: ...
def load_skeleton(path: Any, fps: float = 30.0, body: Optional[int] = None,
                  max_gap: int = 10) -> _F64: ...
def load_ntu_bodies(path: Any) -> List[NtuBody]: ...
def save_skeleton_csv(path: Any, frames: _ArrayLike, fps: float = 30.0) -> None: ...
def ball_features(frames: _ArrayLike, cycle: Optional[_Cycle] = None, fps: float = 30.0) -> _F64: ...
def preis_features(frames: _ArrayLike, cycle: Optional[_Cycle] = None,
                   fps: float = 30.0) -> _F64: ...

class GaitRecognizer(Estimator):
    min_bins: float
    vote: str
    n_neighbors: Optional[int]
    cost: str
    window: Optional[int]
    bin_deg: float
    start_leg: str
    fps: float
    pairs_: _I64
    relevance_: _F64
    classes_: np.ndarray
    def __init__(self, min_bins: float = 20.0, vote: str = "nearest",
                 n_neighbors: Optional[int] = None, cost: _Cost = "abs",
                 window: Optional[int] = None, bin_deg: float = 1.0,
                 start_leg: Literal["left", "right", "any"] = "left",
                 fps: float = 30.0) -> None: ...
    def fit(self, X: Sequence[_ArrayLike], y: Sequence[Hashable]) -> "GaitRecognizer": ...
    def predict(self, X: Sequence[_ArrayLike]) -> np.ndarray: ...
    def score(self, X: Sequence[_ArrayLike], y: Sequence[Hashable]) -> float: ...
    def rank(self, frames: _ArrayLike) -> Tuple[np.ndarray, _F64]: ...
    def rank_indices(self, frames: _ArrayLike) -> Tuple[_I64, _F64]: ...

def make_walkers(n_subjects: int = 20, n_sessions: int = 3, seed: int = 0,
                  heading_deg: Tuple[float, float] = (-60.0, 60.0),
                  speed: Tuple[float, float] = (0.9, 1.1),
                  walk_s: Tuple[float, float] = (2.5, 4.0), sit_prob: float = 0.5,
                  noise: bool = True, n_joints: int = 25) -> SyntheticWalks: ...
def evaluate_synthetic(n_subjects: int = 20, n_sessions: int = 3,
                       seed: int = 0, n_joints: int = 25) -> GaitEvaluation: ...
