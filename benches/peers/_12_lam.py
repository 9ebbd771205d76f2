"""Development fit of paper 12's noise-aware data weight: Krishnan-Fergus's `lam` as a function
of the input's noise level. Photographs from scikit-image, treated as linear intensities in
[0, 1], blurred with a known kernel (an 11-pixel horizontal box, or a gyro-rendered shake
kernel), plus white Gaussian noise of standard deviation sigma; PSNR (peak 1) without a 16 px
border. The rule is fitted on `camera` only (`fit`), then checked on other photographs
(`check`). Run: python benches/peers/_12_lam.py fit|check|estimator"""

import sys

import numpy as np
from skimage import color, data

from wscg import deblur

SIGMAS = [0.002, 0.005, 0.01, 0.02]
BORDER = 16


def photo(name):
    img = getattr(data, name)()
    if img.ndim == 3:
        img = color.rgb2gray(img)
    img = img.astype(np.float64)
    return img / 255.0 if img.max() > 1.5 else img


def box():
    return np.full((1, 11), 1 / 11)


def gyro_kernel(seed=3):
    g = deblur.make_gyro(0.2, seed=seed)
    k, o = deblur.render_kernel(g, 0.05, 0.03, 600.0, 320, 240, 320, 240)
    return k.astype(np.float64), o


def psnr(x, ref):
    b = BORDER
    e = np.mean((x[b:-b, b:-b] - ref[b:-b, b:-b]) ** 2)
    return 10 * np.log10(1 / e)


def case(sharp, kernel, origin, sigma, seed=0):
    blurred = deblur.convolve(sharp, kernel, origin)
    rng = np.random.default_rng(seed)
    return blurred + sigma * rng.standard_normal(blurred.shape)


def scores(sharp, kernel, origin, sigma, lams, seed=0):
    b = case(sharp, kernel, origin, sigma, seed)
    rl = psnr(deblur.richardson_lucy(b, kernel, origin), sharp)
    ks = [psnr(deblur.deconv_krishnan(b, kernel, origin, lam=lam), sharp) for lam in lams]
    return rl, ks, b


def mad_sigma(b):
    """Donoho's estimator: median |HH| / 0.6745 of the finest diagonal Haar subband."""
    h, w = (b.shape[0] // 2) * 2, (b.shape[1] // 2) * 2
    x = b[:h, :w]
    hh = (x[0::2, 0::2] - x[0::2, 1::2] - x[1::2, 0::2] + x[1::2, 1::2]) / 2
    return np.median(np.abs(hh)) / 0.6745


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "fit"
    if what == "estimator":
        for name in ["camera", "astronaut", "coffee", "chelsea"]:
            s = photo(name)
            for kname, (k, o) in [("box", (box(), None)), ("gyro", gyro_kernel())]:
                ests = [mad_sigma(case(s, k, o, sg)) for sg in SIGMAS]
                print(name, kname, " ".join(f"{sg}:{e:.5f}" for sg, e in zip(SIGMAS, ests)), flush=True)
    elif what == "fit":
        sharp = photo("camera")
        lams = [500, 1000, 2000, 4000, 8000, 16000, 32000, 64000]
        for kname, (k, o) in [("box", (box(), None)), ("gyro", gyro_kernel())]:
            for sg in SIGMAS:
                rl, ks, b = scores(sharp, k, o, sg, lams)
                est = mad_sigma(b)
                best = lams[int(np.argmax(ks))]
                print(f"{kname} sigma {sg} est {est:.5f} RL {rl:.2f} | "
                      + " ".join(f"{l}:{v:.2f}" for l, v in zip(lams, ks))
                      + f" | best {best} c=best*est^2 {best * est ** 2:.3f}", flush=True)
    elif what == "rule":
        # lam = c / sigma_hat^2 for a few c on the fitting photograph.
        sharp = photo("camera")
        cs = [0.15, 0.2, 0.25, 0.3, 0.35, 0.4]
        for kname, (k, o) in [("box", (box(), None)), ("gyro", gyro_kernel())]:
            for sg in SIGMAS:
                b = case(sharp, k, o, sg)
                est = mad_sigma(b)
                rl, ks, _ = scores(sharp, k, o, sg, [c / est ** 2 for c in cs])
                print(f"{kname} sigma {sg} RL {rl:.2f} | " + " ".join(f"{c}:{v:.2f}" for c, v in zip(cs, ks)), flush=True)
    elif what == "check":
        # The frozen rule (wscg.deblur's lam="auto") against the paper's lam and RL on photographs
        # not used for the fit.
        for name in sys.argv[2:] or ["astronaut", "coffee"]:
            sharp = photo(name)
            for kname, (k, o) in [("box", (box(), None)), ("gyro", gyro_kernel(7))]:
                for sg in SIGMAS:
                    b = case(sharp, k, o, sg, seed=1)
                    rl = psnr(deblur.richardson_lucy(b, k, o), sharp)
                    paper = psnr(deblur.deconv_krishnan(b, k, o, lam=2000.0), sharp)
                    lam = 0.3 / max(mad_sigma(b), 1e-3) ** 2  # lam="auto", written out
                    auto = psnr(deblur.deconv_krishnan(b, k, o, lam=lam), sharp)
                    print(f"| {name} | {kname} | {sg} | {rl:.2f} | {paper:.2f} ({paper - rl:+.2f}) | "
                          f"{auto:.2f} ({auto - rl:+.2f}) |", flush=True)
