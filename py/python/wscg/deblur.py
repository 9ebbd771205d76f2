"""Gyroscope-driven multi-frame blur estimation and removal: paper 12 of WSCG vol. 23
(G. Sörös, S. Münger, C. Beltrame and L. Humair, "Multiframe Visual-Inertial Blur Estimation
and Removal for Unmodified Smartphones").

Camera shake blurs a smartphone preview frame ``B``. The phone's gyroscope measures the
rotation during the exposure, so the blur is known: under the rotation-only homography
``H_t = K R_t K^-1`` a latent point traces a path that is rendered into a blur kernel per
``30 x 30`` region (rolling-shutter timing: row ``y`` opens at
``t_frame + t_delay + t_readout * y / height``). Each region is deconvolved with the
hyper-Laplacian prior of Krishnan and Fergus (KS); the neighbouring frames, deblurred and
aligned to ``B``, then enter as a quadratic prior weighted per region by the sharpness of
their kernels (KM, eq. 9).

- :func:`render_kernel`, :func:`kernel_grid`, :func:`blurriness`: gyro blur kernels.
- :func:`deconv_krishnan`, :func:`deconv_krishnan_multi`, :func:`wiener`,
  :func:`richardson_lucy`, :func:`convolve`: uniform-kernel deconvolution (single frame and
  with the multi-frame prior of eq. 9) and the forward model, on whole images.
- :func:`estimate_noise`: the noise level of a blurred image, from which the default
  Krishnan-Fergus weight ``lam="auto"`` is derived.
- :func:`deblur_piecewise`: region-wise deblurring of one frame with its gyro kernels
  (Krishnan-Fergus, Wiener, Richardson-Lucy, or one global kernel).
- :func:`deblur_multiframe`: the full pipeline of the paper's section 5.
- :func:`rectify_rolling_shutter`, :func:`phase_correlation`, :func:`estimate_time_delay`:
  rolling-shutter rectification and gyro-camera delay calibration.
- :func:`w_step`: the exact per-pixel minimiser of the Krishnan-Fergus w-subproblem.
- :func:`make_gyro`, :func:`add_gyro_noise`, :func:`render_blurred`, :func:`make_scene`:
  Ornstein-Uhlenbeck hand shake and densely rendered blurred frames with exact ground truth,
  standing in for the paper's recorded hand shake (section 6.2), which is not public: the
  tests never blur with the kernels they deblur with.

Conventions: images are 2-D grayscale arrays ``(H, W)``, pixel ``(x, y)`` = column, row with
centres at integer coordinates. The solvers work on **linear** intensities in ``[0, 1]``;
:func:`deblur_multiframe` takes display (gamma-encoded) frames as a camera delivers them and
linearises them with ``gamma``. Gyroscope traces are ``(N, 4)`` float arrays of rows
``(t, wx, wy, wz)``: time in seconds on the gyroscope clock (strictly increasing) and
angular rates in rad/s about the camera's x (right), y (down) and z (optical axis) axes,
or about the IMU's axes with ``r_cam_imu`` mapping them to the camera's. A kernel ``k``
with origin ``(row, col)`` blurs as ``B(x) = sum_d k(d) I(x - d)`` where ``d`` is the
displacement from the origin; a positive yaw rate (about +y) moves the kernel's mass
towards -x. Bad input raises ``ValueError``.

References
----------
G. Sörös, S. Münger, C. Beltrame and L. Humair, "Multiframe Visual-Inertial Blur Estimation
and Removal for Unmodified Smartphones", Sörös et al., WSCG 2015, Journal of WSCG vol. 23.
D. Krishnan and R. Fergus, "Fast image deconvolution using hyper-Laplacian priors",
NIPS 2009.
A. Karpenko, D. Jacobs, J. Baek and M. Levoy, "Digital video stabilization and rolling
shutter correction using gyroscopes", Stanford CS Tech Report 2011.
"""

from __future__ import annotations

import warnings
from typing import List, Optional, Sequence, Union

import numpy as np

from ._native import deblur as _d
from ._native.deblur import (add_gyro_noise, blurriness, convolve, deblur_piecewise,
                             deconv_krishnan, deconv_krishnan_multi, estimate_noise,
                             estimate_time_delay, kernel_grid, make_gyro, make_scene,
                             phase_correlation, rectify_rolling_shutter, render_blurred,
                             render_kernel, richardson_lucy, w_step, wiener)
from ._checks import integer_ranges as _integer_ranges
from ._results import from_mapping as _from_mapping, result as _result

__all__ = [
    "render_kernel", "kernel_grid", "blurriness", "estimate_noise", "deconv_krishnan",
    "deconv_krishnan_multi",
    "wiener", "richardson_lucy", "convolve", "deblur_piecewise", "deblur_multiframe",
    "rectify_rolling_shutter", "phase_correlation", "estimate_time_delay", "w_step",
    "make_gyro", "add_gyro_noise", "render_blurred", "make_scene", "METHODS",
    "MultiframeDeblur",
]

@_result
class MultiframeDeblur:
    """The result of :func:`deblur_multiframe` (paper section 5, eq. 9). Images hold display
    values in ``[0, 1]``.

    Attributes
    ----------
    image : float32 array (H, W)
        The multi-frame result (KM).
    single : float32 array (H, W)
        The single-frame result of the main frame (KS).
    weights : float32 array (rows, cols, frames)
        Per-region frame weights ``nu_j`` of eq. 9 (0 for the main frame, which enters
        through the data term, and for unused frames; they sum to 1 over the neighbours of a
        region whenever one is used).
    used_frames : list of int
        The frames that contributed, sorted (the main frame included).
    warnings : list of str
        Why neighbours were dropped.
    kernels : float32 array (rows, cols, K, K)
        The main frame's region kernels.
    """

    image: np.ndarray
    single: np.ndarray
    weights: np.ndarray
    used_frames: List[int]
    warnings: List[str]
    kernels: np.ndarray


#: Valid ``method`` names of :func:`deblur_piecewise`.
METHODS = ("krishnan", "wiener", "rl", "global")

_REFERENCE = "Sörös et al., WSCG 2015, Journal of WSCG vol. 23"


# ----------------------------------------------------------------------------------------
# The multi-frame pipeline, whose Python layer builds its result and issues its warnings;
# the other functions are the native ones (py/src/deblur.rs), imported above.
# ----------------------------------------------------------------------------------------

def deblur_multiframe(frames: Sequence, frame_times, gyro, f: float, cx: float, cy: float,
                      t_exposure: float, t_readout: float = 0.0, t_delay: float = 0.0,
                      main: Optional[int] = None, mu: float = 250.0,
                      lam: Union[float, str] = 2000.0,
                      alpha: float = 0.5, gamma: Optional[float] = 2.2, align: str = "ecc",
                      min_ncc: float = 0.8, temporal_radius: Optional[int] = None,
                      tile: int = 30,
                      r_cam_imu=None, bias=None) -> MultiframeDeblur:
    """Multi-frame blur removal of ``frames[main]`` (paper section 5, eq. 9).

    Parameters
    ----------
    frames : sequence of arrays (H, W)
        Grayscale frames of equal size as the camera delivers them: uint8 ``0..255`` or
        float display values in ``[0, 1]`` (gamma-encoded; see ``gamma``).
    frame_times : sequence of float
        Time stamp of every frame (s, frame clock).
    gyro : array (N, 4)
        Gyroscope samples ``(t, wx, wy, wz)`` covering every exposure.
    f, cx, cy : float
        Intrinsics in pixels.
    t_exposure, t_readout, t_delay : float
        Exposure ``t_e``, rolling-shutter readout ``t_r`` and gyro-camera delay ``t_d`` (s),
        as in :func:`render_kernel`.
    main : int, optional
        Index of the frame to deblur; default the middle one, ``len(frames) // 2``.
    mu : float, default 250
        Weight of the multi-frame prior (``lambda / 8`` for the paper's ``lam=2000``, tuned on
        the development image).
    lam, alpha : float (lam also "auto")
        Krishnan-Fergus parameters (see :func:`deconv_krishnan`); the paper's ``lam=2000`` by
        default (``mu`` was tuned with it). With ``lam="auto"`` every frame's single-frame
        pass and the final multi-frame solve use the weight of their own (rectified, linear)
        frame's noise level, which loses on gyro-estimated kernels (see
        :func:`deblur_piecewise`).
    gamma : float or None, default 2.2
        Camera response: linear = display ** gamma (section 3.3). ``None`` treats the frames
        as linear.
    align : {"ecc", "gyro"}, default "ecc"
        Neighbour alignment: the gyroscope's homography ``K R K^-1`` refined by ECC on a
        3-level pyramid, or the gyroscope's homography as is.
    min_ncc : float, default 0.8
        Neighbours whose aligned correlation with the main estimate is lower are dropped.
    temporal_radius : int, optional
        Use at most this many frames on each side of ``main`` (default: all).
    tile : int, default 30
        Region side in pixels.
    r_cam_imu, bias
        As in :func:`render_kernel`.

    Returns
    -------
    result : MultiframeDeblur
        ``image`` (the multi-frame result KM), ``single`` (the single-frame result KS of
        ``main``), the per-region frame ``weights`` of eq. 9, ``used_frames``, ``warnings``
        (why neighbours were dropped) and the main frame's region ``kernels``.

    Warns
    -----
    UserWarning
        Once per neighbour dropped because its alignment failed (also listed in
        ``warnings``). With no usable neighbour the result equals ``single``.

    Notes
    -----
    Every frame used is linearised, rolling-shutter rectified (Karpenko 2011) and deblurred
    region by region with its gyroscope kernels. The neighbours' estimates ``I_j`` are
    aligned to the main estimate; per region, a neighbour covering it gets
    ``mu_j = 1 / max(sigma_j, 0.5)`` with ``sigma_j`` the spread of its kernel
    (:func:`blurriness`) at the region, normalised to ``nu_j``, and the main region is
    solved again with ``mu/2 ||I - sum_j nu_j I_j||^2`` added to eq. 7. The latent image is
    the main frame in the pose of its middle row's shutter opening.

    References
    ----------
    Sörös et al., WSCG 2015, Journal of WSCG vol. 23, section 5 and eq. 9.

    Examples
    --------
    >>> from wscg import deblur
    >>> gyro = deblur.make_gyro(0.6, seed=3)
    >>> sharp = deblur.make_scene(90, 120, seed=3)
    >>> times = [0.1 + i / 30 for i in range(3)]
    >>> frames = [deblur.render_blurred(sharp, gyro, t, 0.03, 600, 59.5, 44.5, 0.1,
    ...                                       seed=i) for i, t in enumerate(times)]
    >>> out = deblur.deblur_multiframe(frames, times, gyro, 600, 59.5, 44.5, 0.03)
    >>> out.image.shape, out.weights.shape
    ((90, 120), (3, 4, 3))
    """
    out = _d.deblur_multiframe(frames, frame_times, gyro, f, cx, cy, t_exposure, t_readout,
                               t_delay, main, mu, lam, alpha, gamma, align, min_ncc,
                               temporal_radius, tile, r_cam_imu, bias)
    for w in out["warnings"]:
        warnings.warn(w, UserWarning, stacklevel=2)
    return _from_mapping(MultiframeDeblur, out)


# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
