"""Predictive human movement synthesis: paper 16 of WSCG vol. 23 (Mukovskiy, Land, Schack and
Giese, "Modeling of predictive human movement coordination patterns for applications in
computer graphics").

Joint-angle trajectories of a walk-then-reach task (a normal step, a shortened step, a reach
into a drawer) are decomposed into *kinematic primitives* by anechoic demixing,
``x_i^r(t) ~ sum_j w_ij^r s_j(t - tau_ij)``, with band-limited periodic sources and delays
shared across trials (:class:`AnechoicModel`, :func:`fit_anechoic`); PCA is the synchronous
baseline (:func:`pca_quality`). :class:`StepwiseModel` (:func:`fit_stepwise`) learns the three
actions step by step (3 sources for the step, 2 more for the shortened step, the reach reuses
all 5) into a :class:`Library`. A :class:`Synthesizer`, fitted on that library, turns it into
*dynamic primitives* (a star network of Hopf oscillators whose followers are mapped onto the
sources), regresses the weights from the step parameters, blends actions at the leader's phase
wrap and re-plans the steps with the predictive planner (:func:`plan_steps`) when the goal
moves. :func:`save_bvh` exports the result for any animation tool.

The three models are scikit-learn estimators: hyper-parameters in ``__init__``
(``get_params`` / ``set_params``, ``sklearn.base.clone``), ``fit(X)`` returns the model, what
it learns ends in ``_``; fitted or not they pickle and deep-copy (a :class:`Library` pickles
through its exact JSON form).

Data: :func:`make_synthetic_dataset` draws trials of a seeded synthetic walker with known
ground truth (17 joints, 51 exponential-map channels, 5 periodic sources with shared delays),
standing in for the paper's motion capture. Also: the regression statistics of the paper's
Fig. 2 (:func:`fit_line`, :func:`regression_p_value`), the LIBSVM-style RBF epsilon-SVR used
for the state maps (:func:`svr_fit_predict`), the Hopf network (:func:`hopf_simulate`) and
the skeleton (:func:`skeleton`, :func:`forward_kinematics`).

Conventions: trial data are float64 arrays ``(R, I, N)`` (trials x channels x samples of one
action period); time is normalised to one period, so delays are fractions of a period.
Distances are in metres, angles in radians (exponential maps, channel ``3 j + c`` is
component ``c`` of joint ``j``). Bad arguments raise ``ValueError``; a file that cannot be
read or written raises ``OSError``. The GIL is released while Rust works.
"""

from __future__ import annotations

import copyreg
import math as _math
import os
from collections.abc import Mapping
from typing import Any, List, Optional, Sequence, Tuple, Union

import numpy as np

from ._checks import integer_ranges as _integer_ranges
from ._estimator import Estimator
from ._native import motion as _m
from ._native.motion import (forward_kinematics, pca_qualities, pca_quality, quality,
                             regression_p_value, save_bvh)
from ._results import from_mapping as _from_mapping, result as _result

__all__ = [
    "make_synthetic_dataset", "AnechoicModel", "fit_anechoic", "pca_quality", "pca_qualities",
    "quality", "StepwiseModel", "fit_stepwise", "Library", "plan_steps", "Synthesizer", "save_bvh", "load_bvh",
    "load_bvh_skeleton", "BvhSkeleton",
    "load_dataset", "save_dataset",
    "forward_kinematics", "skeleton", "regression_p_value", "fit_line", "svr_fit_predict",
    "hopf_simulate", "ACTIONS", "DELAY_MODES", "MAPS", "N_CHANNELS",
    "MotionTruth", "MotionDataset", "ActionFit", "StepPlan", "Synthesis",
    "BvhMotion", "Skeleton", "LineFit", "SvrInfo", "HopfTrajectory",
]

#: Names of the three actions, indexed by their integer code.
ACTIONS: Tuple[str, str, str] = ("step", "short_step", "reach")
#: Delay constraints of :func:`fit_anechoic`.
DELAY_MODES: Tuple[str, ...] = ("shared", "per_trial", "zero")
#: State maps of :class:`Synthesizer`.
MAPS: Tuple[str, ...] = ("lut", "fourier", "svr")
#: Exponential-map channels of the 17-joint skeleton.
N_CHANNELS: int = 51

Library = _m.Library


# ------------------------------------------------------------------------------------------
# Results


@_result
class MotionTruth:
    """The hidden model behind :func:`make_synthetic_dataset` (``R`` trials, ``I = 51``
    channels, ``J = 5`` sources, ``N`` samples per period, ``K`` harmonics). Angles are in
    radians, delays in periods.

    Attributes
    ----------
    periodic : float64 array (3, R, I, N)
        Noise-free periodic parts of every action and trial.
    sources : float64 array (J, N)
        The sources over one period.
    source_coeffs : complex128 array (J, K)
        Their complex harmonics ``c_1 .. c_K``.
    delays : float64 array (I, J)
        Shared delays, periods.
    weights : float64 array (3, R, I, J)
        Mixing weights per action and trial.
    means, w0 : float64 arrays (3, R, I)
        Means and non-periodic weights.
    """

    periodic: np.ndarray
    sources: np.ndarray
    source_coeffs: np.ndarray
    delays: np.ndarray
    weights: np.ndarray
    means: np.ndarray
    w0: np.ndarray


@_result
class MotionDataset:
    """Walk-and-reach trials of :func:`make_synthetic_dataset` or :func:`load_dataset`
    (``R`` trials of three actions, 51 exponential-map channels, ``N`` samples per action);
    the input of :func:`fit_stepwise`.

    Attributes
    ----------
    angles : float64 array (R, 3, 51, N)
        Joint angles, radians.
    step_length : float64 array (R, 3)
        Step length of each action, metres (the reach carries the length of the step before
        it).
    duration : float64 array (R, 3)
        Duration of each action, seconds.
    root : float64 array (R, 3, N) or None
        Pelvis travel since each action's start, metres; ``None`` for a loaded folder
        without ``root.npy``.
    distances : float64 array (R,)
        Initial distance to the drawer front of each trial, metres (empty when loaded).
    truth : MotionTruth or None
        The generating model; ``None`` for a loaded folder.
    """

    angles: np.ndarray
    step_length: np.ndarray
    duration: np.ndarray
    root: Optional[np.ndarray]
    distances: np.ndarray
    truth: Optional[MotionTruth]


@_result
class ActionFit:
    """The fit of one action in a :class:`Library` (``Library.action_fit(a)``; ``R`` trials,
    ``I`` channels, ``J`` sources of the library).

    Attributes
    ----------
    means, w0 : float64 arrays (R, I)
        Means and non-periodic weights, radians.
    weights : float64 array (R, I, J)
        Weights of the sources (0 for the sources the action does not use).
    q : float
        Approximation quality of the action.
    n_sources : int
        Number of sources the action uses.
    """

    means: np.ndarray
    w0: np.ndarray
    weights: np.ndarray
    q: float
    n_sources: int


@_result
class StepPlan:
    """A plan of the predictive planner (:func:`plan_steps`, :meth:`Synthesizer.plan`; paper
    section 2.5). Lengths are in metres.

    Attributes
    ----------
    actions : list of (str, float)
        ``(name, length)`` of each action in order, names ``"step"``, ``"short_step"`` and
        ``"reach"`` (length 0).
    too_short : bool
        The goal is closer than the comfort distance plus the shortest step: no steps, only
        the reach.
    violation : float
        Metres by which the step lengths leave their trained ranges (0 for a feasible plan).
    n_steps : int
        Number of steps.
    distance : float
        Total pelvis travel.
    """

    actions: List[Tuple[str, float]]
    too_short: bool
    violation: float
    n_steps: int
    distance: float


@_result
class Synthesis:
    """A sequence synthesized by :meth:`Synthesizer.run` (``T`` frames, 51 exponential-map
    channels).

    Attributes
    ----------
    angles : float64 array (T, 51)
        Joint angles, radians.
    root_x : float64 array (T,)
        Pelvis forward position, metres from the start.
    time : float64 array (T,)
        Time of each frame, seconds.
    phase : float64 array (T,)
        Leader phase in ``[0, 2 pi)``, radians.
    action : int64 array (T,)
        Action of each frame (index into :data:`ACTIONS`).
    executed : list of (str, float)
        ``(name, length)`` of the actions performed, lengths in metres.
    transitions : float64 array (n, 51)
        Posture at each action boundary.
    too_short : bool
        Only the reach was performed (the goal was too close for a step).
    goal : float
        The initial goal distance, metres.
    """

    angles: np.ndarray
    root_x: np.ndarray
    time: np.ndarray
    phase: np.ndarray
    action: np.ndarray
    executed: List[Tuple[str, float]]
    transitions: np.ndarray
    too_short: bool
    goal: float


@_result
class BvhMotion:
    """Frames of the 17-joint skeleton read by :func:`load_bvh`.

    Attributes
    ----------
    angles : float64 array (T, 51)
        Exponential maps, radians (made continuous over time).
    root : float64 array (T, 3)
        Pelvis positions, metres.
    frame_time : float
        Time between frames, seconds.
    """

    angles: np.ndarray
    root: np.ndarray
    frame_time: float


@_result
class BvhSkeleton:
    """A BVH file of any skeleton, read by :func:`load_bvh_skeleton`.

    Attributes
    ----------
    names : list of str
        Joint names in file order (a parent precedes its children).
    parents : list of int
        Parent of each joint, -1 for a root.
    offsets : float64 array (J, 3)
        Rest offsets from the parent, file units.
    channels : list of list of str
        Channel names of each joint in file order (``"Zrotation"``, ``"Xposition"``, ...);
        the rotation order of a joint is the order of its rotation channels.
    end_sites : list of list of list of float
        End-site offsets of each joint, file units.
    motion : float64 array (T, C)
        Channel values per frame in file order (positions in file units, rotations in
        degrees).
    positions : float64 array (T, J, 3)
        World joint positions per frame (forward kinematics: a joint's local transform is
        the translation ``OFFSET`` + position channels followed by its rotation channels
        composed in file order), file units.
    frame_time : float
        Time between frames, seconds.
    """

    names: List[str]
    parents: List[int]
    offsets: np.ndarray
    channels: List[List[str]]
    end_sites: List[List[List[float]]]
    motion: np.ndarray
    positions: np.ndarray
    frame_time: float


@_result
class Skeleton:
    """The 17-joint skeleton of :func:`skeleton` (axes: y up, z forward, x left).

    Attributes
    ----------
    names : list of str
        Joint names.
    parents : int64 array (17,)
        Parent of each joint, -1 for the root.
    offsets : float64 array (17, 3)
        Rest offsets from the parent, metres.
    bones : int64 array (21, 2)
        Bones as index pairs into the points of :func:`forward_kinematics`.
    """

    names: List[str]
    parents: np.ndarray
    offsets: np.ndarray
    bones: np.ndarray


@_result
class LineFit:
    """The least-squares line ``y = intercept + slope x`` of :func:`fit_line`.

    Attributes
    ----------
    intercept : float
        In the units of ``y``.
    slope : float
        Units of ``y`` per unit of ``x``.
    r2 : float
        Coefficient of determination.
    p_value : float
        Two-sided p-value of ``slope = 0``.
    n_points : int
        Number of points.
    """

    intercept: float
    slope: float
    r2: float
    p_value: float
    n_points: int


@_result
class SvrInfo:
    """The trained model of :func:`svr_fit_predict` (``return_info=True``).

    Attributes
    ----------
    n_support : int
        Number of support vectors.
    rho : float
        Offset ``rho`` of the decision function ``sum_i a_i K(x_i, x) - rho``.
    n_iter : int
        SMO iterations run.
    """

    n_support: int
    rho: float
    n_iter: int


@_result
class HopfTrajectory:
    """A trajectory of the Hopf star network of :func:`hopf_simulate` (``T`` steps, ``F``
    followers).

    Attributes
    ----------
    time : float64 array (T,)
        Time of each state, seconds.
    leader : float64 array (T, 2)
        Leader state ``(x, y)``.
    followers : float64 array (T, F, 2)
        Follower states.
    leader_phase : float64 array (T,)
        Leader phase in ``[0, 2 pi)``, radians.
    """

    time: np.ndarray
    leader: np.ndarray
    followers: np.ndarray
    leader_phase: np.ndarray


def _library_from_json(text: str) -> Library:
    return Library.from_json(text)


# A Library pickles and deep-copies through its JSON form (floats round-trip exactly).
copyreg.pickle(Library, lambda lib: (_library_from_json, (lib.to_json(),)))


# ------------------------------------------------------------------------------------------
# Data


def make_synthetic_dataset(n_trials: int = 40, seed: int = 0, noise: float = 0.01,
                           human_like: bool = False, n_samples: int = 100,
                           model_seed: int = 7) -> MotionDataset:
    """Walk-and-reach trials of the seeded synthetic walker, with its ground truth.

    Each trial is a normal step (action 1, length ``L1 ~ U[0.670, 0.901]`` m), a shortened
    step (action 2, ``L2 ~ U[1.070, 1.439]`` m) and a reach; the initial distance is
    ``D = 0.6 + L1 + L2``. The human-like set (paper Fig. 2) draws ``D ~ U[2.34, 2.94]`` and a
    first step independent of it.

    Parameters
    ----------
    n_trials : int
        Number of trials ``R`` (>= 1).
    seed : int
        Seed of the trial parameters and the noise.
    noise : float
        Noise standard deviation as a fraction of each channel's RMS (>= 0).
    human_like : bool
        Draw the human-like set instead of the learning set.
    n_samples : int
        Samples per action ``N`` (>= 8).
    model_seed : int
        Seed of the hidden model (sources, delays, weight functions): the "subject".

    Returns
    -------
    MotionDataset
        ``angles`` ``(R, 3, 51, N)``, ``step_length`` ``(R, 3)`` (the reach carries the
        length of the step before it), ``duration`` ``(R, 3)`` seconds, ``root``
        ``(R, 3, N)`` pelvis travel since each action's start, ``distances`` ``(R,)``, and
        ``truth`` (a :class:`MotionTruth`): ``periodic`` ``(3, R, 51, N)`` noise-free
        periodic parts, ``sources`` ``(5, N)``, ``source_coeffs`` ``(5, 3)`` complex
        harmonics, ``delays`` ``(51, 5)`` periods, ``weights`` ``(3, R, 51, 5)``, ``means``
        and ``w0`` ``(3, R, 51)`` (means and non-periodic weights).
    """
    d = _m.make_synthetic_dataset(n_trials, seed, noise, human_like, n_samples, model_seed)
    return _from_mapping(MotionDataset, d, truth=_from_mapping(MotionTruth, d["truth"]))


# ------------------------------------------------------------------------------------------
# Demixing and PCA


class AnechoicModel(Estimator):
    """Anechoic demixing ``x_i^r(t) ~ sum_j w_ij^r s_j(t - tau_ij)`` of mean-free trials.

    Fourier-domain alternating least squares: sources, weights and delays are updated in turn,
    each step lowering the residual, so ``Q`` never decreases over the sweeps of a run.

    Parameters
    ----------
    n_sources : int, default 3
        Number of sources ``J``, ``1 <= J < min(R * I, N / 2)``.
    delays : {"shared", "per_trial", "zero"}
        One delay per (channel, source) shared by all trials (the paper's model), free delays
        per trial, or no delays (synchronous model with band-limited sources).
    n_harmonics : int
        Harmonics per source ``K`` (band limit), ``1 <= K < N / 2``.
    n_restarts : int
        Runs: run 0 starts from ``init``, run 1 from the orbit-subspace start (``"orbit"``;
        with delays and at least ``n_sources`` trials, unless run 0 is one), the others from
        seeded random starts. Every run gets 60 sweeps; the best continues to ``max_iter``
        sweeps and is kept.
    max_iter, tol : int, float
        Sweeps per run, and the change of ``Q`` below which a run stops.
    seed : int
        Seed of the random starts.
    init : {"pca", "random", "greedy", "orbit"}
        Start of run 0 (``"pca"``: leading right singular vectors, at least as good as PCA;
        ``"greedy"``: sources added one at a time from the residual's leading component;
        ``"orbit"``: sources whose delayed copies span every channel's row space over the
        trials, found without the weights, which identifies the generating sources when the
        trial weights vary; a random start where it does not apply).
    delay_search : int
        Grid points per period of the per-channel delay search after the sweeps (shared
        delays and ``n_sources >= 2`` only; 0 turns it off). With the sources held, each
        channel's pairs of delays are searched on this grid, the deepest local minima are
        refined by damped Newton steps, and channels whose residual drops by more than
        0.1 % take the new delays before the sweeps continue; repeated while that happens
        (at most 5 rounds). ``Q`` can only rise. It finds the delays of channels where two
        sources must move together, which single-delay sweeps cannot.

    Attributes
    ----------
    q_ : float
        ``1 - ||X - Xhat||^2 / ||X||^2``.
    q_history_ : ndarray
        ``Q`` at the start and after every sweep of the kept run.
    sources_ : ndarray, shape (J, N)
        The sources sampled over one period (unit RMS).
    source_coeffs_ : ndarray of complex, shape (J, K)
        Their harmonics ``c_1..c_K``.
    delays_ : ndarray, shape (I, J), or (R, I, J) for ``delays="per_trial"``
        Delays in periods.
    weights_ : ndarray, shape (R, I, J)
    reconstruction_ : ndarray, shape (R, I, N)
        The model's approximation of the training trials.
    """

    _matrix_input = False
    _fitted_attr = "sources_"

    def __init__(self, n_sources: int = 3, delays: str = "shared", n_harmonics: int = 8,
                 n_restarts: int = 10, max_iter: int = 500, tol: float = 1e-9, seed: int = 0,
                 init: str = "pca", delay_search: int = 128):
        self.n_sources, self.delays, self.n_harmonics = n_sources, delays, n_harmonics
        self.n_restarts, self.max_iter, self.tol, self.seed = n_restarts, max_iter, tol, seed
        self.init, self.delay_search = init, delay_search

    def fit(self, X, y=None) -> "AnechoicModel":
        """Demixes the trials ``X``, an array ``(R, I, N)`` (trials x channels x samples of
        one period each; finite); ``y`` is ignored. Returns ``self``.

        Raises
        ------
        ValueError
            ``X`` not 3-D or not finite, bad parameters (named).
        """
        res = _m.fit_anechoic(X, self.n_sources, self.delays, self.n_harmonics,
                              self.n_restarts, self.max_iter, self.tol, self.seed, self.init,
                              self.delay_search)
        self.q_ = res["q"]
        self.q_history_ = np.asarray(res["q_history"])
        self.source_coeffs_ = res["source_coeffs"]
        self.delays_ = res["delays"]
        self.weights_ = res["weights"]
        self.reconstruction_ = res["reconstruction"]
        self.sources_ = res["sources"]
        return self


def fit_anechoic(X, n_sources: int, delays: str = "shared", n_harmonics: int = 8,
                 n_restarts: int = 10, max_iter: int = 500, tol: float = 1e-9, seed: int = 0,
                 init: str = "pca", delay_search: int = 128) -> AnechoicModel:
    """``AnechoicModel(n_sources, ...).fit(X)``: the fitted :class:`AnechoicModel` (its
    parameters and attributes are documented there)."""
    return AnechoicModel(n_sources=n_sources, delays=delays, n_harmonics=n_harmonics,
                         n_restarts=n_restarts, max_iter=max_iter, tol=tol, seed=seed,
                         init=init, delay_search=delay_search).fit(X)


# ------------------------------------------------------------------------------------------
# Step-wise learning


def _field(dataset, key: str, required: bool = True, name: str = "X"):
    """``dataset[key]`` of a mapping, else the attribute ``key``; ``None`` when optional
    and absent."""
    if isinstance(dataset, Mapping):
        v = dataset.get(key)
    else:
        v = getattr(dataset, key, None)
    if v is None and required:
        raise ValueError(f"`{name}` lacks {key!r}: it must be a dataset as make_synthetic_dataset "
                         "returns, with 'angles', 'step_length' and 'duration'")
    return v


class StepwiseModel(Estimator):
    """Learns the three actions step by step (paper section 2.3) into a :class:`Library`.

    Action 1: per trial and channel, means and the non-periodic weight are removed by least
    squares, the residual is demixed into ``n_sources_first`` sources with shared delays and
    all weights are refitted. Action 2 keeps these sources and delays and adds
    ``n_sources_extra`` learned from its residual; action 3 refits only means and weights.

    Parameters
    ----------
    n_sources_first, n_sources_extra : int, default 3 and 2
        Sources of action 1 and sources added in action 2 (the paper's 3 and 2).
    n_harmonics, n_restarts, max_iter, tol, seed, delay_search
        Demixing settings, as in :class:`AnechoicModel`.

    Attributes
    ----------
    library_ : Library
        The learned sources, shared delays and per-trial weights of the three actions
        (the input of :meth:`Synthesizer.fit`).
    """

    _matrix_input = False
    _fitted_attr = "library_"

    def __init__(self, n_sources_first: int = 3, n_sources_extra: int = 2,
                 n_harmonics: int = 8, n_restarts: int = 10, max_iter: int = 500,
                 tol: float = 1e-9, seed: int = 0, delay_search: int = 128):
        self.n_sources_first, self.n_sources_extra = n_sources_first, n_sources_extra
        self.n_harmonics, self.n_restarts, self.max_iter = n_harmonics, n_restarts, max_iter
        self.tol, self.seed, self.delay_search = tol, seed, delay_search

    def fit(self, X, y=None) -> "StepwiseModel":
        """Learns the library from the dataset ``X``; ``y`` is ignored. Returns ``self``.

        ``X`` is a dataset as :func:`make_synthetic_dataset` returns (a mapping, or an
        object with these attributes): ``angles`` ``(R, 3, I, N)``, ``step_length`` and
        ``duration`` ``(R, 3)``; optional ``root`` ``(R, 3, N)`` (pelvis travel, for the
        learned progress curve) and ``distances`` ``(R,)``. At least 3 trials.
        """
        root = _field(X, "root", required=False)
        dist = _field(X, "distances", required=False)
        self.library_ = _m.fit_stepwise(
            _field(X, "angles"), _field(X, "step_length"), _field(X, "duration"), root, dist,
            self.n_sources_first, self.n_sources_extra, self.n_harmonics, self.n_restarts,
            self.max_iter, self.tol, self.seed, self.delay_search)
        return self


def fit_stepwise(dataset, n_sources_first: int = 3, n_sources_extra: int = 2,
                 n_harmonics: int = 8, n_restarts: int = 10, max_iter: int = 500,
                 tol: float = 1e-9, seed: int = 0, delay_search: int = 128) -> StepwiseModel:
    """``StepwiseModel(...).fit(dataset)``: the fitted :class:`StepwiseModel` (its
    parameters and ``library_`` are documented there)."""
    return StepwiseModel(n_sources_first=n_sources_first, n_sources_extra=n_sources_extra,
                         n_harmonics=n_harmonics, n_restarts=n_restarts, max_iter=max_iter,
                         tol=tol, seed=seed, delay_search=delay_search).fit(dataset)


# ------------------------------------------------------------------------------------------
# Planning and synthesis


def plan_steps(D: float, comfort: float = 0.6, gamma: float = 0.385,
               range1: Tuple[float, float] = (0.670, 0.901),
               range2: Tuple[float, float] = (1.070, 1.439),
               human_like: Optional[float] = None, max_steps: int = 1000) -> StepPlan:
    """The predictive planner (paper section 2.5): splits the goal distance into steps.

    The reach starts at the comfort distance ``D3``; for three actions the rest is split as
    ``D1 = gamma (D - D3)``, ``D2 = (1 - gamma)(D - D3)``. Longer goals get more normal steps
    (keeping ``L1 / L2 = gamma / (1 - gamma)``), shorter ones shortened steps only; the
    feasible plan (every length inside its trained range) with the fewest steps wins, else
    the one with the smallest range violation.

    Parameters
    ----------
    D : float
        Distance from the pelvis to the drawer front (metres, > 0).
    comfort : float
        Comfort distance ``D3`` of the reach.
    gamma : float
        Share of the first action, in ``(0, 1)``.
    range1, range2 : (float, float)
        Trained step-length ranges of actions 1 and 2.
    human_like : float, optional
        Fixed normal-step length: the non-predictive variant that adapts only the last step.
    max_steps : int
        Upper bound on the number of steps (a goal needing more raises ``ValueError``; a plan
        too long to hold in memory raises ``MemoryError``).

    Returns
    -------
    StepPlan
        ``actions``: list of ``(name, length)`` with names ``"step"``, ``"short_step"``,
        ``"reach"`` (length 0); ``too_short`` (goal closer than the comfort distance plus
        the shortest step: no actions); ``violation`` (metres outside the ranges);
        ``n_steps``; ``distance`` (total pelvis travel).
    """
    return _plan(_m.plan_steps(D, comfort, gamma, range1, range2, human_like, max_steps))


def _plan(d) -> StepPlan:
    return _from_mapping(StepPlan, d, actions=[(str(a), float(x)) for a, x in d["actions"]])


class Synthesizer(Estimator):
    """Online synthesis of the walk-and-reach sequence from a learned :class:`Library`.

    A star network of Hopf oscillators runs at the current action's frequency; each source is
    read from its follower through a state map, with delays applied as rotations; means and
    weights come from locally weighted linear regression of the step parameters and are
    blended over ``+-beta`` around each action boundary; the planner (step ranges from the
    library's training data) is re-run from the remaining distance before every boundary.
    :meth:`fit` builds the state maps (training the SVR maps with ``map="svr"``) and the
    weight regression from a library; :meth:`run` and :meth:`plan` use them.

    Parameters
    ----------
    comfort, gamma : float
        Planner parameters (see :func:`plan_steps`).
    map : {"lut", "fourier", "svr"}
        State maps: a phase table (fast), the learned Fourier series, or epsilon-SVR maps of
        the follower state as in the paper (``svr_C``, ``svr_epsilon``, ``svr_gamma``).
    beta : float
        Blend half-width in radians, in ``(0, pi)``.
    coupling : float
        Follower coupling ``k`` (> 1 guarantees contraction to the leader).
    lut_size : int
        Entries of the phase tables, in ``4 .. 65536`` (one table per channel and source,
        ``8 * channels * sources * lut_size`` bytes; 1024 gives an interpolation error near
        1e-5 of a unit source).
    bandwidth : float, optional
        LWLR bandwidth (default: leave-one-out selection).
    human_like : float, optional
        Fixed normal-step length of the non-predictive planner variant.

    Attributes
    ----------
    library_ : Library
        The library the synthesizer was fitted on.
    """

    _matrix_input = False
    _fitted_attr = "library_"

    def __init__(self, comfort: float = 0.6, gamma: float = 0.385, map: str = "lut",
                 beta: float = _math.pi / 5, coupling: float = 2.0, lut_size: int = 1024,
                 bandwidth: Optional[float] = None, human_like: Optional[float] = None,
                 svr_C: float = 10.0, svr_epsilon: float = 0.01, svr_gamma: float = 2.0):
        self.comfort, self.gamma, self.map, self.beta = comfort, gamma, map, beta
        self.coupling, self.lut_size, self.bandwidth = coupling, lut_size, bandwidth
        self.human_like, self.svr_C, self.svr_epsilon = human_like, svr_C, svr_epsilon
        self.svr_gamma = svr_gamma

    def fit(self, X, y=None) -> "Synthesizer":
        """Builds the synthesizer from ``X``, a :class:`Library` or a fitted
        :class:`StepwiseModel` (its ``library_``); ``y`` is ignored. Returns ``self``.

        Raises
        ------
        ValueError
            ``X`` is neither, or a parameter is out of range (named).
        """
        lib = getattr(X, "library_", X) if isinstance(X, StepwiseModel) else X
        if not isinstance(lib, Library):
            raise ValueError("`X` must be a wscg.motion.Library or a fitted StepwiseModel, "
                             f"got {type(X).__name__}")
        params = self.get_params(deep=False)
        self._s = _synthesizer(lib, params)
        self._fit_params = params
        self.library_ = lib
        return self

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        state.pop("_s", None)
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        if "library_" in state:
            self._s = _synthesizer(self.library_, self._fit_params)

    @property
    def planner(self) -> dict:
        """The planner's ``comfort``, ``gamma``, ``range1``, ``range2`` and ``human_like``."""
        self._check_fitted()
        return self._s.planner

    def plan(self, D: float) -> StepPlan:
        """The synthesizer's plan for a goal at distance ``D`` (as :func:`plan_steps`)."""
        self._check_fitted()
        return _plan(self._s.plan(D))

    def run(self, goal: float = 2.6, fps: float = 120.0,
            goal_changes: Sequence[Tuple[float, float]] = (),
            max_seconds: float = 120.0) -> Synthesis:
        """Synthesizes a whole sequence towards the goal, ending with the reach.

        Parameters
        ----------
        goal : float
            Initial distance from the pelvis to the drawer front (metres, > 0).
        fps : float
            Frame rate.
        goal_changes : sequence of (time, distance)
            Goal moves, applied when their time is reached (they take effect at the next
            re-planning, when the next blend window opens).
        max_seconds : float
            Error when the motion has not finished after this long (a receding goal).

        Returns
        -------
        Synthesis
            ``angles`` ``(T, 51)``, ``root_x`` ``(T,)`` pelvis forward position (metres
            from the start), ``time`` ``(T,)``, ``phase`` ``(T,)`` leader phase in
            ``[0, 2 pi)``, ``action`` ``(T,)`` int codes (indices into :data:`ACTIONS`),
            ``executed`` list of ``(name, length)``, ``transitions`` postures at each
            action boundary ``(n, 51)``, ``too_short`` (only the reach was performed) and
            ``goal``.
        """
        self._check_fitted()
        d = self._s.run(goal, fps, goal_changes, max_seconds)
        return _from_mapping(Synthesis, d,
                             executed=[(str(a), float(x)) for a, x in d["executed"]])


def _synthesizer(lib: Library, p: dict):
    """The native synthesizer of ``lib`` with the parameters ``p`` (checked, named)."""
    return _m.Synthesizer(lib, p["comfort"], p["gamma"], p["map"], p["beta"], p["coupling"],
                          p["lut_size"], p["bandwidth"], p["human_like"], p["svr_C"],
                          p["svr_epsilon"], p["svr_gamma"])


# ------------------------------------------------------------------------------------------
# Skeleton and BVH


def load_dataset(path: Union[str, os.PathLike]) -> MotionDataset:
    """Reads a training folder (paper 16, section 3): ``angles.npy`` ``(R, 3, I, N)``,
    optional ``root.npy`` ``(R, 3, N)`` and ``steps.csv`` (header, then rows
    ``trial,action,step_length,duration``, trials from 0, actions 1 to 3), as
    :func:`save_dataset` and ``wscg motion dataset`` write them.

    Returns a :class:`MotionDataset` without ``truth``. Raises ``OSError`` naming the file
    (and the line of ``steps.csv``) for a missing or malformed one, ``ValueError`` for
    values a dataset cannot hold (a non-positive duration, NaN angles).
    """
    d = _m.load_dataset(path)
    return _from_mapping(MotionDataset, d, truth=None)


def save_dataset(path: Union[str, os.PathLike], dataset: Any) -> None:
    """Writes ``dataset`` (a :class:`MotionDataset`, or a mapping with ``angles``,
    ``step_length``, ``duration`` and optional ``root``) as a training folder that
    :func:`load_dataset` reads back; the folder is created, each file written atomically.
    ``distances`` and ``truth`` are not stored."""
    def field(key: str, required: bool = True):
        return _field(dataset, key, required, name="dataset")

    _m.save_dataset(path, field("angles"), field("step_length"), field("duration"),
                    field("root", required=False))


_BUILTIN_MAPS = ("auto", "model", "cmu", "mixamo")


def _joint_map(joint_map) -> Tuple[str, str]:
    """The joint map as the (kind, value) pair of the native reader."""
    import json

    if joint_map is None:
        return "auto", ""
    if isinstance(joint_map, str) and joint_map.lower() in _BUILTIN_MAPS:
        kind = joint_map.lower()
        return ("auto", "") if kind == "auto" else ("builtin", kind)
    if isinstance(joint_map, Mapping):
        if not all(isinstance(k, str) and isinstance(v, str) for k, v in joint_map.items()):
            raise ValueError("`joint_map` must map model joint names (str) to file joint "
                             "names (str)")
        return "json", json.dumps(dict(joint_map))
    if isinstance(joint_map, (str, os.PathLike)):
        return "file", os.fspath(joint_map)
    raise ValueError(f"`joint_map` must be None, one of {_BUILTIN_MAPS}, a dict or the path "
                     f"of a JSON file, got {type(joint_map).__name__}")


def load_bvh(path: Union[str, os.PathLike], joint_map=None,
             units_per_metre: float = 100.0) -> BvhMotion:
    """Reads a BVH file of any skeleton onto the model's 17-joint skeleton.

    Any hierarchy, channel order and rotation order is read; the file's joints are matched
    to the 17 model joints by name. Each model joint takes the world rotation of its file
    joint, corrected by the constant rotation that aligns the two rest poses (so a file in a
    T-pose drives the model's arms-down rest skeleton); intermediate file joints are folded
    into their neighbours. Files written by :func:`save_bvh` read back channel for channel.

    Parameters
    ----------
    path : str or PathLike
    joint_map : None, str, dict or PathLike
        ``None`` or ``"auto"``: the model's joint names, then CMU's, then Mixamo's (with or
        without the ``mixamorig:`` prefix). ``"model"``, ``"cmu"`` or ``"mixamo"``: that
        map only. A dict ``{"model joint": "file joint"}`` (model joints left out keep their
        own name), or the path of a JSON file holding one.
    units_per_metre : float, default 100.0
        File units per metre (100: centimetres; 39.37: inches).

    Returns
    -------
    BvhMotion
        ``angles`` ``(T, 51)`` exponential maps (made continuous over time), ``root``
        ``(T, 3)`` pelvis positions in metres, ``frame_time`` seconds.

    Raises
    ------
    OSError
        Unreadable or malformed file, or model joints the map finds no file joint for (the
        message lists every one with the names tried).
    ValueError
        A bad ``joint_map`` (an unknown model joint name) or ``units_per_metre``.
    """
    kind, value = _joint_map(joint_map)
    return _from_mapping(BvhMotion, _m.load_bvh(path, (kind, value), units_per_metre))


def load_bvh_skeleton(path: Union[str, os.PathLike]) -> BvhSkeleton:
    """Reads a BVH file of any skeleton as written: hierarchy, motion and world joint
    positions (forward kinematics), without mapping it onto the model.

    Returns
    -------
    BvhSkeleton

    Raises
    ------
    OSError
        Unreadable or malformed file (truncated, not starting with ``HIERARCHY``, a frame
        count that does not match the values, unknown channels).
    """
    return _from_mapping(BvhSkeleton, _m.load_bvh_skeleton(path))


def skeleton() -> Skeleton:
    """The 17-joint skeleton, a :class:`Skeleton`: ``names``, ``parents`` (-1 for the root),
    ``offsets`` ``(17, 3)`` metres (axes: y up, z forward, x left) and ``bones`` ``(21, 2)``
    index pairs into the points of :func:`forward_kinematics`."""
    return _from_mapping(Skeleton, _m.skeleton())


# ------------------------------------------------------------------------------------------
# Statistics, SVR, oscillators


def fit_line(x, y) -> LineFit:
    """Least-squares line ``y = intercept + slope x`` (as ``scipy.stats.linregress``).

    Returns
    -------
    LineFit
        ``intercept``, ``slope``, ``r2``, ``p_value`` (two-sided, slope = 0) and
        ``n_points``.
    """
    return _from_mapping(LineFit, _m.fit_line(x, y),
                         rename={"n": "n_points"})


def svr_fit_predict(x_train, y_train, x_test, C: float = 10.0, epsilon: float = 0.01,
                    gamma: float = 2.0, tol: float = 1e-3,
                    return_info: bool = False) -> Union[np.ndarray, Tuple[np.ndarray, SvrInfo]]:
    """Trains the RBF epsilon-SVR (SMO with LIBSVM's working-set selection) and predicts.

    Same model as ``sklearn.svm.SVR(kernel="rbf", C=C, epsilon=epsilon, gamma=gamma,
    tol=tol)``: ``K(a, b) = exp(-gamma ||a - b||^2)``.

    Parameters
    ----------
    x_train : array_like, shape (n, 2)
        At most 4000 samples.
    y_train : array_like, shape (n,)
    x_test : array_like, shape (m, 2)
    C, epsilon, gamma, tol : float
        Box constraint, tube width, RBF parameter, stopping tolerance.
    return_info : bool
        Also return the model's :class:`SvrInfo` (``n_support``, ``rho``, ``n_iter``).

    Returns
    -------
    ndarray, shape (m,), or (ndarray, SvrInfo) with ``return_info``.
    """
    pred, n_sv, rho, it = _m.svr_fit_predict(x_train, y_train, x_test, C, epsilon, gamma, tol)
    if return_info:
        return pred, SvrInfo(n_support=n_sv, rho=rho, n_iter=it)
    return pred


def hopf_simulate(duration: float, dt: float = 1e-3, omega: float = 2 * _math.pi,
                  coupling: float = 2.0, leader: Tuple[float, float] = (1.0, 0.0),
                  followers=()) -> HopfTrajectory:
    """Integrates a star network of Hopf oscillators (classical RK4).

    ``x' = (1 - x^2 - y^2) x - omega y + k (x_p - x)`` and likewise for ``y``; the leader is
    uncoupled, each follower sees the leader's state. Without coupling the unit circle is a
    limit cycle traversed at angular frequency ``omega``; any ``k > 1`` makes followers
    converge to the leader.

    Parameters
    ----------
    duration, dt : float
        Simulated time and output step (seconds, > 0).
    omega, coupling : float
        Angular frequency (> 0) and follower coupling (>= 0).
    leader : (float, float)
        Initial leader state.
    followers : array_like, shape (F, 2)
        Initial follower states (may be empty).

    Returns
    -------
    HopfTrajectory
        ``time`` ``(T,)``, ``leader`` ``(T, 2)``, ``followers`` ``(T, F, 2)``,
        ``leader_phase`` ``(T,)`` in ``[0, 2 pi)``.
    """
    return _from_mapping(HopfTrajectory,
                         _m.hopf_simulate(duration, dt, omega, coupling, leader, followers))

# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
