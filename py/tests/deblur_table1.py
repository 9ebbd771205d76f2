"""Table-1 analogue of paper 12 (section 6.2): a photograph shaken by Ornstein-Uhlenbeck
hand shake, rendered densely into a 5-frame burst (30 Hz, t_e = 30 ms, f = 600, t_d = 15 ms,
noise 0.005, gamma 2.2, 8 bit), the middle frame restored by every method of Table 1.
Shared by the tests and by ``benches/peers/_12_tune.py``."""

import numpy as np
from skimage import color, data
from skimage.metrics import structural_similarity

from wscg import deblur

F, EXPOSURE, DELAY, FPS = 600.0, 0.03, 0.015, 30.0


def photo(name):
    img = getattr(data, name)()
    if img.ndim == 3:
        img = color.rgb2gray(img[..., :3])
    else:
        img = img / 255.0
    return np.clip(img, 0, 1) ** 2.2


def make_burst(sharp, seed, frames=5, std=(0.35, 0.35, 0.10), gyro_noise=0.002):
    h, w = sharp.shape
    cx, cy = (w - 1) / 2, (h - 1) / 2
    times = 0.1 + np.arange(frames) / FPS
    truth = deblur.make_gyro(times[-1] + 0.3, std=std, seed=seed)
    measured = deblur.add_gyro_noise(truth, gyro_noise, seed=seed + 1000)
    world = times[frames // 2] + DELAY
    out = [deblur.render_blurred(sharp, truth, t, EXPOSURE, F, cx, cy, world, t_delay=DELAY,
                                 seed=seed * 31 + i) for i, t in enumerate(times)]
    return out, times, measured


def quality(img, truth_display, border=16):
    a = np.round(np.clip(img, 0, 1) * 255)[border:-border, border:-border]
    b = np.round(np.clip(truth_display, 0, 1) * 255)[border:-border, border:-border]
    p = 10 * np.log10(255.0 ** 2 / np.mean((a - b) ** 2))
    s = structural_similarity(a, b, gaussian_weights=True, sigma=1.5, use_sample_covariance=False,
                              data_range=255)
    return p, s


def table1(sharp, seed, mu=None, lam=2000.0, methods=("B", "W", "RL", "KS", "KM3", "KM5")):
    """{method: (psnr, ssim)} for one burst."""
    frames, times, gyro = make_burst(sharp, seed)
    h, w = sharp.shape
    cx, cy = (w - 1) / 2, (h - 1) / 2
    truth = sharp ** (1 / 2.2)
    main = len(frames) // 2
    kw = dict(lam=lam) if mu is None else dict(lam=lam, mu=mu)
    res = {}
    lin = frames[main] ** 2.2
    for m in methods:
        if m == "B":
            res[m] = quality(frames[main], truth)
        elif m in ("W", "RL", "GU"):
            name = {"W": "wiener", "RL": "rl", "GU": "global"}[m]
            out = deblur.deblur_piecewise(lin, gyro, times[main], EXPOSURE, F, cx, cy, t_delay=DELAY,
                                          method=name, lam=lam)
            res[m] = quality(np.clip(out, 0, 1) ** (1 / 2.2), truth)
        elif m in ("KS", "KM3", "KM5", "KM3-linear"):
            radius = 2 if m == "KM5" else 1
            gamma = None if m.endswith("linear") else 2.2
            r = deblur.deblur_multiframe(frames, times, gyro, F, cx, cy, EXPOSURE, t_delay=DELAY,
                                         temporal_radius=radius, gamma=gamma, **kw)
            res[m] = quality(r.single if m == "KS" else r.image, truth)
    return res


def mean_table(sharp, seeds, **kw):
    runs = [table1(sharp, s, **kw) for s in seeds]
    return {m: tuple(np.mean([r[m][i] for r in runs]) for i in range(2)) for m in runs[0]}
