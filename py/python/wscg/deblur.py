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
from typing import List, Optional, Sequence, Tuple, Union

import numpy as np

from ._native import deblur as _d
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
# Input validation
# ----------------------------------------------------------------------------------------

def _gyro(gyro) -> np.ndarray:
    g = np.asarray(gyro)
    if not np.issubdtype(g.dtype, np.number) or np.iscomplexobj(g):
        raise ValueError(f"`gyro` must be a real numeric array, got dtype {g.dtype}")
    if g.ndim != 2 or g.shape[1] != 4:
        raise ValueError("`gyro` must have shape (N, 4) with rows (t, wx, wy, wz), "
                         f"got shape {g.shape}")
    if g.shape[0] < 2:
        raise ValueError(f"`gyro` needs at least 2 samples, got {g.shape[0]}")
    g = np.ascontiguousarray(g, dtype=np.float64)
    bad = ~np.isfinite(g)
    if bad.any():
        i = int(np.argmax(bad.any(axis=1)))
        raise ValueError(f"`gyro` contains a non-finite value (NaN or infinity) in row {i}")
    dt = np.diff(g[:, 0])
    if (dt <= 0).any():
        i = int(np.argmax(dt <= 0)) + 1
        raise ValueError(f"`gyro` time stamps must be strictly increasing: sample {i} at "
                         f"t = {g[i, 0]!r} follows t = {g[i - 1, 0]!r}")
    return g


def _rotation(r) -> Optional[np.ndarray]:
    if r is None:
        return None
    a = np.asarray(r, dtype=np.float64)
    if a.shape != (3, 3):
        raise ValueError(f"`r_cam_imu` must be a (3, 3) rotation matrix, got shape {a.shape}")
    return np.ascontiguousarray(a)


def _bias(b) -> Optional[Tuple[float, float, float]]:
    if b is None:
        return None
    a = np.asarray(b, dtype=np.float64).ravel()
    if a.shape != (3,) or not np.isfinite(a).all():
        raise ValueError(f"`bias` must be 3 finite rates (bx, by, bz) in rad/s, got {b!r}")
    return float(a[0]), float(a[1]), float(a[2])


def _real(x, name: str) -> np.ndarray:
    a = np.asarray(x)
    if a.dtype == np.bool_ or not np.issubdtype(a.dtype, np.number) or np.iscomplexobj(a):
        raise ValueError(f"`{name}` must be a real numeric array, got dtype {a.dtype}")
    return a


def _image(x, name: str) -> np.ndarray:
    a = _real(x, name)
    if a.ndim != 2:
        raise ValueError(f"`{name}` must be a 2-D grayscale array (H, W), got shape {a.shape}")
    if a.size == 0:
        raise ValueError(f"`{name}` is empty (shape {a.shape})")
    a = np.ascontiguousarray(a, dtype=np.float32)
    if not np.isfinite(a).all():
        i = int(np.argmax(~np.isfinite(a).ravel()))
        raise ValueError(f"`{name}` contains a non-finite value (NaN or infinity) "
                         f"at flat index {i}")
    return a


def _out_dtype(x):
    return np.float64 if np.asarray(x).dtype == np.float64 else np.float32


def _kernel(kernel, origin) -> Tuple[np.ndarray, Tuple[int, int]]:
    k = _real(kernel, "kernel")
    if k.ndim != 2 or k.size == 0:
        raise ValueError(f"`kernel` must be a non-empty 2-D array, got shape {k.shape}")
    k = np.ascontiguousarray(k, dtype=np.float32)
    if not np.isfinite(k).all() or (k < 0).any():
        raise ValueError("`kernel` weights must be finite and >= 0")
    if not k.sum() > 0:
        raise ValueError("`kernel` weights sum to zero")
    if origin is None:
        origin = (k.shape[0] // 2, k.shape[1] // 2)
    try:
        r, c = (int(v) for v in origin)
    except (TypeError, ValueError):
        raise ValueError(f"`origin` must be a (row, col) pair of integers, "
                         f"got {origin!r}") from None
    if not (0 <= r < k.shape[0] and 0 <= c < k.shape[1]):
        raise ValueError(f"`origin` {(r, c)} lies outside the {k.shape[0]}x{k.shape[1]} kernel")
    return k, (r, c)


def _positive(name: str, v) -> float:
    v = float(v)
    if not (np.isfinite(v) and v > 0):
        raise ValueError(f"`{name}` must be finite and > 0, got {v}")
    return v


def _lam(lam) -> Optional[float]:
    """``lam="auto"`` as ``None`` (the noise-aware weight), a number checked to be > 0."""
    if isinstance(lam, str):
        if lam != "auto":
            raise ValueError(f"`lam` must be \"auto\" or a number > 0, got {lam!r}")
        return None
    return _positive("lam", lam)


def _cam(f, cx, cy) -> Tuple[float, float, float]:
    f = _positive("f", f)
    cx, cy = float(cx), float(cy)
    if not (np.isfinite(cx) and np.isfinite(cy)):
        raise ValueError(f"the principal point (`cx`, `cy`) must be finite, got ({cx}, {cy})")
    return f, cx, cy


def _timing(t_frame, t_exposure, t_readout, t_delay) -> Tuple[float, float, float, float]:
    t_frame, t_delay = float(t_frame), float(t_delay)
    for name, v in (("t_frame", t_frame), ("t_delay", t_delay)):
        if not np.isfinite(v):
            raise ValueError(f"`{name}` must be finite, got {v}")
    t_exposure = _positive("t_exposure", t_exposure)
    t_readout = float(t_readout)
    if not (np.isfinite(t_readout) and t_readout >= 0):
        raise ValueError(f"`t_readout` must be finite and >= 0, got {t_readout}")
    return t_frame, t_exposure, t_readout, t_delay


def _count(name: str, v, lo: int = 1) -> int:
    if isinstance(v, (bool, np.bool_)) or int(v) != v or int(v) < lo:
        raise ValueError(f"`{name}` must be an integer >= {lo}, got {v!r}")
    return int(v)


def _display(frame, i: int) -> np.ndarray:
    """A frame of display values as float32 in [0, 1]: unsigned integers are divided by their
    maximum (8-bit: 255), floats must already lie in [0, 1]."""
    a = _real(frame, f"frames[{i}]")
    if np.issubdtype(a.dtype, np.unsignedinteger):
        a = a.astype(np.float32) / np.float32(np.iinfo(a.dtype).max)
    elif np.issubdtype(a.dtype, np.integer):
        raise ValueError(f"`frames[{i}]` has signed integer dtype {a.dtype}; pass uint8 (0..255) "
                         "or float display values in [0, 1]")
    out = _image(a, f"frames[{i}]")
    lo, hi = float(out.min()), float(out.max())
    if lo < -1e-6 or hi > 1 + 1e-6:
        raise ValueError(f"`frames[{i}]` holds floats in [{lo:g}, {hi:g}]; float frames must be "
                         "display values in [0, 1] (pass uint8 for 0..255 data)")
    return out


# ----------------------------------------------------------------------------------------
# Kernels
# ----------------------------------------------------------------------------------------

def render_kernel(gyro, t_frame: float, t_exposure: float, f: float, cx: float, cy: float,
                  x: float, y: float, t_readout: float = 0.0, t_delay: float = 0.0,
                  height: Optional[int] = None, r_cam_imu=None,
                  bias=None) -> Tuple[np.ndarray, Tuple[int, int]]:
    """Render the blur kernel of pixel ``(x, y)`` from the gyroscope (paper section 3.2).

    Parameters
    ----------
    gyro : array (N, 4)
        Gyroscope samples ``(t, wx, wy, wz)``: seconds (strictly increasing) and rad/s.
    t_frame : float
        Frame time stamp (s, frame clock).
    t_exposure : float
        Exposure time ``t_e`` (s, > 0).
    f, cx, cy : float
        Focal length and principal point in pixels.
    x, y : float
        Pixel (column, row) whose kernel is rendered.
    t_readout : float, default 0
        Rolling-shutter readout time of the whole frame (s; 0 = global shutter).
    t_delay : float, default 0
        Gyroscope-camera delay: frame time + ``t_delay`` = gyroscope time.
    height : int, optional
        Frame height in rows; required when ``t_readout > 0`` (row ``y`` opens at
        ``t_frame + t_delay + t_readout * y / height``).
    r_cam_imu : array (3, 3), optional
        Rotation from IMU axes to camera axes (rates are used as ``r_cam_imu @ w``);
        identity by default.
    bias : (3,) float, optional
        Constant gyroscope bias (rad/s, IMU axes) subtracted from every sample.

    Returns
    -------
    kernel : float32 array (k, k)
        Non-negative weights summing to 1, ``k`` odd.
    origin : (int, int)
        ``(row, col)`` of zero displacement (the shutter-open pose): the kernel's centre.

    Notes
    -----
    The latent point ``X = K^-1 [x, y, 1]`` (pose at the shutter opening ``t_open``) is seen
    at ``pi(K R_rel^T X)``, ``R_rel = R(t_open)^T R(tau)``, for sub-steps ``tau`` of the
    exposure (at least 32,
    refined until consecutive positions are closer than 0.25 px); the positions are splatted
    bilinearly with equal weight and the kernel is cropped to the smallest odd square centred
    on the origin that holds all weights above ``1e-4`` of the peak. Orientations between gyro
    samples come from SLERP of the integrated rates.

    References
    ----------
    Sörös et al., WSCG 2015, Journal of WSCG vol. 23, section 3.2 and eqs. 5-6.

    Examples
    --------
    >>> import numpy as np
    >>> from wscg import deblur
    >>> t = np.linspace(0, 0.1, 21)
    >>> gyro = np.column_stack([t, 0 * t, 0.3 + 0 * t, 0 * t])   # pure yaw, 0.3 rad/s
    >>> k, origin = deblur.render_kernel(gyro, 0.0, 1 / 30, 600, 320, 240, 320, 240)
    >>> cols = np.arange(k.shape[1]) - origin[1]
    >>> round(float((k.sum(axis=0) * cols).sum()), 2)     # mean shift -f w t_e / 2
    -3.0
    """
    g = _gyro(gyro)
    tim = _timing(t_frame, t_exposure, t_readout, t_delay)
    if height is None:
        if tim[2] > 0:
            raise ValueError("`height` (the frame's rows) is required when t_readout > 0")
        height = 1
    height = _count("height", height)
    return _d.render_kernel(g, tim, height, _cam(f, cx, cy), float(x), float(y),
                            _rotation(r_cam_imu), _bias(bias))


def kernel_grid(gyro, t_frame: float, t_exposure: float, f: float, cx: float, cy: float,
                height: int, width: int, tile: int = 30, t_readout: float = 0.0,
                t_delay: float = 0.0, r_cam_imu=None, bias=None) -> np.ndarray:
    """Render the piecewise-uniform kernels of a ``height x width`` frame: one kernel per
    ``tile x tile`` region, at the region's centre with its centre row's timing (paper
    section 3, Fig. 3).

    Parameters
    ----------
    gyro, t_frame, t_exposure, f, cx, cy, t_readout, t_delay, r_cam_imu, bias
        As in :func:`render_kernel`.
    height, width : int
        Frame size in pixels (rows, columns: the array's axis order).
    tile : int, default 30
        Region side (the last row and column of regions may be narrower).

    Returns
    -------
    kernels : float32 array (rows, cols, K, K)
        ``rows = ceil(height / tile)``, ``cols = ceil(width / tile)``; every kernel is padded
        with zeros to the common odd size ``K`` with its origin at the centre ``(K // 2,
        K // 2)``.

    References
    ----------
    Sörös et al., WSCG 2015, Journal of WSCG vol. 23, section 3.

    Examples
    --------
    >>> from wscg import deblur
    >>> gyro = deblur.make_gyro(0.5, seed=1)
    >>> deblur.kernel_grid(gyro, 0.1, 0.03, 600, 74.5, 59.5, 120, 150).shape[:2]
    (4, 5)
    """
    g = _gyro(gyro)
    tim = _timing(t_frame, t_exposure, t_readout, t_delay)
    return _d.kernel_grid(g, tim, _cam(f, cx, cy), _count("width", width),
                          _count("height", height), _count("tile", tile),
                          _rotation(r_cam_imu), _bias(bias))


def blurriness(kernel, origin=None) -> float:
    """Spatial standard deviation of a kernel's mass in pixels,
    ``sqrt(sum_d k(d) |d - mean|^2)`` (paper section 5: the frame weight is
    ``1 / max(sigma, 0.5)``). The kernel is normalised first; ``origin`` does not change the
    result."""
    k, o = _kernel(kernel, origin)
    return _d.blurriness(k, o)


def estimate_noise(image) -> float:
    """Standard deviation of white Gaussian noise in a (blurred) grayscale image.

    Parameters
    ----------
    image : array (H, W)
        At least 2 x 2 pixels, finite.

    Returns
    -------
    sigma : float
        ``median(|HH|) / 0.6745`` over the finest diagonal Haar wavelet coefficients
        ``HH = (a - b - c + d) / 2`` of disjoint 2 x 2 blocks (an odd last row or column is
        left out).

    Notes
    -----
    Donoho's robust estimator: the unit-norm ``HH`` filter passes white noise unchanged and
    leaves almost nothing of a blurred photograph; the median ignores the edges that leak
    in. One pass over the image and a linear-time median (about 1 ms for 512 x 512).
    ``lam="auto"`` in :func:`deconv_krishnan` uses ``0.3 / max(sigma, 0.001) ** 2``.

    References
    ----------
    D. L. Donoho, "De-noising by soft-thresholding", IEEE Trans. Inf. Theory 41(3), 1995;
    D. L. Donoho and I. M. Johnstone, Biometrika 81(3), 1994.

    Examples
    --------
    >>> import numpy as np
    >>> from wscg import deblur
    >>> noise = np.random.default_rng(0).normal(0, 0.01, (256, 256))
    >>> round(deblur.estimate_noise(0.5 + noise), 3)
    0.01
    """
    return _d.estimate_noise(_image(image, "image"))


# ----------------------------------------------------------------------------------------
# Uniform-kernel deconvolution
# ----------------------------------------------------------------------------------------

def deconv_krishnan(image, kernel, origin=None, lam: Union[float, str] = "auto",
                    alpha: float = 0.5, beta_max: float = 256.0) -> np.ndarray:
    """Non-blind deconvolution with a hyper-Laplacian gradient prior (Krishnan & Fergus 2009).

    Parameters
    ----------
    image : array (H, W)
        Blurred image of **linear** intensities, nominally in ``[0, 1]``.
    kernel : array (kh, kw)
        Blur kernel, non-negative; normalised to sum 1.
    origin : (int, int), optional
        ``(row, col)`` of zero displacement; default ``(kh // 2, kw // 2)`` (as
        ``scipy.ndimage.convolve`` and ``skimage.restoration`` centre a PSF).
    lam : float or "auto", default "auto"
        Data weight ``lambda`` for intensities in ``[0, 1]`` (> 0). ``"auto"`` derives it from
        the input's noise level: ``0.3 / sigma**2`` with ``sigma`` from
        :func:`estimate_noise` (sigma floored at 0.001). The paper uses Krishnan and Fergus's
        fixed ``lam=2000``, which under-weights the data for mild noise (sigma 0.005: 1.9 dB
        below ``"auto"`` on a photograph with an 11-pixel box blur, BENCHMARKS.md).
    alpha : float, default 0.5
        Gradient exponent in ``(0, 2]`` (the paper's 1/2; 1 = total variation, 2 = Gaussian).
    beta_max : float, default 256
        End of the continuation ``beta = 1, 2 sqrt 2, 8, ...`` (six steps for 256).

    Returns
    -------
    restored : array (H, W)
        float64 for float64 input, float32 otherwise; not clipped.

    Notes
    -----
    Minimises ``lambda/2 ||k * I - B||^2 + sum |dx I|^alpha + |dy I|^alpha`` (paper eq. 7) by
    half-quadratic splitting (eq. 8): per ``beta``, the exact per-pixel w-step
    (:func:`w_step`, tabulated) and the closed-form I-step in the Fourier domain. The image is
    extended by a mirrored margin of the kernel radius + 4 pixels and edge-tapered (MATLAB
    ``edgetaper``) before the periodic solve, so borders do not ring.

    References
    ----------
    Sörös et al., WSCG 2015, Journal of WSCG vol. 23, eqs. 7-8. D. Krishnan and R. Fergus,
    "Fast image deconvolution using hyper-Laplacian priors", NIPS 2009.

    Examples
    --------
    >>> import numpy as np
    >>> from wscg import deblur
    >>> sharp = deblur.make_scene(64, 64, seed=1)
    >>> k = np.ones((1, 7)) / 7
    >>> blurred = deblur.convolve(sharp, k)
    >>> restored = deblur.deconv_krishnan(blurred, k)
    >>> bool(np.abs(restored - sharp).mean() < np.abs(blurred - sharp).mean())
    True
    """
    img = _image(image, "image")
    k, o = _kernel(kernel, origin)
    if not (0 < alpha <= 2):
        raise ValueError(f"`alpha` must lie in (0, 2], got {alpha}")
    out = _d.deconv_krishnan(img, k, o, _lam(lam), float(alpha),
                             _positive("beta_max", beta_max))
    return out.astype(_out_dtype(image), copy=False)


def deconv_krishnan_multi(image, kernel, prior, mu: float = 250.0, origin=None,
                          lam: Union[float, str] = "auto", alpha: float = 0.5,
                          beta_max: float = 256.0) -> np.ndarray:
    """Krishnan-Fergus deconvolution with a multi-frame quadratic prior (paper eq. 9).

    Parameters
    ----------
    image : array (H, W)
        Blurred linear-intensity image.
    kernel, origin, lam, alpha, beta_max
        As in :func:`deconv_krishnan`.
    prior : array (H, W)
        The weighted mean ``sum_j nu_j I_j`` of other estimates of the latent image (e.g.
        deblurred, aligned neighbouring frames), linear intensities.
    mu : float, default 250
        Weight of the prior (>= 0; 0 gives :func:`deconv_krishnan`).

    Returns
    -------
    restored : array (H, W), float64 for float64 input, float32 otherwise.

    Notes
    -----
    Minimises eq. 7 plus ``mu/2 ||I - prior||^2``: the I-step of the half-quadratic splitting
    gains ``(mu/beta) P^`` in its numerator and ``mu/beta`` in its denominator.
    :func:`deblur_multiframe` solves this per region with per-region priors.

    References
    ----------
    Sörös et al., WSCG 2015, Journal of WSCG vol. 23, eq. 9.

    Examples
    --------
    >>> import numpy as np
    >>> from wscg import deblur
    >>> sharp = deblur.make_scene(48, 48, seed=1)
    >>> k = np.ones((1, 5)) / 5
    >>> out = deblur.deconv_krishnan_multi(deblur.convolve(sharp, k), k, sharp, mu=1e6)
    >>> bool(np.abs(out - sharp).max() < 1e-2)
    True
    """
    img = _image(image, "image")
    pr = _image(prior, "prior")
    if pr.shape != img.shape:
        raise ValueError(f"shape mismatch: `image` has shape {img.shape}, `prior` {pr.shape}")
    k, o = _kernel(kernel, origin)
    if not (0 < alpha <= 2):
        raise ValueError(f"`alpha` must lie in (0, 2], got {alpha}")
    mu = float(mu)
    if not (np.isfinite(mu) and mu >= 0):
        raise ValueError(f"`mu` must be finite and >= 0, got {mu}")
    out = _d.deconv_krishnan_multi(img, k, o, pr, mu, _lam(lam), float(alpha),
                                   _positive("beta_max", beta_max))
    return out.astype(_out_dtype(image), copy=False)


def wiener(image, kernel, origin=None, nsr: float = 0.01) -> np.ndarray:
    """Wiener deconvolution ``I^ = K^* B^ / (|K|^2 + nsr)`` (the paper's "W" baseline).

    Parameters
    ----------
    image : array (H, W)
        Blurred linear-intensity image.
    kernel, origin
        As in :func:`deconv_krishnan`.
    nsr : float, default 0.01
        Noise-to-signal ratio (> 0); ``skimage.restoration.wiener``'s ``balance`` with
        ``reg`` the identity.

    Returns
    -------
    restored : array (H, W), float64 for float64 input, float32 otherwise.

    Notes
    -----
    Unlike ``skimage.restoration.wiener`` (periodic image), the image is extended by a
    mirrored margin and edge-tapered first, as in :func:`deconv_krishnan`.

    References
    ----------
    Sörös et al., WSCG 2015, Journal of WSCG vol. 23, Table 1.

    Examples
    --------
    >>> import numpy as np
    >>> from wscg import deblur
    >>> deblur.wiener(np.full((32, 32), 0.5), np.ones((3, 3))).shape
    (32, 32)
    """
    img = _image(image, "image")
    k, o = _kernel(kernel, origin)
    out = _d.wiener(img, k, o, _positive("nsr", nsr))
    return out.astype(_out_dtype(image), copy=False)


def richardson_lucy(image, kernel, origin=None, n_iter: int = 30) -> np.ndarray:
    """Richardson-Lucy deconvolution ``I <- I . k^T (B / (k * I))`` from ``I = max(B, 0)``
    (the paper's "RL" baseline, 30 iterations).

    Parameters
    ----------
    image : array (H, W)
        Blurred linear-intensity image (negative values are treated as 0).
    kernel, origin
        As in :func:`deconv_krishnan`.
    n_iter : int, default 30
        Iterations (>= 1); ``skimage.restoration.richardson_lucy``'s ``num_iter``.

    Returns
    -------
    restored : array (H, W), float64 for float64 input, float32 otherwise; not clipped.

    Notes
    -----
    The convolutions are periodic on the image extended by a mirrored margin and
    edge-tapered, where scikit-image convolves with zero padding.

    References
    ----------
    Sörös et al., WSCG 2015, Journal of WSCG vol. 23, Table 1.

    Examples
    --------
    >>> import numpy as np
    >>> from wscg import deblur
    >>> deblur.richardson_lucy(np.full((32, 32), 0.5), np.ones((1, 5)), n_iter=5).shape
    (32, 32)
    """
    img = _image(image, "image")
    k, o = _kernel(kernel, origin)
    out = _d.richardson_lucy(img, k, o, _count("n_iter", n_iter))
    return out.astype(_out_dtype(image), copy=False)


def convolve(image, kernel, origin=None) -> np.ndarray:
    """The forward model ``B(x) = sum_d k(d) I(x - d)`` on the image extended by a mirrored
    margin (``scipy.ndimage.convolve(image, kernel, mode="reflect")`` for a centred kernel,
    up to float32 rounding). Returns float64 for float64 input, float32 otherwise."""
    img = _image(image, "image")
    k, o = _kernel(kernel, origin)
    return _d.convolve(img, k, o).astype(_out_dtype(image), copy=False)


# ----------------------------------------------------------------------------------------
# Frames
# ----------------------------------------------------------------------------------------

def deblur_piecewise(frame, gyro, t_frame: float, t_exposure: float, f: float, cx: float,
                     cy: float, t_readout: float = 0.0, t_delay: float = 0.0,
                     method: str = "krishnan", tile: int = 30, lam: Union[float, str] = 2000.0,
                     alpha: float = 0.5, nsr: float = 0.03, rl_n_iter: int = 20,
                     r_cam_imu=None, bias=None, return_kernels: bool = False):
    """Deblur one frame region by region with its gyroscope kernels (paper sections 3-4).

    Parameters
    ----------
    frame : array (H, W)
        Blurred frame of **linear** intensities (linearise display values first, e.g.
        ``frame ** 2.2``).
    gyro, t_frame, t_exposure, f, cx, cy, t_readout, t_delay, r_cam_imu, bias
        As in :func:`render_kernel`; the frame height is ``H``.
    method : {"krishnan", "wiener", "rl", "global"}, default "krishnan"
        Per-region solver: Krishnan-Fergus ("KS" of Table 1), Wiener ("W"), Richardson-Lucy
        ("RL"), or Krishnan-Fergus on the whole frame with the kernel of the frame centre
        ("global", the uniform-blur assumption of blind tools).
    tile : int, default 30
        Region side in pixels (> 8).
    lam, alpha : float (lam also "auto")
        Krishnan-Fergus parameters (see :func:`deconv_krishnan`); the paper's ``lam=2000`` by
        default. ``lam="auto"`` estimates the noise once on the whole frame; on gyro-estimated
        kernels it lost 0.03-2.1 dB against 2000 (the kernels' errors are not in the noise
        estimate; BENCHMARKS.md).
    nsr : float, default 0.03
        Wiener noise-to-signal ratio.
    rl_n_iter : int, default 20
        Richardson-Lucy iterations (``method="rl"``).
    return_kernels : bool, default False
        Also return the region kernels as :func:`kernel_grid` does.

    Returns
    -------
    restored : array (H, W)
        float64 for float64 input, float32 otherwise; not clipped.
    kernels : float32 array (rows, cols, K, K), when ``return_kernels``.

    Notes
    -----
    Each region is solved on a window of the region plus a margin of at least
    ``max(8, kernel radius + 4)`` pixels (mirrored at the frame border, FFT-friendly size),
    edge-tapered; the solved regions are blended with linear ramps over 4 pixels across
    region borders (a partition of unity, so no seams).

    References
    ----------
    Sörös et al., WSCG 2015, Journal of WSCG vol. 23, section 4 and Fig. 3.

    Examples
    --------
    >>> from wscg import deblur
    >>> gyro = deblur.make_gyro(0.5, seed=2)
    >>> sharp = deblur.make_scene(90, 120, seed=2)
    >>> b = deblur.render_blurred(sharp, gyro, 0.1, 0.03, 600, 59.5, 44.5, 0.1,
    ...                                 gamma=None, quantise=False)
    >>> deblur.deblur_piecewise(b, gyro, 0.1, 0.03, 600, 59.5, 44.5).shape
    (90, 120)
    """
    img = _image(frame, "frame")
    g = _gyro(gyro)
    if method not in METHODS:
        raise ValueError(f"{method!r} is not a valid method. Valid methods are "
                         + ", ".join(repr(m) for m in METHODS))
    if not (0 < alpha <= 2):
        raise ValueError(f"`alpha` must lie in (0, 2], got {alpha}")
    out, kernels = _d.deblur_piecewise(
        img, g, _timing(t_frame, t_exposure, t_readout, t_delay), _cam(f, cx, cy), method,
        _count("tile", tile), _lam(lam), float(alpha), 256.0,
        _positive("nsr", nsr), _count("rl_n_iter", rl_n_iter), _rotation(r_cam_imu),
        _bias(bias))
    out = out.astype(_out_dtype(frame), copy=False)
    return (out, kernels) if return_kernels else out


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
    frames = list(frames)
    if len(frames) == 0:
        raise ValueError("`frames` is empty: need at least one frame")
    imgs = [_display(fr, i) for i, fr in enumerate(frames)]
    for i, im in enumerate(imgs):
        if im.shape != imgs[0].shape:
            raise ValueError(f"frames differ in size: frames[0] is {imgs[0].shape}, "
                             f"frames[{i}] is {im.shape}")
    times = np.asarray(frame_times, dtype=np.float64).ravel()
    if times.shape != (len(imgs),):
        raise ValueError(f"`frame_times` must hold one time per frame: {len(imgs)} frames, "
                         f"{times.size} times")
    if not np.isfinite(times).all():
        raise ValueError("`frame_times` contains a non-finite value")
    if main is None:
        main = len(imgs) // 2
    if isinstance(main, (bool, np.bool_)) or int(main) != main or not 0 <= int(main) < len(imgs):
        raise ValueError(f"`main` = {main!r} is out of range for {len(imgs)} frames")
    if align not in ("ecc", "gyro"):
        raise ValueError(f"{align!r} is not a valid align mode. Valid modes are 'ecc', 'gyro'")
    if not (0 < alpha <= 2):
        raise ValueError(f"`alpha` must lie in (0, 2], got {alpha}")
    mu = float(mu)
    if not (np.isfinite(mu) and mu >= 0):
        raise ValueError(f"`mu` must be finite and >= 0, got {mu}")
    if gamma is not None:
        gamma = _positive("gamma", gamma)
    if temporal_radius is not None:
        temporal_radius = _count("temporal_radius", temporal_radius, lo=0)
    tim = _timing(0.0, t_exposure, t_readout, t_delay)[1:]
    out = _d.deblur_multiframe(
        imgs, [float(t) for t in times], _gyro(gyro), _cam(f, cx, cy), tim, int(main), mu,
        _lam(lam), float(alpha), 256.0, gamma, align, float(min_ncc), temporal_radius,
        _count("tile", tile), _rotation(r_cam_imu), _bias(bias))
    for w in out["warnings"]:
        warnings.warn(w, UserWarning, stacklevel=2)
    return _from_mapping(MultiframeDeblur, out)


def rectify_rolling_shutter(frame, gyro, t_frame: float, t_exposure: float, t_readout: float,
                            t_delay: float, f: float, cx: float, cy: float, r_cam_imu=None,
                            bias=None) -> np.ndarray:
    """Warp a rolling-shutter frame to a virtual global shutter at the opening of its middle
    row (Karpenko et al. 2011; paper section 5).

    Parameters
    ----------
    frame : array (H, W)
        The frame (any intensity scale; bilinear resampling).
    gyro, t_frame, t_exposure, t_readout, t_delay, f, cx, cy, r_cam_imu, bias
        As in :func:`render_kernel`; the frame height is ``H``.

    Returns
    -------
    rectified : array (H, W), float64 for float64 input, float32 otherwise. Pixels mapping
        outside the frame take the nearest border value. ``t_readout = 0`` returns a copy.

    Notes
    -----
    Output pixel ``p`` samples the frame at ``q = pi(K R(t(y))^T R(t_ref) K^-1 p)`` where
    the row ``y`` of ``q`` decides its time ``t(y)``, found by three fixed-point steps.

    References
    ----------
    Sörös et al., WSCG 2015, Journal of WSCG vol. 23, section 5. A. Karpenko et al.,
    Stanford CS Tech Report CSTR 2011-03.

    Examples
    --------
    >>> import numpy as np
    >>> from wscg import deblur
    >>> t = np.linspace(0, 0.2, 41)
    >>> gyro = np.column_stack([t, 0 * t, 1.0 + 0 * t, 0 * t])
    >>> deblur.rectify_rolling_shutter(np.zeros((40, 50)), gyro, 0.05, 0.01, 0.025, 0.0,
    ...                                600, 24.5, 19.5).shape
    (40, 50)
    """
    img = _image(frame, "frame")
    out = _d.rectify_rolling_shutter(img, _gyro(gyro),
                                     _timing(t_frame, t_exposure, t_readout, t_delay),
                                     _cam(f, cx, cy), _rotation(r_cam_imu), _bias(bias))
    return out.astype(_out_dtype(frame), copy=False)


def phase_correlation(a, b) -> Tuple[float, float]:
    """Translation ``(dx, dy)`` taking image ``a`` to image ``b`` (``b(x) ~ a(x - d)``) by
    phase correlation with a Hann window and a parabolic sub-pixel peak.

    Parameters
    ----------
    a, b : array (H, W)
        Images of the same shape.

    Returns
    -------
    dx, dy : float
        Shift in pixels (columns, rows), each within half the image size.

    References
    ----------
    Sörös et al., WSCG 2015, Journal of WSCG vol. 23, section 3.1.

    Examples
    --------
    >>> import numpy as np
    >>> from wscg import deblur
    >>> a = deblur.make_scene(64, 64, seed=4)
    >>> dx, dy = deblur.phase_correlation(a, np.roll(a, (2, 5), axis=(0, 1)))
    >>> round(dx), round(dy)
    (5, 2)
    """
    ia, ib = _image(a, "a"), _image(b, "b")
    if ia.shape != ib.shape:
        raise ValueError(f"shape mismatch: `a` has shape {ia.shape}, `b` {ib.shape}")
    return _d.phase_correlation(ia, ib)


def estimate_time_delay(gyro, frame_times, shifts, t_exposure: float, t_readout: float,
                        f: float, cx: float, cy: float, lo: float, hi: float,
                        step: float = 2.5e-4, r_cam_imu=None, bias=None) -> float:
    """Estimate the gyroscope-camera delay ``t_d`` (paper section 3.1).

    Parameters
    ----------
    gyro : array (N, 4)
        Gyroscope samples.
    frame_times : sequence of float, length M >= 3
        Frame time stamps.
    shifts : array (M - 1, 2)
        Measured image shift ``(dx, dy)`` from frame ``i`` to frame ``i + 1``, e.g. from
        :func:`phase_correlation`.
    t_exposure, t_readout : float
        Exposure and readout times (s).
    f, cx, cy : float
        Intrinsics in pixels.
    lo, hi : float
        Search range of the delay (s).
    step : float, default 2.5e-4
        Grid step of the search (s); the best candidate is refined by a parabola.

    Returns
    -------
    t_delay : float
        The delay minimising the squared difference between the measured shifts and those
        the gyroscope predicts at the principal point between the frames' mid-exposure poses.

    References
    ----------
    Sörös et al., WSCG 2015, Journal of WSCG vol. 23, section 3.1.
    """
    times = np.asarray(frame_times, dtype=np.float64).ravel()
    s = np.ascontiguousarray(_real(shifts, "shifts"), dtype=np.float64)
    if s.ndim != 2 or s.shape[1] != 2:
        raise ValueError(f"`shifts` must have shape (M - 1, 2) with rows (dx, dy), got {s.shape}")
    if s.shape[0] != times.size - 1:
        raise ValueError(f"{times.size} frame times need {times.size - 1} shifts, got {s.shape[0]}")
    if not (np.isfinite(s).all() and np.isfinite(times).all()):
        raise ValueError("`shifts` and `frame_times` must be finite")
    lo, hi = float(lo), float(hi)
    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
        raise ValueError(f"need a finite search range lo < hi, got ({lo}, {hi})")
    t = _timing(0.0, t_exposure, t_readout, 0.0)
    return _d.estimate_time_delay(_gyro(gyro), [float(v) for v in times], s, t[1], t[2],
                                  _cam(f, cx, cy), lo, hi, _positive("step", step),
                                  _rotation(r_cam_imu), _bias(bias))


def w_step(v, alpha: float, beta: float) -> np.ndarray:
    """Exact minimiser of ``|w|^alpha + beta/2 (w - v)^2`` for every element of ``v`` (the
    w-subproblem of Krishnan & Fergus, paper eq. 8).

    Parameters
    ----------
    v : array_like
        Values (any shape, finite).
    alpha : float
        Exponent in ``(0, 2]``.
    beta : float
        Penalty weight (> 0).

    Returns
    -------
    w : float64 array of ``v``'s shape.

    Notes
    -----
    ``alpha = 1`` is soft thresholding at ``1/beta``; ``alpha = 2`` is ``beta v / (2 + beta)``;
    for ``alpha < 1`` the non-zero stationary point is found by Newton's method from
    ``w = v`` (it covers the cubic of ``alpha = 1/2`` and the quartic of ``2/3`` without
    spurious roots) and compared with ``w = 0``; ties go to 0.

    References
    ----------
    Sörös et al., WSCG 2015, Journal of WSCG vol. 23, eq. 8. D. Krishnan and R. Fergus,
    NIPS 2009.

    Examples
    --------
    >>> from wscg import deblur
    >>> deblur.w_step([-2.0, 0.5, 2.0], alpha=1.0, beta=1.0).tolist()
    [-1.0, 0.0, 1.0]
    """
    a = np.ascontiguousarray(_real(v, "v"), dtype=np.float64)
    if not np.isfinite(a).all():
        raise ValueError("`v` contains a non-finite value (NaN or infinity)")
    alpha, beta = float(alpha), float(beta)
    if not (0 < alpha <= 2):
        raise ValueError(f"`alpha` must lie in (0, 2], got {alpha}")
    return _d.w_step(a, alpha, _positive("beta", beta))


# ----------------------------------------------------------------------------------------
# Synthetic data
# ----------------------------------------------------------------------------------------

def make_gyro(duration: float, rate: float = 200.0, tau: float = 0.05,
              std=(0.35, 0.35, 0.10), t0: float = 0.0, seed: int = 0) -> np.ndarray:
    """A synthetic hand-shake gyroscope trace: Ornstein-Uhlenbeck angular rates per camera
    axis (exact discretisation, started from the stationary distribution), noise-free.

    Parameters
    ----------
    duration : float
        Length of the trace (s); ``ceil(duration * rate) + 1`` samples from ``t0``.
    rate : float, default 200
        Sampling rate (Hz; the paper's phone gyroscope).
    tau : float, default 0.05
        Correlation time (s).
    std : (float, float, float), default (0.35, 0.35, 0.10)
        Stationary standard deviation of the pitch, yaw and roll rates (rad/s).
    t0 : float, default 0
        Time of the first sample.
    seed : int, default 0

    Returns
    -------
    gyro : float64 array (N, 4) of rows ``(t, wx, wy, wz)``.
    """
    s = np.asarray(std, dtype=np.float64).ravel()
    if s.shape != (3,) or not (np.isfinite(s).all() and (s >= 0).all()):
        raise ValueError(f"`std` must be 3 finite deviations >= 0 (rad/s), got {std!r}")
    return _d.make_gyro(_positive("duration", duration), _positive("rate", rate),
                        _positive("tau", tau), (float(s[0]), float(s[1]), float(s[2])),
                        float(t0), int(seed))


def add_gyro_noise(gyro, sigma: float = 0.002, seed: int = 0) -> np.ndarray:
    """``gyro`` with white Gaussian noise of standard deviation ``sigma`` (rad/s) added to
    every rate (time stamps unchanged)."""
    sigma = float(sigma)
    if not (np.isfinite(sigma) and sigma >= 0):
        raise ValueError(f"`sigma` must be finite and >= 0, got {sigma}")
    return _d.add_gyro_noise(_gyro(gyro), sigma, int(seed))


def render_blurred(sharp, gyro, t_frame: float, t_exposure: float, f: float, cx: float,
                   cy: float, t_world: float, t_readout: float = 0.0, t_delay: float = 0.0,
                   noise_sigma: float = 0.005, gamma: Optional[float] = 2.2,
                   quantise: bool = True, seed: int = 0, r_cam_imu=None,
                   bias=None) -> np.ndarray:
    """Render a blurred frame of a planar scene densely (eq. 2 with the homography of eq. 5).

    Parameters
    ----------
    sharp : array (H, W)
        Linear sharp image seen in the camera pose at gyroscope time ``t_world``.
    gyro, t_frame, t_exposure, f, cx, cy, t_readout, t_delay, r_cam_imu, bias
        As in :func:`render_kernel`; the frame height is ``H``.
    t_world : float
        Gyroscope time of the ground-truth pose. The deblurring functions restore the
        pose of the shutter opening, ``t_frame + t_delay`` (plus ``t_readout / 2`` for
        :func:`deblur_multiframe`, which rectifies to the middle row).
    noise_sigma : float, default 0.005
        Gaussian noise added to the linear image.
    gamma : float or None, default 2.2
        Camera response applied after the noise (display = linear ** (1 / gamma)),
        ``None`` keeps linear values (clipped to [0, 1]).
    quantise : bool, default True
        Round to 8-bit levels (multiples of 1/255).
    seed : int, default 0
        Noise seed.

    Returns
    -------
    frame : float32 array (H, W) in [0, 1].

    Notes
    -----
    Row ``y`` averages, over at least 64 time sub-steps of its exposure (more when the
    image moves by more than half a pixel per step), the sharp image warped by
    ``K R(t_world)^T R(tau) K^-1`` (bicubic, borders replicated).
    """
    img = _image(sharp, "sharp")
    ns = float(noise_sigma)
    if not (np.isfinite(ns) and ns >= 0):
        raise ValueError(f"`noise_sigma` must be finite and >= 0, got {ns}")
    if gamma is not None:
        gamma = _positive("gamma", gamma)
    t_world = float(t_world)
    if not np.isfinite(t_world):
        raise ValueError(f"`t_world` must be finite, got {t_world}")
    return _d.render_blurred(img, _gyro(gyro),
                             _timing(t_frame, t_exposure, t_readout, t_delay),
                             _cam(f, cx, cy), t_world, ns, gamma, bool(quantise),
                             int(seed), _rotation(r_cam_imu), _bias(bias))


def make_scene(height: int, width: int, seed: int = 0) -> np.ndarray:
    """A textured test scene of linear intensities in [0.02, 0.98] (smooth blobs,
    sharp-edged discs and bars, fine stripes): float32 ``(height, width)``."""
    return _d.make_scene(_count("height", height), _count("width", width), int(seed))


# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
