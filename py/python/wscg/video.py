"""Localized-search high-definition video completion: paper 06 of WSCG vol. 23 (Benoit and
Paquette, "Localized search for high definition video completion").

Remove an object from a video: every pixel of the hole (a boolean mask per frame) takes the
colour of the centre of its single best-matching space-time patch (``5 x 5 x 5`` by
default) from the rest of the video. Stage 1 completes a copy at about 480 pixels wide with
a pyramid, an inpainting start and an onion-peel filling order; stage 2 refines its worst
matches from their neighbours' matches; stage 3 climbs to full resolution, each pixel
searching exactly only a window of 17, 13, 9 then 5 pixels around its up-scaled match.
Pixels outside the hole are never modified.

Baselines: :func:`wexler_complete` (Wexler et al. 2007: global search and weighted voting at
every level) and :func:`per_frame_patchmatch` (image PatchMatch inpainting of each frame).
Measures: :func:`ssim_masked`, :func:`psnr_masked`, :func:`flicker`. Test clips with exact
ground truth: :func:`make_clip`. Frame folders: :func:`load_frames`, :func:`load_mask`,
:func:`save_frames`. Frames are ``(F, H, W, 3)`` (or ``(F, H, W)`` grey) uint8
arrays, masks ``(F, H, W)`` bool or uint8 (non-zero = hole). Bad input raises
``ValueError``; unreadable files raise ``OSError``.
"""

from __future__ import annotations

from typing import List, Optional, Sequence, Tuple, Union

import numpy as np

from ._native import video as _v
from ._checks import _int, integer_ranges as _integer_ranges
from ._results import from_mapping as _from_mapping, result as _result

__all__ = ["complete_video", "wexler_complete", "per_frame_patchmatch", "inpaint_telea",
           "ssim_masked", "psnr_masked", "flicker", "make_clip", "load_frames", "load_mask",
           "save_frames", "CompletionStats"]


@_result
class CompletionStats:
    """What each stage of :func:`complete_video` did (``return_stats=True``). Energies are
    sums over the hole pixels of the mean squared RGB difference (grey levels squared) of
    their patch to their source's patch.

    Attributes
    ----------
    working_size : (int, int)
        ``(height, width)`` of stage 1's working resolution.
    working_factor : int
        Down-scaling factor from full to working resolution.
    seconds : list of float
        Wall time of stages 1, 2 and 3, in seconds.
    lowres_energy : list of list of float
        Stage 1: the energy after each sweep, one list per level, coarsest first.
    local_energy : list of list of float
        Stage 3: the energy after each window iteration, one list per finer level.
    local_candidates : list of int
        Stage 3: candidate patches compared per finer level.
    refine_changed : list of int or None
        Stage 2: matches replaced in each iteration (``None`` without refinement).
    refine_initial_set_mean : (float, float) or None
        Stage 2: mean patch distance of the matches above the first threshold, before and
        after refinement (``None`` without refinement).
    energy : float
        The energy of the final completion at full resolution.
    """

    working_size: Tuple[int, int]
    working_factor: int
    seconds: List[float]
    lowres_energy: List[List[float]]
    local_energy: List[List[float]]
    local_candidates: List[int]
    energy: float
    refine_changed: Optional[List[int]] = None
    refine_initial_set_mean: Optional[Tuple[float, float]] = None


def _frames(frames, name: str = "frames") -> np.ndarray:
    a = np.asarray(frames)
    if a.dtype != np.uint8:
        raise ValueError(f"`{name}` must be a uint8 array, got dtype {a.dtype}")
    if a.ndim not in (3, 4):
        raise ValueError(f"`{name}` must have shape (F, H, W, C) or (F, H, W), got {a.shape}")
    return np.ascontiguousarray(a)


def _mask(mask, frames: np.ndarray) -> np.ndarray:
    m = np.asarray(mask)
    if m.dtype != bool and m.dtype != np.uint8:
        raise ValueError(f"`mask` must be a bool or uint8 array, got dtype {m.dtype}")
    if m.ndim == 2:
        m = np.broadcast_to(m, (frames.shape[0],) + m.shape)
    if m.shape != frames.shape[:3]:
        raise ValueError(f"`mask` has shape {m.shape}, expected {frames.shape[:3]} (F, H, W) "
                         "or one (H, W) mask for every frame")
    return np.ascontiguousarray(m.astype(np.uint8))


def _sweeps(name: str, counts) -> list:
    """Per-level iteration caps: a non-empty sequence of counts."""
    try:
        out = [_int(name, c, 0) for c in counts]
    except TypeError:
        raise ValueError(f"`{name}` must be a sequence of counts, got {counts!r}") from None
    if not out:
        raise ValueError(f"`{name}` needs the iteration count of at least one level")
    return out


def _patch(patch) -> Tuple[int, int, int]:
    p = tuple(int(v) for v in patch)
    if len(p) != 3:
        raise ValueError(f"`patch` must be (px, py, pt), got {patch!r}")
    return p


def complete_video(frames, mask, patch: Sequence[int] = (5, 5, 5), lowres_width: int = 480,
                   n_levels: Optional[int] = None, lowres_max_iter: Sequence[int] = (10, 5, 3),
                   init: str = "harmonic2d", search: str = "patchmatch",
                   patchmatch_n_iter: int = 5, seed: int = 0, onion_order: bool = True,
                   causal_first_sweep: bool = True, refine_max_iter: int = 4,
                   windows: Sequence[int] = (17, 13, 9, 5), fine_max_iter: int = 16,
                   min_energy_drop: float = 5e-3,
                   temporal_radius: Union[int, Sequence[int]] = (0, 0, 0, 1),
                   max_candidates: int = 1000, propagate: bool = True,
                   temporal_candidates: bool = True,
                   step: str = "double", global_fine_search: bool = False,
                   return_matches: bool = False, return_stats: bool = False
                   ) -> Union[np.ndarray, Tuple[np.ndarray, np.ndarray],
                              Tuple[np.ndarray, CompletionStats],
                              Tuple[np.ndarray, np.ndarray, CompletionStats]]:
    """Completes the hole ``mask`` of ``frames`` by localized search (paper 06).

    Parameters
    ----------
    frames : (F, H, W, 3) or (F, H, W) uint8 array
        The video.
    mask : (F, H, W) or (H, W) bool/uint8 array
        The hole (non-zero); a 2-D mask is used for every frame.
    patch : (px, py, pt)
        Odd patch extents in x, y and frames.
    lowres_width : int
        Width of stage 1's working resolution (the video is down-scaled by
        ``round(W / lowres_width)``; 480 for the paper's 1920 x 1080 -> 480 x 270).
    n_levels : int, optional
        Pyramid levels below the working resolution (default: halve while the next level is
        at least 120 pixels wide and the hole is thicker than two patch radii).
    lowres_max_iter : sequence of int
        Stage 1 sweeps per level at most, coarsest first (the last value repeats for further
        levels); a level stops earlier once fewer than 0.1 % of its matches change or its
        energy drops by no more than ``min_energy_drop``.
    init : {'harmonic2d', 'harmonic3d', 'telea', 'random'}
        Initial colours of the hole at the coarsest level.
    search : {'patchmatch', 'pca_kdtree', 'exact'}
        Stage 1 search: space-time PatchMatch (``patchmatch_n_iter`` whole-field iterations
        before each sweep; memory: one match per hole pixel), the paper's PCA-24 + kd-tree
        index with exact re-ranking (memory: 96 bytes per valid source), or exact search
        (small videos).
    seed : int
        Seed of the random search.
    onion_order : bool
        Onion-peel filling order (``False``: scan-line, the ablation).
    causal_first_sweep : bool
        The first sweep fills pixel after pixel comparing only known and already filled
        pixels.
    refine_max_iter : int
        Stage 2 iterations at most (0: no refinement); it stops once no match changes.
    windows : sequence of odd int
        Stage 3 search windows (pixels) of the first iterations, one each; later iterations
        keep the last width.
    fine_max_iter : int
        Stage 3 iterations at most (at least one per window); ``max_candidates`` may stop it
        earlier.
    min_energy_drop : float
        After the listed windows, stage 3 stops once an iteration lowers the energy by no
        more than this fraction (stage 1's rule; a plateau, e.g. an exact completion, stops
        too).
    temporal_radius : int or sequence of int
        Frames searched on each side of a match's frame in stage 3, per iteration like
        ``windows`` (the last value repeats; an int: every iteration). The default makes the
        5-pixel windows 5 x 5 x 3 blocks; ``0`` is the paper's schedule (windows within the
        match's frame, Fig. 9).
    max_candidates : int
        Stage 3 candidate cubes per hole pixel at most over a level's iterations (window,
        coherence and temporal candidates; at least one iteration per window runs): the
        paper's "less than a thousand patches are searched for each p_h". The default
        schedule fits eight iterations (978 candidates).
    propagate : bool
        After each window, also try the sources the six space-time neighbours' matches imply
        (the coherence candidates of stage 2; an addition to the paper's stage 3, which
        lowers the energy towards exact global search's).
    temporal_candidates : bool
        Stages 1 and 3 also try the same position in the nearest earlier and later frames
        where it is known (two candidates per pixel and update), and stage 1 starts its match
        list from them: behind an object moving in front of a static camera they are exact
        copies of the background, which the paper's spatial search finds only by chance.
        ``False``: the paper's search.
    step : {'double', 'direct'}
        Stage 3 doubles the resolution per level, or goes to full resolution at once.
    global_fine_search : bool
        Exact global search instead of stage 3's windows (ablation, small videos only).
    return_matches, return_stats : bool
        Also return the ``(F, H, W, 3)`` int32 source ``(t, y, x)`` of every hole pixel (-1
        elsewhere) and/or the per-stage statistics, a :class:`CompletionStats`.

    Returns
    -------
    video : ndarray, same shape as ``frames``
        The completed video, or a tuple ``(video, matches?, stats?)``.

    Notes
    -----
    The energy reported in ``stats.energy`` is the sum over hole pixels of the mean
    squared RGB difference of their patch to their source's: the paper's eq. 1 as a sum
    instead of a product, since a product of distances is zero as soon as one match is exact.
    """
    fine = _int("fine_max_iter", fine_max_iter, 0)
    radii = [_int("temporal_radius", r, 0)
             for r in ([temporal_radius] if np.ndim(temporal_radius) == 0 else temporal_radius)]
    budget = _int("max_candidates", max_candidates, 0)
    sweeps = _sweeps("lowres_max_iter", lowres_max_iter)
    f = _frames(frames)
    m = _mask(mask, f)
    out, matches, stats = _v.complete_video(
        f, m, _patch(patch), int(lowres_width), None if n_levels is None else int(n_levels),
        sweeps, str(init), str(search), int(patchmatch_n_iter), int(seed),
        bool(onion_order), bool(causal_first_sweep), int(refine_max_iter),
        [int(w) for w in windows], fine, float(min_energy_drop),
        radii, budget, bool(propagate), bool(temporal_candidates), str(step),
        bool(global_fine_search),
        bool(return_matches))
    out = out.reshape(f.shape)
    extra = (([matches] if return_matches else [])
             + ([_from_mapping(CompletionStats, stats)] if return_stats else []))
    return (out, *extra) if extra else out


def wexler_complete(frames, mask, patch: Sequence[int] = (5, 5, 5), min_width: int = 64,
                    max_iter: Sequence[int] = (10, 5, 3), patchmatch_n_iter: int = 4,
                    seed: int = 0) -> np.ndarray:
    """Wexler et al. 2007 space-time completion (the paper's baseline): random start,
    PatchMatch (``patchmatch_n_iter`` iterations; 0 = exact) global search at every pyramid
    level up to full resolution, and voting ``w = exp(-D / (2 sigma^2)) * 1.3^-dist(p, E)``
    of all patches covering a pixel, at most ``max_iter[k]`` search-and-vote iterations at
    level ``k`` (coarsest first, the last value repeats; a level stops when the vote changes
    nothing). Slow at HD (the paper reports an hour per iteration)."""
    f = _frames(frames)
    m = _mask(mask, f)
    out = _v.wexler(f, m, _patch(patch), int(min_width), _sweeps("max_iter", max_iter),
                    int(patchmatch_n_iter), int(seed), False, False)
    return out.reshape(f.shape)


def per_frame_patchmatch(frames, mask, patch: Sequence[int] = (5, 5), min_width: int = 64,
                         max_iter: Sequence[int] = (10, 5, 3), patchmatch_n_iter: int = 4,
                         seed: int = 0, seed_per_frame: bool = True) -> np.ndarray:
    """Image PatchMatch inpainting of every frame separately (``(px, py)`` patches, Wexler
    voting; ``max_iter`` and ``patchmatch_n_iter`` as in :func:`wexler_complete`): what an
    image tool applied frame by frame gives. ``seed_per_frame`` seeds frame ``t`` with
    ``seed + t``, as separate runs would be."""
    f = _frames(frames)
    m = _mask(mask, f)
    p = tuple(int(v) for v in patch)
    if len(p) != 2:
        raise ValueError(f"`patch` must be (px, py), got {patch!r}")
    out = _v.wexler(f, m, (p[0], p[1], 1), int(min_width), _sweeps("max_iter", max_iter),
                    int(patchmatch_n_iter), int(seed), True, bool(seed_per_frame))
    return out.reshape(f.shape)


def inpaint_telea(image, mask, radius: float = 5.0) -> np.ndarray:
    """Fast-marching inpainting of one image (Telea 2004; one of stage 1's initialisations):
    the hole is filled inwards in order of its distance to the known pixels, each pixel from
    the first-order extrapolations of the known pixels within ``radius``. ``image``:
    ``(H, W, C)`` or ``(H, W)`` uint8; ``mask``: ``(H, W)``, non-zero = hole. Compare
    ``cv2.inpaint(image, mask, radius, cv2.INPAINT_TELEA)``."""
    img = np.asarray(image)
    if img.dtype != np.uint8 or img.ndim not in (2, 3):
        raise ValueError(f"`image` must be an (H, W) or (H, W, C) uint8 array, got {img.dtype} {img.shape}")
    m = np.ascontiguousarray(np.asarray(mask).astype(np.uint8))
    return _v.inpaint_telea(np.ascontiguousarray(img), m, float(radius))


def ssim_masked(a, b, mask) -> float:
    """Mean SSIM over the hole pixels (Gaussian window sigma 1.5, K1 = 0.01, K2 = 0.03, data
    range 255; per-channel maps averaged), counting hole pixels at least 5 pixels from the
    frame border as scikit-image does; with an all-true mask it equals
    ``skimage.metrics.structural_similarity(a, b, gaussian_weights=True, sigma=1.5,
    use_sample_covariance=False, data_range=255, channel_axis=-1)`` per frame."""
    fa, fb = _frames(a, "a"), _frames(b, "b")
    return _v.measure(fa, fb, _mask(mask, fa), "ssim")


def psnr_masked(a, b, mask) -> float:
    """PSNR (dB, data range 255) over the hole pixels; ``inf`` when they are equal."""
    fa, fb = _frames(a, "a"), _frames(b, "b")
    return _v.measure(fa, fb, _mask(mask, fa), "psnr")


def flicker(frames, mask) -> float:
    """Mean absolute frame-to-frame change (grey levels) over the pixel positions in the
    hole at ``t`` or ``t + 1``: 0 for a static completion of a static scene."""
    f = _frames(frames)
    return _v.measure(f, None, _mask(mask, f), "flicker")


def make_clip(kind: str, n_frames: int = 20, height: int = 180, width: int = 320,
              radius: float = 25.0, speed: float = 8.0, step: float = 8.0,
              zoom: float = 1.003, hole: Tuple[int, int] = (30, 40), period: float = 24.0,
              noise: float = 0.0, seed: int = 0):
    """A synthetic clip of ``n_frames`` frames of ``height x width`` with exact ground truth:
    returns ``(clean, observed, mask)``.

    ``kind``: ``'sprite'`` (static camera, an opaque disc of ``radius`` moving ``speed``
    px/frame, Gaussian ``noise``), ``'pan'`` (camera panning ``step`` px/frame under a static
    ``hole = (h, w)`` logo), ``'zoom'`` (zoom by ``zoom`` per frame, disc hole of ``radius``
    moving ``speed`` px/frame), ``'periodic'`` (stripes of ``period`` px over bricks, a
    static square hole of side ``hole[0]`` hidden in every frame). **Synthetic data.**"""
    h = tuple(int(v) for v in hole)
    return _v.make_clip(str(kind), int(n_frames), int(height), int(width), float(radius),
                        float(speed), float(step), float(zoom), (h[0], h[-1]), float(period),
                        float(noise), int(seed))


def load_frames(path) -> np.ndarray:
    """The PNG/JPEG files of a folder, in name order, as an ``(F, H, W, 3)`` uint8 array
    (``OSError`` for unreadable files or frames of different sizes)."""
    return _v.load_frames(str(path))


def load_mask(path, n_frames: int, height: int, width: int) -> np.ndarray:
    """A hole mask from one image (used for every frame) or a folder of one image per frame;
    a pixel is in the hole when any channel is non-zero. Returns ``(n_frames, height,
    width)`` bool."""
    return _v.load_mask(str(path), int(n_frames), int(height), int(width)).astype(bool)


def save_frames(path, frames) -> list:
    """Writes ``frame_00000.png``, ... into the folder ``path`` (created if missing); returns
    the file paths."""
    return [str(p) for p in _v.save_frames(str(path), _frames(frames))]

# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
