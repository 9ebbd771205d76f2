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
) -> Dict[str, Any]: ...
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
    def identify(self, image: ArrayLike) -> Dict[str, Any]: ...
    def scores(self, image: ArrayLike) -> F64: ...
    def identify_baseline(self, image: ArrayLike) -> Dict[str, Any]: ...

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
) -> Dict[str, Any]: ...
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
              width: int = ..., block: int = ...) -> Dict[str, np.ndarray]: ...
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
) -> Dict[str, Any]: ...

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
