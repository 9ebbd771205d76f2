"""Kinect gait recognition with the most relevant joint relative angles and a DTW kernel:
paper 17 of WSCG vol. 23 (F. Ahmed, P. P. Paul and M. L. Gavrilova, "Kinect-Based Gait
Recognition Using Sequences of the Most Relevant Joint Relative Angles").

Person identification from Kinect v2 skeleton streams (25 joints x 3-D, 30 fps):

1. **Gait cycle** (:func:`detect_cycle`, section 3.1): the horizontal distance between the
   ankles, smoothed with a centred moving average, has a minimum each time the legs cross;
   three consecutive prominent minima are the start, middle and end of one gait cycle.
2. **Joint relative angles** (:func:`jra`, :func:`jra_sequences`, section 3.2, eq. 1): for
   joints ``p1``, ``p2`` and the reference ``r = SpineBase``, ``v1 = r - p1``,
   ``v2 = p2 - r`` and ``theta = arccos(v1 . v2 / (|v1| |v2|))``, in every frame of the
   cycle, for the 276 pairs of the 24 other joints (:func:`all_pairs`). Invariant to
   rotation, translation and uniform scaling of the skeleton.
3. **Relevance** (:func:`occupied_bins`, :func:`relevance_matrix`, :func:`select_pairs`,
   section 3.3): a pair's relevance is the number of 1-degree histogram bins its angle
   occupies over the cycle, averaged over the training walks; pairs occupying at least
   ``t = 20`` bins are kept.
4. **DTW kernel** (:func:`dtw`, :func:`dtw_kernel`, :func:`dissimilarity_matrix`,
   section 3.4, eqs. 2-6): ``Delta = sum over the kept pairs of DTW(theta_m, theta'_m)``,
   each pair warping on its own (independent multivariate DTW), no resampling: the two
   cycles may have different lengths. ``multivariate="dependent"`` gives the dependent
   DTW instead (one warp path for all channels; DTW_D of the UEA archive, dtaidistance's
   ``dtw_ndim``).
5. **Vote** (:class:`GaitRecognizer`): training walks ranked by ``Delta``; 1-NN (default),
   majority of the ``n_neighbors`` nearest, or the paper's majority among the top
   ``#classes + 1``.

Baselines: :func:`ball_features` (Ball et al. 2012) and :func:`preis_features` (Preis et al.
2012). :func:`make_walkers` makes synthetic Kinect walks with ground-truth cycles and
identities (the paper's database is private); :func:`evaluate_synthetic` runs the paper's
3-fold cross-validation (Table 1, Fig. 9) on them. :func:`load_ts` reads the UCR/UEA
archive's ``.ts`` files, on which the DTW is checked against published error rates;
:func:`load_skeleton` and :func:`save_skeleton_csv` read and write skeleton streams
(Kinect v2 and v1 CSV, ``.npy``, NTU RGB+D ``.skeleton`` files: :func:`load_ntu_bodies`).

Conventions: a walk (``frames``) is a float64 array of shape ``(T, 25, 3)``: frames x the 25
Kinect v2 joints in the SDK's ``JointType`` order (:data:`JOINT_NAMES`) x ``(x, y, z)`` in
metres. A Kinect v1 walk is ``(T, 20, 3)`` in the v1 SDK's order (:data:`KINECT_V1_NAMES`);
its joint relative angles run over the 171 pairs of its joints. Joint pairs are ``(P, 2)``
int arrays of Kinect v2 joint indices (or lists of name tuples);
angles are in radians. Bad input (wrong shapes, NaN coordinates, ``fps <= 0``, empty
sequences, unknown cost or vote names, label count mismatches, walks without a full gait
cycle) raises ``ValueError`` naming the problem; unreadable files raise ``OSError``. Inputs
are never modified. The GIL is released while Rust computes.

References
----------
F. Ahmed, P. P. Paul and M. L. Gavrilova, "Kinect-Based Gait Recognition Using Sequences of
the Most Relevant Joint Relative Angles", WSCG 2015, Journal of WSCG vol. 23.
"""

from __future__ import annotations

import os
from typing import List, NamedTuple, Optional, Tuple, Union

import numpy as np

from ._checks import _int, integer_ranges as _integer_ranges
from ._estimator import Estimator
from ._native import gait as _g
from ._native.gait import (all_pairs, ball_features, dissimilarity_matrix, dtw, dtw_kernel,
                           dtw_path, jra, jra_sequences, load_skeleton, load_ts, nearest,
                           occupied_bins, preis_features, relevance_matrix, save_skeleton_csv,
                           select_pairs)
from ._results import (from_mapping as _from_mapping, result as _result,
                       tuple_repr as _tuple_repr)

__all__ = [
    "JOINT_NAMES", "N_PAIRS", "all_pairs", "jra", "detect_cycle", "jra_sequences",
    "relevance_matrix", "occupied_bins", "select_pairs", "dtw", "dtw_path", "dtw_kernel",
    "dissimilarity_matrix", "nearest", "load_ts", "load_skeleton", "save_skeleton_csv",
    "ball_features", "preis_features", "GaitRecognizer", "make_walkers",
    "evaluate_synthetic", "GaitCycle", "CycleDetails", "SyntheticWalks", "GaitEvaluation",
    "KINECT_V1_NAMES", "load_ntu_bodies", "NtuBody",
]

#: Names of the 25 Kinect v2 joints in index (``JointType``) order.
JOINT_NAMES: List[str] = list(_g.JOINT_NAMES)
#: Names of the 20 Kinect v1 joints in the v1 SDK's order (the rows of a ``(T, 20, 3)``
#: array); HipCenter, Spine and ShoulderCenter stand for Kinect v2's SpineBase, SpineMid and
#: SpineShoulder, and joint pairs always use Kinect v2 indices.
KINECT_V1_NAMES: List[str] = list(_g.KINECT_V1_NAMES)
#: Number of joint pairs without the reference joint, C(24, 2).
N_PAIRS: int = 276



# ----------------------------------------------------------------------------------------
# Results
# ----------------------------------------------------------------------------------------

class GaitCycle(NamedTuple):
    """One gait cycle found by :func:`detect_cycle`: the frames of three consecutive leg
    crossings, a named tuple (``start, mid, end = detect_cycle(frames)``); the cycle is
    ``frames[start:end + 1]``.

    Attributes
    ----------
    start, mid, end : int
        Frame indices of the first, middle and last leg crossing.
    """

    start: int
    mid: int
    end: int

    __repr__ = _tuple_repr


@_result
class CycleDetails:
    """The cycle of :func:`detect_cycle` with its intermediate results
    (``return_details=True``). Accepted wherever a ``cycle`` is (its :attr:`cycle` is the
    :class:`GaitCycle`).

    Attributes
    ----------
    start, mid, end : int
        Frames of the three consecutive minima (leg crossings) of the cycle.
    ankle_dist : float64 array (T,)
        The smoothed horizontal ankle distance of every frame, metres.
    minima : int64 array
        Frames of all accepted leg crossings, ascending.
    first_step : str or None
        ``"left"`` or ``"right"``: the foot that steps forward in the first half of the
        cycle (``None`` when it cannot be told).
    """

    start: int
    mid: int
    end: int
    ankle_dist: np.ndarray
    minima: np.ndarray
    first_step: Optional[str]

    @property
    def cycle(self) -> GaitCycle:
        """``(start, mid, end)`` as a :class:`GaitCycle`."""
        return GaitCycle(self.start, self.mid, self.end)


@_result
class NtuBody:
    """One body of an NTU RGB+D file (:func:`load_ntu_bodies`).

    Attributes
    ----------
    id : int
        The file's ``bodyID``.
    n_frames : int
        Frames in which the body appears.
    n_tracked : int
        Tracked joints (``trackingState`` 2) summed over those frames.
    """

    id: int
    n_frames: int
    n_tracked: int


@_result
class SyntheticWalks:
    """Synthetic Kinect v2 walks of :func:`make_walkers` with their ground truth, walks in
    subject-major order.

    Attributes
    ----------
    frames : list of float64 arrays (T_i, 25, 3)
        The walks, joint positions in metres at 30 fps.
    labels : int64 array (n,)
        Subject of each walk.
    sessions : int64 array (n,)
        Session index of each walk.
    minima : list of int64 arrays
        The true leg-crossing frames of each walk (minima of the noise-free horizontal ankle
        distance during the walk).
    walk_frames : int64 array (n,)
        Frames of walking; a sit-down tail starts there.
    sit_tail : list of bool
        Whether each walk ends with a sit-down tail.
    """

    frames: List[np.ndarray]
    labels: np.ndarray
    sessions: np.ndarray
    minima: List[np.ndarray]
    walk_frames: np.ndarray
    sit_tail: List[bool]


@_result
class GaitEvaluation:
    """The paper's cross-validation on synthetic walks (:func:`evaluate_synthetic`, section
    4.1, Table 1, Fig. 9). Accuracies are fractions in ``[0, 1]``.

    Attributes
    ----------
    decisions : int
        Number of test decisions.
    jra_nearest, jra_paper_vote, jra_majority : float
        JRA + DTW kernel with the threshold chosen on the training folds: 1-NN, the paper's
        vote (top ``#classes + 1``), majority of the nearest walks.
    jra_fixed : float
        JRA + DTW kernel at the fixed threshold ``t = 20``, 1-NN.
    jra_normalized : float
        Path-length-normalised DTW, chosen threshold, 1-NN.
    jra_resampled : float
        JRA sequences resampled to 32 samples + Euclidean sum, chosen threshold.
    raw_dtw : float
        DTW kernel on raw SpineBase-relative coordinates, 1-NN.
    ball_nn : float
        Ball et al.'s features, z-scored, 1-NN.
    preis_nb, preis_nn : float
        Preis et al.'s features: Gaussian naive Bayes, and z-scored 1-NN.
    chosen_t : list of float
        Threshold (occupied bins) chosen on the training walks of each fold.
    curve : float64 array (30, 2)
        Rows ``(threshold, 1-NN accuracy)``, Fig. 9; NaN where no pair reaches the
        threshold.
    relevance : float64 array (25, 25)
        Relevance map of the first fold's training walks (Fig. 8), mean occupied bins.
    """

    decisions: int
    jra_nearest: float
    jra_paper_vote: float
    jra_majority: float
    jra_fixed: float
    jra_normalized: float
    jra_resampled: float
    raw_dtw: float
    ball_nn: float
    preis_nb: float
    preis_nn: float
    chosen_t: List[float]
    curve: np.ndarray
    relevance: np.ndarray


# ----------------------------------------------------------------------------------------
# Input validation
# ----------------------------------------------------------------------------------------

# ----------------------------------------------------------------------------------------
# Joints and angles
# ----------------------------------------------------------------------------------------

def detect_cycle(frames, fps: float = 30.0, smooth_window: int = 5, min_step_s: float = 0.25,
                 min_prominence: float = 0.2, up="estimate", choice: str = "first",
                 start_leg: str = "left",
                 return_details: bool = False) -> Union[GaitCycle, CycleDetails]:
    """Detects one full gait cycle (section 3.1).

    Parameters
    ----------
    frames : array_like, shape (T, 25, 3)
        The walk.
    fps : float, default 30.0
        Frame rate.
    smooth_window : int, default 5
        Width of the centred moving average of the ankle distance, frames (the window
        shrinks at the ends).
    min_step_s : float, default 0.25
        Smallest time between two leg crossings, seconds (the deeper of two closer minima
        is kept).
    min_prominence : float, default 0.2
        Smallest prominence of a minimum as a fraction of the robust range ``p95 - p5`` of
        the smoothed distance.
    up : {"estimate", "y"} or array_like of shape (3,), default "estimate"
        Vertical direction: ``normalise(mean(SpineShoulder - SpineBase))``, the camera's
        ``+y``, or a given vector.
    choice : {"first", "most_regular"}, default "first"
        The first cycle, or the one with the most even halves.
    start_leg : {"left", "right", "any"}, default "left"
        Which foot steps forward in the first half of the returned cycle (falls back to the
        first cycle when no cycle of that order exists).
    return_details : bool, default False
        Return a :class:`CycleDetails` with the intermediate results instead.

    Returns
    -------
    GaitCycle
        The named tuple ``(start, mid, end)``: frames of the three consecutive minima; the
        cycle is ``frames[start:end + 1]``. With ``return_details=True`` a
        :class:`CycleDetails`: ``start``, ``mid``, ``end``, ``ankle_dist`` (the smoothed
        horizontal ankle distance of every frame, metres), ``minima`` (all accepted leg
        crossings) and ``first_step`` (``"left"`` or ``"right"``).

    Raises
    ------
    ValueError
        Bad shapes or parameters, NaN coordinates, or a walk with fewer than three leg
        crossings ("no full gait cycle").

    Notes
    -----
    The horizontal distance is ``|D - (D . u) u|`` with ``D = AnkleLeft - AnkleRight`` and
    ``u`` the up vector; local minima satisfy ``d(t) <= d(t-1)`` and ``d(t) < d(t+1)``.
    """
    d = _g.detect_cycle(frames, fps, smooth_window, min_step_s, min_prominence, up, choice,
                        start_leg)
    if return_details:
        return _from_mapping(CycleDetails, d, start=int(d["start"]), mid=int(d["mid"]),
                             end=int(d["end"]))
    return GaitCycle(int(d["start"]), int(d["mid"]), int(d["end"]))


# ----------------------------------------------------------------------------------------
# DTW
# ----------------------------------------------------------------------------------------

# ----------------------------------------------------------------------------------------
# Files and baselines
# ----------------------------------------------------------------------------------------

def load_ntu_bodies(path) -> List[NtuBody]:
    """The bodies of an NTU RGB+D ``.skeleton`` file, in order of first appearance.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    list of NtuBody

    Raises
    ------
    OSError
        Unreadable or malformed file.
    """
    return [NtuBody(id=i, n_frames=n, n_tracked=k)
            for i, n, k in _g.load_ntu_bodies(os.fspath(path))]


# ----------------------------------------------------------------------------------------
# Recognizer
# ----------------------------------------------------------------------------------------

def _vote_spec(vote, n_neighbors) -> str:
    if not isinstance(vote, str):
        raise ValueError(f"`vote` must be 'nearest', 'paper', 'majority' or 'majority:K', "
                         f"got {vote!r}")
    if vote == "majority":
        return f"majority:{_int('n_neighbors', 3 if n_neighbors is None else n_neighbors, 1)}"
    if n_neighbors is not None:
        raise ValueError("`n_neighbors` is only used with vote='majority'")
    if vote in ("nearest", "paper"):
        return vote
    if vote.startswith("majority:"):
        try:
            kk = int(vote.split(":", 1)[1])
        except ValueError:
            kk = 0
        if kk >= 1:
            return f"majority:{kk}"
    raise ValueError(f"`vote` must be 'nearest', 'paper', 'majority' or 'majority:K' (K >= 1), "
                     f"got {vote!r}")


def _encode(labels, n: int) -> Tuple[np.ndarray, List[int]]:
    """Distinct labels (sorted when orderable, else in order of first appearance) and the
    code of every label."""
    try:
        seq = list(labels)
    except TypeError:
        raise ValueError("`y` must be a sequence with one label per walk") from None
    if len(seq) != n:
        raise ValueError(f"`y` has {len(seq)} labels for {n} walks: give one label per walk")
    try:
        arr = np.asarray(seq)
        if arr.ndim != 1 or arr.dtype == object:
            raise TypeError
        classes, codes = np.unique(arr, return_inverse=True)
        return classes, [int(c) for c in codes.reshape(-1)]
    except TypeError:
        distinct = list(dict.fromkeys(seq))
        index = {c: i for i, c in enumerate(distinct)}
        classes = np.empty(len(distinct), dtype=object)
        classes[:] = distinct
        return classes, [index[x] for x in seq]


class GaitRecognizer(Estimator):
    """Gait recognition with the most relevant JRA sequences and the DTW kernel (Fig. 6).

    ``fit`` detects a gait cycle in every training walk, computes the JRA sequences of all
    276 pairs, the relevance map of the training walks and the pairs reaching ``min_bins``;
    ``predict`` ranks the training walks by ``Delta`` to each query and votes.

    A scikit-learn classifier whose samples are walks: ``fit(X, y)`` returns ``self``,
    ``predict(X)`` and ``score(X, y)`` take a sequence of walks; ``get_params`` /
    ``set_params``, ``sklearn.base.clone`` and ``cross_val_score`` work, fitted or not it
    pickles and deep-copies.

    Parameters
    ----------
    min_bins : float, default 20.0
        Relevance threshold ``t`` (occupied 1-degree bins).
    vote : {"nearest", "paper", "majority", "majority:K"}, default "nearest"
        1-NN; the paper's majority of the top ``#classes + 1`` walks; majority of the
        ``n_neighbors`` nearest walks (ties: the tied class with the smallest sum of its
        voters' ranks, then the smallest ``Delta``).
    n_neighbors : int, optional
        Voters of ``vote="majority"`` (default 3).
    cost : {"abs", "squared"}, default "abs"
        DTW local cost.
    window : int, optional
        Sakoe-Chiba band (default: full grid, the paper's).
    bin_deg : float, default 1.0
        Histogram bin width of the relevance measure, degrees.
    start_leg : {"left", "right", "any"}, default "left"
        Which step opens the detected cycles (``"any"`` is the paper's rule as printed;
        mixing orders compares mirrored halves).
    fps : float, default 30.0
        Frame rate of the walks.

    Attributes
    ----------
    pairs_ : ndarray of int64, shape (M, 2)
        Selected pairs (Fig. 10).
    relevance_ : ndarray, shape (25, 25)
        Relevance map of the training walks (Fig. 8).
    classes_ : ndarray
        Distinct training labels; labels may be any hashable values.

    Notes
    -----
    The relevance map uses the training walks only (the paper used all 60 videos,
    including the test ones).
    """

    _estimator_type = "classifier"
    _requires_y = True
    _matrix_input = False
    _fitted_attr = "classes_"

    def __init__(self, min_bins: float = 20.0, vote: str = "nearest",
                 n_neighbors: Optional[int] = None, cost: str = "abs",
                 window: Optional[int] = None, bin_deg: float = 1.0, start_leg: str = "left",
                 fps: float = 30.0):
        self.min_bins, self.vote, self.n_neighbors, self.cost = min_bins, vote, n_neighbors, cost
        self.window, self.bin_deg, self.start_leg, self.fps = window, bin_deg, start_leg, fps

    def fit(self, X, y) -> "GaitRecognizer":
        """Fits the recognizer.

        Parameters
        ----------
        X : sequence of array_like, each of shape (T_i, 25, 3)
            Training walks (lengths may differ), or an ``(n, T, 25, 3)`` array.
        y : array_like, shape (n,)
            Identity of each walk (any hashable values).

        Returns
        -------
        self

        Raises
        ------
        ValueError
            No walks, a label count mismatch, a walk without a full gait cycle (named by
            index), no pair reaching ``min_bins`` (the message gives the largest relevance),
            bad parameters.
        """
        vote = _vote_spec(self.vote, self.n_neighbors)
        ws = _walks(X)
        if not ws:
            raise ValueError("`X` is empty: the gallery needs at least one walk")
        if y is None:
            raise ValueError("GaitRecognizer requires y to be passed, but the target y is None")
        classes, codes = _encode(y, len(ws))
        self._model = _g.Recognizer(ws, codes, self.fps, self.min_bins, vote, self.cost,
                                    self.window, self.bin_deg, self.start_leg)
        self.classes_ = classes
        self.pairs_ = self._model.pairs()
        self.relevance_ = self._model.relevance()
        return self

    def _predict(self, frames, name: str = "frames"):
        self._check_fitted()
        return self._model.predict(frames, self.fps, name)

    def predict(self, X) -> np.ndarray:
        """Identifies walks.

        Parameters
        ----------
        X : sequence of array_like, each of shape (T_i, 25, 3)
            The walks, or an ``(n, T, 25, 3)`` array (``predict([walk])[0]`` for one walk).

        Returns
        -------
        ndarray, shape (n,)
            One of :attr:`classes_` per walk.
        """
        self._check_fitted()
        if isinstance(X, np.ndarray) and X.dtype != object and X.ndim == 3:
            raise ValueError(f"`X` of shape {X.shape} is one walk: predict takes a sequence "
                             "of walks (use predict([walk])[0])")
        codes = [self._predict(w, f"X[{i}]")[0] for i, w in enumerate(_walks(X))]
        return self.classes_[np.asarray(codes, dtype=np.int64)]

    def score(self, X, y) -> float:
        """Fraction of the walks ``X`` identified as ``y``."""
        pred = self.predict(X)
        try:
            ys = list(y)
        except TypeError:
            raise ValueError("`y` must be a sequence with one label per walk") from None
        if len(ys) != len(pred):
            raise ValueError(f"`y` has {len(ys)} labels for {len(pred)} walks")
        return float(np.mean([bool(p == t) for p, t in zip(pred, ys)]))

    def rank(self, frames) -> Tuple[np.ndarray, np.ndarray]:
        """The training walks ranked by ``Delta`` to a walk.

        Parameters
        ----------
        frames : array_like, shape (T, 25, 3)

        Returns
        -------
        labels : ndarray, shape (n,)
            Labels of the training walks, ascending ``Delta`` (ties: training order).
        deltas : ndarray, shape (n,)
            Their ``Delta``.
        """
        _, _, codes, deltas, _ = self._predict(frames)
        return self.classes_[np.asarray(codes, dtype=np.int64)], deltas

    def rank_indices(self, frames) -> Tuple[np.ndarray, np.ndarray]:
        """Like :meth:`rank`, with the indices of the training walks instead of labels."""
        _, idx, _, deltas, _ = self._predict(frames)
        return idx, deltas

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        if "_model" in state:
            state["_model"] = state["_model"].to_json()
        return state

    def __setstate__(self, state: dict) -> None:
        state = dict(state)
        if isinstance(state.get("_model"), str):
            state["_model"] = _g.Recognizer.from_json(state["_model"])
        self.__dict__.update(state)


def _walks(X) -> list:
    """The walks of ``X``: a sequence of ``(T, 25, 3)`` arrays or an ``(n, T, 25, 3)``
    array."""
    if isinstance(X, np.ndarray) and X.dtype != object and X.ndim == 4:
        return [X[i] for i in range(X.shape[0])]
    try:
        return list(X)
    except TypeError:
        raise ValueError("`X` must be a sequence of (T, 25, 3) walks") from None


# ----------------------------------------------------------------------------------------
# Synthetic data and the protocol
# ----------------------------------------------------------------------------------------

def make_walkers(n_subjects: int = 20, n_sessions: int = 3, seed: int = 0,
                  heading_deg=(-60.0, 60.0), speed=(0.9, 1.1), walk_s=(2.5, 4.0),
                  sit_prob: float = 0.5, noise: bool = True,
                  n_joints: int = 25) -> SyntheticWalks:
    """Synthetic Kinect v2 walks with ground truth (the paper's database is private).

    Subjects differ in body proportions and above all in gait dynamics (hip, knee, ankle
    and arm-swing curves, cadence, pelvis and shoulder rotation, bob, sway, lean). Each
    session draws a speed factor (a pure time warp), a heading about the vertical, a sensor
    pitch, a position, a walking time, an initial gait phase and optionally a 1 s "sit
    down" tail; angle jitter, bone-length bias and AR(1) sensor noise (a common-mode
    translation plus per-joint noise) are added.

    Parameters
    ----------
    n_subjects, n_sessions : int
        ``n_subjects * n_sessions`` walks, subject-major.
    seed : int
        Seeds subjects, sessions and noise.
    heading_deg, speed, walk_s : (float, float)
        Ranges of the walking direction (degrees; 0 walks at the sensor), the cadence
        factor and the walking time (seconds).
    sit_prob : float, default 0.5
        Probability of a sit-down tail.
    noise : bool, default True
        Sensor noise; ``False`` gives the same sessions without noise.
    n_joints : int, default 25
        25: Kinect v2 skeletons; 20: the same walks as Kinect v1 skeletons (Neck, HandTip and
        Thumb dropped; rows in :data:`KINECT_V1_NAMES` order).

    Returns
    -------
    SyntheticWalks
        ``frames`` (list of ``(T_i, n_joints, 3)`` arrays, 30 fps), ``labels`` (subject of each
        walk), ``sessions`` (session index), ``minima`` (list of int arrays: the true
        leg-crossing frames, minima of the noise-free horizontal ankle distance during the
        walk), ``walk_frames`` (frames of walking; a sit-down tail starts there) and
        ``sit_tail`` (list of bool).
    """
    d = _g.make_walkers(n_subjects, n_sessions, seed, heading_deg, speed, walk_s, sit_prob,
                        noise, n_joints)
    return _from_mapping(SyntheticWalks, d)


def evaluate_synthetic(n_subjects: int = 20, n_sessions: int = 3,
                       seed: int = 0, n_joints: int = 25) -> GaitEvaluation:
    """The paper's evaluation (section 4.1, Table 1, Fig. 9) on :func:`make_walkers`.

    Fold ``k`` tests session ``k`` of every subject and trains on the others; relevance
    maps and thresholds use the training walks only. Accuracies are fractions in [0, 1].

    Parameters
    ----------
    n_subjects, n_sessions, seed : int
        The synthetic walks (default sessions: headings in [-60, 60] degrees, speed factors
        in [0.9, 1.1], noise on).
    n_joints : int, default 25
        25 (Kinect v2) or 20 (the same walks as Kinect v1 skeletons: 171 joint pairs
        instead of 276).

    Returns
    -------
    GaitEvaluation
        ``decisions``; ``jra_nearest``, ``jra_paper_vote``, ``jra_majority`` (JRA + DTW
        kernel with the threshold chosen on the training folds, three vote rules);
        ``jra_fixed`` (t = 20); ``jra_normalized`` (path-length-normalised DTW);
        ``jra_resampled`` (32 samples + Euclidean sum); ``raw_dtw`` (DTW on raw
        SpineBase-relative coordinates); ``ball_nn``, ``preis_nb``, ``preis_nn``
        (baselines); ``chosen_t`` (threshold of each fold); ``curve`` (``(30, 2)`` array of
        threshold and 1-NN accuracy, Fig. 9; NaN where no pair reaches the threshold);
        ``relevance`` (``(25, 25)`` map of the first fold's training walks).
    """
    return _from_mapping(GaitEvaluation,
                         _g.evaluate_synthetic(n_subjects, n_sessions, seed, n_joints))

# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
