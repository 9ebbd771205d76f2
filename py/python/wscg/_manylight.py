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
                     dmax_factor: float = 2.0, defensive: float = 0.5,
                     pixel_filter: str = "box",
                     n_pixel_samples: int = 4) -> Tuple[np.ndarray, ManyLightStats]:
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

    >>> s = make_manylight_scene("cornell", width=32, height=24)
    >>> img, st = render_manylight(s, "adaptive", n_vpl_paths=100, n_cache=30, spp=4)
    >>> img.shape, img.dtype
    ((24, 32, 3), dtype('float32'))
    """
    params = dict(n_vpl_paths=int(n_vpl_paths), max_bounces=int(max_bounces), spp=int(spp),
                  seed=int(seed), vpl_seed=int(vpl_seed), m_nearest=int(m_nearest),
                  delta=float(delta), init_fraction=float(init_fraction),
                  theta_max=float(theta_max), **{"lambda": float(lam)},
                  dmax_factor=float(dmax_factor), defensive=float(defensive),
                  pixel_filter=str(pixel_filter), n_pixel_samples=int(n_pixel_samples))
    if n_cache is not None:
        params["n_cache"] = int(n_cache)
    if clamp_dist is not None:
        params["clamp_dist"] = float(clamp_dist)
    img, st = _r.manylight_render(scene, method, params, camera)
    return img, _from_mapping(ManyLightStats, st, rename={
        "inserted": "n_inserted", "passes": "n_passes", "initial": "n_initial",
        "shadow_rays_cache": "n_cache_shadow_rays"})

def manylight_record_weight(x, normal, record_pos, record_normal, d_max: float,
                            theta_max: float = np.pi / 6, lam: float = 5.0) -> np.ndarray:
    """The paper's similarity weight (eqs. 2-4, after Clarberg and Akenine-Moller 2008) of
    each record for the shading point ``x`` (3,) with unit ``normal`` (3,): records at
    ``record_pos`` (K, 3) with unit normals ``record_normal`` (K, 3); returns (K,) float64
    in [0, 1]: ``sqrt(1 - |n . v|) * w_hat(d, theta)``, ``v`` the unit vector to the record
    (1 when it coincides with ``x``), ``d`` its distance, ``theta`` the angle between the
    normals, ``w(d, theta) = (1 - theta / pi) (1 - d' / (1 + lam d'))`` with
    ``d' = d / d_max``, and ``w_hat = max(0, (w - w0) / (1 - w0))``,
    ``w0 = w(d_max, theta_max)``. A render normalises the weights of the ``M`` nearest
    records within ``d_max`` (and blends them with uniform ones, see ``defensive`` of
    :func:`render_manylight`).

    >>> w = manylight_record_weight([0, 0, 0], [0, 0, 1], [[0.25, 0, 0], [0, 0, 0.25]],
    ...                             [[0, 0, 1], [0, 0, 1]], d_max=1.0)
    >>> np.round(w, 6).tolist()
    [0.636364, 0.0]
    """
    def vec3(name, v):
        a = np.asarray(v, dtype=np.float64)
        if a.shape != (3,):
            raise ValueError(f"`{name}` must have shape (3,), got {a.shape}")
        return [float(c) for c in a]
    return _r.manylight_record_weight(
        vec3("x", x), vec3("normal", normal),
        np.ascontiguousarray(record_pos, dtype=np.float64),
        np.ascontiguousarray(record_normal, dtype=np.float64),
        float(d_max), float(theta_max), float(lam))


# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
