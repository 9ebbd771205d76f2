"""wscg: software for the papers of the Journal of WSCG, vol. 23.

Graphics, imaging, vision, biometrics, medical volumes and animation, implemented in Rust
and exposed to Python with numpy arrays in and out. One submodule per field:

- :mod:`wscg.math`: shared numerics (image, volume and mesh IO, FFT, filters, resizing,
  metrics, sparse and dense linear algebra, seeded random numbers).
- :mod:`wscg.biometrics`: paper 01, FDKECA with PCA, kernel PCA and KECA baselines and 1-NN
  recognition (scikit-learn-style estimators).
- :mod:`wscg.cloth`: paper 02, cloth simulation with soft constraints.
- :mod:`wscg.meshfilter`: paper 04, joint bilateral mesh denoising with colour (and its
  bilateral and Laplacian baselines).
- :mod:`wscg.video`: paper 06, localized-search HD video completion (and the Wexler and
  per-frame PatchMatch baselines).
- :mod:`wscg.raytrace`: paper 07, spectral rendering of metallic-flake paint from its
  microstructure, the off-axis stereo rig and the virtual observer.
- :mod:`wscg.doe`: paper 07's study statistics (central composite designs, response
  surfaces, repeated-measures ANOVA, Fisher's LSD).
- :mod:`wscg.isosurface`: paper 09, marching cubes on sparse grids (missing samples) with
  tetrahedral-spline normals, and the LSN and central-difference baselines.
- :mod:`wscg.octree`: paper 10, one sparse voxel octree with pre-filtered voxels in every
  node and triangles in its leaves (early stop), ray casting with level of detail.
- :mod:`wscg.csmri`: paper 11, compressed-sensing MRI with a uniform discrete curvelet prior
  (exact tight UDCT, C-SALSA, and the FCSA, TVCMRI and WaTMRI baselines).
- :mod:`wscg.deblur`: paper 12, gyroscope-driven multi-frame blur estimation and removal
  (gyro blur kernels with rolling-shutter timing, piecewise and multi-frame hyper-Laplacian
  deconvolution, Wiener and Richardson-Lucy baselines, a dense gyro-blur simulator).
- :mod:`wscg.hdr`: paper 13, multiscopic HDR image sequence generation (epipolar PatchMatch
  with a coherence-penalised cost, bidirectional-similarity voting and Khan-weighted merging
  per view; Debevec-Malik responses; 2-D PatchMatch, ZNCC stereo and unaligned baselines; a
  layered multi-view scene with ground truth).
- :mod:`wscg.ear`: paper 14, occlusion detection and index-based ear recognition (skin
  model in rg chromaticity, disk closing and hole filling, Haar LL block features matched
  by block index under one-block shifts, rejection of heavily occluded probes, the
  whole-ear baseline, CMC curves, synthetic ears with exact occluder masks); also
  :mod:`wscg.biometrics.ear`.
- :mod:`wscg.gait`: paper 17, Kinect gait recognition (gait cycles from the ankle distance,
  joint relative angles, pair relevance, the DTW kernel with 1-NN and the paper's vote,
  Ball and Preis baselines, UCR/UEA ``.ts`` reader, a synthetic Kinect walker with ground
  truth); also :mod:`wscg.biometrics.gait`.
- :mod:`wscg.motion`: paper 16, predictive human movement synthesis (anechoic demixing with
  shared delays and its PCA baseline, step-wise learning of walk-and-reach actions, Hopf
  oscillator networks with SVR state maps, predictive step planning, online synthesis, BVH).
- :mod:`wscg.volseg`: paper 18, BoneSplit bone separation in CT (random walks on a bone-only
  graph with Jacobi-preconditioned CG and warm-started re-solves, the geodesic nearest-seed
  baseline, the local grow brush, small-island removal, a fractured-shell CT phantom with
  ground truth, multi-label Dice).
- :mod:`wscg.volren`: paper 03, hybrid ROI-based visualisation of medical volumes (TF-aware
  wavelets, Gradient Octree, client/server packages, ray casting).
- :mod:`wscg.distributed`: batch pipelines on Dask (bone separation, identification, video
  completion, MRI reconstruction over many files, on worker processes and machines); needs
  the optional dependencies ``pip install 'wscg[dask]'``.

Threads: every module runs its Rust work in one thread pool per process, sized by
:func:`set_num_threads` (default: the environment variable ``WSCG_NUM_THREADS`` read at
import, else ``RAYON_NUM_THREADS``, else one thread per CPU core) and read back by
:func:`get_num_threads`. A process created by ``fork`` (``multiprocessing``,
``ProcessPoolExecutor``, joblib) starts its own pool on its first wscg call.

Logging: the Rust code reports through Python's :mod:`logging`, on the logger ``wscg`` and its
children named after the Rust module (``wscg.volseg.walker``, ``wscg.math.sparse``,
``wscg.math.io.nifti``, ...): solver convergence and stage summaries at ``INFO`` and
``DEBUG``, problems at ``WARNING`` (random-walker labels stopped at the iteration cap, a
NIfTI orientation that is not applied). Nothing is shown until the application configures
logging (the ``wscg`` logger has only a ``NullHandler``): ``logging.basicConfig(level=
logging.INFO)``, or a handler on ``logging.getLogger("wscg")``, shows them. Records written
on worker threads reach ``logging`` from the calling thread while it waits, in order.

Conventions (``py/API.md``): one name per concept across the modules, ``load_`` / ``save_``
with the path first, ``make_`` for generated data; a volume ``[z, y, x]`` has its ``spacing``
``(dz, dy, dx)`` and ``origin`` ``(oz, oy, ox)`` in array axis order, and its voxel ``[k, j,
i]`` lies at the world point ``(x, y, z) = (ox + i dx, oy + j dy, oz + k dz)`` in every
module.

Errors are raised as ``ValueError`` (bad arguments) or ``OSError`` (files). A negative or
too large integer for a count, size or seed raises :class:`IntegerRangeError`, a
``ValueError`` (and ``OverflowError``) that names the argument; an argument of the wrong kind
(``None`` where a value is required, a string or array where a number is, a complex array
where real values are) raises :class:`ArgumentTypeError`, a ``ValueError`` (and
``TypeError``) that names it; ``NaN`` where a number is raises ``ValueError``.

Estimators (the models of :mod:`wscg.biometrics`, :class:`wscg.gait.GaitRecognizer`,
:class:`wscg.ear.EarMatcher` and :class:`wscg.ear.SkinModel`, the models of
:mod:`wscg.motion`) follow scikit-learn's protocol without depending on it: hyper-parameters
in ``__init__`` (``get_params`` / ``set_params``, ``sklearn.base.clone``), ``fit(X, y=None)``
returns the estimator, what it learns ends in ``_``; they pickle and deep-copy, fitted or
not. A method called before ``fit`` raises :class:`NotFittedError` (a ``ValueError`` and an
``AttributeError``; also scikit-learn's ``NotFittedError`` when scikit-learn is imported).

Limits: a size argument that would need a buffer larger than the memory limit (default: the
machine's physical memory; :func:`set_memory_limit` or the environment variable
``WSCG_MAX_MEMORY``, in bytes) raises ``MemoryError`` naming the argument, before anything is
allocated. An image file declaring more than :func:`get_max_image_pixels` pixels (default
16384 x 16384; :func:`set_max_image_pixels` or ``WSCG_MAX_IMAGE_PIXELS``) is refused with a
``ValueError`` before it is decoded, and only regular files are read (a device such as
``/dev/zero`` raises ``OSError``). Ctrl-C stops a long call (rendering, iterative solvers,
video completion, simulation steps) with ``KeyboardInterrupt`` within a fraction of a second;
it stops every wscg call running in the process at that moment.
"""

from __future__ import annotations

import logging as _logging

import numpy as _np

from . import _native
from ._checks import ArgumentTypeError, IntegerRangeError, _int
from ._estimator import DataConversionWarning, NotFittedError
from . import biometrics, cloth, csmri, deblur, doe, ear, gait, hdr, isosurface, math, meshfilter, motion, octree, raytrace, video, volren, volseg
# Dask itself is imported by the pipelines when they run, never here.
from . import distributed

__version__: str = _native.__version__

# A library's logger stays silent until the application configures logging.
_logging.getLogger("wscg").addHandler(_logging.NullHandler())

#: Most threads :func:`set_num_threads` accepts.
MAX_THREADS = 1024


def set_num_threads(n: int | None) -> None:
    """Sets the number of threads of the pool that runs the Rust work of every wscg module
    in this process.

    Parameters
    ----------
    n : int or None
        Threads, 1..1024; 0 or None restores the default (``WSCG_NUM_THREADS`` as read at
        import, else ``RAYON_NUM_THREADS``, else one per CPU core). With N worker
        processes on N cores, ``set_num_threads(1)`` in each keeps the machine at N
        threads. Results do not depend on the number of threads.

    Raises
    ------
    ValueError
        ``n`` is not an integer in 0..1024.
    """
    if isinstance(n, (bool, _np.bool_)):
        raise ValueError(f"`n` must be an integer thread count, got {n!r}")
    _native.set_num_threads(None if n is None else _int("n", n, 0, MAX_THREADS))


def get_num_threads() -> int:
    """The number of threads of the pool that runs the Rust work of every wscg module in
    this process (see :func:`set_num_threads`)."""
    return _native.get_num_threads()


def set_memory_limit(nbytes: int | None) -> None:
    """Sets the largest single buffer, in bytes, that a size argument may make wscg
    allocate, for the whole process; 0 or None restores the default (``WSCG_MAX_MEMORY`` as
    read on first use, else the machine's physical memory). A request above it raises
    ``MemoryError`` naming the argument before anything is allocated. Raise it on a machine
    with swap or a generous overcommit policy; lower it to keep a service within a budget.

    Raises
    ------
    ValueError
        ``nbytes`` is not a non-negative integer.
    """
    if isinstance(nbytes, (bool, _np.bool_)):
        raise ValueError(f"`nbytes` must be an integer byte count, got {nbytes!r}")
    _native.set_memory_limit(None if nbytes is None else _int("nbytes", nbytes, 0, 2**64 - 1))


def get_memory_limit() -> int:
    """The largest single buffer, in bytes, that a size argument may make wscg allocate (see
    :func:`set_memory_limit`)."""
    return _native.get_memory_limit()


def set_max_image_pixels(pixels: int | None) -> None:
    """Sets the largest ``width x height`` an image file may declare to be decoded, for the
    whole process; 0 or None restores the default (``WSCG_MAX_IMAGE_PIXELS`` as read on first
    use, else 16384 x 16384). A larger file raises ``ValueError`` naming it, from its header,
    before any pixel is decoded (a small PNG can declare gigabytes of pixels).

    Raises
    ------
    ValueError
        ``pixels`` is not a non-negative integer.
    """
    if isinstance(pixels, (bool, _np.bool_)):
        raise ValueError(f"`pixels` must be an integer pixel count, got {pixels!r}")
    _native.set_max_image_pixels(None if pixels is None else _int("pixels", pixels, 0, 2**64 - 1))


def get_max_image_pixels() -> int:
    """The largest ``width x height`` an image file may declare to be decoded (see
    :func:`set_max_image_pixels`)."""
    return _native.get_max_image_pixels()


__all__ = ["biometrics", "cloth", "csmri", "deblur", "doe", "ear", "gait", "hdr", "isosurface",
           "math", "meshfilter", "motion", "octree", "raytrace", "video", "volren", "volseg",
           "distributed",
           "IntegerRangeError", "ArgumentTypeError", "NotFittedError", "DataConversionWarning",
           "set_num_threads", "get_num_threads", "set_memory_limit",
           "get_memory_limit", "set_max_image_pixels", "get_max_image_pixels", "__version__"]
