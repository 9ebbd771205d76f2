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
from ._checks import integer_ranges as _integer_ranges
from ._results import from_mapping as _from_mapping, result as _result

ManyLightScene = _r.ManyLightScene

__all__ = ["ManyLightScene", "make_manylight_scene", "manylight_from_arrays",
           "load_manylight_obj", "render_manylight", "ManyLightStats"]


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
    n_records : int or None
        Final number of records.
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
    n_records: Optional[int] = None
    n_inserted: Optional[int] = None
    n_passes: Optional[int] = None
    n_cache_shadow_rays: Optional[int] = None
    cache_bytes: Optional[int] = None


def make_manylight_scene(name: str = "cornell", subdiv: int = 1, width: int = 256,
                         height: int = 192) -> ManyLightScene:
    """A procedural scene with its camera.

    ``name``: ``'cornell'`` (the Cornell box of the paper's Fig. 3), ``'colonnade'`` (a hall
    of pillars lit through a roof opening, standing in for Sponza), ``'conference'`` (a room
    with a table and chairs half under it, standing in for Conference) or ``'plane'`` (a
    plane under a tiny light, for the closed-form check). ``subdiv`` splits every quad into
    ``subdiv x subdiv`` cells (more triangles, same picture).

    >>> s = make_manylight_scene("cornell", width=64, height=48)
    >>> s.n_triangles, s.n_emitters
    (36, 2)
    """
    return _r.make_manylight_scene(name, int(subdiv), int(width), int(height))


def manylight_from_arrays(vertices, faces, albedo, emission,
                          camera: Optional[dict] = None) -> ManyLightScene:
    """A scene from an indexed triangle mesh: ``vertices`` (V, 3), ``faces`` (F, 3)
    (counter-clockwise seen from the front; emitters radiate from the front), per-face
    ``albedo`` (F, 3) in [0, 1] and emitted radiance ``emission`` (F, 3) >= 0. ``camera``:
    dict with ``eye``, ``target``, ``up``, ``fov_deg`` (vertical, degrees), ``width``,
    ``height``. Degenerate triangles are skipped (counted by ``n_skipped_degenerate``)."""
    return _r.manylight_from_arrays(
        np.ascontiguousarray(vertices, dtype=np.float64),
        np.ascontiguousarray(faces, dtype=np.int64),
        np.ascontiguousarray(albedo, dtype=np.float64),
        np.ascontiguousarray(emission, dtype=np.float64), camera)


def load_manylight_obj(path, camera: Optional[dict] = None) -> ManyLightScene:
    """A scene from a Wavefront OBJ file and its MTL library (``Kd``: albedo, ``Ke``:
    emitted radiance). The file is only read."""
    return _r.load_manylight_obj(str(path), camera)


def render_manylight(scene: ManyLightScene, method: str = "adaptive",
                     camera: Optional[dict] = None, *, n_vpl_paths: int = 1000,
                     max_bounces: int = 2, n_cache: Optional[int] = None, spp: int = 16,
                     seed: int = 0, vpl_seed: int = 0, clamp_dist: Optional[float] = None,
                     m_nearest: int = 3, delta: float = 0.5, init_fraction: float = 0.6,
                     theta_max: float = np.pi / 6, lam: float = 5.0,
                     dmax_factor: float = 2.0) -> Tuple[np.ndarray, ManyLightStats]:
    """Renders ``scene`` with ``method``; returns the linear RGB image (H, W, 3) float32 and
    its :class:`ManyLightStats` (``n_vpls``, ``records`` (K, 3) positions,
    ``record_pixels``, ``record_inserted``, ``n_records``, ``n_inserted``, ``n_passes``,
    ``cache_seconds``, ``render_seconds``, ...).

    ``n_vpl_paths`` light paths of ``max_bounces`` bounces give the VPLs; ``n_cache``
    records (default 1 % of the pixels; the adaptive budget, the screen grid's count);
    ``spp`` VPL samples per pixel shared among the strategies; ``clamp_dist`` the geometry
    term's clamping distance (default 1 % of the scene's diagonal, 0 for none); ``delta``,
    ``init_fraction``: the adaptive insertion's threshold and the share of records placed by
    clustering; ``theta_max``, ``lam``, ``dmax_factor``: the similarity weights (eqs. 2-4).

    >>> s = make_manylight_scene("cornell", width=32, height=24)
    >>> img, st = render_manylight(s, "adaptive", n_vpl_paths=100, n_cache=30, spp=4)
    >>> img.shape, img.dtype
    ((24, 32, 3), dtype('float32'))
    """
    params = dict(n_vpl_paths=int(n_vpl_paths), max_bounces=int(max_bounces), spp=int(spp),
                  seed=int(seed), vpl_seed=int(vpl_seed), m_nearest=int(m_nearest),
                  delta=float(delta), init_fraction=float(init_fraction),
                  theta_max=float(theta_max), **{"lambda": float(lam)},
                  dmax_factor=float(dmax_factor))
    if n_cache is not None:
        params["n_cache"] = int(n_cache)
    if clamp_dist is not None:
        params["clamp_dist"] = float(clamp_dist)
    img, st = _r.manylight_render(scene, method, params, camera)
    return img, _from_mapping(ManyLightStats, st, rename={
        "inserted": "n_inserted", "passes": "n_passes",
        "shadow_rays_cache": "n_cache_shadow_rays"})

# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
