"""Predictive rendering of metallic-flake car paint: paper 07 of WSCG vol. 23 (da Graça, Paljic
and Diaz, "Evaluating stereoscopic visualization for predictive rendering").

The "virtual material workshop": from two microstructure parameters of a metallic paint, the
aluminium flake radius and the flake density, generate a 3-D flake microstructure (stack
model), render the painted plate spectrally (81 wavelengths, 380-780 nm) under a lamp of
known spectrum and small angular size, for the left and right eyes of an off-axis stereo rig
(6.5 cm apart, 77 cm from the plate, shown at 1:1 scale on the study's 1920 x 1080 screen) or
the cyclopean eye (the monoscopic condition), and score the result against a reference with
a virtual observer.

Plate parameters: keyword-only arguments of :func:`render_plate` (all of them),
:func:`make_tile` (the microstructure), :func:`plate_layout` (the microstructure and
``size_mm``) and :func:`workshop` (all but ``radius_um`` and ``density``, which its runs set);
every one has the paper's value or a documented default:

- microstructure: ``radius_um`` (30), ``radius_cv`` (0.15, lognormal), ``thickness_um``
  (0.5), ``density`` (6.5, mean number of flakes above a point), ``tilt`` ('halfnormal',
  'cap' or 'flat') with ``tilt_deg`` (8), ``layer_um`` (20.24), ``tile_um`` (450),
  ``model`` ('boolean' or 'deposit'), ``n_pool_tiles`` (16, tiles in the pool the plate is
  paved with), ``max_clamped_fraction`` (0.05), ``seed`` (0);
- layers: ``size_mm`` ((150, 100)), ``coat_ior`` (1.5; 1 for no coat), ``coat_um`` (40),
  ``binder_ior`` (1.5), ``binder_sigma_a_per_mm`` (0), ``base_albedo`` (0, the black
  base; a diffuse base's light reflected back down by the coat and the flakes is summed,
  so that a white base under a clear coat renders near Y = 1), ``metal`` ('al_k6': aluminium with the paper's k = 6; 'al': Rakic's aluminium) or
  ``metal_nk=(n, k)``;
- lamp: ``light_elevation_deg`` (45), ``light_deg`` (angular radius, 1), ``light_cct``
  (CIE daylight at 4700 K by default, the SOLUX lamp) or ``light_spectrum`` (81 values),
  ``radiance_scale`` (1, a factor on the lamp's radiance);
- rendering: ``spp`` (64), ``max_depth`` (8), ``render_seed`` (0), ``region_mm``
  ((x0, y0, x1, y1), plate centre at the origin, y up; default the whole plate),
  ``magnification`` (1: the rig's screen pixels), ``independent_samples`` (False),
  ``color_mode`` ('spectral' or 'rgb', the non-spectral baseline), ``keep_spectrum`` (False:
  with ``return_info``, also the radiance per band as ``info.spectrum`` (H, W, bands) and
  ``info.bands_nm``), ``n_photons`` (2 000 000 photons for the flakes' caustics on a
  diffuse base, used only when ``base_albedo > 0``; 0 leaves the caustics out),
  ``n_photon_neighbors`` (50 photons per density estimate).

Bad input raises ``ValueError``.
"""

from __future__ import annotations

import dataclasses
import json
import os
from typing import List, Optional, Sequence, Tuple, Union

import numpy as np

from ._native import raytrace as _r
from ._native.raytrace import (aluminium_nk, binocular_overlap, daylight, fresnel_conductor,
                               fresnel_dielectric, project, spectrum_to_xyz)
from ._checks import integer_ranges as _integer_ranges
from ._manylight import (ManyLightScene, ManyLightStats, load_manylight_obj,
                         make_manylight_scene, manylight_from_arrays,
                         manylight_record_weight, render_manylight)
from ._results import from_mapping as _from_mapping, result as _result

__all__ = ["load_paint", "save_paint", "PaintDescription", "render_plate", "xyz_to_srgb", "make_tile", "plate_layout", "glint_stats",
           "binocular_overlap", "workshop", "fresnel_conductor", "fresnel_dielectric", "aluminium_nk", "daylight",
           "spectrum_to_xyz", "project", "FLAKE_DTYPE", "PlateInfo", "GlintStats",
           "WorkshopScores",
           # paper 08: many-light rendering
           "ManyLightScene", "make_manylight_scene", "manylight_from_arrays",
           "load_manylight_obj", "render_manylight", "ManyLightStats",
           "manylight_record_weight"]

#: Fields of the structured array returned by :func:`make_tile`.
FLAKE_DTYPE = np.dtype([("cx", "f8"), ("cy", "f8"), ("cz", "f8"), ("nx", "f8"), ("ny", "f8"),
                        ("nz", "f8"), ("r", "f8")])

_XYZ_TO_SRGB = np.array(_r.XYZ_TO_SRGB)


@_result
class PlateInfo:
    """What a view of :func:`render_plate` (``return_info=True``) shows besides the image.

    Attributes
    ----------
    flake_id : uint64 array (H, W)
        The flake glinting directly in each pixel; ``2**64 - 1`` where none does.
    glint_ids : uint64 array (G,)
        Sorted ids of every flake glinting directly in the view.
    mm_per_px : float
        Width of a pixel on the plate, millimetres.
    lamp_y : float
        The lamp's own luminance ``Y`` (the normalised XYZ units of the image): the largest a
        pixel can have.
    region_mm : (x0, y0, x1, y1)
        The rendered region of the plate, millimetres (plate centre at the origin, y up).
    bands_nm : float64 array (B,) or None
        Wavelengths of the spectrum's bands, nanometres; None without ``keep_spectrum``.
    spectrum : float32 array (H, W, B) or None
        Radiance per band, in the units that :func:`spectrum_to_xyz` maps to the image's
        XYZ; None without ``keep_spectrum``.
    """

    flake_id: np.ndarray
    glint_ids: np.ndarray
    mm_per_px: float
    lamp_y: float
    region_mm: Tuple[float, float, float, float]
    bands_nm: Optional[np.ndarray] = None
    spectrum: Optional[np.ndarray] = None


@_result
class GlintStats:
    """Sparkle statistics of a luminance image (:func:`glint_stats`, the virtual observer's
    features).

    Attributes
    ----------
    glint_density_per_mm2 : float
        Glints per mm² of plate.
    mean_y : float
        Mean luminance (the image's units).
    median_y : float
        Median luminance.
    y99_over_median : float
        99th percentile of the luminance over its median (infinite when the median is 0).
    mean_glint_area_mm2 : float
        Mean area of a glint, mm²; 0 without glints.
    mean_glint_peak_y : float
        Mean of the glints' brightest pixels (the image's units); 0 without glints.
    n_glints : int
        Glints: 8-connected groups of pixels above ``threshold``.
    threshold : float
        The luminance threshold: 4x the median, or any positive luminance when the median
        is 0.
    """

    glint_density_per_mm2: float
    mean_y: float
    median_y: float
    y99_over_median: float
    mean_glint_area_mm2: float
    mean_glint_peak_y: float
    n_glints: int
    threshold: float


@_result
class WorkshopScores:
    """The virtual-observer scores of :func:`workshop`.

    Attributes
    ----------
    runs : list of (float, float)
        The candidates, ``(radius_um, density)``.
    scores : float64 array (R,)
        Score of each candidate: 0 (identical to the reference) ... 10 (different).
    features : float64 array (R, F)
        The observer's features of each candidate (see ``feature_names``).
    reference_features : float64 array (n_reference_renders, F)
        The features of each render of the reference.
    feature_names : list of str
        Names of the ``F`` features.
    scale_log : float64 array (F,)
        The observer's scale of each log feature: its standard deviation over the reference
        renders, but at least ``jnd_log``.
    """

    runs: List[Tuple[float, float]]
    scores: np.ndarray
    features: np.ndarray
    reference_features: np.ndarray
    feature_names: List[str]
    scale_log: np.ndarray


def _records(arr: np.ndarray) -> np.ndarray:
    rec = np.zeros(arr.shape[0], dtype=FLAKE_DTYPE)
    for k, name in enumerate(FLAKE_DTYPE.names):
        rec[name] = arr[:, k]
    return rec


def xyz_to_srgb(xyz, exposure: float = 1.0) -> np.ndarray:
    """CIE XYZ (..., 3) to display sRGB in [0, 1] (IEC 61966-2-1 matrix and transfer curve).

    ``exposure`` scales the linear values first; values outside [0, 1] are clipped.
    """
    a = np.asarray(xyz, dtype=np.float64)
    if a.shape[-1:] != (3,):
        raise ValueError(f"`xyz` must have a last axis of 3, got shape {a.shape}")
    lin = np.clip(exposure * a @ _XYZ_TO_SRGB.T, 0.0, 1.0)
    out = np.where(lin <= 0.0031308, 12.92 * lin, 1.055 * np.power(lin, 1 / 2.4) - 0.055)
    return out.astype(np.float32)


# The keyword parameters of the paint model and renderer (module documentation), which the
# native functions read and check by name.
_PAINT_KEYS = frozenset((
    "radius_um", "radius_cv", "thickness_um", "density", "tilt", "tilt_deg", "layer_um",
    "tile_um", "model", "n_pool_tiles", "max_clamped_fraction", "seed", "size_mm", "coat_ior",
    "coat_um", "binder_ior", "binder_sigma_a_per_mm", "base_albedo", "metal", "metal_nk",
    "light_elevation_deg", "light_deg", "light_cct", "light_spectrum", "radiance_scale", "spp",
    "max_depth", "render_seed", "region_mm", "magnification", "independent_samples",
    "color_mode", "keep_spectrum", "n_photons", "n_photon_neighbors"))


def _paint_params(given: dict) -> dict:
    """The paint parameters among a function's arguments ``given`` (its ``locals()``);
    ``None`` leaves the native default."""
    return {k: v for k, v in given.items() if k in _PAINT_KEYS and v is not None}


def render_plate(eye: str = "cyclopean", color_space: str = "xyz", return_info: bool = False, *,
                 radius_um: float = 30.0, radius_cv: float = 0.15, thickness_um: float = 0.5,
                 density: float = 6.5, tilt: str = "halfnormal", tilt_deg: float = 8.0,
                 layer_um: float = 20.24, tile_um: float = 450.0, model: str = "boolean",
                 n_pool_tiles: int = 16, max_clamped_fraction: float = 0.05, seed: int = 0,
                 size_mm: Tuple[float, float] = (150.0, 100.0), coat_ior: float = 1.5,
                 coat_um: float = 40.0, binder_ior: float = 1.5,
                 binder_sigma_a_per_mm: float = 0.0, base_albedo: float = 0.0,
                 metal: str = "al_k6", metal_nk: Optional[Tuple[float, float]] = None,
                 light_elevation_deg: float = 45.0, light_deg: float = 1.0,
                 light_cct: Optional[float] = None, light_spectrum=None,
                 radiance_scale: float = 1.0, spp: int = 64, max_depth: int = 8,
                 render_seed: int = 0,
                 region_mm: Optional[Tuple[float, float, float, float]] = None,
                 magnification: float = 1.0, independent_samples: bool = False,
                 color_mode: str = "spectral", keep_spectrum: bool = False,
                 n_photons: int = 2_000_000, n_photon_neighbors: int = 50
                 ) -> Union[np.ndarray, Tuple[np.ndarray, np.ndarray],
                            Tuple[np.ndarray, PlateInfo],
                            Tuple[Tuple[np.ndarray, PlateInfo], Tuple[np.ndarray, PlateInfo]]]:
    """Renders the metallic-paint plate for one eye or the stereo pair (paper 07).

    Parameters
    ----------
    eye : {'cyclopean', 'left', 'right', 'pair'}
        The view: the monoscopic condition's cyclopean eye, one eye of the off-axis rig, or
        both eyes (same microstructure).
    color_space : {'xyz', 'srgb'}
        CIE XYZ normalised so that a perfect white diffuser under the lamp has Y = 1, or
        display sRGB (glints clip at 1).
    return_info : bool
        Also return, per view, a :class:`PlateInfo` with ``flake_id`` ((H, W) uint64: the
        flake glinting directly in each pixel, ``2**64 - 1`` for none), ``glint_ids`` (sorted
        ids of every flake glinting directly), ``mm_per_px``, ``lamp_y`` (the lamp's own
        luminance, the largest a pixel can have), ``region_mm`` and, with
        ``keep_spectrum``, ``bands_nm`` and ``spectrum``.
    radius_um, radius_cv, thickness_um, density, tilt, tilt_deg, layer_um, tile_um, model, n_pool_tiles, max_clamped_fraction, seed
        The flake microstructure (see the module documentation).
    size_mm, coat_ior, coat_um, binder_ior, binder_sigma_a_per_mm, base_albedo, metal, metal_nk
        The paint's layers.
    light_elevation_deg, light_deg, light_cct, light_spectrum, radiance_scale
        The lamp.
    spp, max_depth, render_seed, region_mm, magnification, independent_samples, color_mode, keep_spectrum, n_photons, n_photon_neighbors
        The renderer.

    Returns
    -------
    image : (H, W, 3) float32, or a ``(left, right)`` pair; with ``return_info`` each view is
        ``(image, info)``.

    Notes
    -----
    Every surface of the paint is specular: a camera ray refracts into the clear coat, meets
    aluminium discs in the binder (Fresnel of the conductor with the index relative to the
    binder), and gathers the lamp's radiance each time it leaves the plate inside the lamp's
    disc; the 81 wavelengths travel together. The only noise is the sampling of each pixel's
    footprint (``spp`` jittered rays).

    References
    ----------
    F. da Graça, A. Paljic, E. Diaz, "Evaluating stereoscopic visualization for predictive
    rendering", Journal of WSCG 23 (2015).

    Examples
    --------
    >>> left, right = render_plate("pair", region_mm=(-2, -2, 2, 2), magnification=4, spp=4)
    >>> left.shape
    (58, 58, 3)
    """
    if eye not in ("cyclopean", "left", "right", "pair"):
        raise ValueError(f"{eye!r} is not a valid eye. Valid eyes are 'cyclopean', 'left', "
                         "'right', 'pair'")
    if color_space not in ("xyz", "srgb"):
        raise ValueError(f"{color_space!r} is not a valid `color_space`. Valid values are "
                         "'xyz', 'srgb'")
    params = _paint_params(locals())
    eyes = ["left", "right"] if eye == "pair" else [eye]
    views = []
    for xyz, flake_id, glint_ids, info in _r.render_plate(params, eyes):
        img = xyz_to_srgb(xyz) if color_space == "srgb" else xyz
        if return_info:
            bands = info.get("bands_nm")
            info = _from_mapping(PlateInfo, info, flake_id=flake_id, glint_ids=glint_ids,
                                 region_mm=tuple(info["region_mm"]),
                                 bands_nm=None if bands is None
                                 else np.asarray(bands, dtype=np.float64))
            views.append((img, info))
        else:
            views.append(img)
    return tuple(views) if eye == "pair" else views[0]


def make_tile(*, radius_um: float = 30.0, radius_cv: float = 0.15, thickness_um: float = 0.5,
              density: float = 6.5, tilt: str = "halfnormal", tilt_deg: float = 8.0,
              layer_um: float = 20.24, tile_um: float = 450.0, model: str = "boolean",
              n_pool_tiles: int = 16, max_clamped_fraction: float = 0.05,
              seed: int = 0) -> Tuple[np.ndarray, int]:
    """One 450 x 450 µm tile of the flake microstructure (stack model, paper 07 section 2.2).

    Returns a structured array of :data:`FLAKE_DTYPE` (centre in µm with z above the base,
    unit normal, radius), in deposition order, and the number of flakes the deposit model
    had to clamp to the layer's top. Parameters: the microstructure of the module
    documentation (``n_pool_tiles`` is only checked here).
    """
    arr, clamped = _r.make_tile(_paint_params(locals()))
    return _records(arr), clamped


def plate_layout(region_mm: Tuple[float, float, float, float], *, radius_um: float = 30.0,
                 radius_cv: float = 0.15, thickness_um: float = 0.5, density: float = 6.5,
                 tilt: str = "halfnormal", tilt_deg: float = 8.0, layer_um: float = 20.24,
                 tile_um: float = 450.0, model: str = "boolean", n_pool_tiles: int = 16,
                 max_clamped_fraction: float = 0.05, seed: int = 0,
                 size_mm: Tuple[float, float] = (150.0, 100.0)):
    """The plate's microstructure over ``region_mm`` (x0, y0, x1, y1), for export to another
    renderer: the pool of tiles (a list of :data:`FLAKE_DTYPE` arrays, tile frame in µm) and
    the cells overlapping the region as ``(x0_um, y0_um, tile, quarter_turns)``. A tile point
    ``q`` appears at ``(x0, y0) + L/2 + R_k (q - L/2)`` (``L`` = ``tile_um``, ``R_k`` a turn
    of ``k`` quarter turns counter-clockwise), clipped to the cell's square. The other
    parameters are the microstructure and ``size_mm`` of the module documentation."""
    params = _paint_params(locals())
    del params["region_mm"]  # the layout's region, not a render's
    pool, cells = _r.plate_layout(params, region_mm)
    return [_records(a) for a in pool], cells

def glint_stats(y, mm_per_px: float) -> GlintStats:
    """Sparkle statistics of a luminance image (the virtual observer's features).

    Glints are 8-connected groups of pixels brighter than 4x the median luminance (any
    positive luminance when the median is 0). Returns a :class:`GlintStats`:
    ``glint_density_per_mm2``, ``mean_y``, ``median_y``, ``y99_over_median``,
    ``mean_glint_area_mm2``, ``mean_glint_peak_y``, ``n_glints`` and ``threshold``.
    """
    return _from_mapping(GlintStats, _r.glint_statistics(y, mm_per_px),
                         rename={"glints": "n_glints"})


def workshop(reference: Tuple[float, float] = (26.0, 7.3),
             runs: Optional[Sequence[Tuple[float, float]]] = None, condition: str = "stereo",
             n_reference_renders: int = 4, jnd_log: float = 0.25, *,
             radius_cv: float = 0.15, thickness_um: float = 0.5, tilt: str = "halfnormal",
             tilt_deg: float = 8.0, layer_um: float = 20.24, tile_um: float = 450.0,
             model: str = "boolean", n_pool_tiles: int = 16,
             max_clamped_fraction: float = 0.05, seed: int = 0,
             size_mm: Tuple[float, float] = (150.0, 100.0), coat_ior: float = 1.5,
             coat_um: float = 40.0, binder_ior: float = 1.5,
             binder_sigma_a_per_mm: float = 0.0, base_albedo: float = 0.0,
             metal: str = "al_k6", metal_nk: Optional[Tuple[float, float]] = None,
             light_elevation_deg: float = 75.0, light_deg: float = 1.0,
             light_cct: Optional[float] = None, light_spectrum=None,
             radiance_scale: float = 1.0, spp: int = 64, max_depth: int = 8,
             render_seed: int = 0,
             region_mm: Optional[Tuple[float, float, float, float]] = None,
             magnification: float = 4.0, independent_samples: bool = False,
             color_mode: str = "spectral", keep_spectrum: bool = False,
             n_photons: int = 2_000_000, n_photon_neighbors: int = 50) -> WorkshopScores:
    """The virtual material workshop: virtual-observer scores of candidate plates.

    The hidden ``reference`` (radius µm, density) is rendered ``n_reference_renders`` times
    (>= 2) with different microstructure seeds to calibrate the observer; each candidate of
    ``runs`` (default: the paper's 13-run inscribed central composite design over radius
    15-45 µm and density 3.5-9.5) is rendered once and scored 0 (identical) ... 10
    (different). The plate parameters are those of :func:`render_plate` but for
    ``radius_um`` and ``density`` (the runs set them), with other defaults: a 10 x 10 mm
    patch (``region_mm=None``) at 4x magnification, 64 spp, the lamp 75 degrees above the
    plate. Fit the scores with :func:`wscg.doe.fit_rsm` and read the stationary point.

    Returns a :class:`WorkshopScores`: ``runs``, ``scores``, ``features``,
    ``reference_features``, ``feature_names`` and ``scale_log``.
    """
    if runs is None:
        from . import doe
        runs = [tuple(r) for r in doe.decode(doe.ccd(2, "inscribed", "rotatable", (3, 2)),
                                              [15.0, 3.5], [45.0, 9.5])]
    if condition not in ("mono", "stereo"):
        raise ValueError(f"{condition!r} is not a valid condition. Valid conditions are "
                         "'mono', 'stereo'")
    res = _r.workshop(_paint_params(locals()), reference, runs, condition, n_reference_renders,
                      jnd_log)
    f64 = lambda v: np.asarray(v, dtype=np.float64)  # noqa: E731
    n_features = len(res["feature_names"])
    runs = [(float(r), float(d)) for r, d in runs]  # checked by the native call
    return _from_mapping(WorkshopScores, res, runs=runs, scores=f64(res["scores"]),
                         features=f64(res["features"]).reshape(len(runs), n_features),
                         reference_features=f64(res["reference_features"]).reshape(
                             -1, n_features),
                         scale_log=f64(res["scale_log"]))


@_result
class PaintDescription:
    """A paint description file (JSON, :func:`load_paint`): any subset of the paint's keys
    (paper 07, section 3), ``None`` where the file leaves the value to the caller, as
    ``wscg raytrace paint --paint FILE`` applies it over its options.

    Attributes
    ----------
    radius_um : float or None
        Mean flake radius, µm (``render_plate``'s ``radius_um``).
    density : float or None
        Mean number of flakes above a point (``density``).
    tilt_deg : float or None
        Standard deviation of the half-normal flake tilt, degrees (``tilt_deg``).
    model : str or None
        Height model of the flake layer, ``"boolean"`` or ``"deposit"``.
    thickness_um, layer_um : float or None
        Flake thickness and flake layer (binder) thickness, µm.
    binder_absorption_per_mm : float or None
        Binder absorption coefficient, 1/mm (``binder_sigma_a_per_mm``).
    binder_ior, coat_ior : float or None
        Refractive indices of the binder and of the clear coat (``coat_ior`` 1: no coat).
    base_albedo : float or None
        Lambertian albedo of the base.
    coat_um : float or None
        Clear coat thickness, µm.
    seed : int or None
        Microstructure seed.
    """

    radius_um: Optional[float] = None
    density: Optional[float] = None
    tilt_deg: Optional[float] = None
    model: Optional[str] = None
    thickness_um: Optional[float] = None
    layer_um: Optional[float] = None
    binder_absorption_per_mm: Optional[float] = None
    binder_ior: Optional[float] = None
    base_albedo: Optional[float] = None
    coat_ior: Optional[float] = None
    coat_um: Optional[float] = None
    seed: Optional[int] = None


def load_paint(path: Union[str, os.PathLike]) -> PaintDescription:
    """Reads a paint description file (JSON object of the keys of
    :class:`PaintDescription`, e.g. ``{"radius_um": 26, "density": 7.3, "seed": 1}``).

    Raises ``OSError`` naming the file for a missing file, malformed JSON, an unknown key, a
    value of the wrong type or a paint the flake and layer parameters refuse (with the
    paper's defaults for the other keys), and ``ValueError`` for a file above 1 MiB.
    """
    return PaintDescription(**json.loads(_r.load_paint(os.fspath(path))))


def save_paint(path: Union[str, os.PathLike], paint: PaintDescription) -> None:
    """Writes ``paint`` as a JSON paint description (only the keys that are not ``None``,
    atomically) after the checks of :func:`load_paint`."""
    keys = {k: v for k, v in dataclasses.asdict(paint).items() if v is not None}
    # numpy scalars as Python numbers; a value of another type is refused as ValueError.
    _r.save_paint(os.fspath(path), json.dumps(keys, default=lambda v: v.item()))


# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
