"""Paper 05 (class-wise slow feature analysis): wscg.biometrics against the numpy/scipy
pipeline a user would otherwise write, and against MDP's ``SFA2Node`` for temporal SFA.

Workloads (spec section 5):
- the synthetic hand-pose set with the paper's protocol (3000 frames per class, 300 test
  frames per class, 1000 rotated training copies per class): 18500 training rows of 2200
  pixels. ``PerClassSFA`` fit against ``PCA(35) -> PolynomialFeatures(2, include_bias=False)
  -> per class scipy.linalg.eigh(A_C, B, subset_by_index=[0, 9])`` (A_C = 2 S_C - (S_C +
  S_not + d d'), eq. 14 in closed form; B the covariance of the expanded rows), and predict
  of 10000 rows against the same pipeline's projection and variance rule (eq. 17). Targets:
  fit >= 2x, predict >= 5x faster; predictions identical, per-class response subspaces
  within 1e-6 rad.
- temporal SFA on a 100000 x 35 signal (the signal of ``benches/biometrics.rs``): quadratic
  ``TemporalSFA(10)`` against ``mdp.nodes.SFA2Node(output_dim=10)``. Target >= 1.5x faster;
  output subspaces within 1e-6 rad.

MDP 3.6 predates numpy 2: the script restores ``numpy.typeDict`` and gives MDP a numpy
``eigh`` with an inspectable signature before importing it, and selects MDP's numpy backend
(its scipy backend imports ``scipy.random``, which scipy no longer has).
"""

import os
import sys

import numpy as np
import scipy.linalg
from sklearn.decomposition import PCA
from sklearn.preprocessing import PolynomialFeatures

from wscg import biometrics as B

sys.path.insert(0, os.path.dirname(__file__))
from _common import best_time, print_table  # noqa: E402


def import_mdp():
    os.environ["MDPNUMX"] = "numpy"
    np.typeDict = np.sctypeDict
    eigh = np.linalg.eigh

    def eigh_signature(a, UPLO="L"):
        return eigh(a, UPLO)

    np.linalg.eigh = eigh_signature
    import mdp

    return mdp


def mixed_sines(t):
    """Channel j: sin(2 pi i/t (j + 1) + j) + 0.3 * uniform noise from splitmix64(35 i + j)."""
    i = np.arange(t, dtype=np.uint64)[:, None]
    j = np.arange(35, dtype=np.uint64)[None, :]
    z = i * np.uint64(35) + j + np.uint64(0x9E3779B97F4A7C15)
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    z ^= z >> np.uint64(31)
    noise = 2.0 * (z >> np.uint64(11)).astype(np.float64) / 2.0**53 - 1.0
    s = np.arange(t)[:, None] / t * 2 * np.pi
    return np.sin(s * (np.arange(35) + 1) + np.arange(35)) + 0.3 * noise


class NumpySFA:
    """The numpy/scipy reference of the class-wise SFA (same equations, no rank handling)."""

    def __init__(self, pca_dims=35, m=10):
        self.pca = PCA(pca_dims)
        self.poly = PolynomialFeatures(2, include_bias=False)
        self.m = m

    def fit(self, X, y):
        Z = self.poly.fit_transform(self.pca.fit_transform(X))
        Bm = np.cov(Z, rowvar=False, bias=True)
        self.classes_ = np.unique(y)
        self.W, self.mu = [], []
        for c in self.classes_:
            inc, out = Z[y == c], Z[y != c]
            Sc = np.cov(inc, rowvar=False, bias=True)
            Sn = np.cov(out, rowvar=False, bias=True)
            d = inc.mean(0) - out.mean(0)
            A = 2 * Sc - (Sc + Sn + np.outer(d, d))
            _, W = scipy.linalg.eigh(A, Bm, subset_by_index=[0, self.m - 1])
            self.W.append(W)
            self.mu.append(inc.mean(0))
        return self

    def responses(self, X, k):
        Z = self.poly.transform(self.pca.transform(X))
        return (Z - self.mu[k]) @ self.W[k]

    def predict(self, X):
        Z = self.poly.transform(self.pca.transform(X))
        var = np.column_stack([(((Z - mu) @ W) ** 2).sum(1) for W, mu in zip(self.W, self.mu)])
        return self.classes_[var.argmin(1)]


masks, _, labels, _ = B.make_hand_poses(3000, seed=0)
split = B.hand_pose_split(masks, labels, 300, 1000, seed=0)
Xtr, ytr = split.X_train, split.y_train
Xq = Xtr[(np.arange(10_000) * 7) % len(Xtr)]
print(f"hand poses: {Xtr.shape[0]} training rows x {Xtr.shape[1]} pixels, "
      f"{len(Xq)} rows to predict")

ours = B.PerClassSFA(shrinkage=0.0).fit(Xtr, ytr)
ref = NumpySFA().fit(Xtr, ytr)
t_fit = best_time(lambda: B.PerClassSFA(shrinkage=0.0).fit(Xtr, ytr), repeat=3)
t_fit_ref = best_time(lambda: NumpySFA().fit(Xtr, ytr), repeat=3)
t_pred = best_time(lambda: ours.predict(Xq), repeat=5)
t_pred_ref = best_time(lambda: ref.predict(Xq), repeat=5)

signal = mixed_sines(100_000)
mdp = import_mdp()


def mdp_fit():
    node = mdp.nodes.SFA2Node(output_dim=10)
    node.train(signal)
    node.stop_training()
    return node


t_tsfa = best_time(lambda: B.TemporalSFA(10).fit(signal), repeat=3)
t_mdp = best_time(mdp_fit, repeat=3)
rows = [
    ("PerClassSFA fit 18500x2200", t_fit, "numpy PCA+poly+scipy eigh", t_fit_ref),
    ("PerClassSFA predict 10000x2200", t_pred, "numpy PCA+poly+variance", t_pred_ref),
    ("TemporalSFA(10) quadratic 100000x35", t_tsfa, "mdp SFA2Node(10)", t_mdp),
]
print_table("paper 05: class-wise and temporal SFA", rows)

print()
agree = np.mean(ours.predict(Xq) == ref.predict(Xq))
Xs = split.X_test
angles = [scipy.linalg.subspace_angles(ours.responses(Xs, c), ref.responses(Xs, k)).max()
          for k, c in enumerate(ref.classes_)]
print(f"class-wise SFA: predictions agree on {100 * agree:.2f} % of {len(Xq)} rows; largest "
      f"angle between per-class response subspaces on the test rows {max(angles):.2e} rad")
exact = NumpySFA()
exact.pca = PCA(35, svd_solver="full")
exact.fit(Xtr, ytr)
angles = [scipy.linalg.subspace_angles(ours.responses(Xs, c), exact.responses(Xs, k)).max()
          for k, c in enumerate(exact.classes_)]
print(f"  with an exact PCA (svd_solver='full') in the reference: {max(angles):.2e} rad, "
      f"predictions agree on {100 * np.mean(ours.predict(Xq) == exact.predict(Xq)):.2f} %")
tsfa = B.TemporalSFA(10).fit(signal)
node = mdp_fit()
angle = scipy.linalg.subspace_angles(tsfa.transform(signal), node.execute(signal)).max()
print(f"temporal SFA: largest angle between our and MDP's output subspaces {angle:.2e} rad; "
      f"delta values ours {tsfa.delta_values_[:3].round(6)}, MDP {node.d[:3].round(6)}")
