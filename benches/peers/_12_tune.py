"""Development tuning of paper 12's free parameters on the development image `coffee` only
(spec section 2.6/2.7): the multi-frame weight mu over {lambda/16, ..., lambda} and the
Wiener NSR; the frozen values are the defaults of wscg.deblur. Run: python benches/peers/_12_tune.py"""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "py", "tests"))
from deblur_table1 import mean_table, photo, table1  # noqa: E402

sharp = photo("coffee")
seeds = range(5)
# Measured (2 cores, 5 seeds): mu 125 / 250 / 500 / 1000 / 2000 -> KM3 29.663 / 29.671 /
# 29.510 / 29.228 / 28.906 dB (KS 28.334); frozen: mu = 250 = lambda / 8.
for mu in [125.0, 250.0, 500.0, 1000.0, 2000.0]:
    t = mean_table(sharp, seeds, mu=mu, methods=("KS", "KM3"))
    print(f"mu {mu:6.0f}: KS {t['KS'][0]:.3f} KM3 {t['KM3'][0]:.3f} dB  SSIM {t['KM3'][1]:.4f}", flush=True)

# Baselines: Wiener NSR and Richardson-Lucy iterations on the same bursts.
import numpy as np  # noqa: E402
from deblur_table1 import DELAY, EXPOSURE, F, make_burst, quality  # noqa: E402
from wscg import deblur  # noqa: E402

bursts = [make_burst(sharp, s) for s in seeds]
truth = sharp ** (1 / 2.2)
h, w = sharp.shape


def baseline(**kw):
    scores = []
    for frames, times, gyro in bursts:
        out = deblur.deblur_piecewise(frames[2] ** 2.2, gyro, times[2], EXPOSURE, F, (w - 1) / 2, (h - 1) / 2,
                                      t_delay=DELAY, **kw)
        scores.append(quality(np.clip(out, 0, 1) ** (1 / 2.2), truth))
    return np.mean(scores, axis=0)


for nsr in [0.001, 0.003, 0.01, 0.03, 0.1]:
    print(f"wiener nsr {nsr}: PSNR {baseline(method='wiener', nsr=nsr)[0]:.3f} SSIM {baseline(method='wiener', nsr=nsr)[1]:.4f}", flush=True)
for iters in [10, 20, 30, 60]:
    p, s = baseline(method="rl", rl_n_iter=iters)
    print(f"rl iters {iters}: PSNR {p:.3f} SSIM {s:.4f}", flush=True)
