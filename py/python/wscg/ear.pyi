from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt
from ._estimator import Estimator

_ArrayLike = npt.ArrayLike
_U8 = npt.NDArray[np.uint8]
_F32 = npt.NDArray[np.float32]
_F64 = npt.NDArray[np.float64]
_I64 = npt.NDArray[np.int64]
_Bool = npt.NDArray[np.bool_]
_Images = Union[_U8, Sequence[_U8]]

__all__ = ["enroll", "enroll_many", "detect_occlusion", "skin_pixels", "EarMatcher", "score",
           "baseline_score", "SkinModel", "cmc", "make_ears", "evaluate", "rgb_to_gray",
           "equalize_hist", "resize", "haar_ll", "block_features", "close_disk", "dilate_disk",
           "erode_disk", "fill_holes", "RULES", "SHIFTS_NINE", "PARAMS", "OCCLUSIONS",
           "OcclusionReport", "Identification", "Ranking", "MatchScore", "EarDataset",
           "EarEvaluation"]

RULES: Tuple[str, ...]
SHIFTS_NINE: Tuple[Tuple[int, int], ...]
PARAMS: Tuple[str, ...]
OCCLUSIONS: Tuple[str, ...]

@dataclass(frozen=True)
class OcclusionReport:
    mask: _Bool
    blocks: _Bool
    block_skin_fraction: _F64
    index: _I64
    occluded_pct: float
    rejected: bool

@dataclass(frozen=True)
class Identification:
    rejected: bool
    occluded_pct: float
    order: _I64
    scores: _F64

@dataclass(frozen=True)
class Ranking:
    order: _I64
    scores: _F64

@dataclass(frozen=True)
class MatchScore:
    rules: Dict[str, float]
    score: float
    per_shift: _F64
    distances: _F64
    best_shift: _I64
    index: _I64
    shifts: _I64
    occluded_pct: float
    rejected: bool

@dataclass(frozen=True)
class EarDataset:
    enrol: _U8
    probes: _U8
    labels: _I64
    occluder_masks: _Bool
    occluded_blocks: _Bool
    occluded_pct: _F64
    skin_rg: _F64

@dataclass(frozen=True)
class EarEvaluation:
    rules: List[str]
    cmc: Dict[str, _F64]
    baseline_cmc: _F64
    baseline_cmc_all: _F64
    rejection_rate: float
    estimated_pct: _F64
    true_pct: _F64
    rejected: _Bool
    ranks: _I64
    baseline_rank: _I64
    degradation: Optional[Dict[str, _F64]] = ...

# The keyword parameters of the pipeline are documented in ear.py (PARAMS names them all).

def enroll(image: _ArrayLike, *, height: int = ..., width: int = ..., block: int = ...,
           gray_enrolment: bool = ...) -> _F32: ...
def enroll_many(images: _Images, *, height: int = ..., width: int = ..., block: int = ...,
                gray_enrolment: bool = ...) -> _F32: ...
def detect_occlusion(
    image: _ArrayLike, *, height: int = ..., width: int = ..., block: int = ...,
    skin_model: Optional[SkinModel] = ..., skin_mean: Optional[Sequence[float]] = ...,
    skin_cov: Optional[Sequence[Sequence[float]]] = ..., skin_rule: str = ...,
    min_likelihood: Optional[float] = ..., min_intensity: int = ...,
    close_radius: float = ..., fill_holes: bool = ..., block_skin_fraction: float = ...,
    reject_above_pct: float = ...,
) -> OcclusionReport: ...
def skin_pixels(
    image: _ArrayLike, *,
    skin_model: Optional[SkinModel] = ..., skin_mean: Optional[Sequence[float]] = ...,
    skin_cov: Optional[Sequence[Sequence[float]]] = ..., skin_rule: str = ...,
    min_likelihood: Optional[float] = ..., min_intensity: int = ...,
) -> _Bool: ...

class EarMatcher(Estimator):
    n_templates_: int
    def __bool__(self) -> bool: ...
    def __init__(
        self, *, height: int = ..., width: int = ..., block: int = ...,
        skin_model: Optional[SkinModel] = ..., skin_mean: Optional[Sequence[float]] = ...,
        skin_cov: Optional[Sequence[Sequence[float]]] = ..., skin_rule: str = ...,
        min_likelihood: Optional[float] = ..., min_intensity: int = ...,
        close_radius: float = ..., fill_holes: bool = ..., block_skin_fraction: float = ...,
        reject_above_pct: float = ...,
        shifts: Sequence[Tuple[int, int]] = ..., score: str = ..., mask_features: bool = ...,
        gray_enrolment: bool = ..., equalize_on_skin: bool = ...,
    ) -> None: ...
    def fit(self, X: _ArrayLike, y: object = None) -> "EarMatcher": ...
    def __len__(self) -> int: ...
    @property
    def templates_(self) -> _F32: ...
    @property
    def params(self) -> Dict[str, Any]: ...
    def identify(self, image: _ArrayLike) -> Identification: ...
    def scores(self, image: _ArrayLike) -> _F64: ...
    def identify_baseline(self, image: _ArrayLike) -> Ranking: ...

def score(
    image: _ArrayLike, template: _ArrayLike, *, height: int = ..., width: int = ...,
    block: int = ...,
    skin_model: Optional[SkinModel] = ..., skin_mean: Optional[Sequence[float]] = ...,
    skin_cov: Optional[Sequence[Sequence[float]]] = ..., skin_rule: str = ...,
    min_likelihood: Optional[float] = ..., min_intensity: int = ...,
    close_radius: float = ..., fill_holes: bool = ..., block_skin_fraction: float = ...,
    reject_above_pct: float = ...,
    shifts: Sequence[Tuple[int, int]] = ..., score: str = ..., mask_features: bool = ...,
    equalize_on_skin: bool = ...,
) -> MatchScore: ...
def baseline_score(image: _ArrayLike, template: _ArrayLike, *, height: int = ...,
                   width: int = ..., block: int = ..., gray_enrolment: bool = ...) -> float: ...

class SkinModel(Estimator):
    mean: _ArrayLike
    cov: _ArrayLike
    def __init__(self, mean: _ArrayLike = ..., cov: _ArrayLike = ...) -> None: ...
    def fit(self, X: _ArrayLike, y: object = None) -> "SkinModel": ...
    def __sklearn_clone__(self) -> "SkinModel": ...
    def fit_rg(self, X: _ArrayLike, y: object = None) -> "SkinModel": ...
    @property
    def mean_(self) -> _F64: ...
    @property
    def cov_(self) -> _F64: ...
    def mahalanobis2_rg(self, r: _ArrayLike, g: _ArrayLike) -> Union[float, _F64]: ...
    def likelihood_rg(self, r: _ArrayLike, g: _ArrayLike) -> Union[float, _F64]: ...
    def marginal_likelihoods_rg(
        self, r: _ArrayLike, g: _ArrayLike
    ) -> Tuple[Union[float, _F64], Union[float, _F64]]: ...
    def likelihood(self, rgb: _ArrayLike) -> Union[float, _F64]: ...

def cmc(ranks: _ArrayLike, max_rank: int) -> _F64: ...
def make_ears(n_subjects: int, n_probes: int, seed: int = ..., occlusion: str = ...,
              min_pct: float = ..., max_pct: float = ..., *,
              canvas: Tuple[int, int] = ..., shape_spread: float = ..., shift_px: float = ...,
              rotation_deg: float = ..., gain: Tuple[float, float] = ...,
              white_balance: float = ..., noise_sigma: float = ..., height: int = ...,
              width: int = ..., block: int = ...) -> EarDataset: ...
def evaluate(
    enrol: _Images, probes: _Images, labels: _ArrayLike, true_pct: Optional[_ArrayLike] = ...,
    max_rank: int = ..., edges: Optional[Sequence[float]] = ..., *, height: int = ...,
    width: int = ..., block: int = ...,
    skin_model: Optional[SkinModel] = ..., skin_mean: Optional[Sequence[float]] = ...,
    skin_cov: Optional[Sequence[Sequence[float]]] = ..., skin_rule: str = ...,
    min_likelihood: Optional[float] = ..., min_intensity: int = ...,
    close_radius: float = ..., fill_holes: bool = ..., block_skin_fraction: float = ...,
    reject_above_pct: float = ...,
    shifts: Sequence[Tuple[int, int]] = ..., score: str = ..., mask_features: bool = ...,
    gray_enrolment: bool = ..., equalize_on_skin: bool = ...,
) -> EarEvaluation: ...

def rgb_to_gray(image: _ArrayLike) -> _U8: ...
def equalize_hist(gray: _ArrayLike, within: Optional[_ArrayLike] = ...) -> _U8: ...
def resize(image: _ArrayLike, height: int, width: int) -> _U8: ...
def haar_ll(plane: _ArrayLike) -> _F64: ...
def block_features(plane: _ArrayLike, *, height: int = ..., width: int = ...,
                   block: int = ...) -> _F32: ...
def close_disk(mask: _ArrayLike, radius: float = ...) -> _Bool: ...
def dilate_disk(mask: _ArrayLike, radius: float) -> _Bool: ...
def erode_disk(mask: _ArrayLike, radius: float) -> _Bool: ...
def fill_holes(mask: _ArrayLike) -> _Bool: ...
