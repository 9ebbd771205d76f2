import os
from dataclasses import dataclass
from typing import Any, Dict, List, Literal, Mapping, NamedTuple, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__all__ = ["multiscopic_hdr", "patchmatch", "patchmatch_2d", "zncc_stereo", "vote_bds",
           "warp_direct", "calibrate_debevec", "calibrate_mitsunaga_nayar", "to_radiance",
           "khan_weight", "merge", "merge_stack", "exif_exposure_times", "make_scene",
           "rmse_log2", "bad_rate", "incoherence", "ALIGN_METHODS", "SYNTHESIS_METHODS", "CRF_NAMES", "HdrSequence",
           "PolynomialResponse", "HdrScene", "load_crf", "save_crf", "load_exposure_times",
           "save_exposure_times"]

ALIGN_METHODS: Tuple[str, ...]
SYNTHESIS_METHODS: Tuple[str, ...]
CRF_NAMES: Tuple[str, ...]

_Crf = Union[str, np.ndarray]
_CrfArg = Union[str, np.ndarray, Sequence[Union[str, np.ndarray]]]
_Fields = Dict[Tuple[int, int], np.ndarray]
_Image = Union[np.ndarray, str, os.PathLike[str]]

class HdrSequence(NamedTuple):
    radiance: List[np.ndarray]
    fields: _Fields
    fallback_pixels: List[int]

@dataclass(frozen=True)
class PolynomialResponse:
    coefficients: List[np.ndarray]
    ratios: List[np.ndarray]
    degree: List[int]
    rms: List[float]
    n_equations: List[int]
    n_iter: List[int]

@dataclass(frozen=True)
class HdrScene:
    views: List[np.ndarray]
    exposure_times: List[float]
    crf: np.ndarray
    radiance: List[np.ndarray]
    disparity: List[np.ndarray]
    seen_by: List[np.ndarray]

@overload
def multiscopic_hdr(views: Sequence[_Image], exposure_times: Optional[Sequence[float]] = ...,
                    crf: _CrfArg = ..., *, patch: int = ..., n_iter: int = ...,
                    max_disparity: int = ..., min_disparity: Optional[int] = ...,
                    coherence: bool = ..., epipolar: bool = ..., align: str = ...,
                    synthesis: str = ..., ordered: bool = ..., weighted_cost: bool = ...,
                    fill_saturated: bool = ..., bits: Optional[int] = ..., seed: int = ...,
                    return_details: Literal[False] = ...) -> List[np.ndarray]: ...
@overload
def multiscopic_hdr(views: Sequence[_Image], exposure_times: Optional[Sequence[float]] = ...,
                    crf: _CrfArg = ..., *, patch: int = ..., n_iter: int = ...,
                    max_disparity: int = ..., min_disparity: Optional[int] = ...,
                    coherence: bool = ..., epipolar: bool = ..., align: str = ...,
                    synthesis: str = ..., ordered: bool = ..., weighted_cost: bool = ...,
                    fill_saturated: bool = ..., bits: Optional[int] = ..., seed: int = ...,
                    return_details: Literal[True]) -> HdrSequence: ...
def patchmatch(a: np.ndarray, b: np.ndarray, *, patch: int = ..., n_iter: int = ...,
               min_disparity: int = ..., max_disparity: int = ..., v_tol: int = ...,
               coherence: bool = ..., epipolar: bool = ..., c_min: float = ...,
               alpha: float = ..., seed: int = ...) -> Tuple[np.ndarray, np.ndarray]: ...
def patchmatch_2d(a: np.ndarray, b: np.ndarray, *, patch: int = ..., n_iter: int = ...,
                  seed: int = ...) -> Tuple[np.ndarray, np.ndarray]: ...
def zncc_stereo(a: np.ndarray, b: np.ndarray, *, window: int = ..., min_disparity: int = ...,
                max_disparity: int = ..., lr_tol: int = ...) -> Tuple[np.ndarray, np.ndarray]: ...
def vote_bds(src: np.ndarray, offsets_rs: np.ndarray, offsets_sr: np.ndarray, *,
             patch: int = ...) -> np.ndarray: ...
def warp_direct(src: np.ndarray, offsets_rs: np.ndarray) -> np.ndarray: ...
def calibrate_debevec(stack: Sequence[_Image], exposure_times: Optional[Sequence[float]] = ..., *,
                      n_samples: int = ..., lam: float = ...,
                      bits: Optional[int] = ...) -> np.ndarray: ...
def calibrate_mitsunaga_nayar(stack: Sequence[_Image], exposure_times: Optional[Sequence[float]] = ..., *,
                              degree: Optional[int] = ..., max_degree: int = ...,
                              n_samples: int = ..., refine_ratios: bool = ..., tol: float = ...,
                              max_iter: int = ...,
                              bits: Optional[int] = ...) -> Tuple[np.ndarray, PolynomialResponse]: ...
def to_radiance(image: np.ndarray, crf: _Crf, exposure_time: float, *,
                bits: Optional[int] = ...) -> np.ndarray: ...
@overload
def khan_weight(z: float, z_max: float = ...) -> float: ...
@overload
def khan_weight(z: Union[np.ndarray, Sequence[float]], z_max: float = ...) -> np.ndarray: ...
def merge(radiances: Sequence[np.ndarray], weights: Sequence[np.ndarray],
          levels: Sequence[np.ndarray],
          exposure_times: Sequence[float]) -> Tuple[np.ndarray, int]: ...
def merge_stack(images: Sequence[_Image], exposure_times: Optional[Sequence[float]] = ...,
                crf: _CrfArg = ..., *, bits: Optional[int] = ...) -> Tuple[np.ndarray, int]: ...
def exif_exposure_times(paths: Sequence[Union[str, os.PathLike[str]]],
                        exposure_times: Optional[Sequence[float]] = ...) -> List[float]: ...
def make_scene(*, height: int = ..., width: int = ..., exposure_times: Sequence[float] = ...,
                emitter_peak: float = ..., noise: float = ..., seed: int = ...,
                layers: Optional[Sequence[Mapping[str, Any]]] = ...) -> HdrScene: ...
def rmse_log2(est: np.ndarray, gt: np.ndarray, mask: Optional[np.ndarray] = ...) -> float: ...
def bad_rate(offsets: np.ndarray, truth: np.ndarray, k: float = ...,
             mask: Optional[np.ndarray] = ...) -> float: ...
def incoherence(offsets: np.ndarray) -> float: ...


def load_crf(path: Union[str, os.PathLike]) -> npt.NDArray[np.float32]: ...
def save_crf(path: Union[str, os.PathLike], crf: npt.ArrayLike) -> None: ...
def load_exposure_times(path: Union[str, os.PathLike]) -> List[float]: ...
def save_exposure_times(path: Union[str, os.PathLike], times: Sequence[float]) -> None: ...
