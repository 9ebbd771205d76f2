"""Compressed-sensing MRI with a uniform discrete curvelet prior: paper 11 of WSCG vol. 23
(B. Yang, M. Yuan, Y. Ma and J. Zhang, "Magnetic Resonance Images Reconstruction using
Uniform Discrete Curvelet Transform Sparse Prior based Compressed Sensing", UDCSMRI).

An MR image ``x`` is reconstructed from undersampled k-space ``y = P F x + noise`` by

    min_x  Phi(Psi x)   subject to   ||P F x - y||_2 <= epsilon,

with ``Psi`` the uniform discrete curvelet transform (UDCT) of the real and imaginary parts
of ``x`` and ``Phi`` the l1 norm (``reg="l1"``) or the total variation of the synthesis
(``reg="tv"``), solved by C-SALSA (ADMM).

- :class:`Udct`: the exact, tight (Parseval) 2-D UDCT with redundancy 4; ``tight=False``
  reproduces the windows of the reference package ``ucurv`` 0.1.1.
- :class:`Fdct`: the wrapping fast discrete curvelet transform (Candes, Demanet, Donoho and
  Ying 2006), the curvelet prior the paper compares against (Tables 2 and 3): an exact
  complex tight frame.
- :func:`reconstruct`: C-SALSA with the ``"udct"``, ``"fdct"``, ``"db1"`` ... ``"db8"`` or
  ``"identity"`` prior.
- :func:`fcsa`, :func:`tvcmri`, :func:`watmri`: the paper's baselines (TV + wavelet l1
  composite objective; TVCMRI is solved by Condat-Vu on its objective);
  :func:`tv_constrained` is a direct TV-constrained solver (Chambolle-Pock).
- :func:`mask_cartesian`, :func:`mask_pseudo_radial`: sampling masks (paper Fig. 2).
- :func:`make_shepp_logan_kspace` (analytic, no inverse crime),
  :func:`make_shepp_logan_reference`, :func:`make_shepp_logan_image`,
  :func:`with_smooth_phase`, :func:`make_diamond_lattice`: test data.
- :func:`psnr`, :func:`rlne`, :func:`noise_epsilon`: the paper's metrics and the noise radius.

Conventions: k-space is **un-shifted** (DC at index ``[0, 0]``, as ``numpy.fft.fft2``
returns it) and scaled by the **unitary** FFT, i.e. ``np.fft.fft2(x, norm="ortho")``; use
``np.fft.fftshift`` to display it. Masks are boolean arrays of the k-space's shape. Images
are complex128 ``(H, W)``. Bad input raises ``ValueError``.

References: T. Nguyen and H. Chauris, "Uniform
discrete curvelet transform", IEEE TSP 58(7), 2010, doi:10.1109/TSP.2010.2047666;
M. Afonso, J. Bioucas-Dias and M. Figueiredo, "An augmented Lagrangian approach to the
constrained optimization formulation of imaging inverse problems", IEEE TIP 20(3), 2011,
doi:10.1109/TIP.2010.2076294.
"""

from __future__ import annotations

from typing import List, Optional, Sequence, Tuple, Union

import numpy as np

from ._native import csmri as _c
from ._native.csmri import (make_diamond_lattice, make_shepp_logan_image,
                            make_shepp_logan_kspace, make_shepp_logan_reference, mask_cartesian,
                            mask_pseudo_radial, noise_epsilon, psnr, rlne, tv_constrained,
                            with_smooth_phase)
from ._checks import integer_ranges as _integer_ranges

# MR images and k-space are complex throughout: every array argument may be complex.
_TAKES_COMPLEX = True
from ._results import result as _result

__all__ = [
    "Udct", "Fdct", "Sflct", "reconstruct", "fcsa", "tvcmri", "watmri", "tv_constrained", "zero_filled",
    "simulate", "mask_cartesian", "mask_pseudo_radial", "make_shepp_logan_kspace",
    "make_shepp_logan_reference", "make_shepp_logan_image", "with_smooth_phase",
    "make_diamond_lattice",
    "psnr", "rlne", "noise_epsilon", "ReconstructionHistory", "ScaleChoice", "choose_scales",
]


@_result
class ReconstructionHistory:
    """The iterations of :func:`reconstruct`, :func:`fcsa`, :func:`tvcmri` or :func:`watmri`
    (``return_history=True``), one entry per iteration run in every array.

    Attributes
    ----------
    n_iter : int
        Iterations run (``max_iter`` or ``n_iter``, fewer when ``tol`` stopped C-SALSA).
    iteration : int64 array (n_iter,)
        The iteration numbers, from 1.
    rel_change : float64 array (n_iter,)
        Relative change ``||x_k - x_{k-1}|| / ||x_{k-1}||`` of the image.
    residual : float64 array (n_iter,)
        Data misfit ``||P F x_k - y||``, k-space units.
    objective : float64 array (n_iter,)
        The objective: the regulariser ``Phi(Psi x_k)`` of C-SALSA (eq. 1), or the baselines'
        ``1/2 ||P F x - y||^2 + a TV(x) + b ||W x||_1`` (plus WaTMRI's tree term), for
        images normalised to unit peak.
    mse : float64 array (n_iter,) or None
        Mean squared error against ``reference`` (the paper's Fig. 6); None without one.
    """

    n_iter: int
    iteration: np.ndarray
    rel_change: np.ndarray
    residual: np.ndarray
    objective: np.ndarray
    mse: Optional[np.ndarray] = None


@_result
class ScaleChoice:
    """The number of UDCT scales chosen by :func:`choose_scales` and how each candidate scored.

    Attributes
    ----------
    scales : int
        The chosen number of scales ``J`` (the UDCT's ``wedges`` is ``[[6, 6]] * J`` with the
        default wedge counts).
    candidates : tuple of int
        The candidates scored, in the order given (those the image size allows).
    scores : float64 array (len(candidates), folds)
        Weighted squared hold-out error of each candidate on each fold, in k-space units
        squared: an estimate of the squared error over the unmeasured positions. The chosen
        candidate has the smallest row sum.
    held_out : int
        Samples held out per fold (0 when no sample lies outside the fully sampled region:
        then nothing is unmeasured there and the first possible candidate is returned).
    """

    scales: int
    candidates: Tuple[int, ...]
    scores: np.ndarray
    held_out: int


def _history(d) -> ReconstructionHistory:
    mse = d.get("mse")
    return ReconstructionHistory(
        n_iter=int(d["iters"]), iteration=np.asarray(d["iter"], dtype=np.int64),
        rel_change=np.asarray(d["rel_change"], dtype=np.float64),
        residual=np.asarray(d["residual"], dtype=np.float64),
        objective=np.asarray(d["objective"], dtype=np.float64),
        mse=None if mse is None else np.asarray(mse, dtype=np.float64))


def _with_history(img, hist, return_history: bool):
    return (img, _history(hist)) if return_history else img


def _complex2(x, name: str) -> np.ndarray:
    a = np.asarray(x)
    if not (np.issubdtype(a.dtype, np.number) or a.dtype == np.bool_):
        raise ValueError(f"`{name}` must be a numeric array, got dtype {a.dtype}")
    if a.ndim != 2:
        raise ValueError(f"`{name}` must be a 2-D array, got shape {a.shape}")
    return np.ascontiguousarray(a, dtype=np.complex128)


def _mask(m, shape) -> np.ndarray:
    a = np.asarray(m)
    if a.shape != tuple(shape):
        raise ValueError(f"shape mismatch: mask has shape {a.shape}, k-space {tuple(shape)}")
    return np.ascontiguousarray(a != 0)


class Udct:
    """Uniform discrete curvelet transform of real ``(rows, cols)`` images.

    Parameters
    ----------
    shape : (int, int)
        Image shape; each size must be divisible by the decimation factors (the error names
        the divisor).
    wedges : list of [int, int], default [[6, 6]]
        Per scale (coarse to fine) the number of wedges along each axis, multiples of 3.
        ``[[6, 6]]`` is the paper's one scale with 12 directional bands.
    alpha : float, default 0.1
        Angular overlap of neighbouring wedges.
    tight : bool, default True
        Exactly tight frame (window tails that alias on the decimated grid are dropped).
        ``False`` gives ``ucurv`` 0.1.1's windows, tight only to about 1e-10.

    Notes
    -----
    ``forward`` returns the real low-pass block and one complex array per band; counting a
    complex value twice there are ``4 * rows * cols`` real coefficients. ``backward`` is
    both the inverse and the adjoint. Band order (``band_ids``) is scale, pyramid
    (0: frequencies dominant along rows), wedge, the order of ``ucurv``'s dictionary.
    """

    def __init__(self, shape: Tuple[int, int], wedges=((6, 6),), alpha: float = 0.1,
                 tight: bool = True):
        self._u = _c.Udct(shape, wedges, alpha, tight)
        self._args = (shape, wedges, alpha, tight)

    def __reduce__(self):
        # A plan is a function of its arguments: pickles and copies rebuild it.
        return (type(self), self._args)

    @property
    def shape(self) -> Tuple[int, int]:
        return self._u.shape()

    @property
    def band_ids(self) -> List[Tuple[int, int, int]]:
        """``(scale, pyramid, wedge)`` of every band, in coefficient order."""
        return self._u.band_ids()

    @property
    def n_real_coeffs(self) -> int:
        return self._u.num_real_coeffs()

    def forward(self, x) -> Tuple[np.ndarray, List[np.ndarray]]:
        """Coefficients ``(lowpass, bands)`` of the real image ``x``."""
        return self._u.forward(x)

    def backward(self, lowpass, bands: Sequence) -> np.ndarray:
        """The real image of coefficients ``(lowpass, bands)`` (inverse and adjoint)."""
        return self._u.backward(lowpass, bands)

    def windows(self) -> List[np.ndarray]:
        """Dense frequency windows in FFT order (DC at ``[0, 0]``): low-pass, then bands."""
        return self._u.windows()


class Fdct:
    """Fast discrete curvelet transform via wrapping of complex ``(rows, cols)`` images.

    The frequency plane is cut into dyadic coronae (``scales`` of them, the coarse one
    included) and each corona into wedges equispaced in slope, ``angles_coarse`` at the
    coarsest curvelet scale and doubling every other scale (parabolic scaling); each
    windowed wedge is wrapped around the origin onto a rectangle and inverse transformed
    there (Candes et al. 2006, section 3). The squared windows sum to one and the wrapping is
    one to one, so the transform is a tight frame: ``backward`` is the inverse and the
    adjoint and coefficient energy equals image energy.

    Parameters
    ----------
    shape : (int, int)
        Image shape.
    scales : int, optional
        Number of scales; default ``ceil(log2(min(shape))) - 3`` (5 for 256 x 256).
    angles_coarse : int, default 16
        Wedges at the coarsest curvelet scale, a multiple of 4 and at least 8.
    finest : {"wavelets", "curvelets"}, default "wavelets"
        One isotropic band at the finest scale (CurveLab's default) or curvelet wedges.
    transition : float, default 1.0
        Share of a wedge taken by its angular transitions, in (0, 1]. 1 is the paper's
        window (two wedge widths, redundancy about 5.3); 0.5 gives about 4.2 and 0.25 about
        3.5. CurveLab's narrower wedges give 2.8.

    Notes
    -----
    ``forward`` returns ``coeffs[scale][angle]``, complex arrays whose shapes are the wrapped
    rectangles (``bands`` lists them); ``backward`` takes the same nesting. Wedges are
    numbered counter-clockwise from the lower edge of the east cone (``directions`` gives
    the centre angle of each, ``atan2(row frequency, column frequency)``).

    Examples
    --------
    >>> import numpy as np
    >>> from wscg import csmri
    >>> f = csmri.Fdct((64, 64))
    >>> x = np.random.default_rng(0).standard_normal((64, 64))
    >>> c = f.forward(x)
    >>> bool(np.allclose(f.backward(c), x))
    True
    """

    def __init__(self, shape: Tuple[int, int], scales: Optional[int] = None,
                 angles_coarse: int = 16, finest: str = "wavelets", transition: float = 1.0):
        self._f = _c.Fdct(shape, scales, angles_coarse, finest, transition)
        # Checked by the plan: the settings reconstruct() passes on for an Fdct prior.
        self._config = (scales, angles_coarse, finest, transition)
        self._bands = self._f.bands()

    def __reduce__(self):
        # A plan is a function of its arguments: pickles and copies rebuild it.
        return (type(self), (self.shape, *self._config))

    @property
    def shape(self) -> Tuple[int, int]:
        return self._f.shape()

    @property
    def n_scales(self) -> int:
        return self._f.num_scales()

    @property
    def bands(self) -> List[Tuple[int, int, Tuple[int, int]]]:
        """``(scale, angle, (rows, cols))`` of every band, coarse first."""
        return list(self._bands)

    @property
    def redundancy(self) -> float:
        """Complex coefficients per pixel."""
        return self._f.redundancy()

    def _nest(self, flat):
        out: List[list] = [[] for _ in range(self.n_scales)]
        for (s, _, _), v in zip(self._bands, flat):
            out[s].append(v)
        return out

    def forward(self, x) -> List[List[np.ndarray]]:
        """Coefficients ``coeffs[scale][angle]`` of the (real or complex) image ``x``."""
        return self._nest(self._f.forward(x))

    def backward(self, coeffs: Sequence[Sequence]) -> np.ndarray:
        """The complex image of ``coeffs[scale][angle]`` (inverse and adjoint)."""
        if len(coeffs) != self.n_scales:
            raise ValueError(f"{len(coeffs)} scales given, the transform has {self.n_scales}")
        flat = [b for scale in coeffs for b in scale]
        return self._f.backward(flat)

    def windows(self) -> List[List[np.ndarray]]:
        """Dense frequency windows in FFT order (DC at ``[0, 0]``), ``[scale][angle]``."""
        return self._nest(self._f.windows())

    def directions(self) -> List[List[Optional[float]]]:
        """Centre direction (radians) of every wedge, ``None`` for non-directional bands."""
        return self._nest(self._f.directions())


class Sflct:
    """Sharp-frequency-localized contourlet transform (Lu & Do 2006) of ``(rows, cols)`` images.

    A frequency-domain pyramid (separable raised-cosine low-pass ``L`` and high-pass
    ``sqrt(1 - L^2)``, a tight frame) feeds each high-pass image to a ladder directional
    filter bank with the PKVA filters (``2^n`` wedge-shaped subbands, perfectly
    reconstructing and nearly orthogonal). These are the LRSFLCT / MRSFLCT priors of the
    paper's Tables 2 and 3.

    Parameters
    ----------
    shape : (int, int)
        Image shape; both sides must be divisible by ``2`` per downsampled level and by
        ``2^n`` for ``n`` directional levels at that scale.
    redundancy : {"less", "more"}, default "less"
        ``"less"``: every low-pass is downsampled (about 1.33 coefficients per pixel);
        ``"more"``: the finest low-pass is not (about 2.33).
    levels : sequence of int, default (3, 3, 4)
        Directional levels per scale, coarsest first (``n`` gives ``2^n`` directions).

    Notes
    -----
    ``forward`` returns ``coeffs[scale][direction]``: scale 0 holds the low-pass image, scales
    1... the directional subbands from coarse to fine. The transform is real: a real image
    gives real coefficients (returned as float arrays). ``inverse`` reconstructs exactly;
    ``adjoint`` is the transpose (it differs slightly, the frame is not tight).

    Examples
    --------
    >>> import numpy as np
    >>> from wscg import csmri
    >>> t = csmri.Sflct((64, 64), levels=(2, 3))
    >>> x = np.random.default_rng(0).standard_normal((64, 64))
    >>> bool(np.allclose(t.inverse(t.forward(x)), x))
    True
    """

    def __init__(self, shape: Tuple[int, int], redundancy: str = "less",
                 levels: Sequence[int] = (3, 3, 4)):
        self._t = _c.Sflct(shape, redundancy, levels)
        self._bands = self._t.bands()
        self._scales = 1 + max(s for s, _, _ in self._bands)
        self._args = (shape, redundancy, levels)

    def __reduce__(self):
        # A plan is a function of its arguments: pickles and copies rebuild it.
        return (type(self), self._args)

    @property
    def shape(self) -> Tuple[int, int]:
        return self._t.shape()

    @property
    def bands(self) -> List[Tuple[int, int, Tuple[int, int]]]:
        """``(scale, direction, (rows, cols))`` of every band, the low-pass first."""
        return list(self._bands)

    @property
    def redundancy(self) -> float:
        """Coefficients per pixel."""
        return self._t.redundancy()

    def _nest(self, flat, real: bool):
        out: List[list] = [[] for _ in range(self._scales)]
        for (s, _, _), v in zip(self._bands, flat):
            out[s].append(np.ascontiguousarray(v.real) if real else v)
        return out

    def _flat(self, coeffs):
        if len(coeffs) != self._scales:
            raise ValueError(f"{len(coeffs)} scales given, the transform has {self._scales}")
        return [b for scale in coeffs for b in scale]

    def forward(self, x) -> List[List[np.ndarray]]:
        """Coefficients ``coeffs[scale][direction]`` of the (real or complex) image ``x``."""
        a = np.asarray(x)
        return self._nest(self._t.forward(a), not np.iscomplexobj(a))

    def inverse(self, coeffs: Sequence[Sequence]) -> np.ndarray:
        """The image of ``coeffs[scale][direction]`` (exact reconstruction); real when every
        band is real."""
        real = all(not np.iscomplexobj(b) for scale in coeffs for b in scale)
        y = self._t.inverse(self._flat(coeffs))
        return np.ascontiguousarray(y.real) if real else y

    def adjoint(self, coeffs: Sequence[Sequence]) -> np.ndarray:
        """``Psi^H`` of ``coeffs[scale][direction]``; real when every band is real."""
        real = all(not np.iscomplexobj(b) for scale in coeffs for b in scale)
        y = self._t.adjoint(self._flat(coeffs))
        return np.ascontiguousarray(y.real) if real else y


def reconstruct(kspace, mask, prior: Union[str, "Fdct"] = "udct", reg: str = "l1", epsilon: float = 0.0,
                max_iter: int = 70, tau0: Optional[float] = None, rho: float = 1.0,
                tau_cap: float = 10.0, tol: float = 0.0, wedges="auto", alpha: float = 0.1,
                levels: int = 4, tv_n_iter: int = 20, shrink_lowpass: bool = True,
                reference=None, return_history: bool = False,
                sflct_levels: Sequence[int] = (3, 3, 4)
                ) -> Union[np.ndarray, Tuple[np.ndarray, ReconstructionHistory]]:
    """Reconstruct an image from undersampled k-space by C-SALSA (UDCSMRI).

    Parameters
    ----------
    kspace : complex array (H, W)
        Measured k-space, un-shifted, unitary scaling; values outside ``mask`` are ignored.
    mask : bool array (H, W)
        Sampled positions.
    prior : {"udct", "fdct", "lrsflct", "mrsflct", "db1", ..., "db8", "identity"} or Fdct
        Sparsifying transform ``Psi``: the UDCT, the SFLCTs and the wavelets act on the real
        and imaginary parts separately, the FDCT on the complex image (``"fdct"``: the default
        :class:`Fdct` configuration; an :class:`Fdct` instance: its configuration). The
        SFLCTs (:class:`Sflct`, less or more redundant) are frames but not tight ones, so each
        C-SALSA iteration solves its x-update by preconditioned CG (slower; l1 only).
    reg : {"l1", "tv"}
        ``||Psi x||_1`` or ``TV(Psi^H alpha)``.
    epsilon : float
        Noise radius in k-space units (0: exact data consistency). For complex Gaussian noise
        of standard deviation ``sigma`` per component use :func:`noise_epsilon`.
    max_iter : int
        ADMM iteration cap (paper: 70; fewer when ``tol`` stops it). 0 returns the
        zero-filled image.
    tau0 : float, optional
        Threshold on the image normalised to unit peak. Default 0.01 for ``"udct"``, 0.02 for
        ``"fdct"`` and the SFLCTs and 0.04 for wavelets (chosen on a development image by grid
        search).
    rho, tau_cap : float
        ``tau <- min(rho tau, tau_cap tau0)`` after every iteration (paper's "lambda <- rho
        lambda"; ``rho = 1`` is textbook C-SALSA).
    tol : float
        Stop early when the relative change of ``x`` falls below ``tol``.
    wedges : "auto" or list of [int, int]
        UDCT wedges per scale (see :class:`Udct`). ``"auto"`` (default) chooses the number of
        scales ``J`` among 1, 2 and 3 (those the size allows) with ``[6, 6]`` wedges each by
        hold-out validation on the measured samples (:func:`choose_scales`, with the other
        settings given here); it costs 9 extra reconstructions from 95 % of the samples,
        about 10x the time of one reconstruction. The paper's brain-image setting is
        ``wedges=[[6, 6]]`` (one scale); more scales suit natural images with smooth
        regions and textures (measured: +1 to +2 dB on photographs), one scale suits images
        whose energy sits in a few sharp harmonics. Used by ``prior="udct"`` only.
    alpha : float
        Angular overlap of the UDCT's wedges (see :class:`Udct`).
    levels : int
        Wavelet levels for the ``db`` priors.
    sflct_levels : sequence of int
        Directional levels per scale (coarsest first) of the SFLCT priors.
    tv_n_iter : int
        Chambolle iterations of the TV prox (``reg="tv"``), a fixed count.
    shrink_lowpass : bool
        Whether the l1 norm includes the low-pass coefficients (paper: yes).
    reference : complex array, optional
        Ground truth, only used to record the MSE per iteration (paper Fig. 6).
    return_history : bool
        Also return a :class:`ReconstructionHistory`: ``n_iter`` and the per-iteration
        ``rel_change``, ``residual``, ``objective`` (and ``mse`` with ``reference``).

    Returns
    -------
    image : complex128 array (H, W)
        The reconstruction; its sampled Fourier values satisfy ``||P F x - y|| <= epsilon``.
    history : ReconstructionHistory, when ``return_history``

    Examples
    --------
    >>> from wscg import csmri
    >>> k = csmri.make_shepp_logan_kspace(64)
    >>> m = csmri.mask_cartesian((64, 64), 0.4, seed=1)
    >>> x = csmri.reconstruct(k, m, max_iter=10)
    >>> x.shape
    (64, 64)
    """
    fdct = None
    if isinstance(prior, Fdct):
        if prior.shape != np.shape(kspace):
            raise ValueError(f"the Fdct prior is planned for {prior.shape}, the k-space is "
                             f"{np.shape(kspace)}")
        fdct, prior = prior._config, "fdct"
    if tau0 is None:
        tau0 = _c.tuned_tau0(str(prior))
    if isinstance(wedges, str):
        if wedges != "auto":
            raise ValueError(f"`wedges` must be 'auto' or a list of [n_rows, n_cols] pairs, got {wedges!r}")
        wedges = [[6, 6]]
        if str(prior) == "udct" and int(max_iter) > 0:  # 0: the zero-filled image
            choice = choose_scales(kspace, mask, reg=reg, epsilon=epsilon, max_iter=max_iter, tau0=tau0,
                                   rho=rho, tau_cap=tau_cap, tol=tol, alpha=alpha,
                                   tv_n_iter=tv_n_iter, shrink_lowpass=shrink_lowpass)
            wedges = [[6, 6]] * choice.scales
    img, hist = _c.reconstruct(kspace, mask, prior, reg, epsilon, max_iter, tau0, rho, tau_cap,
                               tol, wedges, alpha, levels, tv_n_iter, shrink_lowpass, reference,
                               return_history, fdct, sflct_levels)
    return _with_history(img, hist, return_history)


def choose_scales(kspace, mask, reg: str = "l1", epsilon: float = 0.0, max_iter: int = 70,
                  tau0: float = 0.01, rho: float = 1.0, tau_cap: float = 10.0, tol: float = 0.0,
                  wedge: Tuple[int, int] = (6, 6), alpha: float = 0.1, tv_n_iter: int = 20,
                  shrink_lowpass: bool = True, candidates: Sequence[int] = (1, 2, 3),
                  folds: int = 3, holdout: float = 0.05, seed: int = 0,
                  cluster: float = 2.0) -> ScaleChoice:
    """Choose the number of UDCT scales for :func:`reconstruct` from the data alone.

    Hold-out validation (beyond the paper, which fixes the scales per image class): ``folds``
    disjoint sets of ``holdout`` times the number of samples are drawn from the sampled
    positions outside the fully sampled rings of radial frequency, as clusters (the samples
    within ``cluster`` positions of a random seed, so that the prior must fill a gap as it
    fills the mask's own, rather than a single sample its neighbours pin down); for each
    candidate ``J``
    C-SALSA (UDCT prior with ``wedge`` wedges at every scale, the other settings as given)
    reconstructs from the remaining samples, and the squared errors of its Fourier values at
    the held-out positions, weighted by ``(1 - d) / d`` for the sampling density ``d`` of
    their ring (an estimate of the error over the ring's unmeasured positions), are summed.
    The candidate with the smallest sum wins. ``tau0`` is kept as given (scoring it jointly
    was measured to prefer too small a threshold on piecewise-constant images).

    Cost: ``folds x len(candidates)`` reconstructions (9 with the defaults).

    Parameters
    ----------
    kspace : complex array (H, W)
        Measured k-space, as for :func:`reconstruct`.
    mask : bool array (H, W)
        Sampled positions.
    reg, epsilon, max_iter, tau0, rho, tau_cap, tol, alpha, tv_n_iter, shrink_lowpass
        C-SALSA settings, as for :func:`reconstruct` (``tau0``: the UDCT's default 0.01).
    wedge : (int, int)
        Wedge counts of every scale.
    candidates : sequence of int
        Numbers of scales to score (each 1 to 8; those the size does not allow are skipped).
    folds : int
        Hold-out sets per candidate (1 to 20).
    holdout : float
        Fraction of the samples held out per fold, in (0, 0.5], ``folds * holdout <= 1``.
    seed : int
        Seed of the hold-out draw.
    cluster : float
        Radius of the held-out clusters in k-space positions, 0 to 16 (2: up to 13
        neighbouring samples; 0: single samples, which were measured to prefer two scales on
        diamond lattices under pseudo-radial masks, 0.7 to 1.0 dB below one scale).

    Returns
    -------
    ScaleChoice

    Examples
    --------
    >>> from wscg import csmri
    >>> k = csmri.make_shepp_logan_kspace(64)
    >>> m = csmri.mask_cartesian((64, 64), 0.4, seed=1)
    >>> csmri.choose_scales(k, m, max_iter=10, candidates=(1, 2)).scales in (1, 2)
    True
    """
    scales, held, rows = _c.choose_udct_scales(
        kspace, mask, reg, epsilon, max_iter, tau0, rho, tau_cap, tol, wedge, alpha, tv_n_iter,
        shrink_lowpass, candidates, folds, holdout, cluster, seed)
    return ScaleChoice(scales=scales, candidates=tuple(j for j, _ in rows),
                       scores=np.asarray([e for _, e in rows], dtype=np.float64).reshape(
                           len(rows), folds if rows else 0),
                       held_out=held)


def _composite(method, kspace, mask, a, b, group_weight, mu_g, n_iter, tv_n_iter, order,
               levels, reference, return_history):
    img, hist = _c.composite(method, kspace, mask, a, b, group_weight, mu_g, n_iter, tv_n_iter,
                             order, levels, reference, return_history)
    return _with_history(img, hist, return_history)


def fcsa(kspace, mask, a: float = 0.001, b: float = 0.035, n_iter: int = 70,
         tv_n_iter: int = 20, order: int = 4, levels: int = 4, reference=None,
         return_history: bool = False
         ) -> Union[np.ndarray, Tuple[np.ndarray, ReconstructionHistory]]:
    """FCSA (Huang, Zhang and Metaxas 2011): FISTA on
    ``1/2 ||P F x - y||^2 + a TV(x) + b ||W x||_1`` (``W``: db``order``, periodic) with the
    composite-splitting average of the two proximal steps, ``n_iter`` iterations (a fixed
    count) with ``tv_n_iter`` Chambolle iterations per TV prox. ``a`` and ``b`` are for
    images of unit peak (data are normalised internally). Returns the complex image (and,
    with ``return_history``, its :class:`ReconstructionHistory`)."""
    return _composite("fcsa", kspace, mask, a, b, b, 0.001, n_iter, tv_n_iter, order, levels,
                      reference, return_history)


def tvcmri(kspace, mask, a: float = 0.001, b: float = 0.035, n_iter: int = 70,
           order: int = 4, levels: int = 4, reference=None, return_history: bool = False
           ) -> Union[np.ndarray, Tuple[np.ndarray, ReconstructionHistory]]:
    """TVCMRI's objective (Ma et al. 2008), the same as :func:`fcsa`'s, minimised by the
    Condat-Vu primal-dual algorithm (gradient step on the data, wavelet shrinkage, projected
    TV dual variables), ``n_iter`` iterations (a fixed count)."""
    return _composite("tvcmri", kspace, mask, a, b, b, 0.001, n_iter, 0, order, levels,
                      reference, return_history)


def watmri(kspace, mask, a: float = 0.001, b: float = 0.035, group_weight: Optional[float] = None,
           mu_g: float = 0.001, n_iter: int = 70, tv_n_iter: int = 20, order: int = 4,
           levels: int = 4, reference=None, return_history: bool = False
           ) -> Union[np.ndarray, Tuple[np.ndarray, ReconstructionHistory]]:
    """WaTMRI (Chen and Huang 2012): :func:`fcsa` plus wavelet-tree sparsity
    ``group_weight * sum ||(W x)_{child, parent}||_2`` handled by group replication with
    coupling ``mu_g``. ``group_weight`` defaults to ``b``; ``n_iter`` and ``tv_n_iter`` as in
    :func:`fcsa`."""
    gw = b if group_weight is None else group_weight
    return _composite("watmri", kspace, mask, a, b, gw, mu_g, n_iter, tv_n_iter, order, levels,
                      reference, return_history)


def zero_filled(kspace, mask) -> np.ndarray:
    """The zero-filled reconstruction ``F^H P^T y``."""
    k = _complex2(kspace, "kspace")
    m = _mask(mask, k.shape)
    return np.fft.ifft2(np.where(m, k, 0), norm="ortho")


def simulate(image, mask) -> np.ndarray:
    """k-space of ``image`` on ``mask`` (unitary FFT, un-shifted; zeros elsewhere)."""
    x = _complex2(image, "image")
    m = _mask(mask, x.shape)
    return np.where(m, np.fft.fft2(x, norm="ortho"), 0)


# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
