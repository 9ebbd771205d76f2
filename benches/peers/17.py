"""Paper 17 (Kinect gait recognition with joint relative angles and a DTW kernel) against
dtaidistance, the fast C/OpenMP DTW library a user would pick (spec section 5).

Workload: 300 synthetic Kinect walks (100 subjects x 3 sessions, seed 17), one gait cycle
each (28-42 frames), 100 joint-pair JRA channels (every other pair of the first 200 in the
276-pair order, as benches/gait.rs). The full symmetric 300 x 300 matrix of the DTW kernel
Delta = sum over channels of DTW with the squared local cost.

- ours: ``wscg.gait.dissimilarity_matrix(walks, cost="squared")`` (all pairs once, channels
  fused 8 per SIMD pass, rayon over the pairs);
- peer: dtaidistance has no independent multivariate kernel (its issue #94: "add the results
  of 1-dim DTW"), so Delta is the sum over the 100 channels of
  ``dtaidistance.dtw.distance_matrix_fast(channel_series, parallel=True)`` squared (its DTW
  returns the square root of the accumulated squared cost).
The two matrices are checked equal (relative 1e-9) before timing.

The dependent multivariate DTW (one warp path over the 100 channels, squared Euclidean frame
cost) on the same walks:

- ours: ``wscg.gait.dissimilarity_matrix(walks, cost="squared", multivariate="dependent")``
  (frame-major copies made once, rayon over the pairs, no allocation per pair);
- peer: ``dtaidistance.dtw_ndim.distance_matrix_fast(frames, parallel=True)`` squared (it
  returns the square root of the accumulated squared cost), frames ``(T, 100)`` per walk.

Also timed: one DTW of two cycles (``wscg.gait.dtw`` against ``dtaidistance.dtw.distance_fast``), each called from Python.

Environment: WSCG_REPEAT (timing repeats, default 3).
"""

import os
import sys

import numpy as np
from dtaidistance import dtw as ddtw
from dtaidistance import dtw_ndim

from wscg import gait as G

sys.path.insert(0, os.path.dirname(__file__))
from _common import best_time, print_table  # noqa: E402

REPEAT = int(os.environ.get("WSCG_REPEAT", "3"))

data = G.make_walkers(n_subjects=100, n_sessions=3, seed=17)
walks = [G.jra_sequences(f)[0:200:2] for f in data.frames]
lengths = [w.shape[1] for w in walks]
channels = [[np.ascontiguousarray(w[c]) for w in walks] for c in range(100)]


def ours():
    return G.dissimilarity_matrix(walks, cost="squared")


def peer():
    total = np.zeros((len(walks), len(walks)))
    for series in channels:
        d = ddtw.distance_matrix_fast(series, parallel=True)
        d = np.where(np.isfinite(d), d, 0.0)  # the lower triangle is left at inf
        total += d * d
    return np.maximum(total, total.T)


a, b = ours(), peer()
err = np.max(np.abs(a - b) / np.maximum(np.abs(b), 1.0))
assert err < 1e-9, f"matrices differ: {err}"
print(f"300 walks, 100 channels, cycle lengths {min(lengths)}-{max(lengths)} frames; "
      f"max relative difference of the two Delta matrices {err:.1e}")

frames = [np.ascontiguousarray(w.T) for w in walks]


def ours_dep():
    return G.dissimilarity_matrix(walks, cost="squared", multivariate="dependent")


def peer_dep():
    d = dtw_ndim.distance_matrix_fast(frames, parallel=True)
    d = np.where(np.isfinite(d), d, 0.0)
    d = d * d
    return np.maximum(d, d.T)


a, b = ours_dep(), peer_dep()
err_dep = np.max(np.abs(a - b) / np.maximum(np.abs(b), 1.0))
assert err_dep < 1e-9, f"dependent matrices differ: {err_dep}"
print(f"dependent DTW: max relative difference of the two matrices {err_dep:.1e}")

x, y = channels[0][0], channels[0][1]
assert abs(G.dtw(x, y, cost="squared") - ddtw.distance_fast(x, y) ** 2) < 1e-9
rows = [
    ("Delta matrix 300 walks x 100 pairs", best_time(ours, REPEAT), "dtaidistance matrix_fast x100",
     best_time(peer, REPEAT)),
    ("dependent DTW matrix 300 walks x 100 channels", best_time(ours_dep, REPEAT),
     "dtaidistance dtw_ndim matrix_fast", best_time(peer_dep, REPEAT)),
    (f"1000 DTWs {len(x)} x {len(y)} (Python calls)",
     best_time(lambda: [G.dtw(x, y, cost="squared") for _ in range(1000)], REPEAT),
     "dtaidistance distance_fast",
     best_time(lambda: [ddtw.distance_fast(x, y) for _ in range(1000)], REPEAT)),
]
print_table("paper 17: DTW kernel matrix against dtaidistance (ratio > 1: wscg faster)", rows)
