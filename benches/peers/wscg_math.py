"""wscg.math against numpy, scipy and scikit-image on the workloads of benches/math.rs."""

import os
import sys

import numpy as np
import scipy.sparse
import scipy.sparse.linalg
from skimage.metrics import structural_similarity

import wscg.math as wm

sys.path.insert(0, os.path.dirname(__file__))
from _common import best_time, print_table  # noqa: E402

rows = []
rng = np.random.default_rng(0)

# FFT 2-D, 1024 x 1024 complex128.
x = rng.standard_normal((1024, 1024)) + 0j
assert np.allclose(wm.fft2(x), np.fft.fft2(x), atol=1e-8)
rows.append(("fft2_1024x1024", best_time(lambda: wm.fft2(x)), "numpy.fft.fft2",
             best_time(lambda: np.fft.fft2(x))))

# Jacobi-preconditioned CG on the 7-point 3-D Poisson matrix, 100^3 = 1M unknowns, rtol 1e-6.
indptr, indices, data = wm.laplacian_3d(100, 100, 100)
n = len(indptr) - 1
a = scipy.sparse.csr_matrix((data, indices, indptr), shape=(n, n))
b = np.ones(n)
inv_diag = scipy.sparse.diags(1.0 / a.diagonal())


def ours_cg():
    return wm.cg(indptr, indices, data, b, tol=1e-6, max_iter=2000, preconditioner="jacobi")


def scipy_cg():
    try:
        return scipy.sparse.linalg.cg(a, b, rtol=1e-6, maxiter=2000, M=inv_diag)
    except TypeError:  # scipy < 1.12 names it tol
        return scipy.sparse.linalg.cg(a, b, tol=1e-6, maxiter=2000, M=inv_diag)


xo, info = ours_cg()
xs, _ = scipy_cg()
assert info.converged and np.linalg.norm(xo - xs) <= 1e-4 * np.linalg.norm(xs)
rows.append(("pcg_poisson3d_100^3_tol1e-6", best_time(ours_cg, repeat=3), "scipy.sparse.linalg.cg",
             best_time(scipy_cg, repeat=3)))

# SSIM, 2048 x 2048 float, Gaussian window (Wang et al. 2004).
img = rng.random((2048, 2048))
noisy = img + 0.05 * rng.standard_normal(img.shape)
kw = dict(data_range=1.0, gaussian_weights=True, sigma=1.5, use_sample_covariance=False)
assert abs(wm.ssim(img, noisy, data_range=1.0) - structural_similarity(img, noisy, **kw)) < 1e-4
rows.append(("ssim_2048x2048", best_time(lambda: wm.ssim(img, noisy, data_range=1.0), repeat=3),
             "skimage structural_similarity",
             best_time(lambda: structural_similarity(img, noisy, **kw), repeat=3)))

print_table("wscg.math vs numpy / scipy / scikit-image", rows)
