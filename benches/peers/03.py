"""Paper 03 (hybrid ROI visualisation): the server's block Haar codec against PyWavelets.

Workload (spec section 5): the 4-step 3-D Haar transform of every 16^3 block of a volume,
``pywt.wavedecn(blocks, 'haar', mode='periodization', level=4, axes=(1, 2, 3))`` on the
``(n_blocks, 16, 16, 16)`` float32 array against ``wscg.volren.haar_blocks`` on the same
array (transform only, no quantisation or coding; both produce every coefficient). Volumes:
the head phantom at the paper's skull size (256 x 256 x 112, 1792 blocks) and the thorax
phantom at 256^3 (4096 blocks). pytest checks that the coefficients agree up to the
per-level scale (test_block_haar_matches_pywavelets).

The rendering comparison of the specification (VTK's fixed-point ray cast mapper on the
full-resolution volume) is not part of this script.
"""

import os
import sys

import numpy as np
import pywt

from wscg import volren as V

sys.path.insert(0, os.path.dirname(__file__))
from _common import best_time, print_table  # noqa: E402


def blocks_of(vol):
    z, y, x = (s // 16 * 16 for s in vol.shape)
    v = vol[:z, :y, :x].astype(np.float32)
    b = v.reshape(z // 16, 16, y // 16, 16, x // 16, 16).transpose(0, 2, 4, 1, 3, 5)
    return np.ascontiguousarray(b.reshape(-1, 16, 16, 16))


rows = []
for name, shape in [("head", (112, 256, 256)), ("thorax", (256, 256, 256))]:
    blocks = blocks_of(V.phantom(name, shape, seed=1))
    ours = best_time(lambda: V.haar_blocks(blocks), repeat=5)
    peer = best_time(lambda: pywt.wavedecn(blocks, "haar", mode="periodization", level=4,
                                           axes=(1, 2, 3)), repeat=3)
    rows.append((f"{name} {len(blocks)} blocks 16^3, 4 steps", ours, "pywt.wavedecn haar", peer))
print_table("paper 03: block Haar transform, wscg.volren vs PyWavelets", rows)
