"""Many-light rendering with adaptive importance caching: paper 08 of WSCG vol. 23 (Yoshida,
Nabata, Iwasaki, Dobashi and Nishita, "Adaptive importance caching for many-light
rendering"), re-exported by :mod:`wscg.raytrace`.

A scene of Lambertian triangles, some emissive, is lit by virtual point lights (VPLs) traced
from its emitters (instant radiosity). Each pixel's radiance, the sum over all VPLs, is
estimated from a few VPLs drawn from distributions cached at sparse records and interpolated:

- ``'adaptive'``: the paper's records (6-D clustering of the shading points, then insertion
  where a record disagrees with its neighbours' interpolation) and similarity weights;
- ``'adaptive_uniform'``: the paper's ablation, its records with uniform weights;
- ``'ic'``: importance caching (Georgiev et al. 2012), records on a jittered screen grid;
- ``'power'``: VPLs drawn in proportion to their power, no cache;
- ``'reference'``: every VPL at every pixel (the estimators are unbiased against it).

All estimators combine the four distributions (full, unoccluded, bounded, conservative) with
the alpha-max heuristic. Bad input raises ``ValueError``; an unreadable file ``OSError``.
"""

from __future__ import annotations

from typing import Optional, Tuple

import numpy as np

from ._native import raytrace as _r
from ._native.raytrace import (load_manylight_obj, make_manylight_scene, manylight_from_arrays,
                               manylight_record_weight)
from ._checks import integer_ranges as _integer_ranges
from ._results import from_mapping as _from_mapping, result as _result

ManyLightScene = _r.ManyLightScene

__all__ = ["ManyLightScene", "make_manylight_scene", "manylight_from_arrays",
           "load_manylight_obj", "render_manylight", "ManyLightStats",
           "manylight_record_weight"]


@_result
class ManyLightStats:
    """What a render of :func:`render_manylight` did. The cache fields are None for the
    methods without a cache (``'power'``, ``'reference'``).

    Attributes
    ----------
    method : str
        The method's name.
    n_vpls : int
        Virtual point lights traced from the emitters.
    setup_seconds : float
        Wall-clock seconds generating the VPLs and the shading points.
    cache_seconds : float
        Wall-clock seconds building the cache (0 without one).
    render_seconds : float
        Wall-clock seconds rendering.
    records : float64 array (K, 3)
        Positions ``(x, y, z)`` of the cache records (K = 0 without a cache).
    record_pixels : int64 array (K,)
        Flat pixel index (``row * width + column``) of each record; -1 for a record that is
        not on a pixel (``'ic'`` places its records at jittered points of a screen grid).
    record_inserted : bool array (K,)
        Whether each record came from the adaptive insertion (not the initial placement).
    record_normals : float64 array (K, 3)
        Unit normal of each record (turned towards the camera).
    record_radii : float64 array (K,)
        Radius of influence of each record (its bounded distribution holds over the disc).
    n_records : int or None
        Final number of records.
    n_initial : int or None
        Records of the initial placement (clustering, or the screen grid).
    n_inserted : int or None
        Records added by the adaptive insertion.
    n_passes : int or None
        Insertion passes.
    n_cache_shadow_rays : int or None
        Shadow rays traced for the records' full distributions.
    cache_bytes : int or None
        Bytes of the records' distributions.
    """

    method: str
    n_vpls: int
    setup_seconds: float
    cache_seconds: float
    render_seconds: float
    records: np.ndarray
    record_pixels: np.ndarray
    record_inserted: np.ndarray
    record_normals: np.ndarray
    record_radii: np.ndarray
    n_records: Optional[int] = None
    n_initial: Optional[int] = None
    n_inserted: Optional[int] = None
    n_passes: Optional[int] = None
    n_cache_shadow_rays: Optional[int] = None
    cache_bytes: Optional[int] = None


def render_manylight(scene: ManyLightScene, method: str = "adaptive",
                     camera: Optional[dict] = None, *, n_vpl_paths: int = 1000,
                     max_bounces: int = 2, n_cache: Optional[int] = None, spp: int = 16,
                     seed: int = 0, vpl_seed: int = 0, clamp_dist: Optional[float] = None,
                     m_nearest: int = 3, delta: float = 0.5, init_fraction: float = 0.6,
                     theta_max: float = np.pi / 6, lam: float = 5.0,
                     dmax_factor: float = 2.0, defensive: float = 0.5,
                     pixel_filter: str = "box",
                     n_pixel_samples: int = 4, near_share: float = 0.25,
                     n_near_vpls: int = 32) -> Tuple[np.ndarray, ManyLightStats]:
    """Renders ``scene`` with ``method``; returns the linear RGB image (H, W, 3) float32 and
    its :class:`ManyLightStats` (``n_vpls``, ``records`` (K, 3) positions,
    ``record_pixels``, ``record_inserted``, ``n_records``, ``n_inserted``, ``n_passes``,
    ``cache_seconds``, ``render_seconds``, ...).

    ``n_vpl_paths`` light paths of ``max_bounces`` bounces give the VPLs; ``n_cache``
    records (default 1 % of the pixels; the adaptive budget, the screen grid's count);
    ``spp`` VPL samples per pixel shared among the strategies; ``clamp_dist`` the geometry
    term's clamping distance (default 1 % of the scene's diagonal, 0 for none); ``delta``,
    ``init_fraction``: the adaptive insertion's threshold and the share of records placed by
    clustering; ``theta_max``, ``lam``, ``dmax_factor``: the similarity weights (eqs. 2-4)
    (see :func:`manylight_record_weight`); ``defensive``: the share ``c`` of the uniform
    weights blended into them, ``(1 - c) w + c u``, so that no VPL's probability falls
    below ``c`` times the uniform weights' one (0.5; 0 gives the paper's weights, whose
    occasional near-zero probabilities make the estimate heavy-tailed behind hard, repeated
    shadows). ``pixel_filter``: ``'box'`` (default: ``n_pixel_samples`` sub-pixel positions
    uniform over each pixel, as a film renderer's pixels; ``spp`` is shared out among
    them), ``'tent'`` (radius one pixel) or ``'center'`` (one ray through the pixel centre,
    the paper's setting; ``n_pixel_samples`` is ignored). ``'reference'`` follows the same
    filter (with many ``n_pixel_samples`` it is the brute-force filtered image).
    ``near_share`` (beyond the paper, 0.25): the share of the unoccluded strategy's VPL
    samples drawn from each pixel's own distribution over the ``n_near_vpls`` VPLs
    nearest its first shading point (their contributions without visibility there). A VPL
    next to a shading point but far from every record gets a tiny probability from the
    records' distributions while its contribution there is large, which made single bright
    pixels behind hard, repeated shadows; the share bounds those samples, keeps the
    estimate unbiased, lowered the mean RMSE by 5-20 % on such scenes and costs 20-30 %
    more render time; 0 gives the paper's strategies.

    >>> s = make_manylight_scene("cornell", width=32, height=24)
    >>> img, st = render_manylight(s, "adaptive", n_vpl_paths=100, n_cache=30, spp=4)
    >>> img.shape, img.dtype
    ((24, 32, 3), dtype('float32'))
    """
    # The keyword parameters, read and checked by name by the native renderer; None leaves
    # its default.
    params = {k: v for k, v in locals().items()
              if k not in ("scene", "method", "camera") and v is not None}
    img, st = _r.manylight_render(scene, method, params, camera)
    return img, _from_mapping(ManyLightStats, st, rename={
        "inserted": "n_inserted", "passes": "n_passes", "initial": "n_initial",
        "shadow_rays_cache": "n_cache_shadow_rays"})

# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
