from dataclasses import dataclass
from typing import Any, Literal, Optional, Sequence, Tuple, overload

import numpy as np

__all__ = ["HybridOctree", "build", "load", "from_bytes", "voxelize", "bvh_intersect",
           "make_scene", "BuildStats", "MemoryReport", "RayHits", "RenderStats"]

@dataclass(frozen=True)
class BuildStats:
    n_fragments: int
    n_degenerate_triangles: int
    n_nodes: int
    n_voxels: int
    n_early_leaves: int
    n_finest_leaves: int
    voxelize_seconds: float
    hierarchy_seconds: float
    attributes_seconds: float

@dataclass(frozen=True)
class MemoryReport:
    nodes: int
    triangles: int
    tri_index: int
    voxels: int
    total: int

@dataclass(frozen=True)
class RayHits:
    t: np.ndarray
    prim: np.ndarray
    level: np.ndarray
    normal: Optional[np.ndarray] = None
    color: Optional[np.ndarray] = None

@dataclass(frozen=True)
class RenderStats:
    n_triangle_hits: int
    n_voxel_hits: int
    n_misses: int
    blend_min: float
    blend_max: float
    seconds: float

class HybridOctree:
    stats: Optional[BuildStats]
    def __init__(self, native: Any, stats: Optional[BuildStats] = None) -> None: ...
    @property
    def depth(self) -> int: ...
    @property
    def early_stop(self) -> bool: ...
    @property
    def n_nodes(self) -> int: ...
    @property
    def n_voxels(self) -> int: ...
    @property
    def n_triangles(self) -> int: ...
    @property
    def cube(self) -> Tuple[Tuple[float, float, float], float]: ...
    def memory_report(self) -> MemoryReport: ...
    def intersect(self, origins: np.ndarray, dirs: np.ndarray, mode: str = ...,
                  footprint_spread: float = ..., lod_scale: float = ..., blend: bool = ...,
                  small_leaves_as_voxels: bool = ..., level: Optional[int] = ...,
                  shading: bool = ...) -> RayHits: ...
    @overload
    def render(self, eye: Sequence[float], target: Sequence[float],
               up: Sequence[float] = ..., fov_deg: float = ..., width: int = ...,
               height: int = ..., mode: str = ..., light_pos: Optional[Sequence[float]] = ...,
               shadows: bool = ..., lod_scale: float = ..., blend: bool = ...,
               small_leaves_as_voxels: bool = ..., level: Optional[int] = ...,
               focus: Optional[Sequence[float]] = ..., n_ao_samples: int = ...,
               ao_radius: float = ..., return_stats: Literal[False] = ...) -> np.ndarray: ...
    @overload
    def render(self, eye: Sequence[float], target: Sequence[float],
               up: Sequence[float] = ..., fov_deg: float = ..., width: int = ...,
               height: int = ..., mode: str = ..., light_pos: Optional[Sequence[float]] = ...,
               shadows: bool = ..., lod_scale: float = ..., blend: bool = ...,
               small_leaves_as_voxels: bool = ..., level: Optional[int] = ...,
               focus: Optional[Sequence[float]] = ..., n_ao_samples: int = ...,
               ao_radius: float = ..., *,
               return_stats: Literal[True]) -> Tuple[np.ndarray, RenderStats]: ...
    def occupancy(self, level: int) -> np.ndarray: ...
    def voxels(self) -> Tuple[np.ndarray, np.ndarray, np.ndarray]: ...
    def save(self, path) -> None: ...
    def to_bytes(self) -> bytes: ...

def build(vertices: np.ndarray, faces: np.ndarray, colors: Optional[np.ndarray] = ...,
          depth: int = ..., early_stop: bool = ...,
          domain: Optional[Tuple[Sequence[float], float]] = ...) -> HybridOctree: ...
def load(path) -> HybridOctree: ...
def from_bytes(data: bytes) -> HybridOctree: ...
def voxelize(vertices: np.ndarray, faces: np.ndarray, depth: int,
             domain: Tuple[Sequence[float], float]) -> Tuple[np.ndarray, np.ndarray]: ...
def bvh_intersect(vertices: np.ndarray, faces: np.ndarray, origins: np.ndarray,
                  dirs: np.ndarray) -> Tuple[np.ndarray, np.ndarray]: ...
def make_scene(name: str, size: Optional[int] = ..., seed: int = ...
          ) -> Tuple[np.ndarray, np.ndarray, np.ndarray]: ...
