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

from typing import Sequence, Tuple, Union

import numpy as np

from ._native import doe as _d
from ._checks import integer_ranges as _integer_ranges

__all__ = ["ccd", "decode", "encode", "williams", "fit_rsm", "fit_rsm_blocked", "rm_anova",
           "rm_anova_oneway", "lsd", "panel_pca"]


def _f64(a, name: str, ndim: int) -> np.ndarray:
    arr = np.ascontiguousarray(np.asarray(a, dtype=np.float64))
    if arr.ndim != ndim:
        raise ValueError(f"`{name}` must be a {ndim}-D array, got shape {arr.shape}")
    return arr


def ccd(k: int, face: str = "circumscribed", alpha: Union[str, float] = "orthogonal",
        center: Union[int, Tuple[int, int]] = (4, 4)) -> np.ndarray:
    """Central composite design in coded units, one row per run (pyDOE3's ``ccdesign``).

    Parameters
    ----------
    k : int
        Number of factors (>= 2).
    face : {'circumscribed', 'inscribed', 'faced'} (or 'ccc', 'cci', 'ccf')
        Where the axial points lie; inscribed designs scale everything into [-1, 1].
    alpha : {'orthogonal', 'rotatable'} or float
        Axial distance rule (pyDOE3's default is orthogonal).
    center : int or (int, int)
        Centre points in the factorial and axial blocks; an int puts them all in the first.

    Returns
    -------
    (runs, k) float64 array: factorial block with its centre points, then axial block with its
    centre points.

    Examples
    --------
    >>> ccd(2, "inscribed", "rotatable", (3, 2)).shape   # the paper's 13 runs
    (13, 2)
    """
    c = (int(center), 0) if np.isscalar(center) else tuple(int(v) for v in center)
    return _d.ccd(int(k), str(face), str(alpha), c)


def decode(coded, low: Sequence[float], high: Sequence[float]) -> np.ndarray:
    """Coded units [-1, 1] to physical units, per factor ``low`` ... ``high``."""
    return _d.decode(_f64(coded, "coded", 2), [float(v) for v in low], [float(v) for v in high])


def encode(physical, low: Sequence[float], high: Sequence[float]) -> np.ndarray:
    """Physical units to coded units [-1, 1]."""
    return _d.encode(_f64(physical, "physical", 2), [float(v) for v in low],
                     [float(v) for v in high])


def williams(n: int) -> np.ndarray:
    """Williams Latin square: presentation orders balanced for first-order carry-over.

    ``n`` rows for even ``n``, ``2n`` rows for odd ``n`` (26 for the paper's 13 plates: one
    order per observer); every row is a permutation of ``0 .. n-1``.
    """
    return np.asarray(_d.williams(int(n)), dtype=np.int64)


def fit_rsm(x, y, interaction: bool = True) -> dict:
    """Second-order response surface by ordinary least squares.

    ``y = b0 + sum b_i x_i + sum b_ii x_i^2 (+ sum b_ij x_i x_j)`` on the runs ``x``
    (runs x factors, coded units) and responses ``y``.

    Returns a dict: ``names``, ``coef``, ``se``, ``t``, ``p`` (two-sided), ``r2``,
    ``r2_adj``, ``r2_pred`` (1 - PRESS / SST), ``press`` (sum of squared leave-one-out
    residuals ``e_i / (1 - h_ii)``), ``sse``, ``sst``, ``df_resid``, ``sigma2``,
    ``leverage``, ``residuals``, ``fitted``, ``stationary`` (``-B^-1 b / 2``),
    ``y_stationary``, ``canonical_eigs`` and ``canonical_axes`` (eigenvalues and vectors of
    B; all positive: a minimum, the best match on the paper's scale).
    """
    return _d.fit_rsm(_f64(x, "x", 2), [float(v) for v in np.asarray(y, dtype=np.float64).ravel()],
                      bool(interaction))


def fit_rsm_blocked(x, scores, interaction: bool = True) -> dict:
    """The surface of :func:`fit_rsm` on every score, ``scores`` (subjects x runs), with the
    subjects as blocks (one intercept shift per subject): the fit behind significance
    levels computed on all observations rather than on panel means."""
    return _d.fit_rsm_blocked(_f64(x, "x", 2), _f64(scores, "scores", 2), bool(interaction))


def rm_anova(scores) -> dict:
    """Two-way repeated-measures ANOVA on ``scores`` (subjects, conditions, stimuli).

    Returns one dict per effect (``'condition'``, ``'stimulus'``, ``'condition:stimulus'``) with
    ``ss, df, ms, F, p, ss_error, df_error, ms_error, np2`` (partial eta squared),
    ``eps_gg`` and ``p_gg`` (Greenhouse-Geisser), plus ``ss_subject`` and ``ss_total``.
    """
    return _d.rm_anova(_f64(scores, "scores", 3))


def rm_anova_oneway(scores) -> dict:
    """One-way repeated-measures ANOVA on ``scores`` (subjects, levels)."""
    return _d.rm_anova_oneway(_f64(scores, "scores", 2))


def lsd(scores, alpha: float = 0.05) -> dict:
    """Fisher's least significant difference on one condition, ``scores`` (subjects,
    stimuli): ``lsd = t(1 - alpha/2, df_err) sqrt(2 MS_err / subjects)``; returns ``lsd``,
    ``t_crit``, ``ms_error``, ``df_error``, ``means``, ``pairs`` (``(i, j, separated)``) and
    ``n_separated``."""
    return _d.lsd(_f64(scores, "scores", 2), float(alpha))


def panel_pca(scores) -> np.ndarray:
    """Explained-variance ratios of the PCA of the panel (stimuli x subjects, subjects
    standardised): the first above 0.8 means the observers agree (paper 07, section 5.1)."""
    return np.asarray(_d.panel_pca(_f64(scores, "scores", 2)))

# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
