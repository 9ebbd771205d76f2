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
from ._native.video import (flicker, inpaint_telea, load_frames, load_mask, make_clip,
                            per_frame_patchmatch, psnr_masked, save_frames, ssim_masked,
                            wexler_complete)
from ._checks import integer_ranges as _integer_ranges
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


def complete_video(frames, mask, patch: Sequence[int] = (5, 5, 5), lowres_width: int = 480,
                   n_levels: Optional[int] = None, lowres_max_iter: Sequence[int] = (10, 5, 3),
                   init: str = "harmonic2d", search: str = "patchmatch",
                   patchmatch_n_iter: int = 5, seed: int = 0, onion_order: bool = True,
                   causal_first_sweep: bool = True, refine_max_iter: int = 4,
                   windows: Sequence[int] = (17, 13, 9, 5), fine_max_iter: int = 16,
                   min_energy_drop: float = 5e-3,
                   temporal_radius: Union[int, Sequence[int]] = (0, 0, 0, 1),
                   max_candidates: int = 1000, propagate: bool = True,
                   temporal_candidates: bool = True, hypotheses: int = 6,
                   scan_propagation: bool = False,
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
    hypotheses : int
        With ``search='pca_kdtree'``: stage 1's next-best sources kept per hole pixel (ranked
        by its index on the completed working resolution); at the first finer level, each
        pixel's first stage-3 iteration also searches a 3 x 3 window around each, up-scaled.
        A region can then leave the copy its up-scaled match started it on for one the windows
        never reach (the local minimum the paper names in its section 5). The default costs
        54 candidates per pixel out of ``max_candidates`` (seven iterations fit instead of
        eight) and brought localized search to 0.99-1.12x the energy of exact global search
        on six zoom clips where it reached 1.00-1.22x; the energy is 4 % lower on average,
        though a few per cent higher on some clips, and the PSNR in the hole stays within
        0.05 dB. ``0``: the paper's stage 3. Other searches rank no alternatives, so this
        does nothing with them. A count whose sources per hole pixel exceed the memory limit
        raises ``MemoryError``.
    scan_propagation : bool
        After each stage-3 iteration, a raster scan and its reverse in which each hole pixel
        tries the sources its already-scanned neighbours' matches imply (PatchMatch's
        propagation order), so an offset one pixel found crosses its region at once. Four
        candidates per pixel and iteration, within ``max_candidates``. On 19 zoom clips at
        320 x 180 the energy was 3.3 % lower in the geometric mean (one clip 0.8 % higher),
        3.6 % on four clips that did not choose it;
        off by default because the scan runs on one core.
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
    out, matches, stats = _v.complete_video(
        frames, mask, patch, lowres_width, n_levels, lowres_max_iter, init, search,
        patchmatch_n_iter, seed, onion_order, causal_first_sweep, refine_max_iter, windows,
        fine_max_iter, min_energy_drop, temporal_radius, max_candidates, propagate,
        temporal_candidates, hypotheses, scan_propagation, step, global_fine_search,
        return_matches)
    extra = (([matches] if return_matches else [])
             + ([_from_mapping(CompletionStats, stats)] if return_stats else []))
    return (out, *extra) if extra else out


# Negative or too large integers raise IntegerRangeError, a ValueError naming the argument.
_integer_ranges(globals())
