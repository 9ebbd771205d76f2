"""Medical volume rendering: papers 03 and 15 of WSCG vol. 23.

**Paper 03** (Campoalegre, Navazo and Brunet, "Hybrid ROI-Based Visualization of Medical
Models"). A :class:`HybridServer` turns an 8-bit volume and its transfer functions into

- a *static* package, sent once: the transfer functions, a low-resolution volume from
  transfer-function-aware block Haar wavelets (1/64 of the voxels with ``steps_sent=2``) and
  the structure of a Gradient Octree of the material-boundary voxels at one bit per node;
- a *dynamic* package per region of interest: the 3-byte data (material and normal) of the
  octree leaves inside the ROI, in an order both ends derive, so no index travels.

A :class:`HybridClient` rebuilds the octree structure losslessly, checks every package
(magic, version, length, CRC-32, volume id, leaf count) and ray-casts the low-resolution
volume outside the ROI and the octree inside it.

Paper-03 conventions: volumes are ``uint8`` arrays indexed ``[z, y, x]`` with unit spacing;
world points (camera ``eye`` and ``target``) are ``(x, y, z)`` with the centre of voxel ``[k,
j, i]`` at ``(i, j, k)`` (``py/API.md``). ROIs are half-open boxes of voxel indices in array
axis order, ``(z0, z1, y0, y1, x0, x1)``, snapped outward to multiples of 16; a voxel is
given by its index ``(k, j, i)``. Transfer functions are ``(n, 5)`` arrays of ``(density, r,
g, b, opacity)`` rows with increasing densities in ``[0, 255]``. Images are ``(height, width,
4)`` float32 RGBA arrays and ``size`` is ``(height, width)``. Bad input raises
``ValueError``.

**Paper 15** (Angelelli and Bruckner, "Performance and Quality Analysis of Convolution-Based
Volume Illumination"). :func:`render` draws a volume slice by slice with *instant
convolution shadows* (ICS): a 2-D light buffer is attenuated by each view-aligned slice and
blurred by a kernel before it reaches the next one, so shadows cost one convolution per
slice and no 3-D illumination volume. The paper decouples the light sampling (the slice
distance) from the tissue sampling: ``"scs"`` takes ``n_subsamples`` extra tissue samples
between slices lit by interpolated light, ``"pi-ics"`` pre-integrates each slab
(:func:`preintegration_table`) and ``"pi-scs"`` does both. Baselines: emission-absorption
(``"raycast"``) and Blinn-Phong (``"phong"``) ray casting and ray casting with shadow rays
(``"shadow-rays"``, what ICS with the delta kernel equals). :func:`study` runs the paper's
quality/speed sweep (:func:`mean_abs_diff` is its Table 1 error); :func:`light_buffer`
exposes the light arriving at a depth. :class:`PreparedVolume` normalises a volume once for
many renders. Test data: :func:`make_marschner_lobb`, the tissue labels
of a ``.vti`` file (:func:`load_vti`, e.g. the frog shipped with pyvista) turned into a
CT-like field by :func:`labels_to_density`, and their transfer functions.

The volume's box bounds the light's propagation: the light buffer starts unattenuated at
the box's front face and everything outside the box is empty, so light passes round an
occluder that does not reach the box's sides and, with a blurring kernel, leaks in under
its edges (a slab that stops short of the sides casts a shadow lit at its rim). Pad the
volume with opaque (or occluding) voxels where the surroundings should block the light.

Paper-15 conventions (``py/API.md``): volumes are ``uint8``, ``uint16`` or ``float32`` arrays
indexed ``[z, y, x]`` with a physical ``spacing`` ``(dz, dy, dx)`` in array axis order (as
in :mod:`wscg.math`, :mod:`wscg.volseg` and :mod:`wscg.isosurface`). World points
(``center``) are ``(x, y, z)`` with voxel ``[k, j, i]`` at ``(i dx, j dy, k dz)`` (the volume
box is ``[-d/2, (n - 1/2) d]`` per axis); world directions (``view_dir``, ``up``) are ``(x, y,
z)`` too. Every length (``slice_distance``, ``pixel_size``, ``spread``, ``depth``) is in the
units of the spacing (millimetres for medical volumes; voxels for the default spacing ``(1,
1, 1)``). Transfer functions are ``(N, 4)`` float arrays of RGBA rows evenly spaced over the
normalised value range ``[0, 1]``, the opacity referring to one unit of length of the
spacing. Images are ``(height, width, 4)`` float32 RGBA arrays, colour composited over the
background and alpha the accumulated opacity; ``size`` is ``(height, width)``. Bad input
raises ``ValueError``; a file that cannot be read raises ``OSError``.
"""

from __future__ import annotations

from typing import List, Optional, Sequence, Tuple

import numpy as np

from ._native import volren as _v
from ._native.volren import (haar_blocks, labels_to_density, load_vti, make_marschner_lobb,
                             make_phantom, marschner_lobb_tf, mean_abs_diff, octree_address,
                             phantom_tfs, preintegration_table, render_reference, skin_tf,
                             tissue_tf)
from ._checks import integer_ranges as _integer_ranges
from ._results import from_mapping as _from_mapping, result as _result

__all__ = ["HybridServer", "HybridClient", "render_reference", "make_phantom", "phantom_tfs",
           "octree_address", "orbit_camera", "haar_blocks", "SizeReport",
           # paper 15
           "render", "PreparedVolume", "light_buffer", "preintegration_table",
           "make_marschner_lobb", "marschner_lobb_tf", "tissue_tf", "skin_tf",
           "labels_to_density", "load_vti", "mean_abs_diff", "study", "METHODS", "KERNELS",
           "IlluminationStudy", "StudyEntry"]

Roi = Tuple[int, int, int, int, int, int]


@_result
class SizeReport:
    """Bytes sent by every scheme of the paper's Tables 1 and 2, measured on serialized
    buffers (:meth:`HybridServer.size_report`).

    Attributes
    ----------
    raw : int
        The volume itself, one byte per voxel.
    wavelets : int
        The TF-aware block wavelets, all steps.
    gradient_octree : int
        The Gradient Octree: structure and every leaf.
    hybrid_static : int
        The hybrid scheme's static package (low-resolution context and octree structure).
    hybrid_roi : int
        The hybrid scheme's dynamic package of the ROI.
    hybrid : int
        ``hybrid_static + hybrid_roi``.
    thin_client_frame : int or None
        One JPEG frame (quality 85) of a thin client at the viewport; None without
        ``thin_client_view``.
    """

    raw: int
    wavelets: int
    gradient_octree: int
    hybrid_static: int
    hybrid_roi: int
    hybrid: int
    thin_client_frame: Optional[int]


def orbit_camera(shape: Sequence[int], azimuth: float = 30.0, elevation: float = 20.0,
                 fov_deg: float = 30.0) -> dict:
    """A camera (keyword arguments of the paper-03 render functions) looking at the centre
    ``((nx - 1) / 2, (ny - 1) / 2, (nz - 1) / 2)`` of a volume of ``shape`` ``(nz, ny, nx)``
    from ``azimuth`` degrees about the ``z`` axis and ``elevation`` degrees above the ``xy``
    plane, ``z`` up, far enough for the volume to fill about 80 % of the view. ``eye`` and
    ``target`` are world points ``(x, y, z)``, voxel ``[k, j, i]`` at ``(i, j, k)``."""
    nz, ny, nx = (float(s) for s in shape)
    c = (np.array([nx, ny, nz]) - 1) / 2
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
        self._s = _v.HybridServer(volume, list(tfs), canonical, steps_sent, delta)

    def static_package(self) -> bytes:
        """The static package (sent once)."""
        return self._s.static_package()

    def roi_package(self, roi: Roi) -> bytes:
        """The dynamic package of ``roi`` ``(z0, z1, y0, y1, x0, x1)`` (half-open voxel index
        ranges in array axis order)."""
        return self._s.roi_package(roi)

    @property
    def leaf_count(self) -> int:
        """Voxels stored in the Gradient Octree (material-boundary voxels)."""
        return self._s.leaf_count

    @property
    def node_counts(self) -> List[int]:
        """Grey nodes per octree level 32, 64, ..., R."""
        return self._s.node_counts

    def size_report(self, roi: Roi, roi_tf: int = 1, thin_client_view: Optional[dict] = None,
                    viewport: Tuple[int, int] = (1080, 1920)) -> SizeReport:
        """Bytes of every scheme of the paper's Tables 1 and 2, measured on serialized
        buffers, as a :class:`SizeReport`: ``raw``, ``wavelets`` (all steps),
        ``gradient_octree`` (structure and every leaf), ``hybrid_static``, ``hybrid_roi``,
        ``hybrid``, and with ``thin_client_view`` (a camera dict, e.g. from
        :func:`orbit_camera`) ``thin_client_frame``, the JPEG size of one full-resolution
        frame at ``viewport`` ``(height, width)``."""
        return _from_mapping(SizeReport, self._s.size_report(roi, roi_tf, thin_client_view,
                                                             viewport))


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
        """The current ROI box ``(z0, z1, y0, y1, x0, x1)``, snapped, or None."""
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
        """Ray-casts a ``size`` ``(height, width)`` RGBA image from ``eye`` towards ``target``
        (world points ``(x, y, z)``, voxel ``[k, j, i]`` at ``(i, j, k)``; ``up`` a direction,
        ``fov_deg`` the vertical field of view). ``mode="hybrid"``: the
        low-resolution volume under the canonical transfer function outside the ROI and the
        octree under ``roi_tf`` inside; ``"context"``: the low-resolution volume only (the
        wavelet baseline); ``"octree"``: the ROI's octree only (the Gradient Octree
        baseline when the ROI covers the volume)."""
        return self._c.render(mode, eye, target, up, fov_deg, size, roi_tf)


# ---------------------------------------------------------------------------------------------
# Paper 15: convolution-based volume illumination.

#: The rendering methods of :func:`render`.
METHODS = ("ics", "scs", "pi-ics", "pi-scs", "raycast", "phong", "shadow-rays")
#: The light-propagation kernels of :func:`render`.
KERNELS = ("gaussian", "delta", "disk")

_DISTANCES = (0.2, 0.4, 0.6, 0.8, 1.0, 1.2, 1.4, 1.6, 1.8, 2.0)
Vec3 = Tuple[float, float, float]


def _illum_source(volume):
    """The native volume of a render: a :class:`PreparedVolume`'s field, or the array (the
    native call checks the dtype, the shape and the ``spacing`` / ``value_range`` rules)."""
    return volume._native if isinstance(volume, PreparedVolume) else volume


class PreparedVolume:
    """A volume normalised once for many renders (paper 15).

    :func:`render`, :func:`light_buffer` and :func:`study` take it in place of the array.
    It keeps the normalised field, its empty-space cells and the value-and-gradient bricks
    of the Phong ray caster, so a sequence of views pays for them once, as a viewer does.

    Parameters
    ----------
    volume : uint8, uint16 or float32 array ``[z, y, x]``
        As in :func:`render` (copied; not modified).
    spacing : (dz, dy, dx), default (1, 1, 1)
        Physical voxel spacing, in array axis order.
    value_range : (lo, hi), optional
        As in :func:`render`.

    Attributes: ``shape`` ``(nz, ny, nx)`` and ``spacing`` ``(dz, dy, dx)``. Raises
    ``ValueError`` for bad input.
    """

    def __init__(self, volume, spacing: Sequence[float] = (1.0, 1.0, 1.0),
                 value_range: Optional[Tuple[float, float]] = None) -> None:
        self._native = _v.IllumVolume(volume, spacing, value_range)

    @property
    def shape(self) -> Tuple[int, int, int]:
        return tuple(self._native.shape)  # type: ignore[return-value]

    @property
    def spacing(self) -> Vec3:
        return tuple(self._native.spacing)  # type: ignore[return-value]

    def __repr__(self) -> str:
        return f"PreparedVolume(shape={self.shape}, spacing={self.spacing})"


def _render_opts(view_dir, up, size, pixel_size, center, method, slice_distance, n_subsamples,
                 kernel, spread, tan_half, light_dir, ambient, background, interp,
                 light_attenuation, border) -> dict:
    """The options of a render by name, read and checked by the native call."""
    return dict(view_dir=view_dir, up=up, size=size, pixel_size=pixel_size, center=center,
                method=method, slice_distance=slice_distance, n_subsamples=n_subsamples,
                kernel=kernel, spread=spread, tan_half=tan_half, light_dir=light_dir,
                ambient=ambient, background=background, interp=interp,
                light_attenuation=light_attenuation, border=border)


def render(volume, tf, spacing: Optional[Sequence[float]] = None,
           view_dir: Sequence[float] = (0.0, 0.0, 1.0), up: Sequence[float] = (0.0, 1.0, 0.0),
           size: Tuple[int, int] = (512, 512), pixel_size: Optional[float] = None,
           center: Optional[Sequence[float]] = None, method: str = "scs",
           slice_distance: float = 1.0, n_subsamples: int = 0, kernel: str = "gaussian",
           spread: float = 0.5, tan_half: float = 0.5,
           light_dir: Sequence[float] = (0.0, 0.0, 1.0), ambient: float = 0.0,
           background: Sequence[float] = (0.0, 0.0, 0.0), interp: str = "trilinear",
           value_range: Optional[Tuple[float, float]] = None,
           light_attenuation: str = "segment", border: str = "open") -> np.ndarray:
    """Renders a volume with convolution shadows or a ray-casting baseline (paper 15).

    Parameters
    ----------
    volume : uint8, uint16 or float32 array ``[z, y, x]``, or a :class:`PreparedVolume`
        The scalar volume, normalised to ``[0, 1]``: uint8 as ``v / 255``, uint16 as
        ``v / 65535``, float32 from ``value_range`` or, when None, from the data's min/max
        (a constant float volume keeps its value clamped to ``[0, 1]``). Given a
        ``value_range``, integer volumes are mapped by it too (e.g. 12-bit CT in uint16).
        Not modified.
    tf : ``(N, 4)`` float array, ``N >= 2``
        Transfer function: RGBA rows in ``[0, 1]`` evenly spaced over the normalised values;
        the opacity refers to one unit of length of the spacing (the extinction ``-ln(1 -
        a)`` is interpolated linearly between rows and every sampling distance is
        opacity-corrected).
        Outside its box the volume has the value 0, classified by the first row throughout
        the volume's depth range: give that row zero opacity for empty surroundings.
    spacing : (dz, dy, dx), default None (``(1, 1, 1)``)
        Physical voxel spacing in array axis order: voxel ``[k, j, i]`` is at the world point
        ``(i dx, j dy, k dz)``, and lengths are in the spacing's units. Leave None (and
        ``value_range`` None) with a :class:`PreparedVolume`, which has its own.
    view_dir, up : 3 floats
        Orthographic viewing direction and up vector in world ``(x, y, z)`` (the image's
        right is ``view_dir x up``, its down ``view_dir x right``).
    size : (height, width), default (512, 512)
        Image size in pixels; the result has shape ``(height, width, 4)``.
    pixel_size, center : optional
        With ``pixel_size=None`` the camera looks at the volume's centre and fits its whole
        projection (2 % border); otherwise pixels are ``pixel_size`` units of length wide and
        the image centre is the world point ``center`` ``(x, y, z)`` (default: the volume's
        centre, ``((nx - 1) dx / 2, (ny - 1) dy / 2, (nz - 1) dz / 2)``).
    method : str, default "scs"
        ``"ics"`` (instant convolution shadows), ``"scs"`` (with ``n_subsamples`` tissue
        samples between slices, lit by linearly interpolated light), ``"pi-ics"`` and
        ``"pi-scs"`` (pre-integrated slabs, resp. sub-slabs), or the ray casters
        ``"raycast"`` (emission-absorption), ``"phong"`` (Blinn-Phong, ``k_a, k_d, k_s, n =
        0.3, 0.6, 0.3, 20``) and ``"shadow-rays"`` (a Beer-Lambert shadow ray per sample).
    slice_distance : float, default 1
        Slice distance (units of the spacing) of the slice methods, sample step of the ray
        casters.
    n_subsamples : int in 0..=64, default 0
        Tissue sub-samples per slice (``"scs"``, ``"pi-scs"``): tissue step
        ``slice_distance / (n_subsamples + 1)``. Not allowed with ``"ics"``/``"pi-ics"`` (use
        ``"scs"``/``"pi-scs"``) or the ray casters.
    kernel : str, default "gaussian"
        Light kernel per slice: ``"gaussian"`` (variance ``2 spread slice_distance``, so the
        total blur after a depth ``z`` is ``2 spread z`` whatever the slice distance),
        ``"delta"`` (hard shadows) or ``"disk"`` (radius ``slice_distance * tan_half``, the
        cone of directional occlusion shading).
    spread, tan_half : float >= 0
        Parameters of the Gaussian (a length) and disk (a slope) kernels.
    light_dir : 3 floats, default (0, 0, 1)
        Direction towards the light in view coordinates (``x`` right, ``y`` up, ``z``
        towards the viewer); ``z > 0`` is required (slices carry light front to back).
    ambient : float in [0, 1], default 0
        Ambient term ``k_a``: shading ``k_a + (1 - k_a) L``.
    background : 3 floats in [0, 1]
        Colour composited behind the volume.
    interp : "trilinear" or "nearest"
        Reconstruction filter.
    light_attenuation : "segment" or "slice-only"
        With sub-samples, whether the light is attenuated by every tissue sample of a
        segment (default) or by the slice sample only.
    border : "open" or "closed", default "open"
        What the light propagated through the slices meets outside the volume's box.
        ``"open"``: empty space, so light passes round an occluder that stops short of the
        box's sides and a blurring kernel carries light from outside in under its edges.
        ``"closed"``: opaque beyond every face of the box not turned towards the light (the
        sides for a light along an axis, and the back), so the light enters only through
        the faces turned towards it. The delta kernel and the ray casters give the same
        image for both.

    Returns
    -------
    ``(height, width, 4)`` float32 RGBA, colour composited over the background, alpha the
    accumulated opacity.

    Raises ``ValueError`` for bad input, including a ``slice_distance`` giving more than
    2^20 slices (or samples per ray) through the volume's box and kernels wider than 65536
    (Gaussian, ``3 sigma``) or 1024 (disk radius) pixels per slice. The GIL is released
    while rendering.
    """
    opts = _render_opts(view_dir, up, size, pixel_size, center, method, slice_distance,
                        n_subsamples, kernel, spread, tan_half, light_dir, ambient, background,
                        interp, light_attenuation, border)
    return _v.illum_render(_illum_source(volume), tf, spacing, value_range, opts)


def light_buffer(volume, tf, depth: float, spacing: Optional[Sequence[float]] = None,
                 view_dir: Sequence[float] = (0.0, 0.0, 1.0),
                 up: Sequence[float] = (0.0, 1.0, 0.0), size: Tuple[int, int] = (512, 512),
                 pixel_size: Optional[float] = None, center: Optional[Sequence[float]] = None,
                 method: str = "scs", slice_distance: float = 1.0, n_subsamples: int = 0,
                 kernel: str = "gaussian", spread: float = 0.5, tan_half: float = 0.5,
                 light_dir: Sequence[float] = (0.0, 0.0, 1.0), ambient: float = 0.0,
                 background: Sequence[float] = (0.0, 0.0, 0.0), interp: str = "trilinear",
                 value_range: Optional[Tuple[float, float]] = None,
                 light_attenuation: str = "segment",
                 border: str = "open") -> Tuple[np.ndarray, float]:
    """The light buffer arriving at the slice nearest to ``depth`` (a test and debugging
    hook of the slice methods).

    ``depth`` is a length (units of the spacing) behind the front of the volume's depth range
    along the view direction; the other arguments are those of :func:`render` (``method``
    must be a slice method). Returns an ``(height, width)`` float32 array in ``[0, 1]``, 1
    where nothing is in the way, and the exact depth of the slice it belongs to (``(k + 1/2)
    slice_distance``).
    """
    opts = _render_opts(view_dir, up, size, pixel_size, center, method, slice_distance,
                        n_subsamples, kernel, spread, tan_half, light_dir, ambient, background,
                        interp, light_attenuation, border)
    return _v.illum_light_buffer(_illum_source(volume), tf, depth, spacing, value_range, opts)


@_result
class StudyEntry:
    """One configuration of :func:`study`, scored against the reference and averaged over
    the views.

    Attributes
    ----------
    method : str
        ``"ics"``, ``"scs"``, ``"pi-ics"`` or ``"pi-scs"``.
    slice_distance : float
        Slice distance, in the units of the spacing.
    n_subsamples : int
        Sub-samples per slab (0 for ICS and PI-ICS).
    mad : float
        Mean absolute difference of the RGB channels to the reference (:func:`mean_abs_diff`).
    energy : float
        Mean squared Laplacian of the RGB difference to the reference (ring and wood-grain
        energy).
    seconds : float
        Wall-clock seconds per frame.
    alias_free : bool
        ``mad <= max_mad`` and ``energy <= max_energy_ratio * fine_energy``.
    """

    method: str
    slice_distance: float
    n_subsamples: int
    mad: float
    energy: float
    seconds: float
    alias_free: bool


@_result
class IlluminationStudy:
    """The quality and speed study of :func:`study` (the paper's section 5).

    Attributes
    ----------
    reference_seconds : float
        Wall-clock seconds per frame of the reference ICS.
    fine_energy : float
        Laplacian energy of the finer ICS against the reference: the aliasing scale of the
        criterion.
    entries : list of StudyEntry
        Every configuration of the grid, in grid order (per distance: ICS, SCS with
        ``1..max_subsamples``, PI-ICS, PI-SCS with ``1..max_subsamples``).
    """

    reference_seconds: float
    fine_energy: float
    entries: List[StudyEntry]


def study(volume, tf, n_views: int = 4, size: int = 256, azimuth: float = 30.0,
          elevation: float = 20.0, distances: Sequence[float] = _DISTANCES,
          max_subsamples: int = 5, reference: float = 0.2, fine: float = 0.1,
          spacing: Optional[Sequence[float]] = None, spread: float = 0.5,
          light_dir: Sequence[float] = (0.0, 0.0, 1.0), ambient: float = 0.0,
          max_mad: float = 0.005, max_energy_ratio: float = 2.0,
          value_range: Optional[Tuple[float, float]] = None) -> IlluminationStudy:
    """The paper's quality and speed study (its section 5), with a quantitative alias test
    in place of the paper's visual judgement.

    Renders ``n_views`` orbit views (azimuth ``azimuth + 360 k / n_views`` degrees about the
    volume's ``z`` axis, ``elevation`` degrees above its ``xy`` plane, ``z`` up,
    ``size x size`` pixels, the whole volume in view) with the reference ICS at slice
    distance ``reference``, a finer ICS at ``fine`` (the aliasing scale; these and
    ``distances`` are lengths in the units of the spacing) and every
    configuration of the grid: for each distance of ``distances``, ICS, SCS with
    ``1..max_subsamples`` sub-samples and PI-SCS with ``0..max_subsamples`` (``m = 0`` is
    PI-ICS). Every configuration is scored against the reference, averaged over the views:
    ``mad`` (:func:`mean_abs_diff`), ``energy`` (mean squared Laplacian of the RGB
    difference, the ring/wood-grain energy) and ``seconds`` (wall time per frame). A
    configuration is ``alias_free`` when ``mad <= max_mad`` and ``energy <=
    max_energy_ratio * fine_energy``. Light: Gaussian kernel of ``spread``, ``light_dir`` and
    ``ambient`` as in :func:`render`; ``volume``, ``tf``, ``spacing`` and ``value_range`` as
    in :func:`render`.

    Returns an :class:`IlluminationStudy`: ``reference_seconds``, ``fine_energy`` and the
    ``entries`` (:class:`StudyEntry`: ``method``, ``slice_distance``, ``n_subsamples``,
    ``mad``, ``energy``, ``seconds``, ``alias_free``) in grid order.
    """
    opts = dict(n_views=n_views, size=size, azimuth=azimuth, elevation=elevation,
                distances=distances, max_subsamples=max_subsamples, reference=reference,
                fine=fine, spread=spread, light_dir=light_dir, ambient=ambient, max_mad=max_mad,
                max_energy_ratio=max_energy_ratio)
    st = _v.illum_study(_illum_source(volume), tf, spacing, value_range, opts)
    return _from_mapping(IlluminationStudy, st,
                         entries=[_from_mapping(StudyEntry, e) for e in st["entries"]])

# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
