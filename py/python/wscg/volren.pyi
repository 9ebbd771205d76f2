import os
from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

Roi = Tuple[int, int, int, int, int, int]

__all__ = ["HybridServer", "HybridClient", "render_reference", "make_phantom", "phantom_tfs",
           "octree_address", "orbit_camera", "haar_blocks", "SizeReport", "render",
           "PreparedVolume", "light_buffer", "preintegration_table", "make_marschner_lobb",
           "marschner_lobb_tf", "tissue_tf", "skin_tf", "labels_to_density", "load_vti",
           "mean_abs_diff", "study", "METHODS", "KERNELS", "IlluminationStudy", "StudyEntry"]

@dataclass(frozen=True)
class SizeReport:
    raw: int
    wavelets: int
    gradient_octree: int
    hybrid_static: int
    hybrid_roi: int
    hybrid: int
    thin_client_frame: Optional[int]

@dataclass(frozen=True)
class StudyEntry:
    method: str
    slice_distance: float
    n_subsamples: int
    mad: float
    energy: float
    seconds: float
    alias_free: bool

@dataclass(frozen=True)
class IlluminationStudy:
    reference_seconds: float
    fine_energy: float
    entries: List[StudyEntry]

def orbit_camera(shape: Sequence[int], azimuth: float = 30.0, elevation: float = 20.0,
                 fov_deg: float = 30.0) -> dict: ...

class HybridServer:
    @property
    def leaf_count(self) -> int: ...
    @property
    def node_counts(self) -> List[int]: ...
    def __init__(self, volume: npt.ArrayLike, tfs: Sequence[npt.ArrayLike], canonical: int = 0,
                 steps_sent: int = 2, delta: float = 2.0) -> None: ...
    def static_package(self) -> bytes: ...
    def roi_package(self, roi: Roi) -> bytes: ...
    def size_report(self, roi: Roi, roi_tf: int = 1, thin_client_view: Optional[dict] = None,
                    viewport: Tuple[int, int] = (1080, 1920)) -> SizeReport: ...

class HybridClient:
    @property
    def roi(self) -> Optional[Roi]: ...
    @property
    def lowres(self) -> npt.NDArray[np.float32]: ...
    @property
    def shape(self) -> Tuple[int, int, int]: ...
    def __init__(self, static_package: bytes) -> None: ...
    def set_roi(self, roi_package: bytes) -> None: ...
    def clear_roi(self) -> None: ...
    def render(self, eye: Sequence[float], target: Sequence[float],
               up: Sequence[float] = ..., fov_deg: float = 30.0,
               size: Tuple[int, int] = (512, 512), roi_tf: int = 1,
               mode: str = "hybrid") -> npt.NDArray[np.float32]: ...

def render_reference(volume: npt.ArrayLike, tf: npt.ArrayLike, eye: Sequence[float],
                     target: Sequence[float], up: Sequence[float] = ...,
                     fov_deg: float = 30.0, size: Tuple[int, int] = (512, 512),
                     roi: Optional[Roi] = None,
                     roi_tf: Optional[npt.ArrayLike] = None) -> npt.NDArray[np.float32]: ...
def make_phantom(name: str = "head", shape: Optional[Tuple[int, int, int]] = None,
                 seed: int = 0) -> npt.NDArray[np.uint8]: ...
def phantom_tfs(name: str = "head") -> List[npt.NDArray[np.float64]]: ...
def octree_address(index: Sequence[int], r: int) -> Tuple[Tuple[int, int, int], List[int]]: ...
def haar_blocks(blocks: npt.ArrayLike) -> npt.NDArray[np.float32]: ...

# Paper 15: convolution-based volume illumination.

METHODS: Tuple[str, ...]
KERNELS: Tuple[str, ...]

class PreparedVolume:
    def __init__(self, volume: npt.ArrayLike, spacing: Sequence[float] = ...,
                 value_range: Optional[Tuple[float, float]] = None) -> None: ...
    @property
    def shape(self) -> Tuple[int, int, int]: ...
    @property
    def spacing(self) -> Tuple[float, float, float]: ...

def render(volume: Union[npt.ArrayLike, PreparedVolume], tf: npt.ArrayLike,
           spacing: Optional[Sequence[float]] = None,
           view_dir: Sequence[float] = ..., up: Sequence[float] = ...,
           size: Tuple[int, int] = (512, 512), pixel_size: Optional[float] = None,
           center: Optional[Sequence[float]] = None, method: str = "scs",
           slice_distance: float = 1.0, n_subsamples: int = 0, kernel: str = "gaussian",
           spread: float = 0.5, tan_half: float = 0.5, light_dir: Sequence[float] = ...,
           ambient: float = 0.0, background: Sequence[float] = ..., interp: str = "trilinear",
           value_range: Optional[Tuple[float, float]] = None,
           light_attenuation: str = "segment",
           border: str = "open") -> npt.NDArray[np.float32]: ...
def light_buffer(volume: Union[npt.ArrayLike, PreparedVolume], tf: npt.ArrayLike, depth: float,
                 spacing: Optional[Sequence[float]] = None, view_dir: Sequence[float] = ...,
                 up: Sequence[float] = ..., size: Tuple[int, int] = (512, 512),
                 pixel_size: Optional[float] = None, center: Optional[Sequence[float]] = None,
                 method: str = "scs", slice_distance: float = 1.0, n_subsamples: int = 0,
                 kernel: str = "gaussian", spread: float = 0.5, tan_half: float = 0.5,
                 light_dir: Sequence[float] = ..., ambient: float = 0.0,
                 background: Sequence[float] = ..., interp: str = "trilinear",
                 value_range: Optional[Tuple[float, float]] = None,
                 light_attenuation: str = "segment", border: str = "open"
                 ) -> Tuple[npt.NDArray[np.float32], float]: ...
def preintegration_table(tf: npt.ArrayLike, ds: float) -> npt.NDArray[np.float32]: ...
def make_marschner_lobb(n: int = 41) -> npt.NDArray[np.float32]: ...
def marschner_lobb_tf() -> npt.NDArray[np.float32]: ...
def tissue_tf() -> npt.NDArray[np.float32]: ...
def skin_tf() -> npt.NDArray[np.float32]: ...
def labels_to_density(labels: npt.ArrayLike, spacing: Sequence[float] = ...,
                      sigma: float = 1.0) -> npt.NDArray[np.float32]: ...
def load_vti(path: Union[str, os.PathLike]
             ) -> Tuple[npt.NDArray[np.generic], Tuple[float, float, float]]: ...
def mean_abs_diff(a: npt.ArrayLike, b: npt.ArrayLike) -> float: ...
def study(volume: Union[npt.ArrayLike, PreparedVolume], tf: npt.ArrayLike, n_views: int = 4,
          size: int = 256,
          azimuth: float = 30.0, elevation: float = 20.0, distances: Sequence[float] = ...,
          max_subsamples: int = 5, reference: float = 0.2, fine: float = 0.1,
          spacing: Optional[Sequence[float]] = None, spread: float = 0.5,
          light_dir: Sequence[float] = ..., ambient: float = 0.0, max_mad: float = 0.005,
          max_energy_ratio: float = 2.0,
          value_range: Optional[Tuple[float, float]] = None) -> IlluminationStudy: ...
