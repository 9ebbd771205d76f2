"""Paper 16 (predictive human movement coordination): synthesis and demixing against
scikit-learn and a numpy reference, on the seeded synthetic walker (spec section 5).

1. SVR path: the 1200 x 255 map evaluations of 10 s at 120 fps (51 channels x 5 sources per
   frame, each a delayed follower state on the unit circle) with
   ``sklearn.svm.SVR(kernel="rbf", C=10, epsilon=0.01, gamma=2.0).predict``, single thread,
   fitted on our ``SvrMap`` training set (200 phases on the rings 0.9 / 1.0 / 1.1 of the first
   learned source). Ours: the same evaluations through ``svr_fit_predict`` (its fit
   subtracted), and whole syntheses of 10 s (``Synthesizer.run``, per 1200 frames) with SVR
   and LUT maps. Spec targets: SVR path <= 1.0x sklearn's time, LUT path >= 200x faster.
2. ``fit_anechoic`` (R = 10, I = 51, N = 100, J = 3, K = 8, shared delays, PCA start, one
   run, 100 sweeps, tol 0) against a numpy reference of the same Fourier-domain ALS (written
   below after crates/motion/src/anechoic.rs): per-harmonic complex normal equations for the
   sources, per-row real least squares for the weights, coordinate-wise delays maximising the
   trigonometric gain polynomial (grid of 32 K points + Newton), gauge fixing. Spec target:
   >= 20x faster; < 5 ms per sweep.
3. PCA quality ``Q_PCA(J)`` against ``sklearn.decomposition.PCA`` (and ``FastICA`` as an
   extra baseline of Q at J = 3) on the same data.

OpenBLAS gets one thread (``OPENBLAS_NUM_THREADS=1`` unless set): at these sizes (J x J
solves, a 510 x 100 SVD) its worker threads do not make numpy faster (the ALS reference took
251-258 ms with one thread and 291-310 ms with two on the 2-core VM), and after each call
they spin on the cores our pool runs on (our fit took 15.4-15.8 ms after the numpy runs,
11.3-12.5 ms with one BLAS thread).

Environment: WSCG_REPEAT (timing repeats, default 5).
"""

import os
import sys
import time
import warnings

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # before numpy loads OpenBLAS

import numpy as np  # noqa: E402
from sklearn.decomposition import PCA, FastICA  # noqa: E402
from sklearn.svm import SVR  # noqa: E402

from wscg import motion as M  # noqa: E402

sys.path.insert(0, os.path.dirname(__file__))
from _common import best_time, print_table  # noqa: E402

REPEAT = int(os.environ.get("WSCG_REPEAT", "5"))
FPS = 120.0
FRAMES = 1200
SVR_KW = dict(C=10.0, epsilon=0.01, gamma=2.0)
J, K, SWEEPS = 3, 8, 100


def timed(fn):
    t = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t


# ------------------------------------------------------------------------------------------
# numpy reference of the Fourier-domain ALS with shared delays (crates/motion/src/anechoic.rs)


class NumpyAls:
    def __init__(self, x, j, k):
        r, i, n = x.shape
        self.r, self.i, self.n, self.j, self.k = r, i, n, j, k
        self.ks = np.arange(1, k + 1)
        self.X = np.fft.fft(x, axis=-1)[..., 1:k + 1] / n  # (R, I, K)
        self.total = float(np.sum(x * x))
        self.out_band = max(self.total - 2.0 * n * float(np.sum(np.abs(self.X) ** 2)), 0.0)
        # PCA start: top-J right singular vectors of the (R I) x N matrix, zero delays.
        _, _, vt = np.linalg.svd(x.reshape(r * i, n), full_matrices=False)
        self.c = np.fft.fft(vt[:j], axis=-1)[:, 1:k + 1] / n  # (J, K)
        self.tau = np.zeros((i, j))
        self.w = np.ones((r, i, j))
        self.update_weights()
        self.normalize()

    def phasors(self, tau):
        return np.exp(-2j * np.pi * tau[..., None] * self.ks)

    def model(self):
        ph = self.phasors(self.tau)  # (I, J, K)
        return np.einsum("rij,ijk,jk->rik", self.w, ph, self.c)

    def quality(self):
        err = self.out_band + 2.0 * self.n * float(np.sum(np.abs(self.X - self.model()) ** 2))
        return 1.0 - err / self.total

    def update_sources(self):
        a = self.w[..., None] * self.phasors(self.tau)[None]  # (R, I, J, K)
        a = a.reshape(self.r * self.i, self.j, self.k)
        h = np.einsum("njk,nqk->kjq", a.conj(), a)
        rhs = np.einsum("njk,nk->kj", a.conj(), self.X.reshape(self.r * self.i, self.k))
        h += 1e-12 * np.trace(h, axis1=1, axis2=2).real[:, None, None] * np.eye(self.j)
        self.c = np.linalg.solve(h, rhs[..., None])[..., 0].T

    def update_weights(self):
        b = self.phasors(self.tau) * self.c[None]  # (I, J, K)
        g = np.einsum("ipk,iqk->ipq", b, b.conj()).real  # shared by all trials
        h = np.einsum("rik,ipk->rip", self.X, b.conj()).real
        g = np.broadcast_to(g, (self.r,) + g.shape)
        self.w = np.linalg.solve(g, h[..., None])[..., 0]

    def trig_argmax(self, g):
        """Row-wise global maximum over tau of Re sum_k g_k e^{-2 pi i k tau}."""
        m = max(32 * self.k, 64)
        grid = np.arange(m) / m
        f = (g @ np.exp(-2j * np.pi * np.outer(self.ks, grid))).real
        best = np.argmax(f, axis=1)
        tau, fb = grid[best], f[np.arange(len(g)), best]
        for _ in range(8):
            z = g * np.exp(-2j * np.pi * np.outer(tau, self.ks))
            d1 = (z * (-2j * np.pi * self.ks)).real.sum(axis=1)
            d2 = -(z.real * (2 * np.pi * self.ks) ** 2).sum(axis=1)
            cand = np.where(d2 < 0, tau - d1 / np.where(d2 < 0, d2, 1.0), tau)
            fc = (g * np.exp(-2j * np.pi * np.outer(cand, self.ks))).real.sum(axis=1)
            ok = fc >= fb
            tau, fb = np.where(ok, cand, tau), np.where(ok, fc, fb)
        return np.mod(tau, 1.0), fb

    def update_delays(self):
        res = self.X - self.model()  # (R, I, K)
        for j in range(self.j):
            c = self.c[j]
            wj = self.w[:, :, j]  # (R, I)
            old = self.tau[:, j]
            res += wj[..., None] * self.phasors(old)[None] * c
            g = np.einsum("ri,rik->ik", wj, res.conj()) * c  # (I, K)
            f_old = (g * self.phasors(old)).real.sum(axis=1)
            cand, f_new = self.trig_argmax(g)
            better = f_new > f_old + 1e-15 * np.maximum(np.abs(f_old), 1.0)
            new = np.where(better, cand - np.floor(cand + 0.5), old)
            self.tau[:, j] = new
            res -= wj[..., None] * self.phasors(new)[None] * c

    def normalize(self):
        for j in range(self.j):
            rms = np.sqrt(2.0 * np.sum(np.abs(self.c[j]) ** 2))
            if not (rms > 0 and np.isfinite(rms)):
                continue
            scale = -rms if self.w[:, :, j].sum() < 0 else rms
            self.c[j] /= scale
            self.w[:, :, j] *= scale
            acc = np.sum(np.abs(self.w[:, :, j]).sum(axis=0) * np.exp(2j * np.pi * self.tau[:, j]))
            if abs(acc) <= 0:
                continue
            mu = np.angle(acc) / (2 * np.pi)
            self.c[j] *= np.exp(-2j * np.pi * self.ks * mu)
            t = self.tau[:, j] - mu
            self.tau[:, j] = t - np.floor(t + 0.5)

    def fit(self, sweeps):
        hist = [self.quality()]
        for _ in range(sweeps):
            self.update_sources()
            self.update_weights()
            self.update_delays()
            self.normalize()
            hist.append(self.quality())
        return hist


def numpy_fit(x, sweeps):
    return NumpyAls(x, J, K).fit(sweeps)


# ------------------------------------------------------------------------------------------
# Data

walk10 = M.make_synthetic_dataset(n_trials=10, noise=0.0)
X = np.ascontiguousarray(walk10.truth.periodic[0])  # (10, 51, 100), noise-free action 1
walk40 = M.make_synthetic_dataset(n_trials=40)
model, t_lib = timed(lambda: M.fit_stepwise(walk40))
lib = model.library_
print(f"synthetic walker: action-1 periodic part {X.shape} (R, I, N); library of 40 trials "
      f"({lib.n_sources} sources, Q total {lib.q_total:.4f}) learned in {t_lib:.2f} s")

# ------------------------------------------------------------------------------------------
# 1. SVR path

n = lib.n_samples
src = lib.sources[0]
coef = np.fft.fft(src)[1:K + 1] / n  # the learned source is band-limited to K harmonics
ks = np.arange(1, K + 1)


def source_at(t):
    return 2.0 * (np.exp(2j * np.pi * np.outer(t, ks)) @ coef).real


phases = np.arange(200) / 200.0
radii = np.array([0.9, 1.0, 1.1])
x_train = np.array([[r * np.cos(2 * np.pi * t), r * np.sin(2 * np.pi * t)]
                    for t in phases for r in radii])
y_train = np.repeat(source_at(phases), len(radii))

# Test states: the leader at 1 Hz over 10 s, each (channel, source) rotated by its delay.
tau = lib.delays.ravel()  # (51 * 5,)
theta = 2 * np.pi * (np.arange(FRAMES)[:, None] / FPS - tau[None, :])
x_test = np.ascontiguousarray(np.stack([np.cos(theta), np.sin(theta)], axis=-1).reshape(-1, 2))
print(f"SVR training set {x_train.shape[0]} states; {x_test.shape[0]} = {FRAMES} x "
      f"{tau.size} map evaluations")

peer = SVR(kernel="rbf", tol=1e-3, **SVR_KW)
t_peer_fit = best_time(lambda: peer.fit(x_train, y_train), repeat=REPEAT)
t_peer = best_time(lambda: peer.predict(x_test), repeat=REPEAT)
pred_peer = peer.predict(x_test)

pred_ours, info = M.svr_fit_predict(x_train, y_train, x_test, tol=1e-3, return_info=True,
                                    **SVR_KW)
t_ours_fit = best_time(lambda: M.svr_fit_predict(x_train, y_train, x_test[:1], **SVR_KW),
                       repeat=REPEAT)
t_ours_all = best_time(lambda: M.svr_fit_predict(x_train, y_train, x_test, **SVR_KW),
                       repeat=REPEAT)
t_ours_pred = t_ours_all - t_ours_fit
print(f"support vectors: ours {info.n_support}, sklearn {peer.support_.size}; "
      f"max |ours - sklearn| prediction {np.max(np.abs(pred_ours - pred_peer)):.2e} "
      f"(source RMS {np.sqrt(np.mean(src ** 2)):.2f})")


def synth_per_10s(map_name):
    syn = M.Synthesizer(map=map_name).fit(lib)
    goal = 12.0
    out = syn.run(goal=goal, fps=FPS, max_seconds=600.0)
    frames = len(out.time)
    t = best_time(lambda: syn.run(goal=goal, fps=FPS, max_seconds=600.0), repeat=REPEAT)
    return t * FRAMES / frames, frames


t_syn_svr, frames = synth_per_10s("svr")
t_syn_lut, _ = synth_per_10s("lut")
print(f"synthesis: goal 12 m gives {frames} frames ({frames / FPS:.1f} s); times below are "
      f"scaled to {FRAMES} frames")
print_table("paper 16: 1200 x 255 SVR map evaluations (10 s at 120 fps), single thread", [
    ("SVR map evaluations only", t_ours_pred, "sklearn SVR.predict", t_peer),
    ("synthesis 10 s, SVR maps", t_syn_svr, "sklearn SVR.predict", t_peer),
    ("synthesis 10 s, LUT maps", t_syn_lut, "sklearn SVR.predict", t_peer),
    ("SVR fit (600 states)", t_ours_fit, "sklearn SVR.fit", t_peer_fit),
])
print(f"real time: SVR path {10.0 / t_syn_svr:.0f}x (spec >= 50x), LUT path "
      f"{10.0 / t_syn_lut:.0f}x (spec >= 1e4x); LUT vs sklearn predict "
      f"{t_peer / t_syn_lut:.0f}x (spec >= 200x); SVR path / sklearn "
      f"{t_syn_svr / t_peer:.2f} (spec <= 1.0)")

# ------------------------------------------------------------------------------------------
# 2. fit_anechoic against the numpy ALS


def ours_fit(restarts=1, delay_search=0):
    # The numpy reference is the ALS alone, so the comparison runs ours without the
    # per-channel delay search that follows the sweeps by default.
    return M.fit_anechoic(X, J, delays="shared", n_harmonics=K, n_restarts=restarts,
                          max_iter=SWEEPS, tol=0.0, delay_search=delay_search)


m = ours_fit()
hist_np = numpy_fit(X, SWEEPS)
assert len(m.q_history_) == SWEEPS + 1
t_ours = best_time(ours_fit, repeat=REPEAT)
t_np = best_time(lambda: numpy_fit(X, SWEEPS), repeat=max(REPEAT // 2, 2))
t_ours10 = best_time(lambda: ours_fit(10), repeat=max(REPEAT // 2, 2))
t_search = best_time(lambda: ours_fit(10, 128), repeat=max(REPEAT // 2, 2))
print()
print(f"Q after {SWEEPS} sweeps: ours {m.q_:.6f}, numpy {hist_np[-1]:.6f}; start "
      f"{m.q_history_[0]:.6f} / {hist_np[0]:.6f}; max |Q_ours - Q_numpy| over the sweeps "
      f"{np.max(np.abs(np.asarray(m.q_history_) - np.asarray(hist_np))):.1e}")
print_table(f"paper 16: fit_anechoic R=10 I=51 N=100 J={J} K={K}, 1 run x {SWEEPS} sweeps", [
    (f"fit_anechoic ({SWEEPS} sweeps)", t_ours, "numpy ALS reference", t_np),
])
print(f"per sweep: ours {1e3 * t_ours / SWEEPS:.2f} ms (spec < 5 ms), numpy "
      f"{1e3 * t_np / SWEEPS:.2f} ms; 10 restarts x {SWEEPS} sweeps: ours {t_ours10:.3f} s "
      f"(spec < 0.5 s), with the default delay search (128) {t_search:.3f} s")

# ------------------------------------------------------------------------------------------
# 3. PCA quality against scikit-learn

rows = X.reshape(-1, X.shape[-1])
q_ours = M.pca_qualities(X)
q_sk = np.cumsum(PCA().fit(rows.T).explained_variance_ratio_)
t_pca = best_time(lambda: M.pca_qualities(X), repeat=REPEAT)
t_sk = best_time(lambda: PCA().fit(rows.T).explained_variance_ratio_, repeat=REPEAT)
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    ica = FastICA(n_components=J, random_state=0, max_iter=1000).fit(rows.T)
    xhat = ica.inverse_transform(ica.transform(rows.T)).T
q_ica = M.quality(rows, xhat)
print()
print(f"Q_PCA(1..6): ours {np.array2string(q_ours[:6], precision=4)}, max |ours - sklearn| "
      f"over all {q_ours.size} components {np.max(np.abs(q_ours - q_sk[:q_ours.size])):.1e}")
print(f"Q at J = {J}: anechoic (shared delays) {m.q_:.4f}, PCA {q_ours[J - 1]:.4f}, FastICA "
      f"{q_ica:.4f}")
print_table("paper 16: PCA qualities of the (R I) x N matrix", [
    ("pca_qualities (all components)", t_pca, "sklearn PCA().fit", t_sk),
])
