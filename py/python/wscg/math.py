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
from typing import Optional, Tuple, Union

import numpy as np

from ._native import math as _m
from ._native.math import (box_filter, dice, eigh, eigh_generalized, fft2, fftfreq, fftn,
                           fftshift, gaussian_filter, ifft2, ifftn, ifftshift, laplacian_3d,
                           load_image, lstsq, mse, normal, permutation, psnr, resize, rmse,
                           save_image, save_mesh, save_volume, ssim, svd, uniform, wavedec2,
                           waverec2)
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


# ---------------------------------------------------------------- Python layers
# Result classes, the warning of a solve that did not converge and scipy.sparse input; the
# other functions are the native ones (py/src/math.rs), imported above.


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
    x, n_iter, residual, converged = _m.cg(indptr, indices, data, b, shape, x0, tol, max_iter,
                                           preconditioner)
    info = CgInfo(n_iter=n_iter, relative_residual=residual, converged=converged)
    if not converged:
        import warnings
        warnings.warn(f"cg did not converge: relative residual {residual:.3e} "
                      f"after {n_iter} iterations (tol {tol})", RuntimeWarning, stacklevel=2)
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
    t, n, iso = _m.read_exif(path)
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
    return _volume_file(_m.load_volume(path, spacing, series))


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
    return _volume_file(_m.load_raw_volume(path, shape, dtype, spacing))


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
    return _from_mapping(Mesh, _m.load_mesh(path))


# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
