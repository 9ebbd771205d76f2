"""Paper 01 (FDKECA): wscg.biometrics against scikit-learn on the same synthetic images.

Workloads (spec section 5 and issue 3): fit on N training images plus transform of 1000
test images, l = 100 components.
- d = 256 (16 x 16), N = 4000: FDKECA vs KernelPCA(eigen_solver="dense") (the algorithmic
  comparison), our KernelPCA vs scikit-learn's (same algorithm), our PCA vs
  PCA(svd_solver="full").
- d = 1024 (32 x 32), N = 400, 2000, 8000: FDKECA and PCA against scikit-learn's KernelPCA
  and PCA, showing FDKECA's flat cost in N.
"""

import os
import sys

import numpy as np
from sklearn.decomposition import PCA as SkPCA
from sklearn.decomposition import KernelPCA as SkKernelPCA

from wscg import biometrics as B

sys.path.insert(0, os.path.dirname(__file__))
from _common import best_time, print_table  # noqa: E402

L = 100


def images(n, side, seed):
    X, _ = B.make_finger_veins(n_subjects=n // 10, n_per_subject=10, size=(side, side),
                               canvas=(4 * side, 4 * side), seed=seed)
    return X.reshape(n, -1)


def fit_transform(model, Xtr, Xte):
    return lambda: model.fit(Xtr).transform(Xte)


rows = []
Xtr, Xte = images(4000, 16, 0), images(1000, 16, 1)
fd = B.FDKECA(n_components=L)
kp = B.KernelPCA(n_components=L)
kp.fit(Xtr[:500])
gamma = 1.0 / (2.0 * kp.sigma_ ** 2)
sk_kpca = SkKernelPCA(n_components=L, kernel="rbf", gamma=gamma, eigen_solver="dense")
t_sk_kpca = best_time(fit_transform(sk_kpca, Xtr, Xte), repeat=3)
rows.append(("FDKECA N=4000 d=256 l=100", best_time(fit_transform(fd, Xtr, Xte)),
             "KernelPCA dense", t_sk_kpca))
ours_kpca = B.KernelPCA(n_components=L, sigma=kp.sigma_)
Z, R = ours_kpca.fit(Xtr).transform(Xte), sk_kpca.fit(Xtr).transform(Xte)
assert np.max(np.abs(np.abs(Z) - np.abs(R))) <= 1e-6 * np.max(np.abs(R))
rows.append(("KernelPCA N=4000 d=256 l=100",
             best_time(fit_transform(ours_kpca, Xtr, Xte), repeat=3),
             "KernelPCA dense", t_sk_kpca))
rows.append(("PCA N=4000 d=256 l=100", best_time(fit_transform(B.PCA(n_components=L), Xtr, Xte)),
             "PCA full", best_time(fit_transform(SkPCA(L, svd_solver="full"), Xtr, Xte))))

Xte = images(1000, 32, 1)
for n in (400, 2000, 8000):
    Xtr = images(n, 32, 0)
    reps = 1 if n == 8000 else 3
    t_fd = best_time(fit_transform(B.FDKECA(n_components=L), Xtr, Xte), repeat=reps)
    sk = SkKernelPCA(n_components=L, kernel="rbf", gamma=1.0 / Xtr.shape[1],
                     eigen_solver="dense")
    rows.append((f"FDKECA N={n} d=1024 l=100", t_fd, "KernelPCA dense",
                 best_time(fit_transform(sk, Xtr, Xte), repeat=reps, warmup=0 if n == 8000 else 1)))
    rows.append((f"PCA N={n} d=1024 l=100",
                 best_time(fit_transform(B.PCA(n_components=L), Xtr, Xte), repeat=reps),
                 "PCA full",
                 best_time(fit_transform(SkPCA(L, svd_solver="full"), Xtr, Xte), repeat=reps)))

print_table("paper 01: wscg.biometrics vs scikit-learn (fit + transform of 1000 images)", rows)
