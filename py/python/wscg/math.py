"""Shared numerics of wscg: metrics, filters, resizing, FFT, linear algebra, random numbers
and image / volume / mesh files.

Every function takes numpy arrays (any numeric dtype, any memory layout: inputs are
converted, never modified) and returns new numpy arrays. Bad arguments raise
``ValueError`` naming the argument; file problems raise ``OSError``. Heavy work runs in
Rust with the GIL released.

Conventions
-----------
- Images are ``(H, W)`` or ``(H, W, C)`` arrays. Files load as float32 in ``[0, 1]`` for
  8/16-bit formats.
- Volumes are 3-D arrays indexed ``[z, y, x]``; voxel spacing is given in the same axis
  order, ``(dz, dy, dx)``. The voxel at index ``[k, j, i]`` sits at the world point
  ``(x, y, z) = (i dx, j dy, k dz)``: the affine of the NIfTI files :func:`save_volume`
  writes, and the formula of every module (``py/API.md``). A file that places the volume in
  the scanner (NIfTI sform/qform, DICOM) gives :func:`load_volume` its 4 x 4 ``affine``
  mapping ``(i, j, k, 1)`` to RAS+ millimetres, which :func:`save_volume` writes back.
- Meshes are ``vertices`` ``(N, 3)`` float64 ``(x, y, z)`` world coordinates and ``faces``
  ``(M, 3)`` integer arrays.
- Files: ``load_<what>(path, ...)`` reads, ``save_<what>(path, data, ...)`` writes.
"""

from __future__ import annotations

import os
from typing import Optional, Sequence, Tuple, Union

import numpy as np

from ._native import math as _m
from ._checks import integer_ranges as _integer_ranges
from ._results import from_mapping as _from_mapping, result as _result

__all__ = [
    "mse", "rmse", "psnr", "ssim", "dice",
    "gaussian_filter", "box_filter", "resize",
    "fftn", "ifftn", "fft2", "ifft2", "fftshift", "ifftshift", "fftfreq",
    "wavedec2", "waverec2",
    "cg", "solve_cg", "laplacian_3d",
    "eigh", "eigh_generalized", "svd", "lstsq",
    "normal", "uniform", "permutation",
    "load_image", "save_image", "load_exif", "load_volume", "save_volume",
    "load_raw_volume", "load_mesh", "save_mesh", "CgInfo", "ExifInfo", "Mesh", "VolumeFile",
]

PathLike = Union[str, "os.PathLike[str]"]


@_result
class ExifInfo:
    """The exposure settings of a photograph's EXIF block, read by :func:`load_exif`.

    Attributes
    ----------
    exposure_time : float or None
        ExposureTime (tag 0x829A), seconds.
    f_number : float or None
        FNumber (tag 0x829D), the aperture's f-number ``N``.
    iso_speed : float or None
        PhotographicSensitivity (ISOSpeedRatings, tag 0x8827).

    Each is None when the block lacks it (or gives zero).
    """

    exposure_time: Optional[float]
    f_number: Optional[float]
    iso_speed: Optional[float]


@_result
class CgInfo:
    """How a conjugate gradient solve of :func:`cg` or :func:`solve_cg` ended.

    Attributes
    ----------
    n_iter : int
        Iterations run (0 when the initial guess already met ``tol``).
    relative_residual : float
        ``||b - A x|| / ||b||`` of the returned ``x`` (dimensionless).
    converged : bool
        Whether ``relative_residual <= tol`` was reached within ``max_iter``.
    """

    n_iter: int
    relative_residual: float
    converged: bool


@_result
class VolumeFile:
    """A volume read by :func:`load_volume` or :func:`load_raw_volume`. It unpacks as the pair
    ``volume, spacing = load_volume(path)``.

    Attributes
    ----------
    volume : ndarray of float32, ``(nz, ny, nx)``
        The values, indexed ``[z, y, x]`` (DICOM: rescaled by RescaleSlope/Intercept, so CT
        is in Hounsfield units).
    spacing : (dz, dy, dx)
        Voxel size in millimetres, in array axis order.
    affine : ndarray of float64, ``(4, 4)``
        Voxel-to-world matrix: ``affine @ (i, j, k, 1)`` is the RAS+ point (millimetres: x
        towards the patient's right, y anterior, z superior) of voxel ``volume[k, j, i]``.
        NIfTI: nibabel's ``img.affine`` (sform, else qform); DICOM: the LPS+ patient frame of
        ImagePositionPatient / ImageOrientationPatient with x and y negated. When the file has
        none, ``diag(dx, dy, dz, 1)``: the formula of ``py/API.md`` with a zero origin.
    has_affine : bool
        Whether the file gave the affine (False: the diagonal above).
    origin : (oz, oy, ox)
        World point of voxel ``[0, 0, 0]`` (millimetres, array axis order): ``affine[2::-1, 3]``.
    """

    volume: np.ndarray
    spacing: Tuple[float, float, float]
    affine: np.ndarray
    has_affine: bool
    origin: Tuple[float, float, float]

    def __iter__(self):
        return iter((self.volume, self.spacing))


def _volume_file(native) -> VolumeFile:
    volume, spacing, rows = native
    dz, dy, dx = spacing
    affine = np.diag([dx, dy, dz, 1.0]) if rows is None else np.vstack(
        [np.asarray(rows, np.float64), [0.0, 0.0, 0.0, 1.0]])
    return VolumeFile(volume=volume, spacing=tuple(spacing), affine=affine,
                      has_affine=rows is not None,
                      origin=tuple(float(v) for v in affine[2::-1, 3]))


@_result
class Mesh:
    """A triangle mesh read by :func:`load_mesh`.

    Attributes
    ----------
    vertices : float64 array (N, 3)
        Positions ``(x, y, z)`` in the file's units.
    faces : int64 array (M, 3)
        Vertex indices, 0-based (polygons triangulated as fans).
    normals : float64 array (N, 3) or None
        Per-vertex normals, when the file has them.
    colors : float32 array (N, 3) or None
        Per-vertex RGB in ``[0, 1]``, when the file has them.
    """

    vertices: np.ndarray
    faces: np.ndarray
    normals: Optional[np.ndarray] = None
    colors: Optional[np.ndarray] = None


def _real(x, name: str, dtype=np.float64) -> np.ndarray:
    """``x`` as a C-contiguous array of ``dtype`` (a copy when needed)."""
    a = np.asarray(x)
    if np.iscomplexobj(a):
        raise ValueError(f"`{name}` must be real-valued, got dtype {a.dtype}")
    if not (np.issubdtype(a.dtype, np.number) or a.dtype == np.bool_):
        raise ValueError(f"`{name}` must be a numeric array, got dtype {a.dtype}")
    return np.ascontiguousarray(a, dtype=dtype)


def _complex(x, name: str) -> np.ndarray:
    a = np.asarray(x)
    if not (np.issubdtype(a.dtype, np.number) or a.dtype == np.bool_):
        raise ValueError(f"`{name}` must be a numeric array, got dtype {a.dtype}")
    return np.ascontiguousarray(a, dtype=np.complex128)


def _path(p, name: str = "path") -> str:
    try:
        return os.fspath(p)
    except TypeError:
        raise TypeError(f"`{name}` must be a str or os.PathLike, got {type(p).__name__}") from None


# ---------------------------------------------------------------- metrics


def mse(a, b) -> float:
    """Mean squared error of two arrays of the same shape.

    Parameters
    ----------
    a, b : array_like
        Arrays of equal shape (any numeric dtype).

    Returns
    -------
    float
        ``mean((a - b) ** 2)``.

    Raises
    ------
    ValueError
        Shapes differ, arrays are empty or hold NaN/inf.

    Examples
    --------
    >>> mse([0.0, 0.0], [3.0, 4.0])
    12.5
    """
    return _m.mse(_real(a, "a"), _real(b, "b"))


def rmse(a, b) -> float:
    """Root mean squared error ``sqrt(mse(a, b))``.

    Parameters
    ----------
    a, b : array_like
        Arrays of equal shape.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        As :func:`mse`.
    """
    return float(np.sqrt(mse(a, b)))


def psnr(a, b, data_range: float = 1.0) -> float:
    """Peak signal-to-noise ratio in dB, ``10 log10(data_range**2 / mse)``.

    Parameters
    ----------
    a, b : array_like
        Reference and test arrays of equal shape.
    data_range : float, default 1.0
        Dynamic range of the data (1 for images in [0, 1], 255 for 8-bit values).

    Returns
    -------
    float
        PSNR in dB; ``inf`` for identical inputs.

    Raises
    ------
    ValueError
        Shapes differ, empty input, NaN/inf, ``data_range <= 0``.

    Notes
    -----
    Equals ``skimage.metrics.peak_signal_noise_ratio(a, b, data_range=data_range)``.
    """
    return _m.psnr(_real(a, "a"), _real(b, "b"), float(data_range))


def ssim(a, b, data_range: float = 1.0, sigma: float = 1.5, truncate: float = 3.5,
         k1: float = 0.01, k2: float = 0.03) -> float:
    """Mean structural similarity (SSIM) of two images.

    Parameters
    ----------
    a, b : array_like
        Images of equal shape, ``(H, W)`` or ``(H, W, C)`` (channels are averaged).
    data_range : float, default 1.0
        Dynamic range ``R`` of the data.
    sigma : float, default 1.5
        Standard deviation of the Gaussian window.
    truncate : float, default 3.5
        Window radius in standard deviations (11 x 11 at sigma 1.5).
    k1, k2 : float, default 0.01, 0.03
        Stabilising constants, ``C1 = (k1 R)^2``, ``C2 = (k2 R)^2``.

    Returns
    -------
    float
        Mean SSIM over the image, cropped by the window radius.

    Raises
    ------
    ValueError
        Shapes differ, images smaller than the window, NaN/inf, bad parameters.

    Notes
    -----
    SSIM (eq. 13 of the reference) is computed from Gaussian-weighted local means,
    variances and covariance with ``reflect`` borders. The result equals
    ``skimage.metrics.structural_similarity(a, b, data_range=R, gaussian_weights=True,
    sigma=1.5, use_sample_covariance=False, channel_axis=-1 for colour)``.

    References
    ----------
    Z. Wang, A. C. Bovik, H. R. Sheikh, E. P. Simoncelli, "Image quality assessment: from
    error visibility to structural similarity", IEEE TIP 13(4), 2004,
    :doi:`10.1109/TIP.2003.819861`.

    Examples
    --------
    >>> import numpy as np
    >>> img = np.linspace(0, 1, 64 * 64).reshape(64, 64)
    >>> round(ssim(img, img), 6)
    1.0
    """
    return _m.ssim(_real(a, "a"), _real(b, "b"), float(data_range), float(sigma),
                   float(truncate), float(k1), float(k2))


def dice(a, b, label: Optional[int] = None) -> float:
    """Dice coefficient ``2 |A & B| / (|A| + |B|)`` of two masks.

    Parameters
    ----------
    a, b : array_like
        Boolean masks of equal shape, or label maps when ``label`` is given.
    label : int, optional
        Compare the regions ``a == label`` and ``b == label``.

    Returns
    -------
    float
        In [0, 1]; two empty masks give 1.

    Raises
    ------
    ValueError
        Shapes differ or the masks are empty arrays.
    """
    masks = []
    for name, m in (("a", a), ("b", b)):
        m = np.asarray(m)
        if m.ndim == 0:
            raise ValueError(f"`{name}` must be a mask array, got a scalar {m!r}")
        if m.dtype.kind not in "biuf":
            raise ValueError(f"`{name}` must be a boolean mask or a label map, got dtype {m.dtype}")
        if m.dtype.kind == "f":
            if not np.isfinite(m).all():
                i = int(np.argmax(~np.isfinite(m).ravel()))
                raise ValueError(f"`{name}` contains a non-finite value (NaN or infinity) at "
                                 f"flat index {i}")
            if label is None and not np.isin(m, (0.0, 1.0)).all():
                raise ValueError(f"`{name}` holds values other than 0 and 1; pass a boolean mask "
                                 "or give `label` to compare label maps")
        masks.append(m == label if label is not None else m.astype(bool, copy=False))
    return _m.dice(np.ascontiguousarray(masks[0]), np.ascontiguousarray(masks[1]))


# ---------------------------------------------------------------- filters and resizing


def gaussian_filter(image, sigma: float, truncate: float = 4.0, mode: str = "reflect",
                    cval: float = 0.0) -> np.ndarray:
    """Gaussian blur of every channel of an image.

    Parameters
    ----------
    image : array_like
        ``(H, W)`` or ``(H, W, C)``; channels are filtered independently.
    sigma : float
        Standard deviation in pixels (> 0).
    truncate : float, default 4.0
        Kernel radius ``int(truncate * sigma + 0.5)``.
    mode : {'reflect', 'mirror', 'nearest', 'wrap', 'constant'}, default 'reflect'
        Border handling, as in ``scipy.ndimage``.
    cval : float, default 0.0
        Value outside the image for ``mode='constant'``.

    Returns
    -------
    ndarray of float64, same shape as ``image``.

    Raises
    ------
    ValueError
        Bad shape, NaN/inf, ``sigma <= 0``, unknown ``mode``.

    Notes
    -----
    Equals ``scipy.ndimage.gaussian_filter(image, sigma=(sigma, sigma[, 0]), truncate=...,
    mode=..., cval=...)``.
    """
    return _m.gaussian_filter(_real(image, "image"), float(sigma), float(truncate), mode,
                              float(cval))


def box_filter(image, radius: int, mode: str = "reflect", cval: float = 0.0) -> np.ndarray:
    """Mean over a ``(2 radius + 1)^2`` window of every channel.

    Parameters
    ----------
    image : array_like
        ``(H, W)`` or ``(H, W, C)``.
    radius : int
        Window radius (>= 0).
    mode : {'reflect', 'mirror', 'nearest', 'wrap', 'constant'}, default 'reflect'
        Border handling.
    cval : float, default 0.0
        Value outside for ``mode='constant'``.

    Returns
    -------
    ndarray of float64, same shape as ``image``.

    Raises
    ------
    ValueError
        Bad shape, NaN/inf, negative radius, unknown ``mode``.

    Notes
    -----
    Equals ``scipy.ndimage.uniform_filter(image, size=(2r+1, 2r+1[, 1]), mode=...)``.
    """
    if int(radius) < 0:
        raise ValueError(f"`radius` must be >= 0, got {radius}")
    return _m.box_filter(_real(image, "image"), int(radius), mode, float(cval))


def resize(image, shape: Tuple[int, int], method: str = "area") -> np.ndarray:
    """Resizes an image to ``shape = (height, width)``.

    Parameters
    ----------
    image : array_like
        ``(H, W)`` or ``(H, W, C)``.
    shape : (int, int)
        Output height and width (> 0).
    method : {'area', 'bilinear'}, default 'area'
        ``'area'``: exact area-weighted mean of the covered input pixels (block mean for
        integer factors, OpenCV's ``INTER_AREA`` when downscaling). ``'bilinear'``:
        interpolation with half-pixel centres, clamped at the border (``INTER_LINEAR``).

    Returns
    -------
    ndarray of float32, ``(height, width[, C])``.

    Raises
    ------
    ValueError
        Bad shape, zero output size, NaN/inf, unknown ``method``.
    """
    h, w = (int(v) for v in shape)
    if h <= 0 or w <= 0:
        raise ValueError(f"`shape` must be positive, got {shape}")
    return _m.resize(_real(image, "image"), h, w, method)


# ---------------------------------------------------------------- FFT


def _axes(x: np.ndarray, axes) -> Optional[list]:
    if axes is None:
        return None
    out = []
    for a in axes:
        a = int(a)
        if a < -x.ndim or a >= x.ndim:
            raise ValueError(f"`axes` entry {a} is out of range for a {x.ndim}-D array")
        out.append(a % x.ndim)
    return out


def wavedec2(x, wavelet: str = "db4", level: int = 4) -> np.ndarray:
    """Multi-level 2-D orthonormal Daubechies wavelet transform with periodic extension.

    Parameters
    ----------
    x : array_like (H, W)
        Real image; both sizes divisible by ``2**level``.
    wavelet : {'db1', ..., 'db8'}, default 'db4'
    level : int, default 4

    Returns
    -------
    ndarray (H, W), float64, in the in-place (Mallat) layout: after level ``l`` the
    approximation is the top-left ``H / 2^l x W / 2^l`` block; each level's details sit beside
    it (top-right: high-pass along columns, PyWavelets' ``cV``; bottom-left: along rows,
    ``cH``; bottom-right: ``cD``).

    Notes
    -----
    The coefficients equal PyWavelets' ``wavedec2(x, wavelet, mode="periodization",
    level=level)``; the transform is orthogonal, so :func:`waverec2` is its transpose.
    """
    return _m.wavelet2(_real(x, "x"), _db_order(wavelet), int(level), False)


def waverec2(coeffs, wavelet: str = "db4", level: int = 4) -> np.ndarray:
    """Inverse of :func:`wavedec2`: the image from its Mallat-layout coefficients.

    Parameters
    ----------
    coeffs : array_like (H, W)
        Coefficients as :func:`wavedec2` returns them.
    wavelet : {'db1', ..., 'db8'}, default 'db4'
    level : int, default 4
        The number of levels the coefficients were computed with.

    Returns
    -------
    ndarray (H, W), float64. The transform is orthogonal: this is also its transpose.
    """
    return _m.wavelet2(_real(coeffs, "coeffs"), _db_order(wavelet), int(level), True)


def _db_order(wavelet: str) -> int:
    w = str(wavelet)
    if not (w.startswith("db") and w[2:].isdigit()):
        raise ValueError(f"{wavelet!r} is not a valid wavelet. Valid wavelets are 'db1' ... 'db8'")
    return int(w[2:])


def fftn(x, axes: Optional[Sequence[int]] = None, norm: str = "backward") -> np.ndarray:
    """N-dimensional discrete Fourier transform.

    Parameters
    ----------
    x : array_like
        Input (real or complex), any number of dimensions.
    axes : sequence of int, optional
        Axes to transform (default: all).
    norm : {'backward', 'ortho', 'forward'}, default 'backward'
        Scaling, as numpy's ``norm`` argument.

    Returns
    -------
    ndarray of complex128, same shape as ``x``.

    Raises
    ------
    ValueError
        Empty axis, repeated or out-of-range axes, unknown ``norm``.

    Notes
    -----
    ``X[k] = sum_n x[n] exp(-2 pi i k n / N)`` along each axis; equals ``numpy.fft.fftn``.
    """
    xc = _complex(x, "x")
    return _m.fftn(xc, _axes(xc, axes), False, norm)


def ifftn(x, axes: Optional[Sequence[int]] = None, norm: str = "backward") -> np.ndarray:
    """Inverse N-dimensional DFT (``numpy.fft.ifftn``); see :func:`fftn`.

    Parameters
    ----------
    x : array_like
        Spectrum.
    axes : sequence of int, optional
        Axes to transform (default: all).
    norm : {'backward', 'ortho', 'forward'}, default 'backward'
        Scaling.

    Returns
    -------
    ndarray of complex128.
    """
    xc = _complex(x, "x")
    return _m.fftn(xc, _axes(xc, axes), True, norm)


def fft2(x, axes: Sequence[int] = (-2, -1), norm: str = "backward") -> np.ndarray:
    """Two-dimensional DFT over ``axes`` (default the last two), as ``numpy.fft.fft2``.

    Parameters
    ----------
    x : array_like
        At least 2-D.
    axes : (int, int), default (-2, -1)
        The two axes.
    norm : {'backward', 'ortho', 'forward'}, default 'backward'
        Scaling.

    Returns
    -------
    ndarray of complex128.
    """
    return fftn(x, axes=axes, norm=norm)


def ifft2(x, axes: Sequence[int] = (-2, -1), norm: str = "backward") -> np.ndarray:
    """Inverse two-dimensional DFT, as ``numpy.fft.ifft2``.

    Parameters
    ----------
    x : array_like
        At least 2-D.
    axes : (int, int), default (-2, -1)
        The two axes.
    norm : {'backward', 'ortho', 'forward'}, default 'backward'
        Scaling.

    Returns
    -------
    ndarray of complex128.
    """
    return ifftn(x, axes=axes, norm=norm)


def _shift(x, inverse: bool) -> np.ndarray:
    a = np.asarray(x)
    if a.ndim == 0:
        raise ValueError("`x` must have at least one dimension")
    if np.iscomplexobj(a):
        return _m.fftshift_c(np.ascontiguousarray(a, dtype=np.complex128), inverse)
    return _m.fftshift_f(_real(a, "x"), inverse)


def fftshift(x) -> np.ndarray:
    """Moves the zero frequency to the centre of every axis (``numpy.fft.fftshift``).

    Parameters
    ----------
    x : array_like
        Real or complex array.

    Returns
    -------
    ndarray (float64 or complex128), same shape.
    """
    return _shift(x, False)


def ifftshift(x) -> np.ndarray:
    """Inverse of :func:`fftshift` (``numpy.fft.ifftshift``).

    Parameters
    ----------
    x : array_like
        Real or complex array.

    Returns
    -------
    ndarray (float64 or complex128), same shape.
    """
    return _shift(x, True)


def fftfreq(n: int, d: float = 1.0) -> np.ndarray:
    """Sample frequencies of a length-``n`` DFT with spacing ``d`` (``numpy.fft.fftfreq``).

    Parameters
    ----------
    n : int
        Transform length (> 0).
    d : float, default 1.0
        Sample spacing (> 0).

    Returns
    -------
    ndarray of float64, length ``n``.
    """
    if int(n) <= 0:
        raise ValueError(f"`n` must be > 0, got {n}")
    return _m.fftfreq(int(n), float(d))


# ---------------------------------------------------------------- sparse linear algebra


def cg(indptr, indices, data, b, shape: Optional[Tuple[int, int]] = None, x0=None,
       tol: float = 1e-8, max_iter: Optional[int] = None,
       preconditioner: Optional[str] = "jacobi") -> Tuple[np.ndarray, CgInfo]:
    """Preconditioned conjugate gradient for a sparse SPD matrix in CSR form.

    Parameters
    ----------
    indptr, indices, data : array_like
        CSR arrays (as ``scipy.sparse.csr_matrix``: row pointers of length ``n + 1``,
        column indices and values). Duplicates are summed.
    b : array_like
        Right-hand side, length ``n``.
    shape : (int, int), optional
        Matrix shape; default ``(n, n)`` with ``n = len(indptr) - 1``.
    x0 : array_like, optional
        Initial guess (warm start); default zeros.
    tol : float, default 1e-8
        Stop when ``||b - A x|| <= tol ||b||``.
    max_iter : int, optional
        Iteration cap; default ``10 n``.
    preconditioner : {'jacobi', None}, default 'jacobi'
        Diagonal (Jacobi) preconditioning or none.

    Returns
    -------
    x : ndarray of float64
        Solution estimate.
    info : CgInfo
        ``n_iter`` (iterations run), ``relative_residual`` and ``converged``.

    Raises
    ------
    ValueError
        Inconsistent CSR arrays, length mismatch, NaN, ``tol <= 0``, a matrix that is not
        positive definite (the iteration breaks down).

    Notes
    -----
    Hestenes-Stiefel CG with a preconditioner (Saad, *Iterative Methods for Sparse Linear
    Systems*, alg. 9.1). Not converging within ``max_iter`` is reported in ``info``, as
    ``scipy.sparse.linalg.cg`` reports it in its return code. A warning is issued too.
    """
    indptr = np.ascontiguousarray(indptr, dtype=np.int64)
    n = len(indptr) - 1
    nrows, ncols = (n, n) if shape is None else (int(shape[0]), int(shape[1]))
    if nrows != n:
        raise ValueError(f"`shape` {shape} does not match len(indptr) - 1 = {n}")
    x, d = _m.cg(indptr, np.ascontiguousarray(indices, dtype=np.int64),
                 _real(data, "data"), ncols, _real(b, "b"),
                 None if x0 is None else _real(x0, "x0"), float(tol),
                 None if max_iter is None else int(max_iter), preconditioner)
    info = _from_mapping(CgInfo, d, rename={"iterations": "n_iter"})
    if not info.converged:
        import warnings
        warnings.warn(f"cg did not converge: relative residual {info.relative_residual:.3e} "
                      f"after {info.n_iter} iterations (tol {tol})", RuntimeWarning,
                      stacklevel=2)
    return x, info


def solve_cg(a, b, x0=None, tol: float = 1e-8, max_iter: Optional[int] = None,
             preconditioner: Optional[str] = "jacobi") -> Tuple[np.ndarray, CgInfo]:
    """:func:`cg` on a ``scipy.sparse`` matrix (or anything with ``tocsr()``).

    Parameters
    ----------
    a : scipy.sparse matrix or array
        Symmetric positive definite matrix.
    b : array_like
        Right-hand side.
    x0 : array_like, optional
        Initial guess (warm start); default zeros.
    tol : float, default 1e-8
        Stop when ``||b - A x|| <= tol ||b||``.
    max_iter : int, optional
        Iteration cap; default ``10 n``.
    preconditioner : {'jacobi', None}, default 'jacobi'
        Diagonal (Jacobi) preconditioning or none.

    Returns
    -------
    x : ndarray of float64
        Solution estimate.
    info : CgInfo
        As :func:`cg`.
    """
    if not hasattr(a, "tocsr"):
        raise ValueError("`a` must be a scipy.sparse matrix (with a tocsr() method)")
    csr = a.tocsr()
    return cg(csr.indptr, csr.indices, csr.data, b, shape=csr.shape, x0=x0, tol=tol,
              max_iter=max_iter, preconditioner=preconditioner)


def laplacian_3d(nx: int, ny: int, nz: int):
    """CSR arrays of the 7-point Laplacian of an ``nx x ny x nz`` grid (Dirichlet).

    Parameters
    ----------
    nx, ny, nz : int
        Grid size (> 0); unknowns are ordered with x fastest.

    Returns
    -------
    indptr, indices, data : ndarray
        int64, int64 and float64 CSR arrays (diagonal 6, neighbours -1): symmetric positive
        definite, for tests and benchmarks.
    """
    for name, v in (("nx", nx), ("ny", ny), ("nz", nz)):
        if int(v) <= 0:
            raise ValueError(f"`{name}` must be > 0, got {v}")
    return _m.laplacian_3d(int(nx), int(ny), int(nz))


# ---------------------------------------------------------------- dense linear algebra


def eigh(a, k: Optional[int] = None, which: str = "largest"):
    """Eigenpairs of a real symmetric matrix.

    Parameters
    ----------
    a : array_like
        Symmetric ``(n, n)`` matrix.
    k : int, optional
        Number of eigenpairs (default: all).
    which : {'largest', 'smallest'}, default 'largest'
        Which end of the spectrum; values come in that order (descending for
        ``'largest'``, ascending for ``'smallest'``).

    Returns
    -------
    values : ndarray, (k,)
    vectors : ndarray, (n, k)
        Unit eigenvectors as columns.

    Raises
    ------
    ValueError
        Not square, not symmetric, NaN/inf, ``k`` out of range, unknown ``which``.
    """
    if which not in ("largest", "smallest"):
        raise ValueError(f"{which!r} is not a valid `which`. Valid values are 'largest', 'smallest'")
    return _m.eigh(_real(a, "a"), None if k is None else int(k), which)


def eigh_generalized(a, b):
    """Generalized symmetric-definite eigenproblem ``A v = lambda B v``.

    Parameters
    ----------
    a : array_like
        Symmetric ``(n, n)``.
    b : array_like
        Symmetric positive definite ``(n, n)``.

    Returns
    -------
    values : ndarray, (n,)
        Ascending.
    vectors : ndarray, (n, n)
        ``B``-orthonormal eigenvectors as columns (``V.T @ B @ V = I``).

    Raises
    ------
    ValueError
        Shapes, asymmetry, NaN, ``b`` not positive definite.

    Notes
    -----
    Cholesky ``B = L L^T``, then the standard problem for ``L^-1 A L^-T``; eigenvalues equal
    ``scipy.linalg.eigh(a, b)``.
    """
    return _m.eigh_generalized(_real(a, "a"), _real(b, "b"))


def svd(a):
    """Thin singular value decomposition ``a = u @ diag(s) @ vt``.

    Parameters
    ----------
    a : array_like
        ``(m, n)`` matrix.

    Returns
    -------
    u : ndarray, (m, r)
    s : ndarray, (r,)
        Non-increasing, ``r = min(m, n)``.
    vt : ndarray, (r, n)

    Raises
    ------
    ValueError
        Not 2-D, empty, NaN/inf.
    """
    return _m.svd(_real(a, "a"))


def lstsq(a, b, rcond: Optional[float] = None) -> np.ndarray:
    """Minimum-norm least-squares solution of ``a @ x = b``.

    Parameters
    ----------
    a : array_like
        ``(m, n)`` matrix.
    b : array_like
        ``(m,)`` or ``(m, k)``.
    rcond : float, optional
        Relative cut-off for small singular values (default ``eps * max(m, n)``, numpy's).

    Returns
    -------
    ndarray
        ``(n,)`` or ``(n, k)``, matching ``b``.

    Raises
    ------
    ValueError
        Shapes, NaN/inf, negative ``rcond``.
    """
    b = _real(b, "b")
    one = b.ndim == 1
    x = _m.lstsq(_real(a, "a"), b.reshape(-1, 1) if one else b,
                 None if rcond is None else float(rcond))
    return x[:, 0] if one else x


# ---------------------------------------------------------------- random numbers


def normal(seed: int, n: int, mean: float = 0.0, std: float = 1.0) -> np.ndarray:
    """``n`` normal samples from a seeded, portable generator (ChaCha8).

    Parameters
    ----------
    seed : int
        Seed (>= 0); the same seed gives the same values on every machine and thread count.
    n : int
        Number of samples.
    mean, std : float
        Distribution parameters (``std >= 0``).

    Returns
    -------
    ndarray of float64.
    """
    return _m.normal(int(seed), int(n), float(mean), float(std))


def uniform(seed: int, n: int, low: float = 0.0, high: float = 1.0) -> np.ndarray:
    """``n`` samples uniform in ``[low, high)`` from a seeded generator.

    Parameters
    ----------
    seed : int
        Seed (>= 0).
    n : int
        Number of samples.
    low, high : float
        Bounds, ``low < high``.

    Returns
    -------
    ndarray of float64.
    """
    return _m.uniform(int(seed), int(n), float(low), float(high))


def permutation(seed: int, n: int) -> np.ndarray:
    """A seeded random permutation of ``range(n)``.

    Parameters
    ----------
    seed : int
        Seed (>= 0).
    n : int
        Length.

    Returns
    -------
    ndarray of int64.
    """
    return _m.permutation(int(seed), int(n))


# ---------------------------------------------------------------- files


def load_image(path: PathLike) -> np.ndarray:
    """Reads a PNG or TIFF (8/16-bit; TIFF also 32-bit float), JPEG, OpenEXR or Radiance HDR
    image. A multi-page TIFF is read from its first page.

    Parameters
    ----------
    path : str or os.PathLike
        The file (only read).

    Returns
    -------
    ndarray of float32
        ``(H, W)`` for grey images, ``(H, W, C)`` otherwise; integer formats scaled to
        ``[0, 1]`` (``v / 255``, ``v / 65535``: ``np.round(x * 65535).astype(np.uint16)``
        gives back a 16-bit file's codes exactly), float formats unchanged.

    Raises
    ------
    OSError
        Missing, unreadable, truncated or unsupported file.
    """
    return _m.load_image(_path(path))


def save_image(path: PathLike, image, bit_depth: Optional[int] = None) -> None:
    """Writes an image; the format follows the extension (png, tif/tiff, jpg/jpeg, exr,
    hdr). The file is written atomically (a temporary file renamed over ``path``).

    Parameters
    ----------
    path : str or os.PathLike
        Output file.
    image : array_like
        ``(H, W)`` or ``(H, W, C)`` with C in 1..4 (TIFF: 1, 3 or 4). A uint8 array holds
        codes ``0..255`` and a uint16 array codes ``0..65535`` (written exactly at their own
        depth); other arrays hold values in ``[0, 1]`` for integer formats (clamped), any
        finite values for exr/hdr and 32-bit TIFF.
    bit_depth : {8, 16, 32}, optional
        8, 16 (png and tiff) or 32 (float: exr, hdr, and RGB/RGBA tiff). Default: 16 for a
        uint16 array written to png or tiff, 32 for exr/hdr, else 8.

    Raises
    ------
    ValueError
        Bad shape, NaN/inf.
    OSError
        Unsupported extension or depth for the format, unwritable path.
    """
    a = np.asarray(image)
    if a.dtype in (np.uint8, np.uint16):
        scale = 255.0 if a.dtype == np.uint8 else 65535.0
        if bit_depth is None and a.dtype == np.uint16 and str(path).lower().endswith(
                (".png", ".tif", ".tiff")):
            bit_depth = 16
        a = a.astype(np.float64) / scale
    _m.save_image(_path(path), _real(a, "image"), None if bit_depth is None else int(bit_depth))


def load_exif(path: PathLike) -> ExifInfo:
    """Reads the exposure settings of a photograph's EXIF block (JPEG, TIFF or PNG).

    Parameters
    ----------
    path : str or os.PathLike
        The file (only read).

    Returns
    -------
    ExifInfo
        ``exposure_time`` (s), ``f_number`` and ``iso_speed``, each None when absent.

    Raises
    ------
    OSError
        A missing or unreadable file, a file without an EXIF block or with a malformed one
        (the message names the file).

    See Also
    --------
    wscg.hdr.exif_exposure_times : the exposures of a stack of photographs.
    """
    t, n, iso = _m.read_exif(_path(path))
    return ExifInfo(exposure_time=t, f_number=n, iso_speed=iso)


def load_volume(path: PathLike, spacing: Optional[Tuple[float, float, float]] = None,
                series: Optional[str] = None) -> VolumeFile:
    """Reads a NIfTI (.nii, .nii.gz) or .npy volume, or a DICOM series (a DICOM file or a
    folder of them).

    Parameters
    ----------
    path : str or os.PathLike
        The file or DICOM folder (only read). A DICOM folder's files are grouped by
        SeriesInstanceUID and sorted along the slice normal by ImagePositionPatient; missing
        slices, mixed orientations or sizes and uneven slice steps (over 1 %) are errors
        naming the files.
    spacing : (dz, dy, dx), optional
        Voxel size; replaces the file's (the affine's columns are rescaled), default 1 for
        .npy.
    series : str, optional
        SeriesInstanceUID to read from a DICOM folder holding several series (without it,
        several series are an error listing them).

    Returns
    -------
    VolumeFile
        ``volume`` float32 ``[z, y, x]`` (NIfTI's ``(i, j, k)`` voxel is ``volume[k, j, i]``;
        DICOM's column, row, slice likewise), ``spacing`` ``(dz, dy, dx)``, ``affine``
        (4 x 4, RAS+ mm), ``has_affine`` and ``origin``. Unpacks as ``volume, spacing``.

    Raises
    ------
    ValueError
        Several DICOM series without ``series``, an inconsistent series, bad ``spacing``.
    OSError
        Missing, malformed, truncated or unsupported file (a DICOM transfer syntax without a
        decoder here is named).
    MemoryError
        A declared size beyond the memory limit.
    """
    return _volume_file(_m.load_volume(
        _path(path), None if spacing is None else tuple(float(s) for s in spacing),
        None if series is None else str(series)))


def load_raw_volume(path: PathLike, shape: Tuple[int, int, int], dtype: str,
                    spacing: Tuple[float, float, float] = (1.0, 1.0, 1.0)) -> VolumeFile:
    """Reads a headerless raw volume.

    Parameters
    ----------
    path : str or os.PathLike
        The file; its size must equal ``prod(shape) * bytes per voxel``.
    shape : (nz, ny, nx)
        Grid size; the file stores x fastest.
    dtype : {'u8', 'u16le', 'u16be', 'i16le', 'i16be', 'f32le', 'f32be'}
        Voxel type and byte order.
    spacing : (dz, dy, dx), default (1, 1, 1)

    Returns
    -------
    VolumeFile
        ``volume`` float32 ``(nz, ny, nx)``, ``spacing``, and the diagonal ``affine`` (a raw
        file has no orientation). Unpacks as ``volume, spacing``.

    Raises
    ------
    ValueError
        Unknown ``dtype``, bad shape or spacing.
    OSError
        Missing or wrongly sized file.
    """
    nz, ny, nx = (int(v) for v in shape)
    return _volume_file(_m.load_raw_volume(_path(path), (nz, ny, nx), dtype,
                                           tuple(float(s) for s in spacing)))


def save_volume(path: PathLike, volume, spacing: Optional[Tuple[float, float, float]] = None,
                affine=None) -> None:
    """Writes a volume as .nii / .nii.gz (NIfTI-1, float32), .npy or .raw (f32 little endian).

    Parameters
    ----------
    path : str or os.PathLike
        Output file; the extension picks the format.
    volume : array_like
        3-D array indexed ``[z, y, x]``.
    spacing : (dz, dy, dx), optional
        Voxel size (> 0), default (1, 1, 1), or the lengths of ``affine``'s columns when it is
        given (a ``spacing`` that differs from them is an error). Without ``affine`` a NIfTI
        file gets the affine of ``py/API.md``: its voxel ``(i, j, k)``, which is
        ``volume[k, j, i]``, maps to ``(x, y, z) = (i dx, j dy, k dz)``.
    affine : array_like (4, 4) or (3, 4), optional
        Voxel-to-world matrix acting on ``(i, j, k, 1)`` (RAS+ mm, as
        :attr:`VolumeFile.affine`): the NIfTI sform, and the qform when it is a rotation.
        Ignored by .npy and .raw, which hold no geometry.

    Raises
    ------
    ValueError
        Not 3-D, bad spacing, a singular or non-finite affine, or one that disagrees with
        ``spacing``.
    OSError
        Unsupported extension, unwritable path.
    """
    rows = None
    if affine is not None:
        a = np.asarray(affine, np.float64)
        if a.shape not in ((4, 4), (3, 4)):
            raise ValueError(f"`affine` must be a 4 x 4 or 3 x 4 matrix, got shape {a.shape}")
        if a.shape == (4, 4) and not np.allclose(a[3], [0, 0, 0, 1]):
            raise ValueError(f"`affine`'s last row must be (0, 0, 0, 1), got {a[3]}")
        rows = [[float(v) for v in r] for r in a[:3]]
        norms = np.linalg.norm(a[:3, :3], axis=0)
        implied = (float(norms[2]), float(norms[1]), float(norms[0]))
        if spacing is not None and not np.allclose(
                [float(s) for s in spacing], implied, rtol=1e-5, atol=0.0):
            raise ValueError(f"`spacing` {tuple(spacing)} differs from the lengths of "
                             f"`affine`'s columns {implied} (dz, dy, dx)")
        spacing = implied
    elif spacing is None:
        spacing = (1.0, 1.0, 1.0)
    _m.save_volume(_path(path), _real(volume, "volume", np.float32),
                   tuple(float(s) for s in spacing), rows)


def load_mesh(path: PathLike) -> Mesh:
    """Reads a triangle mesh from .obj or .ply (ascii or binary).

    Parameters
    ----------
    path : str or os.PathLike
        The file (only read). Polygons are triangulated as fans.

    Returns
    -------
    Mesh
        ``vertices`` (N, 3) float64 ``(x, y, z)``, ``faces`` (M, 3) int64, and ``normals``
        (N, 3) float64 and ``colors`` (N, 3) float32 in [0, 1] when the file has them
        (``None`` otherwise).

    Raises
    ------
    OSError
        Missing, malformed or truncated file, indices out of range, unknown extension.
    """
    return _from_mapping(Mesh, _m.load_mesh(_path(path)))


def save_mesh(path: PathLike, vertices, faces, colors=None, normals=None,
              binary: bool = True) -> None:
    """Writes a triangle mesh as .obj or .ply.

    Parameters
    ----------
    path : str or os.PathLike
        Output file; the extension picks the format.
    vertices : array_like, (N, 3)
        ``(x, y, z)`` positions.
    faces : array_like of int, (M, 3)
        Vertex indices, 0-based.
    colors : array_like, (N, 3), optional
        Per-vertex RGB in [0, 1].
    normals : array_like, (N, 3), optional
        Per-vertex normals.
    binary : bool, default True
        Binary little-endian PLY (ignored for OBJ).

    Raises
    ------
    ValueError
        Bad shapes, NaN, indices out of range or repeated within a face.
    OSError
        Unsupported extension, unwritable path.
    """
    faces = np.asarray(faces)
    if not np.issubdtype(faces.dtype, np.integer):
        raise ValueError(f"`faces` must be an integer array, got dtype {faces.dtype}")
    _m.save_mesh(_path(path), _real(vertices, "vertices"),
                  np.ascontiguousarray(faces, dtype=np.int64),
                  None if colors is None else _real(colors, "colors", np.float32),
                  None if normals is None else _real(normals, "normals"), bool(binary))

# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
