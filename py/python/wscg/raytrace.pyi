import os
from dataclasses import dataclass
from typing import final, Any, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_F32 = npt.NDArray[np.float32]
_F64 = npt.NDArray[np.float64]

__all__ = ["load_paint", "save_paint", "PaintDescription", "render_plate", "xyz_to_srgb", "make_tile", "plate_layout", "glint_stats",
           "binocular_overlap", "workshop", "fresnel_conductor", "fresnel_dielectric",
           "aluminium_nk", "daylight", "spectrum_to_xyz", "project", "FLAKE_DTYPE",
           "PlateInfo", "GlintStats", "WorkshopScores", "ManyLightScene",
           "make_manylight_scene", "manylight_from_arrays", "load_manylight_obj",
           "render_manylight", "ManyLightStats", "manylight_record_weight"]
FLAKE_DTYPE: np.dtype

@dataclass(frozen=True)
class PlateInfo:
    flake_id: npt.NDArray[np.uint64]
    glint_ids: npt.NDArray[np.uint64]
    mm_per_px: float
    lamp_y: float
    region_mm: Tuple[float, float, float, float]
    bands_nm: Optional[_F64] = None
    spectrum: Optional[_F32] = None

@dataclass(frozen=True)
class GlintStats:
    glint_density_per_mm2: float
    mean_y: float
    median_y: float
    y99_over_median: float
    mean_glint_area_mm2: float
    mean_glint_peak_y: float
    n_glints: int
    threshold: float

@dataclass(frozen=True)
class WorkshopScores:
    runs: List[Tuple[float, float]]
    scores: _F64
    features: _F64
    reference_features: _F64
    feature_names: List[str]
    scale_log: _F64

@dataclass(frozen=True)
class ManyLightStats:
    method: str
    n_vpls: int
    setup_seconds: float
    cache_seconds: float
    render_seconds: float
    records: _F64
    record_pixels: npt.NDArray[np.int64]
    record_inserted: npt.NDArray[np.bool_]
    record_normals: _F64
    record_radii: _F64
    n_records: Optional[int] = None
    n_initial: Optional[int] = None
    n_inserted: Optional[int] = None
    n_passes: Optional[int] = None
    n_cache_shadow_rays: Optional[int] = None
    cache_bytes: Optional[int] = None

def xyz_to_srgb(xyz: npt.ArrayLike, exposure: float = 1.0) -> _F32: ...
def render_plate(eye: str = "cyclopean", color_space: str = "xyz", return_info: bool = False, *,
                 radius_um: float = 30.0, radius_cv: float = 0.15, thickness_um: float = 0.5,
                 density: float = 6.5, tilt: str = "halfnormal", tilt_deg: float = 8.0,
                 layer_um: float = 20.24, tile_um: float = 450.0, model: str = "boolean",
                 n_pool_tiles: int = 16, max_clamped_fraction: float = 0.05, seed: int = 0,
                 size_mm: Tuple[float, float] = (150.0, 100.0), coat_ior: float = 1.5,
                 coat_um: float = 40.0, binder_ior: float = 1.5,
                 binder_sigma_a_per_mm: float = 0.0, base_albedo: float = 0.0,
                 metal: str = "al_k6", metal_nk: Optional[Tuple[float, float]] = None,
                 light_elevation_deg: float = 45.0, light_deg: float = 1.0,
                 light_cct: Optional[float] = None,
                 light_spectrum: Optional[npt.ArrayLike] = None, radiance_scale: float = 1.0,
                 spp: int = 64, max_depth: int = 8, render_seed: int = 0,
                 region_mm: Optional[Tuple[float, float, float, float]] = None,
                 magnification: float = 1.0, independent_samples: bool = False,
                 color_mode: str = "spectral", keep_spectrum: bool = False,
                 n_photons: int = 2_000_000, n_photon_neighbors: int = 50
                 ) -> Union[_F32, Tuple[_F32, _F32], Tuple[_F32, PlateInfo],
                            Tuple[Tuple[_F32, PlateInfo], Tuple[_F32, PlateInfo]]]: ...
def make_tile(*, radius_um: float = 30.0, radius_cv: float = 0.15, thickness_um: float = 0.5,
              density: float = 6.5, tilt: str = "halfnormal", tilt_deg: float = 8.0,
              layer_um: float = 20.24, tile_um: float = 450.0, model: str = "boolean",
              n_pool_tiles: int = 16, max_clamped_fraction: float = 0.05,
              seed: int = 0) -> Tuple[np.ndarray, int]: ...
def plate_layout(region_mm: Tuple[float, float, float, float], *, radius_um: float = 30.0,
                 radius_cv: float = 0.15, thickness_um: float = 0.5, density: float = 6.5,
                 tilt: str = "halfnormal", tilt_deg: float = 8.0, layer_um: float = 20.24,
                 tile_um: float = 450.0, model: str = "boolean", n_pool_tiles: int = 16,
                 max_clamped_fraction: float = 0.05, seed: int = 0,
                 size_mm: Tuple[float, float] = (150.0, 100.0)
                 ) -> Tuple[list[np.ndarray], list[Tuple[float, float, int, int]]]: ...
def glint_stats(y: npt.ArrayLike, mm_per_px: float) -> GlintStats: ...
def binocular_overlap(left_ids: npt.ArrayLike, right_ids: npt.ArrayLike) -> float: ...
def workshop(reference: Tuple[float, float] = (26.0, 7.3),
             runs: Optional[Sequence[Tuple[float, float]]] = None, condition: str = "stereo",
             n_reference_renders: int = 4, jnd_log: float = 0.25, *,
             radius_cv: float = 0.15, thickness_um: float = 0.5, tilt: str = "halfnormal",
             tilt_deg: float = 8.0, layer_um: float = 20.24, tile_um: float = 450.0,
             model: str = "boolean", n_pool_tiles: int = 16,
             max_clamped_fraction: float = 0.05, seed: int = 0,
             size_mm: Tuple[float, float] = (150.0, 100.0), coat_ior: float = 1.5,
             coat_um: float = 40.0, binder_ior: float = 1.5,
             binder_sigma_a_per_mm: float = 0.0, base_albedo: float = 0.0,
             metal: str = "al_k6", metal_nk: Optional[Tuple[float, float]] = None,
             light_elevation_deg: float = 75.0, light_deg: float = 1.0,
             light_cct: Optional[float] = None,
             light_spectrum: Optional[npt.ArrayLike] = None, radiance_scale: float = 1.0,
             spp: int = 64, max_depth: int = 8, render_seed: int = 0,
             region_mm: Optional[Tuple[float, float, float, float]] = None,
             magnification: float = 4.0, independent_samples: bool = False,
             color_mode: str = "spectral", keep_spectrum: bool = False,
             n_photons: int = 2_000_000, n_photon_neighbors: int = 50) -> WorkshopScores: ...
def fresnel_conductor(cos_i: npt.ArrayLike, n: float, k: float) -> _F64: ...
def fresnel_dielectric(cos_i: npt.ArrayLike, eta: float) -> _F64: ...
def aluminium_nk(lambda_nm: npt.ArrayLike) -> _F64: ...
def daylight(cct_k: float) -> _F64: ...
def spectrum_to_xyz(spd: npt.ArrayLike) -> _F64: ...
def project(points: npt.ArrayLike, eye: str = "cyclopean") -> _F64: ...


# Paper 08: many-light rendering with adaptive importance caching.
@final
class ManyLightScene:
    @property
    def n_triangles(self) -> int: ...
    @property
    def n_emitters(self) -> int: ...
    @property
    def n_skipped_degenerate(self) -> int: ...
    @property
    def camera(self) -> dict: ...
    def triangle_vertices(self) -> _F64: ...
    def triangle_albedo(self) -> _F64: ...
    def triangle_emission(self) -> _F64: ...
    def occluded(self, origins: npt.ArrayLike, targets: npt.ArrayLike) -> npt.NDArray[np.bool_]: ...

def make_manylight_scene(name: str = "cornell", subdiv: int = 1, width: int = 256,
                         height: int = 192) -> ManyLightScene: ...
def manylight_from_arrays(vertices: npt.ArrayLike, faces: npt.ArrayLike, albedo: npt.ArrayLike,
                          emission: npt.ArrayLike,
                          camera: Optional[dict] = None) -> ManyLightScene: ...
def load_manylight_obj(path: Any, camera: Optional[dict] = None) -> ManyLightScene: ...
def render_manylight(scene: ManyLightScene, method: str = "adaptive",
                     camera: Optional[dict] = None, *, n_vpl_paths: int = 1000,
                     max_bounces: int = 2, n_cache: Optional[int] = None, spp: int = 16,
                     seed: int = 0, vpl_seed: int = 0, clamp_dist: Optional[float] = None,
                     m_nearest: int = 3, delta: float = 0.5, init_fraction: float = 0.6,
                     theta_max: float = ..., lam: float = 5.0,
                     dmax_factor: float = 2.0, defensive: float = 0.5,
                     pixel_filter: str = "box",
                     n_pixel_samples: int = 4, near_share: float = 0.25,
                     n_near_vpls: int = 32) -> Tuple[_F32, ManyLightStats]: ...
def manylight_record_weight(x: npt.ArrayLike, normal: npt.ArrayLike, record_pos: npt.ArrayLike,
                            record_normal: npt.ArrayLike, d_max: float,
                            theta_max: float = ..., lam: float = 5.0) -> _F64: ...


@dataclass(frozen=True)
class PaintDescription:
    radius_um: Optional[float] = ...
    density: Optional[float] = ...
    tilt_deg: Optional[float] = ...
    model: Optional[str] = ...
    thickness_um: Optional[float] = ...
    layer_um: Optional[float] = ...
    binder_absorption_per_mm: Optional[float] = ...
    binder_ior: Optional[float] = ...
    base_albedo: Optional[float] = ...
    coat_ior: Optional[float] = ...
    coat_um: Optional[float] = ...
    seed: Optional[int] = ...


def load_paint(path: Union[str, os.PathLike]) -> PaintDescription: ...
def save_paint(path: Union[str, os.PathLike], paint: PaintDescription) -> None: ...
