from dataclasses import dataclass
from typing import Any, List, Literal, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

_U8 = npt.NDArray[np.uint8]
_I32 = npt.NDArray[np.int32]

__all__ = ["complete_video", "wexler_complete", "per_frame_patchmatch", "inpaint_telea",
           "ssim_masked", "psnr_masked", "flicker", "make_clip", "load_frames", "load_mask",
           "save_frames", "CompletionStats"]

@dataclass(frozen=True)
class CompletionStats:
    working_size: Tuple[int, int]
    working_factor: int
    seconds: List[float]
    lowres_energy: List[List[float]]
    local_energy: List[List[float]]
    local_candidates: List[int]
    energy: float
    refine_changed: Optional[List[int]] = ...
    refine_initial_set_mean: Optional[Tuple[float, float]] = ...

@overload
def complete_video(frames: npt.ArrayLike, mask: npt.ArrayLike, patch: Sequence[int] = (5, 5, 5),
                   lowres_width: int = 480, n_levels: Optional[int] = None,
                   lowres_max_iter: Sequence[int] = (10, 5, 3), init: str = "harmonic2d",
                   search: str = "patchmatch", patchmatch_n_iter: int = 5, seed: int = 0,
                   onion_order: bool = True, causal_first_sweep: bool = True,
                   refine_max_iter: int = 4, windows: Sequence[int] = (17, 13, 9, 5),
                   fine_max_iter: int = 16, min_energy_drop: float = 5e-3,
                   temporal_radius: Union[int, Sequence[int]] = (0, 0, 0, 1),
                   max_candidates: int = 1000, propagate: bool = True,
                   temporal_candidates: bool = True, hypotheses: int = 6,
                   scan_propagation: bool = False,
                   step: str = "double",
                   global_fine_search: bool = False, return_matches: Literal[False] = ...,
                   return_stats: Literal[False] = ...) -> _U8: ...
@overload
def complete_video(frames: npt.ArrayLike, mask: npt.ArrayLike, patch: Sequence[int] = (5, 5, 5),
                   lowres_width: int = 480, n_levels: Optional[int] = None,
                   lowres_max_iter: Sequence[int] = (10, 5, 3), init: str = "harmonic2d",
                   search: str = "patchmatch", patchmatch_n_iter: int = 5, seed: int = 0,
                   onion_order: bool = True, causal_first_sweep: bool = True,
                   refine_max_iter: int = 4, windows: Sequence[int] = (17, 13, 9, 5),
                   fine_max_iter: int = 16, min_energy_drop: float = 5e-3,
                   temporal_radius: Union[int, Sequence[int]] = (0, 0, 0, 1),
                   max_candidates: int = 1000, propagate: bool = True,
                   temporal_candidates: bool = True, hypotheses: int = 6,
                   scan_propagation: bool = False,
                   step: str = "double",
                   global_fine_search: bool = False, *, return_matches: Literal[True],
                   return_stats: Literal[False] = ...) -> Tuple[_U8, _I32]: ...
@overload
def complete_video(frames: npt.ArrayLike, mask: npt.ArrayLike, patch: Sequence[int] = (5, 5, 5),
                   lowres_width: int = 480, n_levels: Optional[int] = None,
                   lowres_max_iter: Sequence[int] = (10, 5, 3), init: str = "harmonic2d",
                   search: str = "patchmatch", patchmatch_n_iter: int = 5, seed: int = 0,
                   onion_order: bool = True, causal_first_sweep: bool = True,
                   refine_max_iter: int = 4, windows: Sequence[int] = (17, 13, 9, 5),
                   fine_max_iter: int = 16, min_energy_drop: float = 5e-3,
                   temporal_radius: Union[int, Sequence[int]] = (0, 0, 0, 1),
                   max_candidates: int = 1000, propagate: bool = True,
                   temporal_candidates: bool = True, hypotheses: int = 6,
                   scan_propagation: bool = False,
                   step: str = "double",
                   global_fine_search: bool = False, *, return_matches: Literal[False] = ...,
                   return_stats: Literal[True]) -> Tuple[_U8, CompletionStats]: ...
@overload
def complete_video(frames: npt.ArrayLike, mask: npt.ArrayLike, patch: Sequence[int] = (5, 5, 5),
                   lowres_width: int = 480, n_levels: Optional[int] = None,
                   lowres_max_iter: Sequence[int] = (10, 5, 3), init: str = "harmonic2d",
                   search: str = "patchmatch", patchmatch_n_iter: int = 5, seed: int = 0,
                   onion_order: bool = True, causal_first_sweep: bool = True,
                   refine_max_iter: int = 4, windows: Sequence[int] = (17, 13, 9, 5),
                   fine_max_iter: int = 16, min_energy_drop: float = 5e-3,
                   temporal_radius: Union[int, Sequence[int]] = (0, 0, 0, 1),
                   max_candidates: int = 1000, propagate: bool = True,
                   temporal_candidates: bool = True, hypotheses: int = 6,
                   scan_propagation: bool = False,
                   step: str = "double",
                   global_fine_search: bool = False, *, return_matches: Literal[True],
                   return_stats: Literal[True]) -> Tuple[_U8, _I32, CompletionStats]: ...
def wexler_complete(frames: npt.ArrayLike, mask: npt.ArrayLike, patch: Sequence[int] = (5, 5, 5),
                    min_width: int = 64, max_iter: Sequence[int] = (10, 5, 3),
                    patchmatch_n_iter: int = 4, seed: int = 0) -> _U8: ...
def per_frame_patchmatch(frames: npt.ArrayLike, mask: npt.ArrayLike, patch: Sequence[int] = (5, 5),
                         min_width: int = 64, max_iter: Sequence[int] = (10, 5, 3),
                         patchmatch_n_iter: int = 4, seed: int = 0,
                         seed_per_frame: bool = True) -> _U8: ...
def inpaint_telea(image: npt.ArrayLike, mask: npt.ArrayLike, radius: float = 5.0) -> _U8: ...
def ssim_masked(a: npt.ArrayLike, b: npt.ArrayLike, mask: npt.ArrayLike) -> float: ...
def psnr_masked(a: npt.ArrayLike, b: npt.ArrayLike, mask: npt.ArrayLike) -> float: ...
def flicker(frames: npt.ArrayLike, mask: npt.ArrayLike) -> float: ...
def make_clip(kind: str, n_frames: int = 20, height: int = 180, width: int = 320,
              radius: float = 25.0, speed: float = 8.0, step: float = 8.0, zoom: float = 1.003,
              hole: Tuple[int, int] = (30, 40), period: float = 24.0, noise: float = 0.0,
              seed: int = 0) -> Tuple[_U8, _U8, _U8]: ...
def load_frames(path: Any) -> _U8: ...
def load_mask(path: Any, n_frames: int, height: int, width: int) -> npt.NDArray[np.bool_]: ...
def save_frames(path: Any, frames: npt.ArrayLike) -> list[str]: ...
