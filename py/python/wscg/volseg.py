"""Bone separation in CT with random walks on a bone-only graph: paper 18 of WSCG vol. 23
(J. Nysjö, F. Malmberg, I.-M. Sintorn and I. Nyström, "BoneSplit - A 3D Texture Painting
Tool for Interactive Bone Separation in CT Images").

A threshold segments touching bones together; BoneSplit separates them from a few user
strokes (seeds), one label per bone or fragment:

1. **Bone graph** (section 2.4): the voxels with ``ct >= t_bone`` (300 HU) are the nodes,
   6-adjacent bone voxels are joined by edges of weight ``w_ij = exp(-beta (g_i - g_j)^2) +
   eps`` (eq. 1, after Grady 2006), ``g`` the CT mapped to ``[0, 1]`` (default window
   ``[-1024, 3071]`` HU), ``beta = 1e4``, ``eps = 2e-3`` by default (the paper's
   ``beta = 3000``, ``eps = 0.01`` with ``preset="paper"``). Only bone voxels are stored:
   about 10 % of a head CT.
2. **Random walks** (:func:`random_walker_bone`, :class:`RandomWalkerSession`): for every
   label ``k`` the combinatorial Dirichlet problem ``(L_U + kappa I) x_k = -B^T m_k``
   (``kappa = 3e-5`` by default, the paper's ``kappa = 1e-3`` with
   ``preset="paper"``), solved by Jacobi-preconditioned
   conjugate gradients to a relative residual of ``3e-3`` (all labels in one sweep over the
   graph, multithreaded); each bone voxel takes the label of largest probability.
   :meth:`RandomWalkerSession.solve` re-solves warm-started from the previous solution after
   strokes are added (the paper's stage 2).
3. **Editing** (section 2.6, stage 3): :func:`local_grow_edit`, the local 3-D grow brush;
   :func:`remove_small_components`, the removal of small label islands.
4. **Evaluation**: :func:`dice` (eq. 2, multi-label Dice), :func:`nearest_seed` (geodesic
   nearest-seed labelling, the cheap baseline) and :func:`make_fractured_shell_phantom`, a
   CT phantom of a fractured bone shell with exact fragment labels and seed strokes (no
   clinical CT ships with a Python package).

Conventions (``py/API.md``): volumes are 3-D numpy arrays indexed ``[z, y, x]``; ``spacing``
is ``(dz, dy, dx)`` in the same axis order (as in :mod:`wscg.math`, :mod:`wscg.isosurface`,
:mod:`wscg.volren` and scikit-image), so the voxel ``[k, j, i]`` lies at the world point
``(x, y, z) = (i dx, j dy, k dz)``; strokes and brush centres are voxel indices ``(z, y,
x)``. CT values are Hounsfield units (any real dtype, converted to float32); label volumes
are uint16 with 0 for "no label" (seeds: integer arrays with values in ``0..65534``). Bad
input (wrong shapes or dtypes, NaN or infinite CT values, negative ``beta``, ``eps`` or
``kappa``, ``tol <= 0``, non-positive spacing, no seed on a bone voxel) raises
``ValueError`` naming the problem. Inputs are never modified. The GIL is released while Rust
computes.

References
----------
J. Nysjö, F. Malmberg, I.-M. Sintorn and I. Nyström, "BoneSplit - A 3D Texture Painting Tool
for Interactive Bone Separation in CT Images", Journal of WSCG 23 (2), 2015, pp. 157-166.

L. Grady, "Random Walks for Image Segmentation", IEEE Trans. Pattern Anal. Mach. Intell.
28 (11), 2006, pp. 1768-1783. :DOI:`10.1109/TPAMI.2006.233`.
"""

from __future__ import annotations

import warnings
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from ._checks import _int, integer_ranges as _integer_ranges
from ._native import volseg as _v
# The baseline, the metric, the preprocessing, the editing functions and the phantom are the
# native ones (docstrings in py/src/volseg.rs).
from ._native.volseg import (bone_mask, dice, local_grow_edit, make_fractured_shell_phantom,
                             nearest_seed, remove_small_components, smooth)
from ._results import from_mapping as _from_mapping, result as _result

__all__ = [
    "random_walker_bone", "RandomWalkerSession", "nearest_seed", "dice", "bone_mask",
    "smooth", "local_grow_edit", "remove_small_components", "make_fractured_shell_phantom",
    "SolveReport",
]

#: Default intensity window (HU) mapped to ``[0, 1]`` before the edge weights.
DEFAULT_WINDOW: Tuple[float, float] = (-1024.0, 3071.0)

_MAX_LABEL = 65534


@_result
class SolveReport:
    """How the random walks of :func:`random_walker_bone` or
    :meth:`RandomWalkerSession.solve` were solved (one conjugate gradient solve per label,
    paper 18 section 2.4). The per-label lists follow ``labels``.

    Attributes
    ----------
    labels : list of int
        The seed labels, ascending (the user's values, not necessarily ``1..K``).
    n_iter : list of int
        Conjugate gradient iterations run per label.
    residuals : list of float
        Final relative residual ``||r|| / ||b||`` per label (dimensionless).
    converged : list of bool
        Whether each label's residual reached ``tol`` within ``max_iter``.
    seconds : list of float
        Wall-clock seconds per label (for the block solver, the block's time divided by the
        number of labels).
    n_unreached : int
        Unseeded bone voxels in graph components without any seed: left out of the systems
        (probability 0, label 0).
    n_labels : int
        Number of labels ``K`` solved for.
    n_nodes : int
        Graph nodes (bone voxels).
    n_seeds : int
        Seed voxels on the graph (seeds off the bone were dropped).
    """

    labels: List[int]
    n_iter: List[int]
    residuals: List[float]
    converged: List[bool]
    seconds: List[float]
    n_unreached: int
    n_labels: int
    n_nodes: int
    n_seeds: int


def _solve_report(d: Dict[str, Any], labels, order=None) -> SolveReport:
    """The :class:`SolveReport` of the native report ``d``, whose per-label lists follow the
    internal labels ``1..K``: ``labels`` are the user's labels in that order, ``order`` the
    permutation that sorts them (None when they are sorted)."""
    order = range(len(labels)) if order is None else order
    per_label = lambda key: [d[key][i] for i in order]  # noqa: E731
    return _from_mapping(
        SolveReport, d, rename={"iterations": "n_iter", "unreached": "n_unreached"},
        labels=[int(labels[i]) for i in order], n_iter=per_label("iterations"),
        residuals=per_label("residuals"), converged=per_label("converged"),
        seconds=per_label("seconds"))


# ----------------------------------------------------------------------------------------
# Label bookkeeping and warnings (the arguments are checked by the native functions)
# ----------------------------------------------------------------------------------------

def _present(seeds: np.ndarray) -> np.ndarray:
    """The distinct non-zero labels of a uint16 array, ascending."""
    counts = np.bincount(seeds.ravel(), minlength=1)
    return (np.flatnonzero(counts[1:]) + 1).astype(np.int64)


def _warn_dropped(total: int, placed: int, stacklevel: int = 3) -> None:
    """Warns when fewer than all ``total`` non-zero seed voxels were ``placed`` on the graph."""
    if placed < total:
        warnings.warn(f"{total - placed} of {total} seed voxels are not bone (below `t_bone` "
                      "or outside `mask`) and were dropped", UserWarning, stacklevel=stacklevel)


def _warn_unconverged(report: SolveReport, stacklevel: int = 3) -> None:
    bad = [k for k, c in enumerate(report.converged) if not c]
    if bad:
        warnings.warn(f"conjugate gradient did not reach `tol` within `max_iter` for labels "
                      f"{[report.labels[k] for k in bad]} (relative residuals "
                      f"{[report.residuals[k] for k in bad]}); increase `max_iter` or "
                      "`kappa`", RuntimeWarning, stacklevel=stacklevel)


# ----------------------------------------------------------------------------------------
# Random walks
# ----------------------------------------------------------------------------------------

def random_walker_bone(ct, seeds, *, t_bone: float = 300.0, beta: Optional[float] = None,
                       eps: Optional[float] = None, kappa: Optional[float] = None,
                       preset: str = "default", tol: float = 3e-3,
                       max_iter: int = 2000, spacing: Sequence[float] = (1.0, 1.0, 1.0),
                       n_smooth_passes: int = 0,
                       norm: Union[str, Tuple[str, float, float]] = "window",
                       spacing_in_weights: bool = False, solver: str = "block",
                       precision: str = "f32", jacobi: bool = True,
                       n_threads: Optional[int] = None, return_prob: bool = False,
                       return_report: bool = False
                       ) -> Union[np.ndarray, Tuple[np.ndarray, np.ndarray],
                                  Tuple[np.ndarray, SolveReport],
                                  Tuple[np.ndarray, np.ndarray, SolveReport]]:
    """Random-walks bone separation (BoneSplit, paper 18 section 2.4).

    Thresholds ``ct`` at ``t_bone``, builds the 6-connected graph on the bone voxels only
    and labels every bone voxel with the seed label a random walker started there most
    probably reaches first.

    Parameters
    ----------
    ct : (Z, Y, X) array
        CT volume in HU (any real dtype; converted to float32). No NaN or infinity.
    seeds : (Z, Y, X) int array
        Seed strokes: a label in ``1..65534`` on seed voxels, 0 elsewhere. Label values
        need not be consecutive (they are numbered ``1..K`` in ascending order for the solve,
        as scikit-image does, and mapped back). Seeds on non-bone voxels are dropped with a
        ``UserWarning``.
    t_bone : float, default 300
        Bone threshold, HU: the graph holds the voxels with ``ct >= t_bone`` (after
        smoothing when ``n_smooth_passes > 0``).
    beta : float, optional
        Weight sharpness of eq. 1 on the normalised intensities. ``>= 0``. Default: the
        preset's, ``1e4`` (``"paper"``: 3000; the paper finds 2000-4000 equivalent).
    eps : float, optional
        Constant added to every edge weight (eq. 1). ``>= 0``. Default: the preset's,
        ``2e-3`` (``"paper"``: 0.01).
    kappa : float, optional
        Regulariser added to the diagonal of every unseeded node: decays the probabilities
        away from the seeds and speeds CG up. ``>= 0``; with 0 the plain Dirichlet problem
        of Grady (components without seeds are excluded, so the systems stay regular).
        Default: the preset's, ``3e-5`` (``"paper"``: 1e-3).
    preset : 'default' or 'paper', default 'default'
        Where ``beta``, ``eps`` and ``kappa`` left at None come from. ``"default"``
        (``1e4, 2e-3, 3e-5``): DSC 0.956-0.979 on fractured-shell phantoms of 96^3-192^3
        voxels with 6-10 fragments and ball strokes, about 160-250 CG iterations per label.
        ``"paper"`` (``3000, 0.01, 1e-3``, section 2.4): half the iterations, but
        ``eps = 0.01`` lets thin fracture lines conduct and ``kappa = 1e-3`` drains the
        probabilities away from the strokes, so voxels far from every stroke are labelled
        by the leak (DSC 0.75-0.92 on the same phantoms). With strokes painted on the outer
        surface (partial-volume voxels weakly joined to the bone's body) both score lower
        (defaults 0.67-0.80, paper 0.68-0.85) and ``kappa = 0`` collapses (one label takes
        most of the bone), which is why the default keeps a small ``kappa``. A much noisier CT (noise well above 30 HU)
        or a narrower ``norm`` window calls for a smaller ``beta``: from about ``1.5e4`` it
        cuts thin bone into pieces. Measurements: BENCHMARKS.md, paper 18.
    tol : float, default 3e-3
        Relative residual ``||r|| / ||b||`` at which CG stops, per label. ``> 0``. What it
        costs with the default weights (float32 and float64 alike): the labels differ from
        those of a fully converged solve on 0.2-0.6 % of the bone voxels (the probabilities
        by up to 0.24, where labels compete far from the strokes), while the Dice against
        the truth moves by at most 0.003; ``1e-3`` brings that to 0.15 % for 1.5 times the
        iterations, ``1e-4`` to 0.01-0.02 % for 2.3-2.6 times.
    max_iter : int, default 2000
        CG iteration cap per label (a ``RuntimeWarning`` reports labels that did not
        converge).
    spacing : (dz, dy, dx), default (1, 1, 1)
        Voxel spacing (finite, > 0); used by the smoothing and by ``spacing_in_weights``.
    n_smooth_passes : int, default 0
        Passes of the anisotropy-aware 3-tap Gaussian (sigma 0.6 voxel on the finest axis;
        :func:`smooth`) before thresholding (0..100; the paper smooths noisy scans once).
    norm : 'window', ('window', lo, hi), 'minmax' or 'none', default 'window'
        Map of the CT to ``g`` in eq. 1: ``clip((ct - lo) / (hi - lo), 0, 1)`` with the
        default window ``(-1024, 3071)`` HU; the bone voxels' own range; or the values as
        they are. Both presets' ``beta`` assume a ``[0, 1]`` scale.
    spacing_in_weights : bool, default False
        Divide intensity differences by the spacing along the edge (scikit-image's
        convention). The paper's eq. 1 ignores spacing.
    solver : 'block' or 'per_label', default 'block'
        All labels in one sweep over the graph per iteration, or one label after the other
        (the paper's CPU path; same results).
    precision : 'f32' or 'f64', default 'f32'
        Precision of the CG vectors (dot products are always accumulated in float64).
    jacobi : bool, default True
        Jacobi preconditioner (False: plain CG).
    n_threads : int, optional
        Worker threads of this solve (1..1024); default: the threads of wscg's pool
        (:func:`wscg.set_num_threads`). Results do not depend on it.
    return_prob : bool, default False
        Also return the K probability volumes.
    return_report : bool, default False
        Also return the solver report.

    Returns
    -------
    labels : (Z, Y, X) uint16 array
        Label of every bone voxel; 0 on non-bone voxels and on bone components that no seed
        reaches. Seeds keep their labels.
    probs : (K, Z, Y, X) float32 array
        Only with ``return_prob``: ``probs[i]`` is the probability of the ``i``-th smallest
        seed label (``report.labels[i]``; label ``i + 1`` when the labels are ``1..K``),
        1 on its seeds, 0 off the graph. They are CG iterates: with a loose ``tol`` values
        can leave ``[0, 1]`` by about ``tol``. With ``kappa > 0`` the probabilities decay away from the
        seeds and do not sum to 1: compare them, never threshold them at 0.5.
    report : SolveReport
        Only with ``return_report``: ``labels`` (the seed labels, ascending), ``n_iter``,
        ``residuals``, ``converged`` and ``seconds`` (lists, one entry per label),
        ``n_unreached`` (unseeded bone voxels of components without seeds), ``n_labels``,
        ``n_nodes`` (bone voxels), ``n_seeds`` (seeds on the graph).

    Raises
    ------
    ValueError
        Shapes differ or are not 3-D, NaN or infinite CT values, out-of-range parameters,
        no seed on a bone voxel (also when ``t_bone`` is above the
        data's range: the graph is empty), a solver state above 32 GiB.

    See Also
    --------
    RandomWalkerSession : the same with added strokes and warm-started re-solves.
    skimage.segmentation.random_walker : Grady's method on the whole grid.

    Notes
    -----
    The weights ``w_ij = exp(-beta (g_i - g_j)^2) + eps`` form the graph Laplacian ``L``;
    splitting it into seeded (``S``) and unseeded (``U``) nodes, the probability of label
    ``k`` solves ``(L_U + kappa I) x_k = -B^T m_k``, ``m_k`` the indicator of the seeds of
    ``k`` (Grady 2006, section II). The matrix is never formed: CG applies the 6-neighbour
    stencil of the bone graph. scikit-image's ``random_walker(data, labels, beta=b_sk,
    mode='cg_j', tol=tol)`` on ``data = g`` with non-bone voxels labelled -1 is the special
    case ``beta = b_sk / (10 data.std())``, ``eps = 1e-10``, ``kappa = 0``,
    ``spacing_in_weights=True``.

    References
    ----------
    J. Nysjö et al., "BoneSplit", Journal of WSCG 23, 2015, section 2.4, eq. 1.
    L. Grady, IEEE TPAMI 28 (11), 2006. :DOI:`10.1109/TPAMI.2006.233`.

    Examples
    --------
    >>> from wscg import volseg
    >>> ct, truth, seeds = volseg.make_fractured_shell_phantom((48, 48, 48), n_fragments=4)
    >>> labels = volseg.random_walker_bone(ct, seeds)
    >>> volseg.dice(labels, truth) > 0.5
    True
    """
    labels, probs, native = _v.random_walker(
        ct, seeds, t_bone=t_bone, beta=beta, eps=eps, kappa=kappa, preset=preset, tol=tol,
        max_iter=max_iter, spacing=spacing, n_smooth_passes=n_smooth_passes, norm=norm,
        spacing_in_weights=bool(spacing_in_weights), solver=solver, precision=precision,
        jacobi=bool(jacobi), n_threads=n_threads, return_prob=bool(return_prob))
    total = native.pop("n_seed_voxels")
    report = _solve_report(native, native.pop("labels"))
    _warn_dropped(total, report.n_seeds)
    _warn_unconverged(report)
    out: Tuple[Any, ...] = (labels,)
    if return_prob:
        out += (probs,)
    if return_report:
        out += (report,)
    return out[0] if len(out) == 1 else out


class RandomWalkerSession:
    """An interactive random-walks segmentation (BoneSplit's stages 1 and 2).

    Builds the bone graph once; seeds are set or added stroke by stroke and every
    :meth:`solve` starts from the previous solution (Grady's warm start), so a re-solve
    after a small stroke takes a fraction of the iterations of the first.

    Parameters
    ----------
    ct : (Z, Y, X) array
        CT volume in HU (converted to float32).
    mask : (Z, Y, X) bool array, optional
        Graph nodes. Default: ``ct >= t_bone`` (after smoothing).
    t_bone, beta, eps, kappa, preset, tol, max_iter, spacing, n_smooth_passes, norm, spacing_in_weights, solver, precision, jacobi, n_threads
        As in :func:`random_walker_bone`.

    Attributes
    ----------
    n_nodes : int
        Number of graph nodes (bone voxels).
    n_edges : int
        Number of graph edges.
    n_labels : int
        Number of labels K (the largest seed label placed).
    shape : (Z, Y, X)
        Volume shape.

    Examples
    --------
    >>> from wscg import volseg
    >>> ct, truth, seeds = volseg.make_fractured_shell_phantom((48, 48, 48), n_fragments=4)
    >>> s = volseg.RandomWalkerSession(ct)
    >>> s.set_seeds(seeds) > 0
    True
    >>> report = s.solve()
    >>> labels = s.labels()
    """

    def __init__(self, ct, mask=None, *, t_bone: float = 300.0, beta: Optional[float] = None,
                 eps: Optional[float] = None, kappa: Optional[float] = None,
                 preset: str = "default", tol: float = 3e-3,
                 max_iter: int = 2000, spacing: Sequence[float] = (1.0, 1.0, 1.0),
                 n_smooth_passes: int = 0,
                 norm: Union[str, Tuple[str, float, float]] = "window",
                 spacing_in_weights: bool = False, solver: str = "block",
                 precision: str = "f32", jacobi: bool = True,
                 n_threads: Optional[int] = None) -> None:
        self._s = _v.Session(
            ct, mask, t_bone=t_bone, beta=beta, eps=eps, kappa=kappa, preset=preset, tol=tol,
            max_iter=max_iter, spacing=spacing, n_smooth_passes=n_smooth_passes, norm=norm,
            spacing_in_weights=bool(spacing_in_weights), solver=solver, precision=precision,
            jacobi=bool(jacobi), n_threads=n_threads)
        self._report: Optional[SolveReport] = None
        # User label of every internal label 1..K (the native session numbers labels 1..K).
        self._user = np.zeros(1, np.uint16)
        self._internal: Dict[int, int] = {}

    # The native session numbers labels 1..K: internal numbers are given in order of
    # appearance and never change; outputs list the user's labels ascending.

    def _order(self, k: int) -> np.ndarray:
        return np.argsort(self._user[1:k + 1], kind="stable")

    def _map(self, internal: np.ndarray) -> np.ndarray:
        return self._user[internal]

    def set_seeds(self, seeds) -> int:
        """Replaces all seeds by the non-zero voxels of ``seeds`` (``(Z, Y, X)`` int array,
        labels ``1..65534``, not necessarily consecutive). Returns how many seed voxels lie
        on the graph; the others are dropped with a ``UserWarning``."""
        s = self._s.check_seeds(seeds)
        present = _present(s)
        # Labels keep their internal number for the whole session, so that warm starts and
        # the last solution stay attached to the right label.
        new = [int(u) for u in present if int(u) not in self._internal]
        internal = dict(self._internal)
        internal.update({u: len(self._user) + i for i, u in enumerate(new)})
        lut = np.zeros(int(present[-1]) + 1 if present.size else 1, np.uint16)
        lut[present] = [internal[int(u)] for u in present]
        placed = self._s.set_seeds(lut[s])
        self._user = np.concatenate([self._user, np.asarray(new, np.uint16)]).astype(np.uint16)
        self._internal = internal
        _warn_dropped(int(np.count_nonzero(s)), placed)
        return placed

    def add_seeds(self, zyx_indices, label: int) -> int:
        """Adds a stroke: the voxels at ``zyx_indices`` (``(N, 3)`` int array of ``(z, y, x)``
        coordinates, or one triple) get seed ``label`` (1..65534), replacing earlier seeds
        there. Returns how many lie on the graph; the others are dropped with a
        ``UserWarning``. Coordinates outside the volume raise ``ValueError``."""
        lab = _int("label", label, 1, _MAX_LABEL)
        z = np.asarray(zyx_indices)
        if z.dtype.kind not in "iu" and not (z.dtype.kind == "f" and z.size == 0):
            raise ValueError(f"`zyx_indices` must be an integer array, got dtype {z.dtype}")
        if z.ndim == 1 and z.shape[0] == 3:
            z = z[None, :]
        if z.size == 0:
            z = z.reshape(0, 3)
        if z.ndim != 2 or z.shape[1] != 3:
            raise ValueError(f"`zyx_indices` must have shape (N, 3), got {z.shape}")
        if z.dtype == np.uint64 and z.size and z.max() > np.iinfo(np.int64).max:
            raise ValueError("`zyx_indices` holds coordinates outside the volume")
        internal = self._internal.get(lab, len(self._user))
        placed = self._s.add_seeds(np.ascontiguousarray(z, dtype=np.int64), internal)
        if internal == len(self._user):
            self._user = np.append(self._user, np.uint16(lab))
            self._internal[lab] = internal
        if placed < len(z):
            warnings.warn(f"{len(z) - placed} of {len(z)} stroke voxels are not bone and were "
                          "dropped", UserWarning, stacklevel=2)
        return placed

    def solve(self, warm_start: bool = True) -> SolveReport:
        """Solves for the current seeds, from the previous solution when ``warm_start`` (and
        one exists), else from zero. Returns the :class:`SolveReport` (per-label lists follow
        ``report.labels``, ascending). ``ValueError`` when no seed lies on the graph."""
        d = self._s.solve(bool(warm_start))
        k = d["n_labels"]
        r = _solve_report(d, self._user[1:k + 1], self._order(k))
        _warn_unconverged(r)
        self._report = r
        return r

    def report(self) -> Optional[SolveReport]:
        """The report of the last :meth:`solve` (None before the first)."""
        return self._report

    def labels(self):
        """Label volume ``(Z, Y, X)`` uint16 of the last solve (before a solve: the seeds;
        seeds added since the last solve keep their label)."""
        return self._map(self._s.labels())

    def probabilities(self, label: Optional[int] = None):
        """Probability volume ``(Z, Y, X)`` float32 of seed ``label`` from the last solve, or
        all of them ``(K, Z, Y, X)`` when ``label`` is None (in the order of
        ``report().labels``, ascending). ``ValueError`` before the first solve or for a
        label without seeds then."""
        if label is None:
            if self._report is None:
                raise ValueError("no probabilities before the first solve()")
            p = self._s.all_probabilities()
            order = self._order(p.shape[0])
            return p if np.all(order == np.arange(order.size)) else p[order]
        lab = _int("label", label, 1, _MAX_LABEL)
        internal = self._internal.get(lab)
        if internal is None or internal > self._s.solved_labels:
            known = [] if self._report is None else self._report.labels
            raise ValueError(f"no probabilities for label {lab}; the last solve had labels "
                             f"{known}")
        return self._s.probabilities(internal)

    def seeds(self):
        """Seed volume ``(Z, Y, X)`` uint16 (only the seeds on the graph)."""
        return self._map(self._s.seeds())

    def nearest_seed(self):
        """Geodesic nearest-seed labels of the current seeds on this graph (the baseline of
        :func:`nearest_seed`)."""
        return self._map(self._s.nearest_seed())

    @property
    def n_nodes(self) -> int:
        return self._s.n_nodes

    @property
    def n_edges(self) -> int:
        return self._s.n_edges

    @property
    def n_labels(self) -> int:
        """Number of labels K of the next solve."""
        return self._s.n_labels

    @property
    def shape(self) -> Tuple[int, int, int]:
        return self._s.shape

    @property
    def graph_bytes(self) -> int:
        """Approximate memory of the bone graph, bytes."""
        return self._s.graph_bytes

    def __repr__(self) -> str:
        return (f"RandomWalkerSession(shape={self.shape}, n_nodes={self.n_nodes}, "
                f"n_labels={self.n_labels})")


# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
