"""Hybrid ROI-based visualisation of medical volumes: paper 03 of WSCG vol. 23 (Campoalegre,
Navazo and Brunet, "Hybrid ROI-Based Visualization of Medical Models").

A :class:`HybridServer` turns an 8-bit volume and its transfer functions into

- a *static* package, sent once: the transfer functions, a low-resolution volume from
  transfer-function-aware block Haar wavelets (1/64 of the voxels with ``steps_sent=2``) and
  the structure of a Gradient Octree of the material-boundary voxels at one bit per node;
- a *dynamic* package per region of interest: the 3-byte data (material and normal) of the
  octree leaves inside the ROI, in an order both ends derive, so no index travels.

A :class:`HybridClient` rebuilds the octree structure losslessly, checks every package
(magic, version, length, CRC-32, volume id, leaf count) and ray-casts the low-resolution
volume outside the ROI and the octree inside it.

Volumes are ``uint8`` arrays indexed ``[z, y, x]``; voxel coordinates ``(x, y, z)`` place
voxel ``(i, j, k)`` in ``[i, i + 1) x [j, j + 1) x [k, k + 1)``. ROIs are
``(x0, x1, y0, y1, z0, z1)`` half-open boxes, snapped outward to multiples of 16. Transfer
functions are ``(n, 5)`` arrays of ``(density, r, g, b, opacity)`` rows with increasing
densities in ``[0, 255]``. Images are ``(height, width, 4)`` float32 RGBA arrays. Bad input
raises ``ValueError``.
"""

from __future__ import annotations

from typing import List, Optional, Sequence, Tuple

import numpy as np

from ._native import volren as _v

__all__ = ["HybridServer", "HybridClient", "render_reference", "phantom", "phantom_tfs",
           "octree_address", "orbit_camera", "haar_blocks"]

Roi = Tuple[int, int, int, int, int, int]


def _volume(v) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(v, dtype=np.uint8))


def _tf(t) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(t, dtype=np.float64))


def _roi(r) -> Roi:
    r = tuple(int(c) for c in r)
    if len(r) != 6 or min(r) < 0:
        raise ValueError(f"a ROI is (x0, x1, y0, y1, z0, z1) with non-negative ints, got {r}")
    return r  # type: ignore[return-value]


def _view(eye, target, up, fov_deg, size) -> tuple:
    """The native camera tuple: eye, target, up, fov (degrees), width, height."""
    v3 = lambda a: [float(c) for c in a]  # noqa: E731
    return (v3(eye), v3(target), v3(up), float(fov_deg), int(size[1]), int(size[0]))


def orbit_camera(shape: Sequence[int], azimuth: float = 30.0, elevation: float = 20.0,
                 fov_deg: float = 30.0) -> dict:
    """A camera (keyword arguments of the render functions) looking at the centre of a volume
    of ``shape`` ``(z, y, x)`` from ``azimuth``/``elevation`` degrees, ``z`` up, far enough
    for the volume to fill about 80 % of the view."""
    nz, ny, nx = (float(s) for s in shape)
    c = np.array([nx, ny, nz]) / 2
    radius = 0.5 * np.sqrt(nx * nx + ny * ny + nz * nz)
    dist = radius / (np.tan(np.radians(fov_deg / 2)) * 0.8)
    a, e = np.radians(azimuth), np.radians(elevation)
    d = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    return {"eye": tuple(c + dist * d), "target": tuple(c), "up": (0.0, 0.0, 1.0),
            "fov_deg": fov_deg}


class HybridServer:
    """The server of the hybrid scheme.

    Parameters
    ----------
    volume : uint8 array ``[z, y, x]``
    tfs : sequence of ``(n, 5)`` arrays
        The transfer functions the clients may choose (at most 63 materials in all).
    canonical : int, default 0
        The transfer function of the low-resolution context.
    steps_sent : int in 1..4, default 2
        Wavelet steps in the static package (2: a 1/64 volume).
    delta : float, default 2
        Quantisation step of the wavelet details.
    """

    def __init__(self, volume, tfs: Sequence, canonical: int = 0, steps_sent: int = 2,
                 delta: float = 2.0):
        self._s = _v.HybridServer(_volume(volume), [_tf(t) for t in tfs], int(canonical),
                                  int(steps_sent), float(delta))

    def static_package(self) -> bytes:
        """The static package (sent once)."""
        return self._s.static_package()

    def roi_package(self, roi: Roi) -> bytes:
        """The dynamic package of ``roi`` ``(x0, x1, y0, y1, z0, z1)``."""
        return self._s.roi_package(_roi(roi))

    @property
    def leaf_count(self) -> int:
        """Voxels stored in the Gradient Octree (material-boundary voxels)."""
        return self._s.leaf_count

    @property
    def node_counts(self) -> List[int]:
        """Grey nodes per octree level 32, 64, ..., R."""
        return self._s.node_counts

    def size_report(self, roi: Roi, roi_tf: int = 1, thin_client_view: Optional[dict] = None,
                    viewport: Tuple[int, int] = (1080, 1920)) -> dict:
        """Bytes of every scheme of the paper's Tables 1 and 2, measured on serialized
        buffers: ``raw``, ``wavelets`` (all steps), ``gradient_octree`` (structure and every
        leaf), ``hybrid_static``, ``hybrid_roi``, ``hybrid``, and with ``thin_client_view``
        (a camera dict, e.g. from :func:`orbit_camera`) ``thin_client_frame``, the JPEG size
        of one full-resolution frame at ``viewport`` ``(height, width)``."""
        view = None
        if thin_client_view is not None:
            c = thin_client_view
            view = _view(c["eye"], c["target"], c.get("up", (0.0, 0.0, 1.0)),
                         c.get("fov_deg", 30.0), viewport)
        return self._s.size_report(_roi(roi), int(roi_tf), view)


class HybridClient:
    """A client built from a static package (``bytes``)."""

    def __init__(self, static_package: bytes):
        self._c = _v.HybridClient(bytes(static_package))

    def set_roi(self, roi_package: bytes) -> None:
        """Receives the dynamic package of a ROI (checked against the static package)."""
        self._c.set_roi(bytes(roi_package))

    def clear_roi(self) -> None:
        """Drops the ROI: renders the low-resolution context only."""
        self._c.clear_roi()

    @property
    def roi(self) -> Optional[Roi]:
        """The current ROI box, snapped, or None."""
        return self._c.roi

    @property
    def lowres(self) -> np.ndarray:
        """The decoded low-resolution volume ``[z, y, x]`` (float32, padded to whole blocks)."""
        return self._c.lowres

    @property
    def shape(self) -> Tuple[int, int, int]:
        """The full-resolution volume shape ``(z, y, x)``."""
        return self._c.shape

    def render(self, eye, target, up=(0.0, 0.0, 1.0), fov_deg: float = 30.0,
               size: Tuple[int, int] = (512, 512), roi_tf: int = 1,
               mode: str = "hybrid") -> np.ndarray:
        """Ray-casts a ``size`` ``(height, width)`` RGBA image. ``mode="hybrid"``: the
        low-resolution volume under the canonical transfer function outside the ROI and the
        octree under ``roi_tf`` inside; ``"context"``: the low-resolution volume only (the
        wavelet baseline); ``"octree"``: the ROI's octree only (the Gradient Octree
        baseline when the ROI covers the volume)."""
        return self._c.render(mode, _view(eye, target, up, fov_deg, size), int(roi_tf))


def render_reference(volume, tf, eye, target, up=(0.0, 0.0, 1.0), fov_deg: float = 30.0,
                     size: Tuple[int, int] = (512, 512), roi: Optional[Roi] = None,
                     roi_tf=None) -> np.ndarray:
    """Full-resolution ray casting of ``volume`` (trilinear densities, central-difference
    gradients, Phong shading) under ``tf``; with ``roi`` and ``roi_tf``, the full-resolution
    counterpart of the hybrid image (``tf`` unlit outside the box, ``roi_tf`` shaded
    inside)."""
    return _v.render_reference(_volume(volume), _tf(tf), _view(eye, target, up, fov_deg, size),
                               None if roi is None else _roi(roi),
                               None if roi_tf is None else _tf(roi_tf))


def phantom(name: str = "head", shape: Optional[Tuple[int, int, int]] = None,
            seed: int = 0) -> np.ndarray:
    """An analytic CT-like phantom ``[z, y, x]`` (uint8): ``"head"`` (3-D modified
    Shepp-Logan; the paper's skull is ``(112, 256, 256)``, the default) or ``"thorax"``
    (body, lungs with vessels, heart, spine, ribs; default ``(256, 256, 256)``, the paper's
    is 512^3)."""
    if name == "head":
        return _v.phantom_head(tuple(int(s) for s in (shape or (112, 256, 256))), int(seed))
    if name == "thorax":
        return _v.phantom_thorax(tuple(int(s) for s in (shape or (256, 256, 256))), int(seed))
    raise ValueError(f"unknown phantom {name!r}; use 'head' or 'thorax'")


def phantom_tfs(name: str = "head") -> List[np.ndarray]:
    """The transfer functions of a phantom: head (soft tissue, canonical; bone), thorax (all
    structures, canonical; bone; lungs; skin)."""
    return _v.phantom_tfs(name)


def octree_address(ijk: Sequence[int], r: int) -> Tuple[Tuple[int, int, int], List[int]]:
    """The paper's eq. 1: the level-32 cell of voxel ``(x, y, z)`` in a cube of side ``r``
    and the child slot taken at each level 32, 64, ..., r/2."""
    cell, slots = _v.octree_address([int(c) for c in ijk], int(r))
    return tuple(cell), list(slots)


def haar_blocks(blocks) -> np.ndarray:
    """The server's 4-step 3-D Haar transform (averaging normalisation) of ``(n, 16, 16, 16)``
    blocks indexed ``[block, z, y, x]``: an ``(n, 4096)`` float32 array per block holding the
    root (the block mean), then the details of steps 4, 3, 2, 1 (coarse to fine), each step's
    parents in raster order (x fastest) with 7 details ``k = 4u + 2v + w`` (u, v, w the x,
    y, z difference bits)."""
    return _v.haar_blocks(np.ascontiguousarray(np.asarray(blocks, dtype=np.float32)))
