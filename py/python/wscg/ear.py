"""Occlusion detection and index-based ear recognition: paper 14 of WSCG vol. 23 (A.
Sultana, P. P. Paul and M. L. Gavrilova, "Occlusion Detection and Index-based Ear
Recognition").

Closed-set ear identification that survives hair, earrings, headphones and scarves:

1. **Enrolment** (:func:`enroll`): the clean colour crop is resized to 100 x 80 (area
   averaging down, bilinear up), converted to grey with OpenCV's fixed-point BT.601,
   histogram-equalised with ``cv2.equalizeHist`` arithmetic and divided by 255; the plane is
   cut into 10 x 8 blocks of 10 x 10 pixels and each block's level-1 Haar LL band (5 x 5
   values in ``[0, 2]``) is stored under its block index: a float32 template of shape
   ``(80, 25)``.
2. **Occlusion detection** (:func:`detect_occlusion`, Algorithm 1): a Gaussian skin model
   in normalised ``(r, g)`` chromaticity (:class:`SkinModel`), closing with an exact
   Euclidean disk of radius 10 and hole filling give the skin mask; a block is un-occluded
   when at least half of it is skin; a probe with more than 60 % occluded blocks is
   *rejected* (reacquire it).
3. **Index-based matching** (:class:`EarMatcher`, :func:`score`): only the un-occluded
   blocks are compared with the same-index blocks of every template, also under the eight
   one-block shifts, with normalised distances ``d = |t - r| / (2 sqrt(25))``; the rules of
   Fig. 11 (:data:`RULES`) combine them, the block-wise maximum by default.

The whole-ear Haar baseline of Fig. 12 is :meth:`EarMatcher.identify_baseline` /
:func:`baseline_score`; :func:`cmc` computes CMC curves, :func:`make_ears` makes
colour ears with exact occluder masks (the paper's WPUT database is not redistributable)
and :func:`evaluate` runs the paper's experiments on labelled images. The building blocks
are exposed for comparison with OpenCV, scikit-image, SciPy and PyWavelets:
:func:`rgb_to_gray`, :func:`equalize_hist`, :func:`resize`, :func:`haar_ll`,
:func:`block_features`, :func:`close_disk`, :func:`dilate_disk`, :func:`erode_disk`,
:func:`fill_holes`.

Parameters
----------
Every pipeline function takes the parameters of the method that it uses as keyword-only
arguments whose defaults are the paper's values (ours where the paper gives none); each
function's docstring lists its own, and :data:`PARAMS` names them all. They are the size of
the normalised image and of its blocks (``height``, ``width``, ``block``), the skin model
and rule (``skin_model`` or ``skin_mean`` / ``skin_cov``, ``skin_rule``,
``min_likelihood``, ``min_intensity``), the occlusion mask (``close_radius``,
``fill_holes``, ``block_skin_fraction``, ``reject_above_pct``), the matching (``shifts``,
``score``, ``mask_features``, ``equalize_on_skin``) and ``gray_enrolment``. The default
skin model is ours (the paper cites one without numbers): fit your own with
``SkinModel().fit(pixels)`` on enrolment images.

Conventions: images are uint8 arrays ``(H, W, 3)`` with channels R, G, B (any size; they
are resized to the normalised size); block ``b`` sits at grid row ``b // 8``, column
``b % 8`` (0-based; the paper numbers 1..80). Rejection is a normal result
(``rejected=True``), never an exception. Bad input (wrong dtype, shape or size, a grey
image where colour is needed, templates that do not fit the parameters, non-finite values,
bad parameters) raises ``ValueError`` with a message naming the problem. The GIL is released
while Rust computes.

References
----------
A. Sultana, P. P. Paul and M. L. Gavrilova, "Occlusion Detection and Index-based Ear
Recognition", WSCG 2015, Journal of WSCG vol. 23.
"""

from __future__ import annotations

import inspect
import textwrap
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ._checks import integer_ranges as _integer_ranges
from ._estimator import Estimator
from ._native import ear as _e
from ._native.ear import (close_disk, cmc, dilate_disk, equalize_hist, erode_disk, fill_holes,
                          haar_ll, resize, rgb_to_gray)
from ._results import from_mapping as _from_mapping, result as _result

__all__ = [
    "enroll", "enroll_many", "detect_occlusion", "skin_pixels", "EarMatcher", "score",
    "baseline_score", "SkinModel", "cmc", "make_ears", "evaluate", "rgb_to_gray",
    "equalize_hist", "resize", "haar_ll", "block_features", "close_disk", "dilate_disk",
    "erode_disk", "fill_holes", "RULES", "SHIFTS_NINE", "PARAMS", "OCCLUSIONS",
    "OcclusionReport", "Identification", "Ranking", "MatchScore", "EarDataset",
    "EarEvaluation",
]

#: Score rules, in the order of Fig. 11 followed by the literal eq. 18.
RULES: Tuple[str, ...] = tuple(_e.RULES)
#: The nine block shifts ``(d_row, d_col)`` of eqs. 8-16, in the paper's order B0..B8.
SHIFTS_NINE: Tuple[Tuple[int, int], ...] = tuple(tuple(s) for s in _e.SHIFTS_NINE)
#: Names of the keyword parameters of the pipeline (plus ``skin_model``).
PARAMS: Tuple[str, ...] = tuple(_e.PARAM_KEYS) + ("skin_model",)
#: Occluder kinds of :func:`make_ears`.
OCCLUSIONS: Tuple[str, ...] = ("none", "colour", "earring", "dark-hair", "blond-hair")


# The docstring entry of every pipeline parameter (numpydoc), appended by `_documented` to
# the docstring of each function that takes it.
_PARAM_DOCS: Dict[str, str] = {
    "height": """height : int, default 100
    Rows of the normalised image: the crop is resized to ``height x width`` (section 3.2).""",
    "width": """width : int, default 80
    Columns of the normalised image.""",
    "block": """block : int, default 10
    Block side in pixels, even and dividing ``height`` and ``width`` (10 x 8 = 80 blocks).""",
    "skin_model": """skin_model : SkinModel, optional
    Skin colour Gaussian in ``(r, g)`` (eqs. 2-5); default ``SkinModel()``. Give either it
    or ``skin_mean`` / ``skin_cov``.""",
    "skin_mean": """skin_mean : (float, float), optional
    Mean ``(r, g)`` of the skin model, instead of ``skin_model`` (default
    ``(0.45, 0.32)``).""",
    "skin_cov": """skin_cov : 2 x 2 floats, optional
    Covariance of the skin model, instead of ``skin_model`` (default
    ``((1.6e-3, 0), (0, 2.5e-4))``).""",
    "skin_rule": """skin_rule : {"marginal-and", "joint"}, default "marginal-and"
    Per-pixel skin decision: the paper's steps 5-6 read literally (both marginal likelihoods
    ``>= min_likelihood``) or the likelihood of eq. 5 ``>= min_likelihood``. The joint
    ellipse reaches further along one channel, so it takes noisy dark-grey occluders for
    skin more often; the marginal rule drops skin tones more than two standard deviations
    from the model's mean in one channel.""",
    "min_likelihood": """min_likelihood : float, optional
    Threshold of ``skin_rule`` in ``(0, 1)``: default ``exp(-2)`` for ``"marginal-and"``,
    0.05 (the 95 % ellipse) for ``"joint"``.""",
    "min_intensity": """min_intensity : int, default 0
    Luminance gate (not in the paper): skin also needs ``(R + G + B) / 3 >= min_intensity``;
    about 35 rejects dark hair, whose chromaticity is skin-like.""",
    "close_radius": """close_radius : float, default 10.0
    Radius of the closing disk in pixels of the normalised image (Algorithm 1, step 7).""",
    "fill_holes": """fill_holes : bool, default True
    Fill the holes of the closed skin mask.""",
    "block_skin_fraction": """block_skin_fraction : float, default 0.5
    A block is un-occluded when at least this fraction of it is skin, in ``(0, 1]``.""",
    "reject_above_pct": """reject_above_pct : float, default 60.0
    Probes with more than this percentage of occluded blocks are rejected (step 12).""",
    "shifts": """shifts : sequence of (int, int), default SHIFTS_NINE
    Block shifts ``(d_row, d_col)`` tried when matching (eqs. 8-16; at least one).""",
    "score": """score : str, default "blockwise-max"
    Score rule, one of :data:`RULES` (Fig. 11).""",
    "mask_features": """mask_features : bool, default False
    Probe features from the masked image ``X = Y . Z`` (step 8) instead of ``Y``.""",
    "gray_enrolment": """gray_enrolment : bool, default False
    Accept single-channel ``(H, W)`` images at enrolment (and for the baseline).""",
    "equalize_on_skin": """equalize_on_skin : bool, default True
    Equalise a probe with the histogram of its detected skin pixels only (not in the
    paper): a large occluder then no longer shifts the grey levels of the visible ear.
    ``False`` is the paper's pre-processing (the whole probe equalised before occlusion is
    detected); it costs the same (one histogram pass) but on occluded probes it loses to
    the whole-ear baseline: 46.7 % rank-1 vs the baseline's 55.7 % and 93.3 % equalised on
    skin (synthetic ears, colour occluders over 10-50 % of the blocks; BENCHMARKS.md).""",
}


def _documented(f):
    """``f`` with the docstring entries of its pipeline parameters appended, in signature
    order, under "Keyword parameters"."""
    names = [n for n in inspect.signature(f).parameters if n in _PARAM_DOCS]
    entries = "\n".join(_PARAM_DOCS[n] for n in names)
    body = textwrap.indent(f"Keyword parameters\n------------------\n{entries}", "    ")
    f.__doc__ = f"{f.__doc__.rstrip()}\n\n{body}\n"
    return f

# ----------------------------------------------------------------------------------------
# Input validation
# ----------------------------------------------------------------------------------------

def _floats(name: str, v) -> np.ndarray:
    try:
        return np.asarray(v, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be numeric, got {v!r}") from None


def _params(given: dict) -> dict:
    """The pipeline parameters among the arguments ``given`` (a function's ``locals()``)
    as the dict the native module reads and checks; ``None`` leaves the native default, a
    ``skin_model`` becomes its ``skin_mean`` and ``skin_cov``."""
    kw = {k: v for k, v in given.items() if k in PARAMS and v is not None}
    model = kw.pop("skin_model", None)
    if model is not None:
        if not isinstance(model, SkinModel):
            raise ValueError(f"`skin_model` must be a SkinModel, got {type(model).__name__}")
        if "skin_mean" in kw or "skin_cov" in kw:
            raise ValueError("give either `skin_model` or `skin_mean`/`skin_cov`, not both")
        kw["skin_mean"], kw["skin_cov"] = model.mean_.tolist(), model.cov_.tolist()
    return kw


# ----------------------------------------------------------------------------------------
# Results
# ----------------------------------------------------------------------------------------

@_result
class OcclusionReport:
    """The occlusion decision of :func:`detect_occlusion` (section 3.3, Algorithm 1) on the
    normalised ``(height, width)`` image cut into ``(rows, cols)`` blocks.

    Attributes
    ----------
    mask : bool array (height, width)
        Skin (un-occluded) mask ``Z`` after closing and hole filling.
    blocks : bool array (rows, cols)
        Grid of un-occluded blocks (``(10, 8)`` by default).
    block_skin_fraction : float64 array (rows, cols)
        Skin fraction of every block, in ``[0, 1]``.
    index : int64 array
        Indices of the un-occluded blocks, ascending (block ``b`` at row ``b // cols``).
    occluded_pct : float
        Percentage of occluded blocks ``E``.
    rejected : bool
        ``E > reject_above_pct``: reacquire the probe.
    """

    mask: np.ndarray
    blocks: np.ndarray
    block_skin_fraction: np.ndarray
    index: np.ndarray
    occluded_pct: float
    rejected: bool


@_result
class Identification:
    """A probe identified by :meth:`EarMatcher.identify`.

    Attributes
    ----------
    rejected : bool
        Whether the probe has more than ``reject_above_pct`` occluded blocks (it is then
        not ranked: reacquire it).
    occluded_pct : float
        Its percentage of occluded blocks.
    order : int64 array (n,)
        Gallery indices, best first (ties: lower index first); empty when rejected.
    scores : float64 array (n,)
        Scores in that order (1 is a perfect match); empty when rejected.
    """

    rejected: bool
    occluded_pct: float
    order: np.ndarray
    scores: np.ndarray


@_result
class Ranking:
    """The gallery ranked by the whole-ear baseline (:meth:`EarMatcher.identify_baseline`;
    never rejected).

    Attributes
    ----------
    order : int64 array (n,)
        Gallery indices, best first (ties: lower index first).
    scores : float64 array (n,)
        Scores ``1 - |t - r| / (2 sqrt(block_len) sqrt(blocks))`` in that order.
    """

    order: np.ndarray
    scores: np.ndarray


@_result
class MatchScore:
    """Every quantity of the match of one probe against one template (:func:`score`, eqs.
    7-18), with ``S`` shifts and ``m`` kept (un-occluded) blocks. Scores and distances are
    dimensionless, scores in ``[0, 1]`` (1 is a perfect match).

    Attributes
    ----------
    rules : dict mapping str to float
        The score under every rule of :data:`RULES` (``-inf`` where the rule has nothing
        defined).
    score : float
        The score under the ``score`` parameter.
    per_shift : float64 array (S,)
        Per-shift scores ``S_s`` (eqs. 8-16), NaN where undefined (fewer than
        ``ceil(m / 2)`` blocks with a partner).
    distances : float64 array (S, m)
        Normalised block distances ``d_{s,j}``, NaN where the partner block lies outside the
        grid.
    best_shift : int64 array (m,)
        Index into ``shifts`` of each kept block's best shift.
    index : int64 array (m,)
        The kept block indices.
    shifts : int64 array (S, 2)
        The shifts ``(d_row, d_col)``, in blocks.
    occluded_pct : float
        Percentage of occluded blocks of the probe.
    rejected : bool
        The occlusion decision (the probe is scored even when rejected).
    """

    rules: Dict[str, float]
    score: float
    per_shift: np.ndarray
    distances: np.ndarray
    best_shift: np.ndarray
    index: np.ndarray
    shifts: np.ndarray
    occluded_pct: float
    rejected: bool


@_result
class EarDataset:
    """Synthetic colour ears of :func:`make_ears` with exact occluder masks; ``m =
    n_subjects * n_probes`` probes, subject-major.

    Attributes
    ----------
    enrol : uint8 array (n_subjects, H, W, 3)
        One clean enrolment capture per subject.
    probes : uint8 array (m, H, W, 3)
        The probe captures.
    labels : int64 array (m,)
        True identity of each probe.
    occluder_masks : bool array (m, H, W)
        Pixels covered by an occluder.
    occluded_blocks : bool array (m, rows, cols)
        Blocks occluded in the normalised image (at least half covered after resizing).
    occluded_pct : float64 array (m,)
        Percentage of occluded blocks of each probe.
    skin_rg : float64 array (n_subjects, 2)
        The subjects' skin chromaticities ``(r, g)``.
    """

    enrol: np.ndarray
    probes: np.ndarray
    labels: np.ndarray
    occluder_masks: np.ndarray
    occluded_blocks: np.ndarray
    occluded_pct: np.ndarray
    skin_rg: np.ndarray


@_result
class EarEvaluation:
    """The paper's experiments (section 4) run by :func:`evaluate` on ``n`` probes. CMC
    values and rates are fractions in ``[0, 1]``; percentages are of blocks.

    Attributes
    ----------
    rules : list of str
        The rules of :data:`RULES`, the column order of ``ranks``.
    cmc : dict mapping str to float64 arrays (max_rank,)
        CMC curve of every rule over the accepted probes.
    baseline_cmc : float64 array (max_rank,)
        The whole-ear baseline over the same accepted probes.
    baseline_cmc_all : float64 array (max_rank,)
        The baseline over every probe (it has no reject path).
    rejection_rate : float
        Fraction of rejected probes.
    estimated_pct : float64 array (n,)
        Estimated occlusion percentage of each probe.
    true_pct : float64 array (n,)
        Ground-truth occlusion percentage (NaN where unknown).
    rejected : bool array (n,)
        Whether each probe was rejected.
    ranks : int64 array (n, len(rules))
        0-based rank of the true identity under each rule (-1 when rejected).
    baseline_rank : int64 array (n,)
        0-based rank of the true identity under the baseline.
    degradation : dict mapping str to float64 arrays (bins, 4), or None
        With ``edges``: per rule, rows ``(lo, hi, count, rank1)`` (rank-1 rate per bin of
        estimated occlusion, NaN for an empty bin; Fig. 13); ``None`` without ``edges``.
    """

    rules: List[str]
    cmc: Dict[str, np.ndarray]
    baseline_cmc: np.ndarray
    baseline_cmc_all: np.ndarray
    rejection_rate: float
    estimated_pct: np.ndarray
    true_pct: np.ndarray
    rejected: np.ndarray
    ranks: np.ndarray
    baseline_rank: np.ndarray
    degradation: Optional[Dict[str, np.ndarray]] = None

# ----------------------------------------------------------------------------------------
# Pipeline
# ----------------------------------------------------------------------------------------

@_documented
def enroll(image, *, height: int = 100, width: int = 80, block: int = 10,
           gray_enrolment: bool = False) -> np.ndarray:
    """Enrolment template of one clean ear crop (section 3.2).

    ``image`` is a uint8 ``(H, W, 3)`` RGB image (``(H, W)`` grey with
    ``gray_enrolment=True``), any size of at least 2 x 2. Returns the float32 Haar LL
    features ``(blocks, block_len)``, ``(80, 25)`` with the default parameters: row ``b``
    holds the 5 x 5 LL band of block ``b`` (row-major), computed on the resized,
    equalised grey image divided by 255. No skin masking (enrolment images are assumed
    un-occluded)."""
    return _e.enroll(image, _params(locals()))


@_documented
def enroll_many(images, *, height: int = 100, width: int = 80, block: int = 10,
                gray_enrolment: bool = False) -> np.ndarray:
    """Templates ``(n, blocks, block_len)`` of a list (or stacked ``(n, H, W, 3)`` array) of
    clean ear crops, enrolled in parallel; the input of :class:`EarMatcher`. Same rules as
    :func:`enroll` for each image."""
    return _e.enroll_many(images, _params(locals()))


@_documented
def detect_occlusion(image, *, height: int = 100, width: int = 80, block: int = 10,
                     skin_model: Optional[SkinModel] = None, skin_mean=None, skin_cov=None,
                     skin_rule: str = "marginal-and", min_likelihood: Optional[float] = None,
                     min_intensity: int = 0, close_radius: float = 10.0,
                     fill_holes: bool = True, block_skin_fraction: float = 0.5,
                     reject_above_pct: float = 60.0) -> OcclusionReport:
    """Occlusion report of an RGB ear crop (section 3.3, Algorithm 1).

    The crop is resized to ``height x width``; every pixel is classified by the skin model
    and rule, the skin mask is closed with a disk of ``close_radius`` and its holes filled,
    and a block is un-occluded when its skin fraction is at least ``block_skin_fraction``.
    Returns an :class:`OcclusionReport`:

    - ``mask``: bool ``(height, width)`` skin (un-occluded) mask ``Z``;
    - ``blocks``: bool ``(rows, cols)`` grid of un-occluded blocks (``(10, 8)``);
    - ``block_skin_fraction``: float64 ``(rows, cols)`` skin fraction of every block;
    - ``index``: int64 indices of the un-occluded blocks, ascending;
    - ``occluded_pct``: percentage of occluded blocks ``E``;
    - ``rejected``: ``E > reject_above_pct`` (reacquire the probe).

    A grey image raises ``ValueError`` (the skin test needs colour)."""
    return _from_mapping(OcclusionReport,
                         _e.detect_occlusion(image, _params(locals())))


@_documented
def skin_pixels(image, *, skin_model: Optional[SkinModel] = None, skin_mean=None,
                skin_cov=None, skin_rule: str = "marginal-and",
                min_likelihood: Optional[float] = None, min_intensity: int = 0) -> np.ndarray:
    """Per-pixel skin decision (Algorithm 1, steps 2-6: skin model, rule and luminance
    gate) of an RGB uint8 image at its own size, before closing and hole filling: bool
    ``(H, W)``. Black pixels are never skin."""
    return _e.skin_pixels(image, _params(locals()))


class EarMatcher(Estimator):
    """A gallery of enrolled ear templates and the parameters to identify probes against it
    (section 3.4).

    The keyword parameters are those of the whole pipeline (``score`` selects the rule used
    by :meth:`identify` and :meth:`scores`). ``fit(X)`` enrols the gallery: ``X`` is a float
    array of templates ``(n, blocks, block_len)`` (e.g. from :func:`enroll_many` with the
    same ``height``, ``width``, ``block`` and ``gray_enrolment``; stored as float32,
    block-major for fast matching), whose block count and length must fit the parameters;
    gallery entry ``i`` is identity ``i``. A scikit-learn estimator: ``get_params`` /
    ``set_params`` (``set_params`` takes effect at the next ``fit``), ``sklearn.base.clone``;
    fitted or not it pickles and deep-copies.

    >>> m = EarMatcher().fit(enroll_many(gallery_images))
    >>> r = m.identify(probe)
    >>> None if r.rejected else r.order[0]
    """

    _matrix_input = False
    _fitted_attr = "n_templates_"

    @_documented
    def __init__(self, *, height: int = 100, width: int = 80, block: int = 10,
                 skin_model: Optional[SkinModel] = None, skin_mean=None, skin_cov=None,
                 skin_rule: str = "marginal-and", min_likelihood: Optional[float] = None,
                 min_intensity: int = 0, close_radius: float = 10.0, fill_holes: bool = True,
                 block_skin_fraction: float = 0.5, reject_above_pct: float = 60.0,
                 shifts: Sequence[Tuple[int, int]] = SHIFTS_NINE,
                 score: str = "blockwise-max", mask_features: bool = False,
                 gray_enrolment: bool = False, equalize_on_skin: bool = True):
        """A matcher with the pipeline parameters below; :meth:`fit` enrols the gallery."""
        self.height, self.width, self.block = height, width, block
        self.skin_model, self.skin_mean, self.skin_cov = skin_model, skin_mean, skin_cov
        self.skin_rule, self.min_likelihood = skin_rule, min_likelihood
        self.min_intensity, self.close_radius, self.fill_holes = (
            min_intensity, close_radius, fill_holes)
        self.block_skin_fraction, self.reject_above_pct = block_skin_fraction, reject_above_pct
        self.shifts, self.score, self.mask_features = shifts, score, mask_features
        self.gray_enrolment, self.equalize_on_skin = gray_enrolment, equalize_on_skin

    def fit(self, X, y=None) -> "EarMatcher":
        """Enrols the templates ``X`` ``(n, blocks, block_len)``; ``y`` is ignored (entry
        ``i`` is identity ``i``). Returns ``self``.

        Raises
        ------
        ValueError
            Bad parameters, no template, non-finite values, or templates that do not fit
            the parameters.
        """
        params = self.get_params(deep=False)
        self._m = _e.EarMatcher(X, _params(params))
        self._fit_params = params
        self.n_templates_ = len(self._m)
        return self

    def __len__(self) -> int:
        """Number of enrolled templates (``NotFittedError`` before ``fit``)."""
        self._check_fitted()
        return self.n_templates_

    def __bool__(self) -> bool:
        """Always true, fitted or not (``len`` needs a fitted matcher)."""
        return True

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        if "_m" in state:
            state["_m"] = state["_m"].templates()
        return state

    def __setstate__(self, state: dict) -> None:
        state = dict(state)
        if isinstance(state.get("_m"), np.ndarray):
            state["_m"] = _e.EarMatcher(state["_m"], _params(state["_fit_params"]))
        self.__dict__.update(state)

    @property
    def templates_(self) -> np.ndarray:
        """A copy of the enrolled templates, float32 ``(n, blocks, block_len)``."""
        self._check_fitted()
        return self._m.templates()

    @property
    def params(self) -> dict:
        """Every keyword parameter by name (``get_params(deep=False)``)."""
        return self.get_params(deep=False)

    def identify(self, image) -> Identification:
        """Identifies an RGB probe: occlusion detection, then index-based matching against
        every template. Returns an :class:`Identification`:

        - ``rejected``: whether the probe has more than ``reject_above_pct`` occluded blocks
          (it is then not ranked: reacquire it);
        - ``occluded_pct``: its occlusion percentage;
        - ``order``: int64 gallery indices, best first (ties: lower index first); empty
          when rejected;
        - ``scores``: float64 scores in that order; empty when rejected.

        Raises ``ValueError`` for bad input, or when no block is un-occluded and the probe
        is not rejected (only possible with ``reject_above_pct >= 100``)."""
        self._check_fitted()
        rej, pct, order, scores = self._m.identify(image)
        return Identification(rejected=rej, occluded_pct=pct, order=order, scores=scores)

    def scores(self, image) -> np.ndarray:
        """Scores of an RGB probe against every template, float64 ``(n,)`` in gallery order,
        under the matcher's rule.

        This is the raw match: it does *not* apply the rejection rule, a probe that
        :meth:`identify` would reject is scored on its few un-occluded blocks (check
        :func:`detect_occlusion` or use :meth:`identify` for the decision). A rule with
        nothing defined (e.g. ``"overall-max"`` when no shift covers half of the kept blocks)
        scores ``-inf``. Raises ``ValueError`` when no block is un-occluded."""
        self._check_fitted()
        s, _rejected, _pct = self._m.scores(image)
        return s

    def identify_baseline(self, image) -> Ranking:
        """The whole-ear Haar baseline (Fig. 12): every block, the single shift B0, no
        occlusion detection and never rejected. Returns a :class:`Ranking`, ``order`` and
        ``scores`` as :meth:`identify` (score ``1 - |t - r| / (2 sqrt(block_len) sqrt(blocks))``). Grey
        probes are accepted with ``gray_enrolment=True``."""
        self._check_fitted()
        order, scores = self._m.identify_baseline(image)
        return Ranking(order=order, scores=scores)


@_documented
def score(image, template, *, height: int = 100, width: int = 80, block: int = 10,
          skin_model: Optional[SkinModel] = None, skin_mean=None, skin_cov=None,
          skin_rule: str = "marginal-and", min_likelihood: Optional[float] = None,
          min_intensity: int = 0, close_radius: float = 10.0, fill_holes: bool = True,
          block_skin_fraction: float = 0.5, reject_above_pct: float = 60.0,
          shifts: Sequence[Tuple[int, int]] = SHIFTS_NINE, score: str = "blockwise-max",
          mask_features: bool = False, equalize_on_skin: bool = True) -> MatchScore:
    """Every quantity of the match of an RGB probe image against one template (the
    reference path of eqs. 7-18; :class:`EarMatcher` computes the same scores for a whole
    gallery).

    ``template`` is a float ``(blocks, block_len)`` array. With ``S`` shifts and ``m`` kept
    blocks, returns a :class:`MatchScore`:

    - ``rules``: ``{name: score}`` under every rule of :data:`RULES` (``-inf`` where the
      rule has nothing defined);
    - ``score``: the score under the ``score`` parameter;
    - ``per_shift``: float64 ``(S,)`` per-shift scores ``S_s`` (eqs. 8-16), NaN where
      undefined (fewer than ``ceil(m / 2)`` blocks with a partner);
    - ``distances``: float64 ``(S, m)`` normalised block distances ``d_{s,j}``, NaN where the
      partner block lies outside the grid;
    - ``best_shift``: int64 ``(m,)`` index into ``shifts`` of each kept block's best shift;
    - ``index``: int64 ``(m,)`` the kept block indices;
    - ``shifts``: int64 ``(S, 2)`` the shifts;
    - ``occluded_pct``, ``rejected``: the occlusion decision (the probe is scored even when
      rejected).

    Raises ``ValueError`` when no block is un-occluded or the template does not fit."""
    return _from_mapping(MatchScore, _e.score(image, template, _params(locals())))


@_documented
def baseline_score(image, template, *, height: int = 100, width: int = 80, block: int = 10,
                   gray_enrolment: bool = False) -> float:
    """Whole-ear baseline score (Fig. 12) of an image against one template: ``1 - |t - r| /
    (2 sqrt(block_len) sqrt(blocks))`` on the full Haar LL vectors, no occlusion
    detection."""
    return _e.baseline_score(image, template, _params(locals()))

# ----------------------------------------------------------------------------------------
# Skin model
# ----------------------------------------------------------------------------------------

class SkinModel(Estimator):
    """Gaussian skin colour model in normalised chromaticity ``(r, g)``, ``r = R / (R + G +
    B)``, ``g = G / (R + G + B)`` (eqs. 2-5): mean ``A`` and covariance ``C``, likelihood
    ``L(x) = exp(-1/2 (x - A)^T C^-1 (x - A))``.

    ``mean`` and ``cov`` give the model until :meth:`fit` (or :meth:`fit_rg`) learns one
    from skin samples; ``mean_`` and ``cov_`` are the model in use. The default is ours (the
    paper cites a model without numbers): ``A = (0.45, 0.32)``, ``C = diag(1.6e-3,
    2.5e-4)``. Pass a model to the pipeline with ``skin_model=``. A non-finite, asymmetric
    or non-positive-definite covariance raises ``ValueError`` when the model is used.

    A scikit-learn estimator whose samples are RGB pixels: ``fit(X)`` returns ``self``,
    ``get_params`` / ``set_params``; it pickles and deep-copies. ``sklearn.base.clone``
    keeps the learned ``mean_`` and ``cov_`` (as scikit-learn's ``FrozenEstimator``
    does): a skin model is fitted once on enrolment images and is a fixed part of the
    pipelines it is passed to, so cloning an :class:`EarMatcher` that holds it keeps its
    colours.

    Parameters
    ----------
    mean : (float, float), default (0.45, 0.32)
        Mean chromaticity ``(r, g)`` used until ``fit``.
    cov : 2 x 2 floats, default ((1.6e-3, 0), (0, 2.5e-4))
        Covariance used until ``fit``.

    Attributes
    ----------
    mean_ : ndarray, shape (2,)
        Mean chromaticity of the model in use (fitted, else ``mean``).
    cov_ : ndarray, shape (2, 2)
        Its covariance (fitted, else ``cov``).
    """

    _matrix_input = False
    _fitted_attr = "_learned"

    def __init__(self, mean=(0.45, 0.32), cov=((1.6e-3, 0.0), (0.0, 2.5e-4))):
        self.mean = mean
        self.cov = cov

    def fit(self, X, y=None) -> "SkinModel":
        """Maximum-likelihood model (covariance divided by ``n``) of uint8 RGB skin pixels
        ``X``, an ``(n, 3)`` array (or any ``(..., 3)`` array, flattened); black pixels,
        whose chromaticity is undefined, are skipped; ``y`` is ignored. Recommended: the
        central part of the enrolment images. Returns ``self``.

        Raises
        ------
        ValueError
            Not uint8, fewer than 3 usable pixels, or a singular result.
        """
        return self._learn(*_e.skin_fit(X))

    def fit_rg(self, X, y=None) -> "SkinModel":
        """Maximum-likelihood model of chromaticity samples ``X``, a float ``(n, 2)`` array
        of ``(r, g)``; ``y`` is ignored. Returns ``self``."""
        return self._learn(*_e.skin_fit_rg(np.ascontiguousarray(_floats("X", X))))

    def _learn(self, mean, cov) -> "SkinModel":
        m, c = _e.skin_check(_floats("mean", mean).ravel().tolist(),
                             _floats("cov", cov).tolist())
        self._learned = (np.array(m, dtype=np.float64), np.array(c, dtype=np.float64))
        return self

    def _model(self) -> Tuple[np.ndarray, np.ndarray]:
        """``(mean, cov)`` in use: learned by ``fit``, else the checked parameters."""
        learned = self.__dict__.get("_learned")
        if learned is not None:
            return learned
        m, c = _e.skin_check(_floats("mean", self.mean).ravel().tolist(),
                             _floats("cov", self.cov).tolist())
        return np.array(m, dtype=np.float64), np.array(c, dtype=np.float64)

    def __sklearn_clone__(self) -> "SkinModel":
        out = type(self)(**self.get_params(deep=False))
        if "_learned" in self.__dict__:
            out._learned = tuple(a.copy() for a in self._learned)
        return out

    @property
    def mean_(self) -> np.ndarray:
        """Mean chromaticity ``(r, g)`` of the model in use, float64 ``(2,)`` (a copy)."""
        return self._model()[0].copy()

    @property
    def cov_(self) -> np.ndarray:
        """Covariance of the model in use, float64 ``(2, 2)`` (a copy)."""
        return self._model()[1].copy()

    def _eval(self, r, g, what):
        mean, cov = self._model()
        ra, ga = np.broadcast_arrays(_floats("r", r), _floats("g", g))
        out = _e.skin_eval_rg(mean.tolist(), cov.tolist(),
                              np.ascontiguousarray(ra).ravel(),
                              np.ascontiguousarray(ga).ravel(), what).reshape(ra.shape)
        return float(out) if out.ndim == 0 else out

    def mahalanobis2_rg(self, r, g):
        """Squared Mahalanobis distance ``(x - A)^T C^-1 (x - A)`` of ``x = (r, g)``;
        vectorised (``r`` and ``g`` broadcast), a float for scalars."""
        return self._eval(r, g, "mahalanobis2")

    def likelihood_rg(self, r, g):
        """Skin likelihood of eq. 5 at chromaticity ``(r, g)``; vectorised as
        :meth:`mahalanobis2_rg`."""
        return self._eval(r, g, "likelihood")

    def marginal_likelihoods_rg(self, r, g):
        """The paper's "P(r)" and "P(g)" of step 5, ``(exp(-(r - A_r)^2 / 2 C_rr),
        exp(-(g - A_g)^2 / 2 C_gg))``; vectorised."""
        return self._eval(r, g, "marginal_r"), self._eval(r, g, "marginal_g")

    def likelihood(self, rgb):
        """Skin likelihood of uint8 RGB pixels, a ``(..., 3)`` array: float64 ``(...)`` (a
        float for one pixel); 0 for black."""
        mean, cov = self._model()
        out = _e.skin_likelihood(mean.tolist(), cov.tolist(), rgb)
        return float(out) if out.ndim == 0 else out

    def __eq__(self, other) -> bool:
        """Whether both use the same model (``mean_`` and ``cov_``)."""
        if not isinstance(other, SkinModel):
            return NotImplemented
        (m1, c1), (m2, c2) = self._model(), other._model()
        return np.array_equal(m1, m2) and np.array_equal(c1, c2)

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        learned = self.__dict__.get("_learned")
        if learned is None:
            return super().__repr__()
        return (f"SkinModel(fitted: mean_={learned[0].tolist()}, "
                f"cov_={learned[1].tolist()})")


# ----------------------------------------------------------------------------------------
# Evaluation
# ----------------------------------------------------------------------------------------

@_documented
def make_ears(n_subjects: int, n_probes: int, seed: int = 0, occlusion: str = "none",
              min_pct: float = 10.0, max_pct: float = 50.0, *,
              canvas: Tuple[int, int] = (200, 160), shape_spread: float = 2.2,
              shift_px: float = 6.0, rotation_deg: float = 3.0,
              gain: Tuple[float, float] = (0.85, 1.15), white_balance: float = 0.03,
              noise_sigma: float = 3.0, height: int = 100, width: int = 80,
              block: int = 10) -> EarDataset:
    """Synthetic colour ears with exact occluder masks (the paper's WPUT database is not
    redistributable).

    ``n_subjects`` subjects (skin tone, ear shape), one clean enrolment capture each and
    ``n_probes`` independent probe captures per subject (pose, gain, white balance, noise)
    with occluders of kind ``occlusion`` (:data:`OCCLUSIONS`): ``"none"``; ``"colour"``, a
    non-skin region (scarf, headphone) covering a share of blocks drawn in ``[min_pct,
    max_pct]`` percent; ``"earring"``; ``"dark-hair"`` / ``"blond-hair"``, 10-60 strands of
    skin-like chromaticity (the stress set). The generator settings default to the
    calibrated ones; the pipeline parameters (``height``, ``width``, ``block``) size the
    occluders and the ground truth. Deterministic for a ``seed``.

    Parameters
    ----------
    canvas : (int, int), default (200, 160)
        ``(height, width)`` of the generated images, at least 16 x 16.
    shape_spread : float, default 2.2
        Spread of the ear shapes between subjects.
    shift_px, rotation_deg : float, default 6.0, 3.0
        Largest shift (pixels) and rotation (degrees) of a capture.
    gain : (float, float), default (0.85, 1.15)
        Range of the brightness gain of a capture, ``0 < low <= high``.
    white_balance : float, default 0.03
        Largest white-balance change of a capture.
    noise_sigma : float, default 3.0
        Sensor noise standard deviation in grey levels.

    Returns an :class:`EarDataset` (``m = n_subjects * n_probes``, probes subject-major):
    ``enrol`` uint8 ``(n_subjects, H, W, 3)``, ``probes`` uint8 ``(m, H, W, 3)``,
    ``labels`` int64 ``(m,)`` true identities, ``occluder_masks`` bool ``(m, H, W)``,
    ``occluded_blocks`` bool ``(m, rows, cols)`` (block occluded when at least half of it is
    covered after resizing), ``occluded_pct`` float64 ``(m,)`` and ``skin_rg`` float64
    ``(n_subjects, 2)`` the subjects' skin chromaticities."""
    return _from_mapping(EarDataset, _e.make_ears(
        n_subjects, n_probes, seed, occlusion, min_pct, max_pct, canvas, shape_spread,
        shift_px, rotation_deg, gain, white_balance, noise_sigma, _params(locals())))


@_documented
def evaluate(enrol, probes, labels, true_pct=None, max_rank: int = 10,
             edges: Optional[Sequence[float]] = None, *, height: int = 100, width: int = 80,
             block: int = 10, skin_model: Optional[SkinModel] = None, skin_mean=None,
             skin_cov=None, skin_rule: str = "marginal-and",
             min_likelihood: Optional[float] = None, min_intensity: int = 0,
             close_radius: float = 10.0, fill_holes: bool = True,
             block_skin_fraction: float = 0.5, reject_above_pct: float = 60.0,
             shifts: Sequence[Tuple[int, int]] = SHIFTS_NINE, score: str = "blockwise-max",
             mask_features: bool = False, gray_enrolment: bool = False,
             equalize_on_skin: bool = True) -> EarEvaluation:
    """The paper's experiments (section 4) on labelled images: enrols ``enrol`` (image ``i``
    is identity ``i``), identifies every probe under all rules of :data:`RULES` and the
    baseline.

    ``enrol`` and ``probes`` are lists of uint8 RGB images or stacked ``(n, H, W, 3)``
    arrays; ``labels`` the true identity of each probe; ``true_pct`` optional ground-truth
    occlusion percentages (NaN: unknown). With ``edges`` (increasing occlusion percentages)
    the rank-1 rate per bin of estimated occlusion is reported too (Fig. 13).

    Returns an :class:`EarEvaluation`: ``rules`` (names), ``cmc`` ``{rule: float64 (max_rank,)}`` over accepted
    probes, ``baseline_cmc`` (the baseline over the same accepted probes),
    ``baseline_cmc_all`` (over every probe; it has no reject path), ``rejection_rate``,
    per probe ``estimated_pct``, ``true_pct`` (NaN where unknown), ``rejected`` (bool),
    ``ranks`` int64 ``(n, 5)`` 0-based rank of the true identity under each rule (-1 when
    rejected) and ``baseline_rank`` int64 ``(n,)``; with ``edges``, ``degradation`` ``{rule:
    float64 (bins, 4)}`` rows ``(lo, hi, count, rank1)`` (rank1 NaN for an empty bin;
    ``None`` without ``edges``).

    ``ValueError`` when every probe is rejected (no CMC can be formed)."""
    return _from_mapping(EarEvaluation, _e.evaluate(enrol, probes, labels, true_pct, max_rank,
                                                    edges, _params(locals())))

# ----------------------------------------------------------------------------------------
# Building blocks
# ----------------------------------------------------------------------------------------

@_documented
def block_features(plane, *, height: int = 100, width: int = 80, block: int = 10) -> np.ndarray:
    """Haar LL features of every block of a ``(height, width)`` float plane (paper §3.2: the
    LL subband of a one-level 2-D Haar DWT per block, ``(a + b + c + d) / 2``): float32
    ``(blocks, block_len)``, row ``b`` the ``block/2 x block/2`` LL of block ``b``
    flattened row-major. :func:`enroll` is this on ``equalize_hist(rgb_to_gray(resize(image,
    100, 80))) / 255``."""
    return _e.block_features(plane, _params(locals()))


# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
