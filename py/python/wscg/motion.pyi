import os
from dataclasses import dataclass
from typing import final, Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union, overload, Literal

import numpy as np
import numpy.typing as npt

_F64 = npt.NDArray[np.float64]
_C128 = npt.NDArray[np.complex128]
_I64 = npt.NDArray[np.int64]
from ._estimator import Estimator

__all__ = ["make_synthetic_dataset", "AnechoicModel", "fit_anechoic", "pca_quality",
           "pca_qualities", "quality", "StepwiseModel", "fit_stepwise", "Library",
           "plan_steps", "Synthesizer", "save_bvh", "load_bvh", "load_bvh_skeleton", "load_dataset", "save_dataset",
           "forward_kinematics",
           "skeleton", "regression_p_value", "fit_line", "svr_fit_predict", "hopf_simulate",
           "ACTIONS", "DELAY_MODES", "MAPS", "N_CHANNELS", "MotionTruth", "MotionDataset",
           "ActionFit", "StepPlan", "Synthesis", "BvhMotion", "BvhSkeleton", "Skeleton", "LineFit", "SvrInfo",
           "HopfTrajectory"]

ACTIONS: Tuple[str, str, str]
DELAY_MODES: Tuple[str, ...]
MAPS: Tuple[str, ...]
N_CHANNELS: int

@dataclass(frozen=True)
class MotionTruth:
    periodic: _F64
    sources: _F64
    source_coeffs: _C128
    delays: _F64
    weights: _F64
    means: _F64
    w0: _F64

@dataclass(frozen=True)
class MotionDataset:
    angles: _F64
    step_length: _F64
    duration: _F64
    root: Optional[_F64]
    distances: _F64
    truth: Optional[MotionTruth]


@dataclass(frozen=True)
class ActionFit:
    means: _F64
    w0: _F64
    weights: _F64
    q: float
    n_sources: int

@dataclass(frozen=True)
class StepPlan:
    actions: List[Tuple[str, float]]
    too_short: bool
    violation: float
    n_steps: int
    distance: float

@dataclass(frozen=True)
class Synthesis:
    angles: _F64
    root_x: _F64
    time: _F64
    phase: _F64
    action: _I64
    executed: List[Tuple[str, float]]
    transitions: _F64
    too_short: bool
    goal: float

@dataclass(frozen=True)
class BvhSkeleton:
    names: List[str]
    parents: List[int]
    offsets: _F64
    channels: List[List[str]]
    end_sites: List[List[List[float]]]
    motion: _F64
    positions: _F64
    frame_time: float

@dataclass(frozen=True)
class BvhMotion:
    angles: _F64
    root: _F64
    frame_time: float

@dataclass(frozen=True)
class Skeleton:
    names: List[str]
    parents: _I64
    offsets: _F64
    bones: _I64

@dataclass(frozen=True)
class LineFit:
    intercept: float
    slope: float
    r2: float
    p_value: float
    n_points: int

@dataclass(frozen=True)
class SvrInfo:
    n_support: int
    rho: float
    n_iter: int

@dataclass(frozen=True)
class HopfTrajectory:
    time: _F64
    leader: _F64
    followers: _F64
    leader_phase: _F64

def make_synthetic_dataset(n_trials: int = 40, seed: int = 0, noise: float = 0.01,
                           human_like: bool = False, n_samples: int = 100,
                           model_seed: int = 7) -> MotionDataset: ...
class AnechoicModel(Estimator):
    n_sources: int
    delays: str
    n_harmonics: int
    n_restarts: int
    max_iter: int
    tol: float
    seed: int
    init: str
    delay_search: int
    q_: float
    q_history_: npt.NDArray[np.float64]
    sources_: npt.NDArray[np.float64]
    source_coeffs_: npt.NDArray[np.complex128]
    delays_: npt.NDArray[np.float64]
    weights_: npt.NDArray[np.float64]
    reconstruction_: npt.NDArray[np.float64]
    def __init__(self, n_sources: int = 3, delays: str = "shared", n_harmonics: int = 8,
                 n_restarts: int = 10, max_iter: int = 500, tol: float = 1e-9, seed: int = 0,
                 init: str = "pca", delay_search: int = 128) -> None: ...
    def fit(self, X: npt.ArrayLike, y: object = None) -> "AnechoicModel": ...

def fit_anechoic(X: npt.ArrayLike, n_sources: int, delays: str = "shared",
                 n_harmonics: int = 8, n_restarts: int = 10, max_iter: int = 500,
                 tol: float = 1e-9, seed: int = 0, init: str = "pca",
                 delay_search: int = 128) -> AnechoicModel: ...
def pca_qualities(X: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
def pca_quality(X: npt.ArrayLike, j: int) -> float: ...
def quality(X: npt.ArrayLike, Xhat: npt.ArrayLike) -> float: ...

@final
class Library:
    @property
    def q_total(self) -> float: ...
    @property
    def q_actions(self) -> List[float]: ...
    @property
    def q_second_before_extra(self) -> float: ...
    @property
    def n_sources(self) -> int: ...
    @property
    def n_channels(self) -> int: ...
    @property
    def n_samples(self) -> int: ...
    @property
    def sources(self) -> npt.NDArray[np.float64]: ...
    @property
    def delays(self) -> npt.NDArray[np.float64]: ...
    @property
    def progress(self) -> npt.NDArray[np.float64]: ...
    def params(self, a: int) -> npt.NDArray[np.float64]: ...
    def action_fit(self, a: int) -> ActionFit: ...
    def to_json(self) -> str: ...
    @staticmethod
    def from_json(s: str) -> "Library": ...

class StepwiseModel(Estimator):
    n_sources_first: int
    n_sources_extra: int
    n_harmonics: int
    n_restarts: int
    max_iter: int
    tol: float
    seed: int
    delay_search: int
    library_: Library
    def __init__(self, n_sources_first: int = 3, n_sources_extra: int = 2,
                 n_harmonics: int = 8, n_restarts: int = 10, max_iter: int = 500,
                 tol: float = 1e-9, seed: int = 0, delay_search: int = 128) -> None: ...
    def fit(self, X: object, y: object = None) -> "StepwiseModel": ...

def fit_stepwise(dataset: object, n_sources_first: int = 3, n_sources_extra: int = 2,
                 n_harmonics: int = 8, n_restarts: int = 10, max_iter: int = 500,
                 tol: float = 1e-9, seed: int = 0, delay_search: int = 128) -> StepwiseModel: ...
def plan_steps(D: float, comfort: float = 0.6, gamma: float = 0.385,
               range1: Tuple[float, float] = (0.670, 0.901),
               range2: Tuple[float, float] = (1.070, 1.439),
               human_like: Optional[float] = None, max_steps: int = 1000) -> StepPlan: ...

class Synthesizer(Estimator):
    comfort: float
    gamma: float
    map: str
    beta: float
    coupling: float
    lut_size: int
    bandwidth: Optional[float]
    human_like: Optional[float]
    svr_C: float
    svr_epsilon: float
    svr_gamma: float
    library_: Library
    def __init__(self, comfort: float = 0.6, gamma: float = 0.385,
                 map: str = "lut", beta: float = ..., coupling: float = 2.0,
                 lut_size: int = 1024, bandwidth: Optional[float] = None,
                 human_like: Optional[float] = None, svr_C: float = 10.0,
                 svr_epsilon: float = 0.01, svr_gamma: float = 2.0) -> None: ...
    def fit(self, X: "Union[Library, StepwiseModel]", y: object = None) -> "Synthesizer": ...
    @property
    def planner(self) -> Dict[str, Any]: ...
    def plan(self, D: float) -> StepPlan: ...
    def run(self, goal: float = 2.6, fps: float = 120.0,
            goal_changes: Sequence[Tuple[float, float]] = (),
            max_seconds: float = 120.0) -> Synthesis: ...

def save_bvh(path: Union[str, os.PathLike], angles: npt.ArrayLike, root: npt.ArrayLike,
             fps: float = 120.0) -> None: ...
def load_bvh(path: Union[str, os.PathLike], joint_map: Any = None,
             units_per_metre: float = 100.0) -> BvhMotion: ...
def load_bvh_skeleton(path: Union[str, os.PathLike]) -> BvhSkeleton: ...
def load_dataset(path: Union[str, os.PathLike]) -> MotionDataset: ...
def save_dataset(path: Union[str, os.PathLike], dataset: Any) -> None: ...
def forward_kinematics(angles: npt.ArrayLike, root: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
def skeleton() -> Skeleton: ...
def regression_p_value(r2: float, n: int) -> float: ...
def fit_line(x: npt.ArrayLike, y: npt.ArrayLike) -> LineFit: ...
@overload
def svr_fit_predict(x_train: npt.ArrayLike, y_train: npt.ArrayLike, x_test: npt.ArrayLike,
                    C: float = 10.0, epsilon: float = 0.01, gamma: float = 2.0,
                    tol: float = 1e-3,
                    return_info: Literal[False] = False) -> npt.NDArray[np.float64]: ...
@overload
def svr_fit_predict(x_train: npt.ArrayLike, y_train: npt.ArrayLike, x_test: npt.ArrayLike,
                    C: float = 10.0, epsilon: float = 0.01, gamma: float = 2.0,
                    tol: float = 1e-3, *,
                    return_info: Literal[True]) -> Tuple[npt.NDArray[np.float64], SvrInfo]: ...
def hopf_simulate(duration: float, dt: float = 1e-3, omega: float = ...,
                  coupling: float = 2.0, leader: Tuple[float, float] = (1.0, 0.0),
                  followers: npt.ArrayLike = ()) -> HopfTrajectory: ...
