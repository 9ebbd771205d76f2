import os
from typing import Dict, List, Optional, Sequence, Tuple, Union, overload, Literal

import numpy as np
import numpy.typing as npt

from ._estimator import Estimator

__all__: list[str]

ACTIONS: Tuple[str, str, str]
DELAY_MODES: Tuple[str, ...]
MAPS: Tuple[str, ...]
N_CHANNELS: int

def make_synthetic_dataset(n_trials: int = 40, seed: int = 0, noise: float = 0.01,
                           human_like: bool = False, n_samples: int = 100,
                           model_seed: int = 7) -> dict: ...
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
    def action_fit(self, a: int) -> dict: ...
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
               human_like: Optional[float] = None, max_steps: int = 1000) -> dict: ...

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
    def planner(self) -> dict: ...
    def plan(self, D: float) -> dict: ...
    def run(self, goal: float = 2.6, fps: float = 120.0,
            goal_changes: Sequence[Tuple[float, float]] = (),
            max_seconds: float = 120.0) -> dict: ...

def save_bvh(path: Union[str, os.PathLike], angles: npt.ArrayLike, root: npt.ArrayLike,
             fps: float = 120.0) -> None: ...
def load_bvh(path: Union[str, os.PathLike]) -> dict: ...
def forward_kinematics(angles: npt.ArrayLike, root: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
def skeleton() -> dict: ...
def regression_p_value(r2: float, n: int) -> float: ...
def fit_line(x: npt.ArrayLike, y: npt.ArrayLike) -> dict: ...
@overload
def svr_fit_predict(x_train: npt.ArrayLike, y_train: npt.ArrayLike, x_test: npt.ArrayLike,
                    C: float = 10.0, epsilon: float = 0.01, gamma: float = 2.0,
                    tol: float = 1e-3,
                    return_info: Literal[False] = False) -> npt.NDArray[np.float64]: ...
@overload
def svr_fit_predict(x_train: npt.ArrayLike, y_train: npt.ArrayLike, x_test: npt.ArrayLike,
                    C: float = 10.0, epsilon: float = 0.01, gamma: float = 2.0,
                    tol: float = 1e-3, *,
                    return_info: Literal[True]) -> Tuple[npt.NDArray[np.float64], dict]: ...
def hopf_simulate(duration: float, dt: float = 1e-3, omega: float = ...,
                  coupling: float = 2.0, leader: Tuple[float, float] = (1.0, 0.0),
                  followers: npt.ArrayLike = ()) -> dict: ...
