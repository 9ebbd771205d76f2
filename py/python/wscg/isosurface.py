"""Isosurfaces of sparse grids with tetrahedral-spline normals: paper 09 of WSCG vol. 23
(Wood and Newman, "Isosurface Orientation Estimation in Sparse Grids Using Tetrahedral
Splines").

Marching cubes on volumes with missing samples (NaN): an edge carries a vertex when both of
its samples are defined and on different sides of the level (inside means ``f >= level``;
scikit-image uses ``f > level``, which differs only where a sample equals the level). Cells
with missing corners are triangulated when the missing corners' sides are given
(``side_hint``) or can be inferred from their neighbours; otherwise they are skipped and
counted.

Vertex normals (all pointing toward increasing ``f``):

- ``"spline"`` (the paper): the gradient of a quadratic Bézier-Bernstein spline on one corner
  tetrahedron of each cell around the vertex's edge, chosen from the cell's triangles; needs
  only four samples per cell and is never zero.
- ``"lsn"``: Locally Supported Normals (Nielson et al. 2002), reconstructed from the paper's
  description: the mean perp of a virtual mesh around the vertex; zero at degenerate
  triangles (reported, never replaced).
- ``"central"``: central differences interpolated along the edge (classic MC); undefined
  (zero) where a neighbour is missing.

Conventions (``py/API.md``): volumes are numpy arrays indexed ``[z, y, x]``; ``spacing`` is
``(dz, dy, dx)`` and ``origin`` ``(oz, oy, ox)``, in array axis order (as in
:mod:`wscg.math`, :mod:`wscg.volseg`, :mod:`wscg.volren` and scikit-image); vertices are
world points ``(x, y, z)``: the sample ``[k, j, i]`` lies at ``(ox + i dx, oy + j dy, oz + k
dz)``. Faces index the vertices and are wound so that their right-hand normal points toward
increasing ``f``. Grid edges (``info.edges``) are rows ``(k, j, i, axis)``: the index of
the edge's low end and the array axis it runs along (0: z, 1: y, 2: x). Bad input raises
``ValueError``.

References: B. A. Wood, T. S. Newman, Journal of WSCG 23 (2015), 73-82. G. M. Nielson,
A. Huang, S. Sylvester, "Approximating normals for marching cubes applied to locally
supported isosurfaces", IEEE Visualization 2002, doi:10.1109/VISUAL.2002.1183808.
"""

from __future__ import annotations

from typing import NamedTuple, Optional, Tuple

import numpy as np

from ._native import isosurface as _m
from ._native.isosurface import (angular_errors, at_risk_configurations, random_dropouts,
                                 rotation_class, sparsify)
from ._checks import integer_ranges as _integer_ranges
from ._results import (from_mapping as _from_mapping, result as _result, tuple_eq as _tuple_eq,
                       tuple_ne as _tuple_ne, tuple_repr as _tuple_repr)

__all__ = ["marching_cubes", "estimate_normals", "sparsify", "random_dropouts",
           "angular_errors", "angular_rms", "rotation_class", "at_risk_configurations",
           "study_full_cd", "study_exact", "fields", "MeshInfo", "NormalStats", "AngularRms",
           "SparseComparison", "ExactComparison"]

# Native keys renamed to the field names of py/API.md (counts are n_<things>).
_COUNTS = {"undefined": "n_undefined", "fallback": "n_fallback",
           "skipped_cells": "n_skipped_cells"}


@_result
class NormalStats:
    """How the normals of :func:`estimate_normals` came about.

    Attributes
    ----------
    n_undefined : int
        Vertices whose normal is undefined (a zero row): a missing central-difference
        neighbour, or a zero LSN perp sum at degenerate triangles (the paper's Table 5).
    n_fallback : int
        Spline normals taken from the fallback (no adjacent cell had a usable tetrahedron).
    n_skipped_cells : int
        Cells with some surface that could not be triangulated (missing corners whose side
        is unknown).
    """

    n_undefined: int
    n_fallback: int
    n_skipped_cells: int


@_result
class MeshInfo:
    """What :func:`marching_cubes` did besides the mesh: the normal counts of
    :class:`NormalStats` and where every vertex and triangle comes from.

    Attributes
    ----------
    n_undefined : int
        Vertices with an undefined (zero) normal.
    n_fallback : int
        Spline normals taken from the fallback.
    n_skipped_cells : int
        Cells with some surface that could not be triangulated.
    edges : int64 array (n, 4)
        The grid edge of each vertex as ``(k, j, i, axis)``: the index of its low end and the
        array axis it runs along (0: z, 1: y, 2: x); pass it to :func:`estimate_normals`.
    cells : int64 array (k, 2)
        Every triangulated cell: the flat index of its low corner in the volume
        (``np.ravel_multi_index((k, j, i), volume.shape)``) and its 8-bit configuration (bit
        ``c`` set when the corner at offsets ``(x, y, z) = (c & 1, c >> 1 & 1, c >> 2)`` is
        inside, ``f >= level``).
    """

    n_undefined: int
    n_fallback: int
    n_skipped_cells: int
    edges: np.ndarray
    cells: np.ndarray


class AngularRms(NamedTuple):
    """The RMS angular error of :func:`angular_rms`, a named tuple (``rms, n_defined,
    n_undefined = angular_rms(a, b)`` unpacks it).

    Attributes
    ----------
    rms : float
        Root mean square of the angles between matching normals, radians, over the rows
        where both are defined; NaN when there are none.
    n_defined : int
        Rows in the RMS.
    n_undefined : int
        Rows left out: a zero (undefined) normal in either array.
    """

    rms: float
    n_defined: int
    n_undefined: int

    __repr__ = _tuple_repr
    # Element-wise, NaN equal to NaN: an RMS over no rows is NaN.
    __eq__ = _tuple_eq
    __ne__ = _tuple_ne


def _rms(d) -> AngularRms:
    return AngularRms(float(d["rms"]), int(d["count"]), int(d["undefined"]))


@_result
class SparseComparison:
    """The paper's Table 1/2 protocol at one level (:func:`study_full_cd`): spline and LSN
    normals on the sparsified volume against central differences on the full volume.

    Attributes
    ----------
    n_vertices : int
        Vertices of the mesh (the same on the full and the sparse volume).
    n_triangles : int
        Triangles of the mesh.
    kept_fraction : float
        Fraction of the samples the sparsification kept.
    cd_defined_on_sparse : float
        Fraction of the vertices where central differences would be defined on the sparse
        volume.
    n_reference_undefined : int
        Vertices where the full-volume central-difference reference itself is zero (left
        out of the errors).
    spline : AngularRms
        Spline normals (sparse) against the reference, radians.
    lsn : AngularRms
        LSN normals (sparse) against the reference, radians.
    n_spline_undefined : int
        Zero spline normals (the paper's claim: always 0).
    n_lsn_undefined : int
        Zero LSN normals (the paper's Table 5).
    """

    n_vertices: int
    n_triangles: int
    kept_fraction: float
    cd_defined_on_sparse: float
    n_reference_undefined: int
    spline: AngularRms
    lsn: AngularRms
    n_spline_undefined: int
    n_lsn_undefined: int


@_result
class ExactComparison:
    """The paper's Table 3 protocol on an analytic field (:func:`study_exact`): normals
    against the field's exact gradient at the vertices.

    Attributes
    ----------
    n_vertices : int
        Vertices of the mesh.
    central : AngularRms
        Central differences on the full grid, radians.
    spline : AngularRms
        Spline normals on the sparsified grid, radians.
    lsn : AngularRms
        LSN normals on the sparsified grid, radians.
    level : float
        The field's isovalue.
    """

    n_vertices: int
    central: AngularRms
    spline: AngularRms
    lsn: AngularRms
    level: float


def marching_cubes(volume, level: float, spacing=(1.0, 1.0, 1.0),
                   normals: Optional[str] = "spline", side_hint=None, selection: str = "mesh",
                   eq8_literal: bool = False, normalize_before_mean: bool = False,
                   ambiguous_face: str = "inside", origin=(0.0, 0.0, 0.0)
                   ) -> Tuple[np.ndarray, np.ndarray, np.ndarray, MeshInfo]:
    """Marching cubes of ``level`` on a volume that may have missing (NaN) samples.

    Parameters
    ----------
    volume : (nz, ny, nx) array_like
        Samples; NaN marks a missing sample. float64 input is processed in double precision
        (vertices and normals float64); anything else is converted to float32.
    level : float
        Isovalue (finite). A level outside the data range gives an empty mesh.
    spacing : (dz, dy, dx), default (1, 1, 1)
        Distance between samples along each array axis (finite, > 0).
    normals : {"spline", "lsn", "central", None}
        Vertex normal estimator (see the module documentation).
    side_hint : (nz, ny, nx) bool array, optional
        Side of every sample (True when ``f >= level``); read only where the volume is NaN.
        :func:`sparsify` returns it.
    selection : {"mesh", "nearest", "both"}
        Spline tetrahedron choice: the paper's rule from the cell's triangles, the nearer
        corner (a static partition), or the mean of both candidates.
    eq8_literal : bool
        Use the paper's eq. 8 as printed instead of the exact spline gradient.
    normalize_before_mean : bool
        Normalise each cell's spline gradient before averaging (the paper averages raw ones).
    ambiguous_face : {"inside", "outside"}
        LSN's assumption on ambiguous faces (isolate the inside or the outside corner).
    origin : (oz, oy, ox), default (0, 0, 0)
        World position of the sample ``[0, 0, 0]``.

    Returns
    -------
    verts : (n, 3) float32, or float64 for a float64 volume
        Vertex positions ``(x, y, z)`` in world units: the sample ``[k, j, i]`` is at
        ``(ox + i dx, oy + j dy, oz + k dz)``.
    faces : (m, 3) int64
        Triangles.
    normals : (n, 3) float32, or float64 for a float64 volume
        Unit normals toward increasing ``f``; zero rows where the estimator is undefined;
        empty for ``normals=None``.
    info : MeshInfo
        ``n_undefined`` (zero normals), ``n_fallback`` (spline normals from the fallback),
        ``n_skipped_cells`` (cells that could not be triangulated), ``edges`` ((n, 4) int64:
        the grid edge of each vertex as ``(k, j, i, axis)``, the index of its low end and the
        array axis it runs along, 0: z, 1: y, 2: x) and ``cells`` ((k, 2) int64: flat index
        and 8-bit configuration of every triangulated cell).

    Examples
    --------
    >>> import numpy as np
    >>> from wscg import isosurface as iso
    >>> z, y, x = np.mgrid[:32, :32, :32]
    >>> vol = np.sqrt((x - 15.3) ** 2 + (y - 16.1) ** 2 + (z - 15.7) ** 2) - 10
    >>> sparse, inside = iso.sparsify(vol, 0.0)
    >>> v, f, n, info = iso.marching_cubes(sparse, 0.0, side_hint=inside)
    >>> info.n_undefined
    0
    """
    verts, faces, nrm, info = _m.marching_cubes(volume, level, spacing, normals, side_hint,
                                                selection, eq8_literal, normalize_before_mean,
                                                ambiguous_face, origin)
    return verts, faces, nrm, _from_mapping(MeshInfo, info, rename=_COUNTS)


def estimate_normals(volume, level: float, edges, spacing=(1.0, 1.0, 1.0),
                     normals: str = "spline", side_hint=None, selection: str = "mesh",
                     eq8_literal: bool = False, normalize_before_mean: bool = False,
                     ambiguous_face: str = "inside") -> Tuple[np.ndarray, NormalStats]:
    """Normals of the vertices on ``edges`` (``info.edges`` of :func:`marching_cubes`:
    rows ``(k, j, i, axis)``) with any estimator, e.g. to compare estimators on one mesh;
    ``spacing`` is ``(dz, dy, dx)`` and the other arguments are those of
    :func:`marching_cubes`. Returns ``(normals (n, 3), NormalStats)``, float64 for a float64
    volume and float32 otherwise. An edge that
    does not cross ``level`` on this volume raises ValueError."""
    n, stats = _m.estimate_normals(volume, level, edges, spacing, normals, side_hint,
                                   selection, eq8_literal, normalize_before_mean,
                                   ambiguous_face)
    return n, _from_mapping(NormalStats, stats, rename=_COUNTS)


def angular_rms(a, b) -> AngularRms:
    """``AngularRms(rms, n_defined, n_undefined)``, a named tuple: the RMS angular error in
    radians over the rows where both normals are defined, their number, and the number of
    rows left out."""
    return AngularRms(*_m.angular_rms(a, b))


def study_full_cd(volume, level: float, spacing=(1.0, 1.0, 1.0)) -> SparseComparison:
    """The paper's Table 1/2 protocol at one level: central differences on the full volume
    (``spacing`` ``(dz, dy, dx)``) as the reference, spline and LSN normals on the sparsified
    volume. Returns a :class:`SparseComparison`: the vertex and triangle counts, the RMS
    errors (``spline``, ``lsn``: :class:`AngularRms`), the zero-normal counts and the
    fraction of vertices where central differences would be defined on the sparse volume."""
    d = _m.study_full_cd(volume, level, spacing)
    return _from_mapping(
        SparseComparison, d,
        rename={"vertices": "n_vertices", "triangles": "n_triangles",
                "reference_undefined": "n_reference_undefined",
                "spline_undefined": "n_spline_undefined", "lsn_undefined": "n_lsn_undefined"},
        spline=_rms(d["spline"]), lsn=_rms(d["lsn"]))


def study_exact(name: str, n: int = 64) -> ExactComparison:
    """The paper's Table 3 protocol on a named analytic field sampled on ``n^3``: RMS angular
    errors (:class:`AngularRms`) against the exact gradient of central differences (full
    grid) and of spline and LSN normals (sparsified grid), as an :class:`ExactComparison`."""
    d = _m.study_exact(name, n)
    return _from_mapping(ExactComparison, d, rename={"vertices": "n_vertices"},
                         central=_rms(d["central"]), spline=_rms(d["spline"]),
                         lsn=_rms(d["lsn"]))


class fields:  # noqa: N801 - a namespace named like the Rust module (``fields.sample(...)``)
    """Analytic test fields (value and exact gradient) of the paper's section 5.2."""

    NAMES = ("sphere", "torus", "marschner_lobb", "genus3", "peaks", "six_peaks", "flower",
             "linear")

    sample = staticmethod(_m.sample)
    exact_normals = staticmethod(_m.exact_normals)
    make_noisy_sphere = staticmethod(_m.make_noisy_sphere)

    @staticmethod
    def make_marschner_lobb(n: int = 64) -> np.ndarray:
        """The Marschner-Lobb signal on [-1, 1]^3 (level 0.5)."""
        return fields.sample("marschner_lobb", n)[0]


# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
