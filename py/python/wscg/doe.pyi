from dataclasses import dataclass
import os
from typing import List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_F64 = npt.NDArray[np.float64]

__all__ = ["ccd", "decode", "encode", "williams", "fit_rsm", "fit_rsm_blocked", "rm_anova",
           "rm_anova_oneway", "lsd", "panel_pca", "RsmFit", "AnovaEffect", "AnovaTable",
           "LeastSignificantDifference", "load_study", "save_study", "load_runs", "save_runs",
           "load_design", "Study", "Runs"]

@dataclass(frozen=True)
class RsmFit:
    names: List[str]
    coef: _F64
    se: _F64
    t: _F64
    p: _F64
    r2: float
    r2_adj: float
    r2_pred: float
    press: float
    sse: float
    sst: float
    df_resid: int
    sigma2: float
    leverage: _F64
    residuals: _F64
    fitted: _F64
    stationary: Optional[_F64]
    y_stationary: Optional[float]
    canonical_eigs: _F64
    canonical_axes: _F64

@dataclass(frozen=True)
class AnovaEffect:
    ss: float
    df: int
    ms: float
    F: float
    p: float
    ss_error: float
    df_error: int
    ms_error: float
    np2: float
    eps_gg: float
    p_gg: float

@dataclass(frozen=True)
class AnovaTable:
    condition: AnovaEffect
    stimulus: AnovaEffect
    interaction: AnovaEffect
    ss_subject: float
    ss_total: float

@dataclass(frozen=True)
class LeastSignificantDifference:
    alpha: float
    t_crit: float
    ms_error: float
    df_error: int
    lsd: float
    means: _F64
    pairs: List[Tuple[int, int, bool]]
    n_separated: int

def ccd(k: int, face: str = "circumscribed", alpha: Union[str, float] = "orthogonal",
        center: Union[int, Tuple[int, int]] = (4, 4)) -> _F64: ...
def decode(coded: npt.ArrayLike, low: Sequence[float], high: Sequence[float]) -> _F64: ...
def encode(physical: npt.ArrayLike, low: Sequence[float], high: Sequence[float]) -> _F64: ...
def williams(n: int) -> npt.NDArray[np.int64]: ...
def fit_rsm(x: npt.ArrayLike, y: npt.ArrayLike, interaction: bool = True) -> RsmFit: ...
def fit_rsm_blocked(x: npt.ArrayLike, scores: npt.ArrayLike,
                    interaction: bool = True) -> RsmFit: ...
def rm_anova(scores: npt.ArrayLike) -> AnovaTable: ...
def rm_anova_oneway(scores: npt.ArrayLike) -> AnovaEffect: ...
def lsd(scores: npt.ArrayLike, alpha: float = 0.05) -> LeastSignificantDifference: ...
def panel_pca(scores: npt.ArrayLike) -> _F64: ...


@dataclass(frozen=True)
class Study:
    subject_names: List[str]
    condition_names: List[str]
    scores: _F64


class Runs(NamedTuple):
    x: _F64
    y: _F64


def load_study(path: Union[str, os.PathLike]) -> Study: ...
def save_study(path: Union[str, os.PathLike], study: Study) -> None: ...
def load_runs(path: Union[str, os.PathLike]) -> Runs: ...
def save_runs(path: Union[str, os.PathLike], x: npt.ArrayLike, y: npt.ArrayLike) -> None: ...
def load_design(path: Union[str, os.PathLike]) -> _F64: ...
