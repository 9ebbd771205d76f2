"""Multiscopic HDR image sequence generation: paper 13 of WSCG vol. 23 (R. Ramirez Orozco,
C. Loscos, I. Martin and A. Artusi, "Multiscopic HDR Image Sequence Generation").

A rectified horizontal camera array shoots a static scene with a different exposure per
camera; every view becomes an HDR radiance image. Each view is converted to radiance space
with its inverse camera response, ``E = f^-1(Z) / dt``; for every ordered pair of views
``(r, s)`` a dense nearest-neighbour field is computed by PatchMatch restricted to the
epipolar line with a cost penalised for incoherence with the neighbours' matches (eqs. 1-4);
every source view is synthesised aligned to every reference by bidirectional-similarity
patch voting (eq. 5) and merged with the reference's own samples using Khan's weights
(eqs. 6-7).

- :func:`multiscopic_hdr`: the whole pipeline (with the 2-D PatchMatch, ZNCC stereo and
  unaligned-merge baselines, and the direct-warp ablation).
- :func:`patchmatch`, :func:`patchmatch_2d`, :func:`zncc_stereo`: dense fields between two
  radiance images (the paper's matcher, original PatchMatch, a stereo baseline).
- :func:`vote_bds`, :func:`warp_direct`: synthesis of a source view aligned to a reference.
- :func:`calibrate_debevec`, :func:`calibrate_mitsunaga_nayar`, :func:`to_radiance`,
  :func:`khan_weight`, :func:`merge_stack`: camera responses, radiance space, weights and the
  merge of an aligned exposure stack.
- :func:`make_scene`: a layered five-camera scene with ground-truth radiance, disparity and
  visibility.
- :func:`rmse_log2`, :func:`bad_rate`, :func:`incoherence`: the evaluation metrics.

Conventions: images are ``(H, W)`` or ``(H, W, C)`` arrays, channels interleaved; an
``(H, W)`` input gives ``(H, W)`` outputs. LDR views are unsigned integer codes (uint8, or
uint16 for 10- to 16-bit RAW data); radiance images are floats. A field maps pixel ``(x, y)``
of image ``A`` to pixel ``(x + dx, y + dy)`` of image ``B`` and is stored as an int32 array
``(H, W, 2)`` of ``(dx, dy)``. Views are ordered left to right, so a point seen at column
``x`` of a left view appears at ``x - d`` (``d > 0``) in a view on its right. Inverse
responses are float tables ``(levels, C)`` (or ``(levels,)``) of ``f^-1(Z)`` for codes
``Z = 0 .. levels - 1``, or the names ``"gamma2.2"`` (``f^-1(Z) = (Z / z_max)^2.2``) and
``"linear"`` (RAW data, ``f^-1(Z) = Z / z_max``). Every function is deterministic for a
given ``seed`` and releases the GIL while it computes. Bad input raises ``ValueError``.

References
----------
R. Ramirez Orozco, C. Loscos, I. Martin and A. Artusi, "Multiscopic HDR Image Sequence
Generation", WSCG 2015, Journal of WSCG vol. 23.
C. Barnes, E. Shechtman, A. Finkelstein and D. B. Goldman, "PatchMatch: a randomized
correspondence algorithm for structural image editing", SIGGRAPH 2009.
D. Simakov, Y. Caspi, E. Shechtman and M. Irani, "Summarizing visual data using
bidirectional similarity", CVPR 2008.
P. Debevec and J. Malik, "Recovering high dynamic range radiance maps from photographs",
SIGGRAPH 1997.
E. A. Khan, A. O. Akyuz and E. Reinhard, "Ghost removal in high dynamic range images",
ICIP 2006.
"""

from __future__ import annotations

import os
import warnings
from typing import Any, Dict, List, Mapping, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from ._checks import integer_ranges as _integer_ranges
from ._native import hdr as _h
from ._native.hdr import (bad_rate, incoherence, khan_weight, load_crf, load_exposure_times,
                          merge, patchmatch, patchmatch_2d, rmse_log2, save_crf,
                          save_exposure_times, to_radiance, vote_bds, warp_direct,
                          zncc_stereo)
from ._results import (from_mapping as _from_mapping, result as _result,
                       tuple_eq as _tuple_eq, tuple_ne as _tuple_ne,
                       tuple_repr as _tuple_repr)

__all__ = [
    "multiscopic_hdr", "patchmatch", "patchmatch_2d", "zncc_stereo", "vote_bds",
    "warp_direct", "calibrate_debevec", "calibrate_mitsunaga_nayar", "to_radiance",
    "khan_weight", "merge", "merge_stack", "exif_exposure_times",
    "make_scene", "rmse_log2", "bad_rate", "incoherence", "ALIGN_METHODS",
    "SYNTHESIS_METHODS", "CRF_NAMES", "HdrSequence", "PolynomialResponse", "HdrScene",
    "load_crf", "save_crf", "load_exposure_times", "save_exposure_times",
]

#: Valid ``align`` names of :func:`multiscopic_hdr`.
ALIGN_METHODS = ("ours", "pm2d", "zncc", "none")
#: Valid ``synthesis`` names of :func:`multiscopic_hdr`.
SYNTHESIS_METHODS = ("bds", "direct")
#: Named inverse camera responses.
CRF_NAMES = ("gamma2.2", "linear")

_REFERENCE = "Ramirez Orozco et al., WSCG 2015, Journal of WSCG vol. 23"


class HdrSequence(NamedTuple):
    """The HDR views of :func:`multiscopic_hdr` with ``return_details=True``, a named tuple
    (``hdr, fields, fallback = multiscopic_hdr(..., return_details=True)`` unpacks it).

    Attributes
    ----------
    radiance : list of float32 arrays
        Radiance ``E_r^HDR`` of every view (relative units: code value per second of
        exposure through the inverse response), of the views' shape.
    fields : dict mapping (r, s) to int32 arrays (H, W, 2)
        Offsets ``(dx, dy)`` in pixels from view ``r`` to view ``s`` for every ordered pair
        (empty for ``align="none"``).
    fallback_pixels : list of int
        Per view, pixels where every sample of some channel was clipped (see
        :func:`merge_stack`).
    """

    radiance: List[np.ndarray]
    fields: Dict[Tuple[int, int], np.ndarray]
    fallback_pixels: List[int]

    __repr__ = _tuple_repr
    __eq__ = _tuple_eq
    __ne__ = _tuple_ne
    __hash__ = None  # type: ignore[assignment]


@_result
class PolynomialResponse:
    """The polynomial response fitted by :func:`calibrate_mitsunaga_nayar`, one entry per
    colour channel in every list.

    Attributes
    ----------
    coefficients : list of float64 arrays (degree + 1,)
        ``c_0 .. c_N`` of ``f(M) = sum_n c_n M^n`` on normalised codes ``M = Z / z_max``.
    ratios : list of float64 arrays (images - 1,)
        Exposure ratios ``t_q / t_{q+1}`` of consecutive exposures in order of time, as
        estimated.
    degree : list of int
        Polynomial degree ``N``.
    rms : list of float
        Root mean square of the residuals ``f(M_q) - R_q f(M_{q+1})`` (normalised response
        units).
    n_equations : list of int
        Equations (pixel pairs) in the least-squares fit.
    n_iter : list of int
        Alternations between coefficients and ratios that were run.
    """

    coefficients: List[np.ndarray]
    ratios: List[np.ndarray]
    degree: List[int]
    rms: List[float]
    n_equations: List[int]
    n_iter: List[int]


@_result
class HdrScene:
    """The layered multi-view scene of :func:`make_scene`, with its ground truth.

    Attributes
    ----------
    views : list of uint8 arrays (H, W, 3)
        One view per camera, left to right.
    exposure_times : list of float
        Exposure time of every view, seconds.
    crf : float32 array (256, 1)
        Table of the inverse response ``f^-1`` (gamma 2.2).
    radiance : list of float32 arrays (H, W, 3)
        True radiance of every view (relative units, as :func:`multiscopic_hdr` returns).
    disparity : list of float32 arrays (H, W)
        True disparity per camera step of the visible layer, pixels: a point at column ``x``
        of view ``r`` is at ``x + (r - s) d`` in view ``s``.
    seen_by : list of uint32 arrays (H, W)
        Bit masks of the views that see each pixel's surface point (bit ``j`` for view
        ``j``).
    """

    views: List[np.ndarray]
    exposure_times: List[float]
    crf: np.ndarray
    radiance: List[np.ndarray]
    disparity: List[np.ndarray]
    seen_by: List[np.ndarray]


# ----------------------------------------------------------------------------------------
# Input validation: images given as files (the arrays, responses, bit depths, exposure
# times and make_scene's layers are checked by the native functions)
# ----------------------------------------------------------------------------------------

def _is_path(x) -> bool:
    return isinstance(x, (str, bytes, os.PathLike))


def _files(xs, name: str):
    """Images given as file paths loaded as codes: ``(arrays, paths, bits)``; other input is
    returned as it is with ``paths = bits = None`` (checked later as arrays)."""
    if isinstance(xs, np.ndarray) or _is_path(xs):
        return xs, None, None
    try:
        xs = list(xs)
    except TypeError:
        return xs, None, None
    n_paths = sum(_is_path(x) for x in xs)
    if n_paths == 0:
        return xs, None, None
    if n_paths != len(xs):
        raise ValueError(f"`{name}` mixes file paths and arrays: give every image as a file or "
                         "every image as an array")
    paths = [os.fsdecode(x) for x in xs]
    loaded = [_h.load_codes(p) for p in paths]
    depths = [b for _, b in loaded]
    for p, b in zip(paths, depths):
        if b != depths[0]:
            raise ValueError(f"`{name}`: {p} is {b}-bit but {paths[0]} is {depths[0]}-bit")
    arrays = [a.astype(np.uint8) if b == 8 else a for a, b in loaded]
    return arrays, paths, depths[0]


def _file_times(exposure_times, paths):
    """The times of a stack: for files, given (checked against the files' EXIF exposures,
    each disagreement a warning) or read from their EXIF blocks; for arrays, as given (the
    native functions check them)."""
    if paths is None:
        return exposure_times
    times, _, messages = _h.exposure_times(paths, exposure_times)
    for m in messages:
        warnings.warn(m, UserWarning, stacklevel=3)
    return times


def exif_exposure_times(paths, exposure_times: Optional[Sequence[float]] = None) -> List[float]:
    """The exposure times of a stack of photographs, from their EXIF blocks.

    Parameters
    ----------
    paths : list of str or os.PathLike
        Image files (JPEG, TIFF or PNG; only read).
    exposure_times : sequence of float, optional
        Times to use instead (seconds, one per file): each that differs from the file's EXIF
        exposure by more than 10 % gives a ``UserWarning`` naming the file.

    Returns
    -------
    list of float
        One exposure per file, seconds: ``exposure_times`` when given, else the EXIF
        ExposureTime. When every file also gives ISO and f-number and they differ between
        the files, the relative exposure ``t_i (S_i / S_0) (N_0 / N_i)^2`` (``t * ISO / N^2``
        normalised to the first file, which keeps its time).

    Raises
    ------
    ValueError
        A count of ``exposure_times`` that differs from the files'.
    OSError
        A missing or unreadable file; without ``exposure_times``, a file without an EXIF
        block or without an exposure time (the message names it).

    Notes
    -----
    The exposure ``X = E dt`` of each photograph is what the merge divides by (Debevec &
    Malik 1997, section 2; Ramirez Orozco et al. 2015, section 3). The functions of this
    module that take images call this when the images are given as file paths.

    References
    ----------
    P. Debevec and J. Malik, SIGGRAPH 1997, section 2; Ramirez Orozco et al., WSCG 2015,
    Journal of WSCG vol. 23, section 3.
    """
    if _is_path(paths) or isinstance(paths, np.ndarray) or not hasattr(paths, "__iter__"):
        raise ValueError(f"`paths` must be a list of file paths, got {type(paths).__name__}")
    files = [os.fsdecode(f) if _is_path(f) else f for f in paths]
    if not files or not all(isinstance(p, str) for p in files):
        raise ValueError("`paths` must be a non-empty list of file paths")
    return _file_times(exposure_times, files)


# ----------------------------------------------------------------------------------------
# Pipeline
# ----------------------------------------------------------------------------------------

def multiscopic_hdr(views, exposure_times=None, crf="gamma2.2", *, patch: int = 7,
                    n_iter: int = 2, max_disparity: int = 64,
                    min_disparity: Optional[int] = None, coherence: bool = True,
                    epipolar: bool = True, align: str = "ours", synthesis: str = "bds",
                    ordered: bool = False, weighted_cost: bool = False,
                    fill_saturated: bool = False, bits: Optional[int] = None, seed: int = 0,
                    return_details: bool = False) -> Union[List[np.ndarray], HdrSequence]:
    """One HDR radiance image per view of a rectified multi-exposure camera array (paper
    section 3, Fig. 2).

    Parameters
    ----------
    views : list of arrays (H, W) or (H, W, C), uint8 or uint16, or of file paths
        At least two views of one size, ordered left to right on a horizontal baseline, each
        shot with its own exposure. Files (8- or 16-bit PNG or TIFF, or JPEG) are read as
        codes, and their bit depth is the default ``bits``.
    exposure_times : sequence of float, optional
        Exposure time ``dt_n`` of every view (seconds, > 0). Default: read from the files'
        EXIF blocks (:func:`exif_exposure_times`; views given as files only); given times
        that disagree with the files' EXIF by more than 10 % give a ``UserWarning``.
    crf : str, array or list, default "gamma2.2"
        Inverse camera response: ``"gamma2.2"``, ``"linear"`` (RAW), a float table
        ``(levels, C)`` or ``(levels,)`` of ``f^-1(Z)`` (as :func:`calibrate_debevec`
        returns), or a list of those, one per view (each camera needs its own response).
    patch : int, default 7
        Patch side ``N`` (odd, >= 3; the paper's figures use 7 x 7).
    n_iter : int, default 2
        PatchMatch iterations per direction (the paper: "two iterations were enough").
    max_disparity : int, default 64
        Largest horizontal offset searched, ``Max_disp`` of eqs. 1 and 4 (< width).
    min_disparity : int, optional
        Smallest horizontal offset; default ``-max_disparity``.
    coherence : bool, default True
        Divide the patch distance by the coherence term ``C`` (eqs. 2 and 4).
    epipolar : bool, default True
        Search on the epipolar line (the paper). ``False`` with ``align="ours"`` searches
        in 2-D over the whole source (keeping the coherence term).
    align : {"ours", "pm2d", "zncc", "none"}, default "ours"
        The paper's PatchMatch, the original 2-D PatchMatch of Barnes et al. (SSD only), ZNCC
        stereo with a left-right check and direct warp (Batz et al. style), or no alignment
        (the paper's Fig. 1a).
    synthesis : {"bds", "direct"}, default "bds"
        Bidirectional-similarity voting with both fields (eq. 5) or the direct warp through
        the reference-to-source field (Fig. 5a); ZNCC always warps directly.
    ordered : bool, default False
        Use the view order: a source right of the reference searches only
        ``[-Max_disp, 0]``, one on its left only ``[0, Max_disp]``.
    weighted_cost : bool, default False
        Not in the paper (an ablation): weight each squared difference by the smaller Khan
        weight of the two samples so clipped pixels do not drive the match.
    fill_saturated : bool, default False
        Not in the paper, which leaves saturated reference areas unsolved (a clipped patch
        carries no data to match): pixels clipped in the reference take the offset of the
        nearest unclipped pixel of their row; then every connected clipped region takes the
        disparity at which its outline matches the source's pixels at least as bright as
        the reference's clipping level (a shorter exposure shows the object unclipped), so
        a bright object whose every pixel clips gets its own depth rather than the
        background's; and radiance is voted weighted by the Khan weights. On the five-view
        scene of :func:`make_scene`, over the pixel-channels of points seen by all five views
        that are well exposed (codes 10-245) in some view, the views' RMSE log2 are 0.110 /
        0.086 / 0.082 / 0.096 / 0.099 (0.121 / 0.088 / 0.103 / 0.173 / 0.220 without); over
        all pixels, occluded bands included, 0.195 / 0.156 / 0.127 / 0.284 / 0.371 (0.198 /
        0.155 / 0.135 / 0.292 / 0.389 without). On a scene with a bright foreground object
        clipped in the two longest of four exposures, its clipped pixels go from 0.075 /
        0.561 to 0.041 / 0.095 in those views.
    bits : int, optional
        Bit depth of named responses: default the files' depth for views given as files, 8
        for uint8 views, otherwise the smallest depth covering the largest code (pass it for
        RAW data, e.g. 10, since ``z_max`` also sets the Khan weights). A table's length must equal ``2**bits`` when both are given.
    seed : int, default 0
        Seed of the random initialisation and search; each ordered pair derives its own.
    return_details : bool, default False
        Return an :class:`HdrSequence` (the radiance, the fields and the fallback counts)
        instead of the list of radiance images.

    Returns
    -------
    hdr : list of float32 arrays
        Radiance ``E_r^HDR`` of every view, of the views' shape.
    details : HdrSequence, with ``return_details``
        A named tuple ``(radiance, fields, fallback_pixels)``: ``fields[(r, s)]``, int32
        ``(H, W, 2)`` offsets ``(dx, dy)`` from view ``r`` to view ``s`` for every ordered
        pair (empty for ``align="none"``); ``fallback_pixels``, per view, pixels where every
        sample of some channel was clipped (see :func:`merge_stack`).

    Notes
    -----
    Every view goes to radiance space, ``E_n = f_n^-1(Z_n) / dt_n`` (numerator of eq. 6).
    For every ordered pair ``(r, s)`` the field ``r -> s`` minimises
    ``D(p, d) = SSD(p, d) / C(p, d)`` (eq. 2): ``SSD`` is the mean squared radiance
    difference of the ``N x N`` patches (eq. 3), ``C = max(1 - d_c / Max_disp, 0.05)``
    (eq. 4) with ``d_c`` the distance of the candidate offset to the closest offset of a
    4-neighbour; candidates come from propagation and the random search
    ``u_i = v_0 + w alpha^i R_i`` on the epipolar line (eq. 1, ``w = Max_disp``,
    ``alpha = 1/2``). Every source is synthesised aligned to every reference by voting with
    both fields (eq. 5; radiance, weights and levels voted together so the weights follow
    the source pixels) and merged with the reference's samples:
    ``E_r^HDR = sum_n w_n E_n / sum_n w_n`` (eq. 6) with ``w(Z) = 1 - (2 Z / z_max - 1)^12``
    (eq. 7). Pairs are matched in parallel; the result depends on ``seed`` only.
    Saturated areas of the reference stay unreliable (the paper's stated limitation).

    References
    ----------
    Ramirez Orozco et al., WSCG 2015, Journal of WSCG vol. 23, section 3, eqs. 1-7.

    Examples
    --------
    >>> from wscg import hdr
    >>> sc = hdr.make_scene(height=48, width=64, exposure_times=(0.005, 0.04, 0.3))
    >>> out = hdr.multiscopic_hdr(sc.views, sc.exposure_times, max_disparity=40)
    >>> len(out), out[0].shape, out[0].dtype
    (3, (48, 64, 3), dtype('float32'))
    """
    views, paths, file_bits = _files(views, "views")
    hdr_list, fields, fallback = _h.multiscopic_hdr(
        views, _file_times(exposure_times, paths), crf, file_bits if bits is None else bits,
        patch, n_iter, max_disparity, min_disparity, coherence, epipolar, align, synthesis,
        ordered, weighted_cost, fill_saturated, seed, return_details)
    if return_details:
        return HdrSequence(hdr_list, fields, fallback)
    return hdr_list


# ----------------------------------------------------------------------------------------
# Responses, radiance and merging of stacks (matching, synthesis, `merge`, the metrics and
# the file functions are the native ones, py/src/hdr.rs, imported above)
# ----------------------------------------------------------------------------------------

def calibrate_debevec(stack, exposure_times=None, *, n_samples: int = 70, lam: float = 10.0,
                      bits: Optional[int] = None) -> np.ndarray:
    """Recover the inverse camera response from a static exposure stack (Debevec & Malik
    1997; the paper's section 3: "for 8bits LDR images a CRF per camera needs to be
    estimated").

    Parameters
    ----------
    stack : list of arrays (H, W) or (H, W, C), uint8 or uint16, or of file paths
        At least two aligned exposures of a static scene (files: 8- or 16-bit PNG or TIFF,
        or JPEG, read as codes).
    exposure_times : sequence of float, optional
        Exposure time of every image (seconds, > 0). Default: the files' EXIF exposures (as
        :func:`multiscopic_hdr`).
    n_samples : int, default 70
        Sample pixels, on a regular grid (as OpenCV's ``CalibrateDebevec`` with
        ``random=False`` places them).
    lam : float, default 10
        Smoothness weight ``lambda`` (> 0).
    bits : int, optional
        Bit depth of the codes (1..16): default the files' depth, else 8. Above 10 bits the
        codes are reduced to 10 bits for the solve (``z >> (bits - 10)``; the dense solve has
        one unknown per code) and ``g`` is interpolated linearly back to every code at the
        bins' centres.

    Returns
    -------
    float32 array (2**bits, C)
        ``f^-1(Z)`` per code and channel, non-decreasing; usable as ``crf`` everywhere.

    Notes
    -----
    Per channel, the least-squares solution of
    ``min_{g, ln E_i} sum_ij [h(Z_ij)(g(Z_ij) - ln E_i - ln dt_j)]^2
    + lambda^2 sum_z [h(z) g''(z)]^2`` with ``g(z_mid) = 0`` and the hat weight
    ``h(z) = min(z, z_max - z)``, solved by SVD; ``f^-1 = exp(g)``. Codes the samples never
    reach are filled by the smoothness term and kept monotone. A ``g`` that decreases over
    the observed codes raises ``ValueError`` ("CRF calibration failed").

    References
    ----------
    P. Debevec and J. Malik, SIGGRAPH 1997; Ramirez Orozco et al., WSCG 2015, Journal of
    WSCG vol. 23, section 3.
    """
    stack, paths, file_bits = _files(stack, "stack")
    return _h.calibrate_debevec(stack, _file_times(exposure_times, paths), n_samples, lam,
                                file_bits if bits is None else bits)


def calibrate_mitsunaga_nayar(stack, exposure_times=None, *, degree: Optional[int] = None,
                              max_degree: int = 10, n_samples: int = 2000,
                              refine_ratios: bool = True, tol: float = 1e-7,
                              max_iter: int = 100,
                              bits: Optional[int] = None) -> Tuple[np.ndarray, PolynomialResponse]:
    """Recover the inverse camera response as a polynomial (Mitsunaga & Nayar 1999, the
    model of RASCAL, which the paper used for its 8-bit views), re-estimating the exposure
    ratios from approximate times.

    Parameters
    ----------
    stack : list of arrays (H, W) or (H, W, C), uint8 or uint16, or of file paths
        At least two aligned exposures of a static scene whose pixels span the codes (a
        calibration chart or a gradient): the polynomial's scale is fixed at the top code,
        so the stack needs samples in the upper half of the range. Files (8- or 16-bit PNG
        or TIFF, or JPEG) are read as codes.
    exposure_times : sequence of float, optional
        Exposure time of every image (seconds, > 0, distinct). The intermediate ones may be
        approximate when ``refine_ratios`` is on; the span from the shortest to the longest
        fixes the response's exponent. Default: the files' EXIF exposures (as
        :func:`multiscopic_hdr`).
    degree : int, optional
        Polynomial degree (1..10); by default chosen per channel on held-out samples (the
        smallest degree within 25 % of the best held-out error whose fit increases).
    max_degree : int, default 10
        Largest degree tried when ``degree`` is None.
    n_samples : int, default 2000
        Sample pixels on a regular grid; each gives one equation per pair of consecutive
        exposures (in time) where both codes lie within 2-98 % of the range.
    refine_ratios : bool, default True
        Alternate between the coefficients and the exposure ratios (the method's
        iteration); False keeps the ratios of ``exposure_times``.
    tol : float, default 1e-7
        Stop when the response moves less than this at every code.
    max_iter : int, default 100
        Most alternations.
    bits : int, optional
        Bit depth of the codes (1..16): default the files' depth, else 8.

    Returns
    -------
    crf : float32 array (2**bits, C)
        ``f(Z / z_max)`` per code and channel with ``f(z_max) = 1``, non-decreasing; usable
        as ``crf`` everywhere.
    fit : PolynomialResponse
        Per channel: ``coefficients`` (``c_0 .. c_N``), ``ratios`` (``t_q / t_{q+1}`` of
        consecutive exposures in order of time, as estimated), ``degree``, ``rms`` (of the
        residuals ``f(M_q) - R_q f(M_{q+1})``), ``n_equations``, ``n_iter``.

    Notes
    -----
    Consecutive exposures satisfy ``f(M_q) = R_q f(M_{q+1})``; with the ratios fixed, the
    coefficients minimise ``sum [f(M_q) - R_q f(M_{q+1})]^2`` by least squares after
    substituting ``c_N = 1 - sum_{n<N} c_n``. Each ratio is then re-estimated as the median
    of the per-pixel ratios ``f(M_q) / f(M_{q+1})`` (the 1999 paper takes their mean, which
    dark pixels make unstable), and all ratios are scaled so that their product keeps the
    given span, which removes the exponential ambiguity (``f**g`` with ratios ``R**g`` fits
    as well). A stack without upper-half samples, or a polynomial that decreases over the
    observed codes, raises ``ValueError`` ("CRF calibration failed").

    References
    ----------
    T. Mitsunaga and S. K. Nayar, "Radiometric self calibration", CVPR 1999; Ramirez Orozco
    et al., WSCG 2015, Journal of WSCG vol. 23, section 3.
    """
    stack, paths, file_bits = _files(stack, "stack")
    table, info = _h.calibrate_mitsunaga_nayar(
        stack, _file_times(exposure_times, paths), file_bits if bits is None else bits,
        degree, max_degree, n_samples, refine_ratios, tol, max_iter)
    fit = _from_mapping(
        PolynomialResponse, info, rename={"equations": "n_equations", "iterations": "n_iter"},
        coefficients=[np.asarray(c, dtype=np.float64) for c in info["coefficients"]],
        ratios=[np.asarray(r, dtype=np.float64) for r in info["ratios"]])
    return table, fit


def merge_stack(images, exposure_times=None, crf="gamma2.2", *,
                bits: Optional[int] = None) -> Tuple[np.ndarray, int]:
    """Merge an aligned exposure stack of one view into HDR (paper eqs. 6-7, no matching).

    Parameters
    ----------
    images : list of arrays (H, W) or (H, W, C), uint8 or uint16, or of file paths
        Aligned exposures of one shape (one image is allowed); files as in
        :func:`multiscopic_hdr`.
    exposure_times : sequence of float, optional
        Exposure time of every image (seconds, > 0). Default: the files' EXIF exposures (as
        :func:`multiscopic_hdr`).
    crf : str, array or list, default "gamma2.2"
        One inverse response or one per image (see :func:`multiscopic_hdr`).
    bits : int, optional
        As in :func:`multiscopic_hdr`.

    Returns
    -------
    hdr : float32 array of the images' shape
        ``E = sum_n w(Z_n) E_n / sum_n w(Z_n)`` per pixel and channel.
    fallback_pixels : int
        Pixels where some channel had total weight ``< 1e-6`` (every sample clipped).

    Notes
    -----
    ``E_n = f^-1(Z_n) / dt_n`` and ``w`` is :func:`khan_weight` (eqs. 6-7). The paper leaves
    the all-clipped case undefined: such a channel takes the radiance of the shortest
    exposure when its samples are clipped high (mean level >= 1/2; a lower bound of the true
    radiance, ``f^-1(z_max) / min dt``) and of the longest exposure when they are clipped
    low. The result has no NaN or infinity.

    References
    ----------
    Ramirez Orozco et al., WSCG 2015, Journal of WSCG vol. 23, eqs. 6-7.

    Examples
    --------
    >>> import numpy as np
    >>> from wscg import hdr
    >>> e, n = hdr.merge_stack([np.full((2, 2), 255, np.uint8)] * 2, [0.01, 0.1])
    >>> float(e[0, 0]), n
    (100.0, 4)
    """
    images, paths, file_bits = _files(images, "images")
    out, fallback = _h.merge_stack(images, _file_times(exposure_times, paths), crf,
                                   file_bits if bits is None else bits)
    return out, int(fallback)


# ----------------------------------------------------------------------------------------
# Synthetic scene and metrics
# ----------------------------------------------------------------------------------------

def make_scene(*, height: int = 160, width: int = 256,
                exposure_times: Sequence[float] = (0.005, 0.030, 0.061, 0.122, 0.280),
                emitter_peak: float = 300.0, noise: float = 0.002,
                seed: int = 7, layers: Optional[Sequence[Mapping[str, Any]]] = None) -> HdrScene:
    """A layered multi-view scene with ground truth, standing in for the paper's camera-array
    data sets (section 4), whose ground-truth radiance is unknown.

    Fronto-parallel textured planes (by default three, at fractional disparities 7.5, 18.3
    and 33.7 px per camera step: the back one covering the image, a rectangle and a disk in
    front) composited back to front (exact occlusions), lit by a field with a Gaussian
    emitter ``emitter_peak`` times the base light on the back plane, seen by one camera per
    exposure time on a horizontal baseline (left to right), gamma-2.2 response, Gaussian
    noise ``noise`` (of full scale) before 8-bit quantisation. ``layers`` sets the planes of
    a scene of your own, e.g. a bright foreground object clipped in the long exposures::

        make_scene(layers=[{"disparity": 7.5},
                           {"disparity": 26.0, "rect": (0.15, 0.55, 0.55, 0.8),
                            "disk": True, "gain": 30.0}])

    Parameters
    ----------
    height, width : int, default 160, 256
        View size (>= 8).
    exposure_times : sequence of float, default the IIS Jumble set (5, 30, 61, 122, 280 ms)
        One camera per time, 2 to 32 cameras.
    emitter_peak : float, default 300
        Peak of the emitter relative to the base light (>= 1).
    noise : float, default 0.002
        Noise standard deviation of the signal in ``[0, 1]`` (>= 0).
    seed : int, default 7
        Noise seed (the geometry and textures are set by ``layers``).
    layers : sequence of dict, optional
        The planes, back to front (the first should cover the image; where no plane covers
        a pixel the first is seen; the emitter lights the first). Keys: ``"disparity"``
        (pixels per camera step, required; a point at column ``x`` of the central view is
        at ``x + (k - c) d`` in view ``k``, ``c`` the central camera), ``"rect"`` (extent in
        the central view as fractions of the image, ``(y0, y1, x0, x1)``, default the whole
        image), ``"disk"`` (elliptic outline inside ``rect``, default False), ``"gain"``
        (radiance factor, default 1; the brightest point of a plane of gain 1 fills 90 % of
        the shortest exposure, so a gain of 20-30 makes an object that clips in exposures
        10-60 times longer) and ``"seed"`` (texture seed, default ``11 + 12 k`` for plane
        ``k``). Default: the three planes above (gain 1).

    Returns
    -------
    HdrScene
        ``views``: list of uint8 ``(H, W, 3)``; ``exposure_times``: list of float; ``crf``:
        float32 ``(256, 1)`` table of ``f^-1`` (gamma 2.2); ``radiance``: list of float32
        ``(H, W, 3)`` true radiance per view; ``disparity``: list of float32 ``(H, W)``
        true disparity per camera step of the visible layer (a point at column ``x`` of view
        ``r`` is at ``x + (r - s) d`` in view ``s``); ``seen_by``: list of uint32 ``(H, W)``
        bit masks of the views that see each pixel's surface point (bit ``j`` for view
        ``j``).

    References
    ----------
    Ramirez Orozco et al., WSCG 2015, Journal of WSCG vol. 23 (exposures of the IIS Jumble
    set, Fig. 7).
    """
    return _from_mapping(HdrScene, _h.make_scene(height, width, exposure_times, emitter_peak,
                                                 noise, seed, layers))


# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
