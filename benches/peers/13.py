"""Paper 13 peers (specification section 5): matching and merging against OpenCV.

* Matching: scikit-image's Middlebury motorcycle pair (500 x 741) with a 1x / 4x exposure
  pair, and a generated 1282 x 1110 two-camera pair (the paper's Aloe size): our epipolar
  PatchMatch (2 and 3 iterations) against `cv2.StereoSGBM(blockSize=7)` on the 8-bit views;
  wall time and bad-2 against the ground truth for both (SGBM also on the views re-encoded
  at a common exposure, which is how a user would feed it differently exposed views).
* Merging: 5 aligned 1282 x 1110 x 3 exposures, our `merge_stack` against
  `cv2.createMergeDebevec().process` with the same (gamma 2.2) response.
* End to end: `multiscopic_hdr` on 3 generated views of 1282 x 1110 (paper: 103 s, i7-2620M).

    python benches/peers/13.py          # needs wscg (release build), opencv, scikit-image
"""

import os
import sys
import time

import cv2
import numpy as np
import skimage.data

sys.path.insert(0, os.path.dirname(__file__))
from _common import best_time, print_table  # noqa: E402

from wscg import hdr  # noqa: E402


def expose(img, k):
    lin = np.clip((img / 255.0) ** 2.2 * k, 0, 1)
    return np.round(lin ** (1 / 2.2) * 255).astype(np.uint8)


def sgbm(left, right, dmax):
    n = int(np.ceil(dmax / 16) * 16)
    m = cv2.StereoSGBM_create(minDisparity=0, numDisparities=n, blockSize=7)
    return lambda: m.compute(left, right)


def bad2_sgbm(disp16, truth):
    d = disp16.astype(np.float32) / 16.0
    ok = np.isfinite(truth)
    valid = ok & (d >= 0)
    # Invalid SGBM pixels (negative) count as bad.
    bad = ~valid | (np.abs(d - truth) > 2)
    return float(np.mean(bad[ok]))


def equalised(er, t_left):
    """The right view re-encoded (gamma 2.2, 8 bits) at the left view's exposure."""
    return np.round(np.clip(er * t_left, 0, 1) ** (1 / 2.2) * 255).astype(np.uint8)


def matching(name, left8, right8, el, er, truth, dmax, rows, quality, t_left):
    for iters in (2, 3):
        f = lambda: hdr.patchmatch(el, er, n_iter=iters, min_disparity=-dmax, max_disparity=0)
        t = best_time(f, repeat=3)
        off, _ = f()
        bad = hdr.bad_rate(off, np.where(np.isfinite(truth), -truth, np.nan), 2.0)
        g = sgbm(cv2.cvtColor(left8, cv2.COLOR_RGB2GRAY), cv2.cvtColor(right8, cv2.COLOR_RGB2GRAY), dmax)
        tp = best_time(g, repeat=3)
        rows.append((f"{name}: ours {iters} it vs SGBM", t, "cv2.StereoSGBM(7)", tp))
        eq = sgbm(cv2.cvtColor(left8, cv2.COLOR_RGB2GRAY),
                  cv2.cvtColor(equalised(er, t_left), cv2.COLOR_RGB2GRAY), dmax)
        quality.append(f"{name}: bad-2 ours ({iters} it) {bad:.3f}, SGBM on the 8-bit views "
                       f"{bad2_sgbm(g(), truth):.3f}, SGBM on exposure-equalised views "
                       f"{bad2_sgbm(eq(), truth):.3f}")


def main():
    rows, quality = [], []
    l, r, d = skimage.data.stereo_motorcycle()
    truth = np.where(np.isfinite(d), d, np.nan).astype(np.float32)
    L, R = expose(l, 1.0), expose(r, 4.0)
    el = hdr.to_radiance(L, "gamma2.2", 1.0)
    er = hdr.to_radiance(R, "gamma2.2", 4.0)
    matching("motorcycle 741x500", L, R, el, er, truth, 64, rows, quality, 1.0)

    sc = hdr.make_scene(height=1110, width=1282, exposure_times=(0.005, 0.04, 0.3), seed=1)
    v0, v1 = sc.views[0], sc.views[1]
    t0, t1 = sc.exposure_times[0], sc.exposure_times[1]
    e0, e1 = hdr.to_radiance(v0, "gamma2.2", t0), hdr.to_radiance(v1, "gamma2.2", t1)
    # View 0 -> view 1: a point at x is at x - d in view 1 (d = layer disparity).
    matching("generated 1282x1110", v0, v1, e0, e1, sc.disparity[0], 48, rows, quality, t0)

    times = [0.005, 0.03, 0.061, 0.122, 0.28]
    rad = sc.radiance[1]
    stack = [np.round(np.clip(rad * t, 0, 1) ** (1 / 2.2) * 255).astype(np.uint8) for t in times]
    resp = np.repeat(((np.arange(256) / 255.0) ** 2.2)[:, None, None], 3, axis=2).astype(np.float32)
    resp[0] = 1e-6  # OpenCV takes the log of the response
    ours = best_time(lambda: hdr.merge_stack(stack, times, "gamma2.2"), repeat=5)
    merger = cv2.createMergeDebevec()
    bgr = [np.ascontiguousarray(s[..., ::-1]) for s in stack]
    tf = np.array(times, dtype=np.float32)
    peer = best_time(lambda: merger.process(bgr, tf, resp), repeat=5)
    rows.append(("merge 5 x 1282x1110x3", ours, "cv2.MergeDebevec", peer))

    t = time.perf_counter()
    hdr.multiscopic_hdr(sc.views, sc.exposure_times, "gamma2.2", max_disparity=70)
    e2e = time.perf_counter() - t
    print_table("Paper 13: matching and merging (OpenCV peers)", rows)
    for q in quality:
        print(q)
    print(f"multiscopic_hdr 3 views 1282x1110, 2 it: {e2e:.2f} s (paper: 103 +- 10 s, i7-2620M)")


if __name__ == "__main__":
    main()
