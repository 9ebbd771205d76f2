"""Paper 12 peers: one 720x480 frame (scikit-image's `coffee`, upsampled bicubically, shaken by
the Table-1 gyro model) deblurred region by region (24 x 16 regions of 30 px, each with its gyro
kernel, on a window of kernel radius + 4 px margin): our Krishnan-Fergus, Wiener and
Richardson-Lucy against scikit-image's `richardson_lucy(num_iter=30, clip=False)` and
`wiener(balance=0.01)` called per region from a Python loop (they take one uniform PSF), as in
spec section 5. Prints times, ratios and the PSNR of every result; then the full 5-frame
multi-frame pipeline (paper: 18 s on a Core i7-4700MQ).

    python benches/peers/12.py          # needs wscg (release build), scikit-image
"""

import os
import sys
import time

import numpy as np
from skimage import restoration, transform

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "py", "tests"))
from deblur_table1 import DELAY, EXPOSURE, F, make_burst, photo, quality  # noqa: E402

from wscg import deblur  # noqa: E402


def best(f, repeat=3):
    times, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t)
    return min(times), out


def tile_loop(lin, kernels, fn, tile=30):
    h, w = lin.shape
    rows, cols, ksz, _ = kernels.shape
    pad = ksz // 2 + 16
    padded = np.pad(lin, pad, mode="symmetric")
    out = np.zeros_like(lin)
    for r in range(rows):
        for c in range(cols):
            k = kernels[r, c]
            nz = np.nonzero(k)
            rad = int(max(np.abs(nz[0] - ksz // 2).max(), np.abs(nz[1] - ksz // 2).max()))
            k = k[ksz // 2 - rad:ksz // 2 + rad + 1, ksz // 2 - rad:ksz // 2 + rad + 1]
            m = max(8, rad + 4)
            y0, x0 = r * tile, c * tile
            ch, cw = min(tile, h - y0), min(tile, w - x0)
            win = padded[y0 + pad - m:y0 + pad + ch + m, x0 + pad - m:x0 + pad + cw + m]
            out[y0:y0 + ch, x0:x0 + cw] = fn(win, k)[m:m + ch, m:m + cw]
    return out


def main():
    sharp = photo("coffee")
    sharp = np.clip(transform.resize(sharp, (480, 720), order=3, anti_aliasing=False), 0, 1)
    frames, times, gyro = make_burst(sharp, seed=0)
    h, w = sharp.shape
    cx, cy = (w - 1) / 2, (h - 1) / 2
    truth = sharp ** (1 / 2.2)
    lin = (frames[2] ** 2.2).astype(np.float64)
    kernels = deblur.kernel_grid(gyro, times[2], EXPOSURE, F, cx, cy, h, w, t_delay=DELAY)

    def q(x):
        return quality(np.clip(x, 0, 1) ** (1 / 2.2), truth)[0]

    def ours(method, **kw):
        return lambda: deblur.deblur_piecewise(lin, gyro, times[2], EXPOSURE, F, cx, cy,
                                               t_delay=DELAY, method=method, **kw)

    print(f"720x480, {kernels.shape[0]}x{kernels.shape[1]} regions, blurry input PSNR {q(lin):.2f} dB")
    t_ks, ks = best(ours("krishnan"))
    t_w, wi = best(ours("wiener", nsr=0.01))
    t_rl, rl = best(ours("rl", rl_n_iter=30))
    t_skrl, skrl = best(lambda: tile_loop(lin, kernels, lambda x, k: restoration.richardson_lucy(
        x, k, num_iter=30, clip=False)), repeat=1)
    t_skw, skw = best(lambda: tile_loop(lin, kernels, lambda x, k: restoration.wiener(x, k, balance=0.01)))
    rows = [
        ("KS (ours) vs skimage RL 30 it loop", t_ks, t_skrl, q(ks), q(skrl)),
        ("KS (ours) vs skimage Wiener loop", t_ks, t_skw, q(ks), q(skw)),
        ("RL 30 it: ours vs skimage loop", t_rl, t_skrl, q(rl), q(skrl)),
        ("Wiener: ours vs skimage loop", t_w, t_skw, q(wi), q(skw)),
    ]
    for name, a, b, pa, pb in rows:
        print(f"{name:40s} ours {a * 1e3:9.1f} ms  peer {b * 1e3:9.1f} ms  peer/ours {b / a:6.2f}x"
              f"  PSNR ours {pa:.2f} dB, peer {pb:.2f} dB")
    t_km, km = best(lambda: deblur.deblur_multiframe(frames, times, gyro, F, cx, cy, EXPOSURE,
                                                     t_delay=DELAY), repeat=2)
    print(f"{'multi-frame KM, 5 frames 720x480':40s} ours {t_km:9.3f} s   (paper: 18 s, i7-4700MQ)"
          f"  PSNR {quality(km.image, truth)[0]:.2f} dB")


if __name__ == "__main__":
    main()
