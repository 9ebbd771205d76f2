"""Unified triangle/voxel octree: paper 10 of WSCG vol. 23 ("A Unified Triangle/Voxel
Structure for GPUs and its Applications").

One sparse voxel octree serves as both a level-of-detail voxel representation and a triangle
ray-tracing structure: every non-empty node carries a pre-filtered voxel (mean colour, mean
normal), the leaves reference the triangles that overlap them, and construction stops early at
nodes holding at most two triangles. Rays stop at the voxel level that matches their pixel
footprint (with colour blending against the parent level) and intersect triangles up close.

- :func:`build` builds the tree from a triangle mesh (exact triangle/box voxelization at
  ``2^depth`` cells per axis; ``early_stop=False`` is the paper's full-octree baseline).
- :class:`HybridOctree` ``.intersect`` casts rays in ``"triangles"`` (exact, the baseline),
  ``"voxels"`` or ``"hybrid"`` mode; ``.render`` draws Phong-shaded images with shadow rays;
  ``.memory_report`` gives the columns of the paper's Table 2; ``.save`` / :func:`load` keep
  the tree and its mesh in a checksummed file.
- :func:`voxelize` returns the exact (cell, triangle) fragments; :func:`bvh_intersect` is the
  BVH baseline; :func:`make_scene` generates the synthetic test scenes.

Conventions (``py/API.md``): vertices ``(V, 3)`` float64 ``(x, y, z)``, faces ``(F, 3)``
integer, colours ``(V, 3)`` in ``[0, 1]``; rays ``(N, 3)`` float32 origins and directions
(any length; ``t`` is measured in direction units); camera and light positions are world
points ``(x, y, z)``. The domain is a cube; by default the mesh's bounding box grown to a
cube by ``1e-5`` of its side, centred. Grid cells (:func:`voxelize`,
:meth:`HybridOctree.occupancy`) are indices ``(k, j, i)`` in array axis order, so that they
index a ``(2^level,) * 3`` array ``[z, y, x]``: with the root cell ``(min_xyz, side)`` and
``h = side / 2^level``, cell ``(k, j, i)`` covers ``min_xyz + h * [(i, j, k), (i + 1, j +
1, k + 1)]``. Bad input raises ``ValueError``; unreadable or damaged files raise
``OSError``.

References: Crassin and Green, "Octree-based sparse voxelization using the GPU hardware
rasterizer", OpenGL Insights (2012); Laine and Karras, "Efficient sparse voxel octrees",
I3D 2010; Igehy, "Tracing ray differentials", SIGGRAPH 1999; Akenine-Möller, "Fast 3D
triangle-box overlap testing", JGT 6(1) 2001.
"""

from __future__ import annotations

from typing import Optional, Sequence, Tuple, Union

import numpy as np

from ._native import octree as _o
from ._native.octree import bvh_intersect, make_scene, voxelize
from ._checks import integer_ranges as _integer_ranges
from ._results import from_mapping as _from_mapping, result as _result

__all__ = ["HybridOctree", "build", "load", "from_bytes", "voxelize", "bvh_intersect",
           "make_scene", "BuildStats", "MemoryReport", "RayHits", "RenderStats"]

_MODES = ("triangles", "voxels", "hybrid")


@_result
class BuildStats:
    """What the construction of :func:`build` did (``HybridOctree.stats``).

    Attributes
    ----------
    n_fragments : int
        (finest cell, triangle) pairs of the exact voxelization.
    n_degenerate_triangles : int
        Zero-area triangles (they produce no fragment).
    n_nodes : int
        Nodes, empty children included.
    n_voxels : int
        Non-empty nodes (one voxel each).
    n_early_leaves : int
        Leaves that stopped above the deepest level (at most two triangles).
    n_finest_leaves : int
        Leaves at the deepest level.
    voxelize_seconds, hierarchy_seconds, attributes_seconds : float
        Wall-clock seconds of the three phases: voxelization, the level-by-level hierarchy
        and the bottom-up voxel colours and normals.
    """

    n_fragments: int
    n_degenerate_triangles: int
    n_nodes: int
    n_voxels: int
    n_early_leaves: int
    n_finest_leaves: int
    voxelize_seconds: float
    hierarchy_seconds: float
    attributes_seconds: float


@_result
class MemoryReport:
    """Bytes per part of a tree, the columns of the paper's Table 2
    (:meth:`HybridOctree.memory_report`).

    Attributes
    ----------
    nodes : int
        Bytes of the nodes, 8 per node, empty children included.
    triangles : int
        Bytes of the triangles, 48 per triangle.
    tri_index : int
        Bytes of the triangle index array (pairs and lists of the leaves), 4 per word.
    voxels : int
        Bytes of the voxels, 8 per non-empty node.
    total : int
        The sum, bytes.
    """

    nodes: int
    triangles: int
    tri_index: int
    voxels: int
    total: int


@_result
class RayHits:
    """The nearest hits of ``N`` rays (:meth:`HybridOctree.intersect`).

    Attributes
    ----------
    t : float32 array (N,)
        Ray parameter of the hit, in units of the direction's length; ``inf`` on a miss.
    prim : int64 array (N,)
        Triangle index of a triangle hit; -1 for a miss or a voxel hit.
    level : int8 array (N,)
        Octree level of a voxel hit; -1 otherwise.
    normal : float32 array (N, 3) or None
        Unit normal at the hit (zeros on a miss); None without ``shading``.
    color : float32 array (N, 3) or None
        Linear RGB in ``[0, 1]`` at the hit (zeros on a miss); None without ``shading``.
    """

    t: np.ndarray
    prim: np.ndarray
    level: np.ndarray
    normal: Optional[np.ndarray] = None
    color: Optional[np.ndarray] = None


@_result
class RenderStats:
    """What a render of :meth:`HybridOctree.render` hit, per primary ray.

    Attributes
    ----------
    n_triangle_hits : int
        Primary rays that stopped at a triangle.
    n_voxel_hits : int
        Primary rays that stopped at a voxel (the LoD cut).
    n_misses : int
        Primary rays that hit nothing.
    blend_min, blend_max : float
        Range of the parent blending factor ``i = (2 v_w - f) / v_w`` over the voxel hits, in
        ``[0, 1]``.
    seconds : float
        Wall-clock seconds of the render.
    """

    n_triangle_hits: int
    n_voxel_hits: int
    n_misses: int
    blend_min: float
    blend_max: float
    seconds: float


class HybridOctree:
    """A built octree and the mesh it references. Create with :func:`build` or :func:`load`."""

    def __init__(self, native, stats: Optional[BuildStats] = None):
        if not isinstance(native, _o.HybridOctree):
            raise ValueError(f"`native` must be a native tree; build one with build() or read one "
                             f"with load() / from_bytes(), got {type(native).__name__}")
        self._n = native
        #: What the construction did (a :class:`BuildStats`: fragments, nodes, voxels, early
        #: leaves, phase times); None for a tree read by :func:`load` or :func:`from_bytes`.
        self.stats = stats

    @property
    def depth(self) -> int:
        """Deepest level ``L``."""
        return self._n.depth

    @property
    def early_stop(self) -> bool:
        """Whether construction stopped at nodes with at most two triangles."""
        return self._n.early_stop

    @property
    def n_nodes(self) -> int:
        """Nodes, empty children included (8 bytes each)."""
        return self._n.n_nodes

    @property
    def n_voxels(self) -> int:
        """Non-empty nodes (one 8-byte voxel each)."""
        return self._n.n_voxels

    @property
    def n_triangles(self) -> int:
        """Triangles of the mesh."""
        return self._n.n_triangles

    @property
    def cube(self) -> Tuple[Tuple[float, float, float], float]:
        """The root cell as ``(min_xyz, side)``."""
        m, s = self._n.cube
        return tuple(m), s

    def memory_report(self) -> MemoryReport:
        """Bytes per part, the columns of the paper's Table 2, as a :class:`MemoryReport`:
        ``nodes`` (8 B per node, empty children included), ``triangles`` (48 B per
        triangle), ``tri_index`` (4 B per word of the pair/list array), ``voxels`` (8 B per
        voxel) and ``total``."""
        return _from_mapping(MemoryReport, self._n.memory_report())

    def intersect(self, origins, dirs, mode: str = "triangles", footprint_spread: float = 0.0,
                  lod_scale: float = 1.0, blend: bool = True,
                  small_leaves_as_voxels: bool = False, level: Optional[int] = None,
                  shading: bool = True) -> RayHits:
        """Nearest hits of ``N`` rays.

        Parameters
        ----------
        origins, dirs : (N, 3) arrays
            Ray origins and directions (a zero or non-finite direction misses).
        mode : {"triangles", "voxels", "hybrid"}
            ``"triangles"``: exact triangle hits (the baseline); ``"voxels"``: the first
            non-empty node at ``level`` or a leaf; ``"hybrid"``: the paper's LoD, stopping at
            the first level whose voxel side is at most ``lod_scale`` times the pixel
            footprint ``footprint_spread * distance``.
        footprint_spread : float
            Footprint growth per unit distance (``2 tan(fov_y / 2) / height`` for a pinhole
            camera); 0 disables the LoD stop.
        blend : bool
            Blend a voxel's colour with its parent's by ``i = (2 v_w - f) / v_w``.
        small_leaves_as_voxels : bool
            Also stop at leaves holding one or two triangles (by default they are intersected
            exactly, the paper's reading).
        shading : bool
            Also return each hit's normal and colour. ``False`` returns the same ``t``,
            ``prim`` and ``level`` faster (no reads of vertex indices, vertex colours or voxel
            attributes): the query for depth maps, picking and distance probes.

        Returns
        -------
        RayHits
            ``t`` float32 (inf on a miss), ``prim`` int64 (-1 for a miss or a voxel hit),
            ``level`` int8 (voxel level, -1 otherwise), and with ``shading`` ``normal`` and
            ``color`` (N, 3) (None without).
        """
        if mode not in _MODES:
            raise ValueError(f"mode {mode!r} is not valid; valid: {', '.join(_MODES)}")
        return _from_mapping(RayHits, self._n.intersect(
            origins, dirs, mode, footprint_spread, lod_scale, blend, small_leaves_as_voxels,
            level, shading))

    def render(self, eye: Sequence[float], target: Sequence[float],
               up: Sequence[float] = (0.0, 0.0, 1.0), fov_deg: float = 45.0, width: int = 512,
               height: int = 512, mode: str = "hybrid",
               light_pos: Optional[Sequence[float]] = None, shadows: bool = True,
               lod_scale: float = 1.0, blend: bool = True,
               small_leaves_as_voxels: bool = False, level: Optional[int] = None,
               focus: Optional[Sequence[float]] = None, n_ao_samples: int = 0,
               ao_radius: float = 0.05, return_stats: bool = False
               ) -> Union[np.ndarray, Tuple[np.ndarray, RenderStats]]:
        """Renders a ``(height, width, 3)`` float32 linear-RGB image: one primary ray per
        pixel, Phong shading (ka 0.1, kd 0.8, ks 0.2, shininess 32), one point light
        (default: above and beside the cube) and one shadow ray per hit.

        ``focus = (cx, cy, a, b, falloff)`` (pixels) gives view-dependent detail in hybrid
        mode (the paper's display-wall application): triangles inside the ellipse, the LoD
        scale doubling every ``falloff`` pixels outside it. ``n_ao_samples``
        ambient-occlusion rays of length ``ao_radius`` cube sides scale the ambient term.
        ``eye``, ``target`` and ``light_pos`` are world points ``(x, y, z)``. With
        ``return_stats`` returns ``(image, RenderStats)``: hit counts (``n_triangle_hits``,
        ``n_voxel_hits``, ``n_misses``), the blend factor range and seconds."""
        if mode not in _MODES:
            raise ValueError(f"mode {mode!r} is not valid; valid: {', '.join(_MODES)}")
        img, st = self._n.render(eye, target, up, fov_deg, width, height, mode, light_pos,
                                 shadows, lod_scale, blend, small_leaves_as_voxels, level,
                                 focus, n_ao_samples, ao_radius)
        if not return_stats:
            return img
        return img, _from_mapping(RenderStats, st, rename={
            "triangle_hits": "n_triangle_hits", "voxel_hits": "n_voxel_hits",
            "misses": "n_misses"})

    def occupancy(self, level: int) -> np.ndarray:
        """``(K, 3)`` integer cells ``(k, j, i)`` (array axis order, ``i`` along x; see the
        module documentation) of the non-empty nodes at ``level`` (leaves that stopped above
        it are not expanded)."""
        return self._n.occupancy(level)

    def voxels(self) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Colours ``(M, 3)``, unit normals ``(M, 3)`` and levels ``(M,)`` of every voxel."""
        return self._n.voxels()

    def save(self, path) -> None:
        """Writes the tree and its mesh to ``path`` (a checksummed binary file)."""
        self._n.save(str(path))

    def to_bytes(self) -> bytes:
        """The file content of :meth:`save`."""
        return self._n.to_bytes()

    def __reduce__(self):
        return (from_bytes, (self.to_bytes(),))

    def __repr__(self) -> str:
        return (f"HybridOctree(depth={self.depth}, early_stop={self.early_stop}, "
                f"nodes={self.n_nodes}, voxels={self.n_voxels}, triangles={self.n_triangles})")


# Native keys of the build statistics renamed to the field names of py/API.md.
_BUILD_KEYS = {"fragments": "n_fragments", "degenerate_triangles": "n_degenerate_triangles",
               "nodes": "n_nodes", "voxels": "n_voxels", "early_leaves": "n_early_leaves",
               "finest_leaves": "n_finest_leaves", "voxelize_s": "voxelize_seconds",
               "hierarchy_s": "hierarchy_seconds", "attributes_s": "attributes_seconds"}


def build(vertices, faces, colors=None, depth: int = 9, early_stop: bool = True,
          domain: Optional[Tuple[Sequence[float], float]] = None) -> HybridOctree:
    """Builds the hybrid octree of a triangle mesh.

    Parameters
    ----------
    vertices : (V, 3) float array
    faces : (F, 3) integer array
    colors : (V, 3) array in [0, 1], optional
        Per-vertex colours (light grey when absent).
    depth : int
        Deepest level ``L`` (the paper: 9, i.e. 512^3); at most 21; 0 is a single node.
    early_stop : bool
        Stop at nodes with at most two triangles (the paper's method); ``False`` builds the
        full-octree baseline of Table 2.
    domain : ((x, y, z), side), optional
        An explicit cube containing the mesh.

    Returns
    -------
    HybridOctree
        With ``.stats``, a :class:`BuildStats`: the fragment, node and voxel counts and the
        phase times.
    """
    n, st = _o.build_octree(vertices, faces, colors, depth, early_stop, domain)
    return HybridOctree(n, _from_mapping(BuildStats, st, rename=_BUILD_KEYS))


def load(path) -> HybridOctree:
    """Reads a tree saved by :meth:`HybridOctree.save` (``OSError`` if missing or damaged)."""
    return HybridOctree(_o.load(str(path)))


def from_bytes(data: bytes) -> HybridOctree:
    """A tree from :meth:`HybridOctree.to_bytes`."""
    return HybridOctree(_o.from_bytes(bytes(data)))


# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
