"""Design-of-experiments statistics of paper 07 of WSCG vol. 23 (the perceptual study of da
Graça, Paljic and Diaz): central composite designs, Williams Latin squares, second-order
response surfaces with PRESS, predicted R² and canonical analysis, repeated-measures ANOVA
with the Greenhouse-Geisser correction, Fisher's LSD and the panel PCA.

The study: 13 virtual plates from an inscribed rotatable central composite design over flake
radius and flake density (:func:`ccd` with ``face='inscribed', alpha='rotatable',
center=(3, 2)``), 26 observers ordered by a Williams square (:func:`williams`), similarity
scores 0 ... 10 in a monoscopic and a stereoscopic condition, one quadratic surface per
condition on the panel means (:func:`fit_rsm`, Tables 2-3), :func:`rm_anova` and
:func:`lsd`. Bad input raises ``ValueError``.
"""

from __future__ import annotations

import os
from typing import List, NamedTuple, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

from ._native import doe as _d
from ._native.doe import ccd, decode, encode, panel_pca, williams
from ._checks import integer_ranges as _integer_ranges
from ._results import (from_mapping as _from_mapping, result as _result,
                       tuple_eq as _tuple_eq, tuple_ne as _tuple_ne, tuple_repr as _tuple_repr)

__all__ = ["ccd", "decode", "encode", "williams", "fit_rsm", "fit_rsm_blocked", "rm_anova",
           "rm_anova_oneway", "lsd", "panel_pca", "RsmFit", "AnovaEffect", "AnovaTable",
           "LeastSignificantDifference", "load_study", "save_study", "load_runs", "save_runs",
           "load_design", "Study", "Runs"]


@_result
class RsmFit:
    """A second-order response surface fitted by :func:`fit_rsm` or :func:`fit_rsm_blocked`
    (paper 07, Tables 2-3). Responses are in the units of ``y`` (the paper's 0 ... 10
    similarity scale), factors in coded units.

    Attributes
    ----------
    names : list of str
        Term names in coefficient order: ``b0``, ``b1`` ... ``bk``, ``b11`` ... ``bkk``,
        then ``b12`` ... (with interaction); a blocked fit appends ``subject0`` ....
    coef, se, t, p : float64 arrays (n_terms,)
        Coefficients, standard errors ``sqrt(sigma2 (X'X)^-1_jj)``, t statistics
        ``coef / se`` and their two-sided p-values on ``df_resid`` degrees of freedom.
    r2, r2_adj, r2_pred : float
        ``1 - SSE / SST``, adjusted ``1 - (1 - R²)(n - 1) / df_resid`` and predicted
        ``1 - PRESS / SST`` (``-inf`` when a run has leverage 1).
    press : float
        Sum of squared leave-one-out residuals ``e_i / (1 - h_ii)`` (units of ``y`` squared).
    sse, sst : float
        Residual and total (centred) sums of squares.
    df_resid : int
        Residual degrees of freedom ``n - p``.
    sigma2 : float
        Residual variance ``SSE / df_resid``.
    leverage, residuals, fitted : float64 arrays (n,)
        Per observation: hat-matrix diagonal ``h_ii``, ``y - y_hat`` and ``y_hat``.
    stationary : float64 array (k,) or None
        Stationary point ``-B^-1 b / 2`` in coded units; ``None`` when ``B`` is singular.
    y_stationary : float or None
        Predicted response there.
    canonical_eigs : float64 array (k,)
        Eigenvalues of ``B``, ascending; all positive: a minimum (the best match on the
        paper's scale).
    canonical_axes : float64 array (k, k)
        Unit eigenvectors of ``B`` as columns, in the order of ``canonical_eigs``.
    """

    names: List[str]
    coef: np.ndarray
    se: np.ndarray
    t: np.ndarray
    p: np.ndarray
    r2: float
    r2_adj: float
    r2_pred: float
    press: float
    sse: float
    sst: float
    df_resid: int
    sigma2: float
    leverage: np.ndarray
    residuals: np.ndarray
    fitted: np.ndarray
    stationary: Optional[np.ndarray]
    y_stationary: Optional[float]
    canonical_eigs: np.ndarray
    canonical_axes: np.ndarray


@_result
class AnovaEffect:
    """One effect of a repeated-measures ANOVA (:func:`rm_anova`, :func:`rm_anova_oneway`).
    Sums of squares and mean squares are in the units of the scores squared.

    Attributes
    ----------
    ss, df, ms : float, int, float
        Sum of squares, degrees of freedom and mean square ``ss / df`` of the effect.
    F : float
        F statistic ``ms / ms_error``.
    p : float
        Uncorrected p-value ``P(F(df, df_error) >= F)``.
    ss_error, df_error, ms_error : float, int, float
        The same for the effect's error term (effect x subject interaction).
    np2 : float
        Partial eta squared ``ss / (ss + ss_error)``.
    eps_gg : float
        Greenhouse-Geisser epsilon (1 for one degree of freedom; NaN when the subjects'
        scores over the effect's cells do not vary).
    p_gg : float
        p-value on the Greenhouse-Geisser corrected degrees of freedom.
    """

    ss: float
    df: int
    ms: float
    F: float
    p: float
    ss_error: float
    df_error: int
    ms_error: float
    np2: float
    eps_gg: float
    p_gg: float


@_result
class AnovaTable:
    """The two-way repeated-measures ANOVA of :func:`rm_anova` (condition x stimulus within
    subjects; sums of squares in the units of the scores squared).

    Attributes
    ----------
    condition, stimulus, interaction : AnovaEffect
        The effects ``condition``, ``stimulus`` and ``condition:stimulus``.
    ss_subject : float
        Between-subject sum of squares (``subjects - 1`` degrees of freedom).
    ss_total : float
        Total sum of squares about the grand mean.
    """

    condition: AnovaEffect
    stimulus: AnovaEffect
    interaction: AnovaEffect
    ss_subject: float
    ss_total: float


@_result
class LeastSignificantDifference:
    """Fisher's least significant difference on one condition (:func:`lsd`); differences
    and means are in the units of the scores.

    Attributes
    ----------
    alpha : float
        Two-sided significance level.
    t_crit : float
        ``t(1 - alpha/2, df_error)``.
    ms_error : float
        Error mean square of the one-way repeated-measures ANOVA (stimulus x subject).
    df_error : int
        Its degrees of freedom ``(stimuli - 1)(subjects - 1)``.
    lsd : float
        ``t_crit sqrt(2 ms_error / subjects)``.
    means : float64 array (stimuli,)
        Mean score of each stimulus.
    pairs : list of (int, int, bool)
        Every pair ``(i, j)``, ``i < j``, lexicographic, with whether
        ``|means[i] - means[j]| > lsd``.
    n_separated : int
        Number of separated pairs.
    """

    alpha: float
    t_crit: float
    ms_error: float
    df_error: int
    lsd: float
    means: np.ndarray
    pairs: List[Tuple[int, int, bool]]
    n_separated: int


_RSM_VECTORS = ("coef", "se", "t", "p", "leverage", "residuals", "fitted", "canonical_eigs")


def _rsm(d: dict) -> RsmFit:
    arrays = {k: np.asarray(d[k], dtype=np.float64) for k in _RSM_VECTORS}
    st = d["stationary"]
    return _from_mapping(RsmFit, d, **arrays,
                         stationary=None if st is None else np.asarray(st, dtype=np.float64))


def _effect(d: dict) -> AnovaEffect:
    return _from_mapping(AnovaEffect, d)


def _f64(a, name: str, ndim: int) -> np.ndarray:
    arr = np.ascontiguousarray(np.asarray(a, dtype=np.float64))
    if arr.ndim != ndim:
        raise ValueError(f"`{name}` must be a {ndim}-D array, got shape {arr.shape}")
    return arr


def fit_rsm(x: npt.ArrayLike, y: npt.ArrayLike, interaction: bool = True) -> RsmFit:
    """Second-order response surface by ordinary least squares.

    ``y = b0 + sum b_i x_i + sum b_ii x_i^2 (+ sum b_ij x_i x_j)`` on the runs ``x``
    (runs x factors, coded units) and responses ``y``.

    Returns an :class:`RsmFit`: coefficients with ``se``, ``t`` and two-sided ``p``, ``r2``,
    ``r2_adj``, ``r2_pred`` (1 - PRESS / SST), ``press`` (sum of squared leave-one-out
    residuals ``e_i / (1 - h_ii)``), the stationary point ``-B^-1 b / 2`` and the canonical
    analysis (eigenvalues and vectors of B; all positive: a minimum, the best match on the
    paper's scale).
    """
    return _rsm(_d.fit_rsm(_f64(x, "x", 2),
                           [float(v) for v in np.asarray(y, dtype=np.float64).ravel()],
                           bool(interaction)))


def fit_rsm_blocked(x, scores, interaction: bool = True) -> RsmFit:
    """The surface of :func:`fit_rsm` on every score, ``scores`` (subjects x runs), with the
    subjects as blocks (one intercept shift per subject): the fit behind significance
    levels computed on all observations rather than on panel means."""
    return _rsm(_d.fit_rsm_blocked(_f64(x, "x", 2), _f64(scores, "scores", 2),
                                   bool(interaction)))


def rm_anova(scores) -> AnovaTable:
    """Two-way repeated-measures ANOVA on ``scores`` (subjects, conditions, stimuli).

    Returns an :class:`AnovaTable`: one :class:`AnovaEffect` per effect (``condition``,
    ``stimulus`` and their ``interaction``) with ``ss, df, ms, F, p, ss_error, df_error,
    ms_error, np2`` (partial eta squared), ``eps_gg`` and ``p_gg`` (Greenhouse-Geisser),
    plus ``ss_subject`` and ``ss_total``.
    """
    d = _d.rm_anova(_f64(scores, "scores", 3))
    return AnovaTable(condition=_effect(d["condition"]), stimulus=_effect(d["stimulus"]),
                      interaction=_effect(d["condition:stimulus"]),
                      ss_subject=d["ss_subject"], ss_total=d["ss_total"])


def rm_anova_oneway(scores) -> AnovaEffect:
    """One-way repeated-measures ANOVA on ``scores`` (subjects, levels): the
    :class:`AnovaEffect` of the levels."""
    return _effect(_d.rm_anova_oneway(_f64(scores, "scores", 2)))


def lsd(scores, alpha: float = 0.05) -> LeastSignificantDifference:
    """Fisher's least significant difference on one condition, ``scores`` (subjects,
    stimuli): ``lsd = t(1 - alpha/2, df_err) sqrt(2 MS_err / subjects)``; returns a
    :class:`LeastSignificantDifference` with ``lsd``, ``t_crit``, ``ms_error``,
    ``df_error``, ``means``, ``pairs`` (``(i, j, separated)``) and ``n_separated``."""
    d = _d.lsd(_f64(scores, "scores", 2), float(alpha))
    return _from_mapping(LeastSignificantDifference, d,
                         means=np.asarray(d["means"], dtype=np.float64),
                         pairs=[(int(i), int(j), bool(s)) for i, j, s in d["pairs"]])


# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.


@_result
class Study:
    """The scores of a perceptual study (paper 07, section 4), as :func:`load_study` reads
    them.

    Attributes
    ----------
    subject_names : list of str
        Subject names, sorted.
    condition_names : list of str
        Condition names, sorted.
    scores : float64 array (subjects, conditions, stimuli)
        The score of every subject, condition and stimulus: the input of :func:`rm_anova`
        (``scores[:, c, :]`` is one condition's input of :func:`lsd` and
        :func:`fit_rsm_blocked`).
    """

    subject_names: List[str]
    condition_names: List[str]
    scores: np.ndarray


class Runs(NamedTuple):
    """The runs of a response-surface experiment, as :func:`load_runs` reads them
    (``x, y = load_runs(path)`` unpacks them for :func:`fit_rsm`).

    Attributes
    ----------
    x : float64 array (n, k)
        Factor levels of each run, coded units.
    y : float64 array (n,)
        The response of each run.
    """

    x: np.ndarray
    y: np.ndarray

    __repr__ = _tuple_repr
    __eq__ = _tuple_eq
    __ne__ = _tuple_ne
    __hash__ = None  # type: ignore[assignment]


def load_study(path: Union[str, os.PathLike]) -> Study:
    """Reads a study's score table (CSV): a header naming the columns ``subject``,
    ``condition``, ``stimulus`` (an index from 0) and ``score`` (any case and order; other
    columns ignored), then one row per observation; every subject must score every stimulus
    in every condition exactly once.

    Returns a :class:`Study`. Raises ``OSError`` naming the file and the line for a missing
    or malformed file (a missing column, a bad number, a cell scored twice, a missing cell,
    which is named).
    """
    subjects, conditions, scores = _d.load_study(os.fspath(path))
    return Study(subject_names=subjects, condition_names=conditions, scores=scores)


def save_study(path: Union[str, os.PathLike], study: Study) -> None:
    """Writes ``study`` (a :class:`Study`) as a score table that :func:`load_study` reads
    back (atomically; one row per subject, condition and stimulus)."""
    _d.save_study(os.fspath(path), [str(s) for s in study.subject_names],
                  [str(c) for c in study.condition_names], _f64(study.scores, "scores", 3))


def load_runs(path: Union[str, os.PathLike]) -> Runs:
    """Reads the runs of an experiment (CSV with a header line): per row the factor levels
    (coded units) then, in the last column, the response. Returns :class:`Runs`
    ``(x, y)``; raises ``OSError`` naming the file (and the line) for a missing or
    malformed one (a bad number, rows of different lengths, fewer than two columns, no
    rows)."""
    x, y = _d.load_runs(os.fspath(path))
    return Runs(x, y)


def save_runs(path: Union[str, os.PathLike], x: npt.ArrayLike, y: npt.ArrayLike) -> None:
    """Writes runs ``x`` (n, k) and ``y`` (n,) as CSV with the header ``x1,...,xk,y``
    (atomically); :func:`load_runs` reads them back."""
    _d.save_runs(os.fspath(path), _f64(x, "x", 2), [float(v) for v in _f64(y, "y", 1)])


def load_design(path: Union[str, os.PathLike]) -> np.ndarray:
    """Reads a design (CSV with a header line, one row of factor levels per stimulus, coded
    units) as a float64 array (stimuli, k); errors as :func:`load_runs`."""
    return _d.load_design(os.fspath(path))


_integer_ranges(globals())
