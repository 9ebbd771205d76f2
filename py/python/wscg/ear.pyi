from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt
from ._estimator import Estimator

ArrayLike = npt.ArrayLike
U8 = npt.NDArray[np.uint8]
F32 = npt.NDArray[np.float32]
F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
Bool = npt.NDArray[np.bool_]
_Images = Union[U8, Sequence[U8]]

__all__: List[str]

RULES: Tuple[str, ...]
SHIFTS_NINE: Tuple[Tuple[int, int], ...]
PARAMS: Tuple[str, ...]
OCCLUSIONS: Tuple[str, ...]

@dataclass(frozen=True)
class OcclusionReport:
    mask: Bool
    blocks: Bool
    block_skin_fraction: F64
    index: I64
    occluded_pct: float
    rejected: bool

@dataclass(frozen=True)
class Identification:
    rejected: bool
    occluded_pct: float
    order: I64
    scores: F64

@dataclass(frozen=True)
class Ranking:
    order: I64
    scores: F64

@dataclass(frozen=True)
class MatchScore:
    rules: Dict[str, float]
    score: float
    per_shift: F64
    distances: F64
    best_shift: I64
    index: I64
    shifts: I64
    occluded_pct: float
    rejected: bool

@dataclass(frozen=True)
class EarDataset:
    enrol: U8
    probes: U8
    labels: I64
    occluder_masks: Bool
    occluded_blocks: Bool
    occluded_pct: F64
    skin_rg: F64

@dataclass(frozen=True)
class EarEvaluation:
    rules: List[str]
    cmc: Dict[str, F64]
    baseline_cmc: F64
    baseline_cmc_all: F64
    rejection_rate: float
    estimated_pct: F64
    true_pct: F64
    rejected: Bool
    ranks: I64
    baseline_rank: I64
    degradation: Optional[Dict[str, F64]] = ...

# The keyword parameters of the pipeline are documented in ear.py (PARAMS names them all).

def enroll(image: ArrayLike, *, height: int = ..., width: int = ..., block: int = ...,
           gray_enrolment: bool = ...) -> F32: ...
def enroll_many(images: _Images, *, height: int = ..., width: int = ..., block: int = ...,
                gray_enrolment: bool = ...) -> F32: ...
def detect_occlusion(
    image: ArrayLike, *, height: int = ..., width: int = ..., block: int = ...,
    skin_model: Optional[SkinModel] = ..., skin_mean: Optional[Sequence[float]] = ...,
    skin_cov: Optional[Sequence[Sequence[float]]] = ..., skin_rule: str = ...,
    min_likelihood: Optional[float] = ..., min_intensity: int = ...,
    close_radius: float = ..., fill_holes: bool = ..., block_skin_fraction: float = ...,
    reject_above_pct: float = ...,
) -> OcclusionReport: ...
def skin_pixels(
    image: ArrayLike, *,
    skin_model: Optional[SkinModel] = ..., skin_mean: Optional[Sequence[float]] = ...,
    skin_cov: Optional[Sequence[Sequence[float]]] = ..., skin_rule: str = ...,
    min_likelihood: Optional[float] = ..., min_intensity: int = ...,
) -> Bool: ...

class EarMatcher(Estimator):
    n_templates_: int
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
    def fit(self, X: ArrayLike, y: object = None) -> "EarMatcher": ...
    def __len__(self) -> int: ...
    @property
    def templates_(self) -> F32: ...
    @property
    def params(self) -> Dict[str, Any]: ...
    def identify(self, image: ArrayLike) -> Identification: ...
    def scores(self, image: ArrayLike) -> F64: ...
    def identify_baseline(self, image: ArrayLike) -> Ranking: ...

def score(
    image: ArrayLike, template: ArrayLike, *, height: int = ..., width: int = ...,
    block: int = ...,
    skin_model: Optional[SkinModel] = ..., skin_mean: Optional[Sequence[float]] = ...,
    skin_cov: Optional[Sequence[Sequence[float]]] = ..., skin_rule: str = ...,
    min_likelihood: Optional[float] = ..., min_intensity: int = ...,
    close_radius: float = ..., fill_holes: bool = ..., block_skin_fraction: float = ...,
    reject_above_pct: float = ...,
    shifts: Sequence[Tuple[int, int]] = ..., score: str = ..., mask_features: bool = ...,
    equalize_on_skin: bool = ...,
) -> MatchScore: ...
def baseline_score(image: ArrayLike, template: ArrayLike, *, height: int = ...,
                   width: int = ..., block: int = ..., gray_enrolment: bool = ...) -> float: ...

class SkinModel(Estimator):
    mean: ArrayLike
    cov: ArrayLike
    def __init__(self, mean: ArrayLike = ..., cov: ArrayLike = ...) -> None: ...
    def fit(self, X: ArrayLike, y: object = None) -> "SkinModel": ...
    def fit_rg(self, X: ArrayLike, y: object = None) -> "SkinModel": ...
    @property
    def mean_(self) -> F64: ...
    @property
    def cov_(self) -> F64: ...
    def mahalanobis2_rg(self, r: ArrayLike, g: ArrayLike) -> Union[float, F64]: ...
    def likelihood_rg(self, r: ArrayLike, g: ArrayLike) -> Union[float, F64]: ...
    def marginal_likelihoods_rg(
        self, r: ArrayLike, g: ArrayLike
    ) -> Tuple[Union[float, F64], Union[float, F64]]: ...
    def likelihood(self, rgb: ArrayLike) -> Union[float, F64]: ...

def cmc(ranks: ArrayLike, max_rank: int) -> F64: ...
def make_ears(n_subjects: int, n_probes: int, seed: int = ..., occlusion: str = ...,
              min_pct: float = ..., max_pct: float = ..., *,
              canvas: Tuple[int, int] = ..., shape_spread: float = ..., shift_px: float = ...,
              rotation_deg: float = ..., gain: Tuple[float, float] = ...,
              white_balance: float = ..., noise_sigma: float = ..., height: int = ...,
              width: int = ..., block: int = ...) -> EarDataset: ...
def evaluate(
    enrol: _Images, probes: _Images, labels: ArrayLike, true_pct: Optional[ArrayLike] = ...,
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

def rgb_to_gray(image: ArrayLike) -> U8: ...
def equalize_hist(gray: ArrayLike, within: Optional[ArrayLike] = ...) -> U8: ...
def resize(image: ArrayLike, height: int, width: int) -> U8: ...
def haar_ll(plane: ArrayLike) -> F64: ...
def block_features(plane: ArrayLike, *, height: int = ..., width: int = ...,
                   block: int = ...) -> F32: ...
def close_disk(mask: ArrayLike, radius: float = ...) -> Bool: ...
def dilate_disk(mask: ArrayLike, radius: float) -> Bool: ...
def erode_disk(mask: ArrayLike, radius: float) -> Bool: ...
def fill_holes(mask: ArrayLike) -> Bool: ...
