"""Paper 11 tuning protocol: grid search of every method's parameters on the development
image (scikit-image's astronaut, grey, 256^2, with a smooth phase; Cartesian 40%, mask seed
2), 70 iterations each. The chosen values are frozen in py/tests/test_csmri.py, which then
compares the methods on a different image (the camera).

    python benches/peers/_11_tune.py
"""

import itertools

import numpy as np
from skimage import color, data

from wscg import csmri

TAU = [0.005, 0.01, 0.02, 0.04, 0.08]
A = [0.0005, 0.001, 0.002, 0.004, 0.008]
B = [0.0025, 0.005, 0.01, 0.02, 0.035]


def half(img):
    return img.reshape(img.shape[0] // 2, 2, img.shape[1] // 2, 2).mean(axis=(1, 3))


def development_case():
    g = half(color.rgb2gray(data.astronaut()))
    img = csmri.with_smooth_phase(g, seed=3)
    mask = csmri.mask_cartesian(img.shape, 0.4, seed=2)
    return csmri.simulate(img, mask), mask, img


def main():
    k, m, img = development_case()
    runs = [("udct (J=1) l1", dict(prior="udct")), ("db4 l1", dict(prior="db4")),
            ("fdct l1", dict(prior="fdct")),
            ("udct (J=3) l1", dict(wedges=[[6, 6]] * 3)),
            ("udct (J=3) tv", dict(wedges=[[6, 6]] * 3, reg="tv"))]
    for label, kw in runs:
        res = {t: csmri.psnr(img, csmri.reconstruct(k, m, tau0=t, **kw)) for t in TAU}
        best = max(res, key=res.get)
        print(f"{label}: " + ", ".join(f"{t}: {v:.2f}" for t, v in res.items()) + f" -> tau0 = {best}")
    for name, f in [("fcsa", csmri.fcsa), ("tvcmri", csmri.tvcmri), ("watmri", csmri.watmri)]:
        res = {(a, b): csmri.psnr(img, f(k, m, a=a, b=b)) for a, b in itertools.product(A, B)}
        best = max(res, key=res.get)
        print(f"{name}: best {res[best]:.2f} dB at a = {best[0]}, b = {best[1]}")


if __name__ == "__main__":
    main()
