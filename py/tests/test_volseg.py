"""Tests of wscg.volseg (paper 18: BoneSplit, random-walks bone separation in CT, Nysjö,
Malmberg, Sintorn and Nyström, WSCG 2015).

The solver is pinned down by an analytic 1-D chain (check 1) and by scikit-image's
``random_walker`` on the same bone-only graph with a weight mapping that makes its edge
weights equal ours (check 10); the pipeline by the fractured-shell phantom's ground truth and the
geodesic nearest-seed baseline.
"""

import warnings

import numpy as np
import pytest

import wscg
from results_check import check_result
from wscg import volseg
from wscg._native import volseg as _native


# ----------------------------------------------------------------------------------------
# Helpers
# ----------------------------------------------------------------------------------------

def _phantom(shape=(48, 48, 48), k=4, seed=0):
    return volseg.make_fractured_shell_phantom(shape, n_fragments=k, seed=seed)


def _skimage_agreement(shape, k, tol, precision, spacing=(1.0, 1.0, 1.0), prob=False):
    """Fraction of bone voxels on which our labels equal scikit-image's (``cg_j``) on the
    same graph, with the weight mapping that matches scikit-image's edge weights to ours; and
    the largest probability gap."""
    skseg = pytest.importorskip("skimage.segmentation")
    ct, _, seeds = _phantom(shape, k)
    bone = ct >= 300.0
    # skimage sees the window-normalised CT (our default norm), non-bone voxels removed (-1).
    data = np.clip((ct.astype(np.float64) + 1024.0) / 4095.0, 0.0, 1.0)
    beta = 3000.0
    beta_sk = beta * 10.0 * data.std()  # skimage divides beta by 10 std(data), whole array
    lab = seeds.astype(np.int32)
    lab[~bone] = -1
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # skimage: "probability range outside [0, 1]"
        sk = skseg.random_walker(data, lab, beta=beta_sk, mode="cg_j", tol=tol,
                                 spacing=spacing, return_full_prob=prob)
    ours = volseg.random_walker_bone(ct, seeds, beta=beta, eps=1e-10, kappa=0.0, tol=tol,
                                     max_iter=100_000, precision=precision, spacing=spacing,
                                     spacing_in_weights=True, return_prob=prob,
                                     return_report=True)
    if prob:
        labels, probs, report = ours
        sk_labels = np.argmax(sk, axis=0) + 1
        gap = float(np.abs(probs[:, bone] - sk[:, bone]).max())
    else:
        labels, report = ours
        sk_labels, gap = sk, None
    assert all(report.converged), report
    sk_labels = np.where(sk_labels < 0, 0, sk_labels)  # skimage: -1 = unreachable
    return float(np.mean(labels[bone] == sk_labels[bone])), gap


# ----------------------------------------------------------------------------------------
# Module
# ----------------------------------------------------------------------------------------

def test_module_is_listed():
    assert "volseg" in wscg.__all__
    assert wscg.volseg is volseg
    for name in volseg.__all__:
        assert getattr(volseg, name).__doc__, name


# ----------------------------------------------------------------------------------------
# Check 1: the analytic chain
# ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("solver", ["block", "per_label"])
def test_chain_matches_the_analytic_solution(solver):
    # All bone: w = 1 + eps = 1.01 with the paper's eps = 0.01 and kappa = 1e-3.
    ct = np.full((101, 1, 1), 1000.0, np.float32)
    seeds = np.zeros(ct.shape, np.uint16)
    seeds[0] = 1
    seeds[100] = 2
    labels, probs = volseg.random_walker_bone(ct, seeds, preset="paper", tol=1e-10,
                                              precision="f64", solver=solver,
                                              return_prob=True)
    assert probs.shape == (2, 101, 1, 1) and probs.dtype == np.float32
    x1 = probs[0, :, 0, 0].astype(np.float64)
    for i, want in [(25, 0.452159), (50, 0.198825), (75, 0.074990)]:
        assert abs(x1[i] - want) < 1e-5, (i, x1[i])
    # sinh(mu (100 - i)) / sinh(100 mu), cosh mu = 1 + kappa / (2 w), everywhere.
    mu = np.arccosh(1.0 + 1e-3 / (2.0 * 1.01))
    i = np.arange(101)
    np.testing.assert_allclose(x1, np.sinh(mu * (100 - i)) / np.sinh(100 * mu), atol=1e-6)
    assert labels[0, 0, 0] == 1 and labels[100, 0, 0] == 2
    # kappa = 0: the linear profile.
    _, probs0 = volseg.random_walker_bone(ct, seeds, kappa=0.0, tol=1e-10, precision="f64",
                                          return_prob=True)
    np.testing.assert_allclose(probs0[0, :, 0, 0], 1.0 - i / 100.0, atol=1e-6)


# ----------------------------------------------------------------------------------------
# Check 10: equality with scikit-image
# ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("precision", ["f32", "f64"])
@pytest.mark.parametrize("spacing", [(1.0, 1.0, 1.0), (2.0, 1.0, 0.5)])
def test_matches_skimage_at_the_paper_tolerance(precision, spacing):
    """Measured: 100 % of the 8840 bone voxels agree, f32 and f64, both spacings."""
    agree, _ = _skimage_agreement((48, 48, 48), 4, 3e-3, precision, spacing)
    assert agree >= 0.999, agree


def test_matches_skimage_probabilities_at_tight_tolerance():
    """tol 1e-6, f64: labels agree on 100 % of the bone voxels, probabilities within 1e-3."""
    agree, gap = _skimage_agreement((32, 32, 32), 4, 1e-6, "f64", prob=True)
    assert agree >= 0.999, agree
    assert gap < 1e-3, gap


# ----------------------------------------------------------------------------------------
# Check 3: phantom accuracy against the nearest-seed baseline
# ----------------------------------------------------------------------------------------

def test_random_walks_beat_nearest_seed_on_the_phantom():
    ct, truth, seeds = volseg.make_fractured_shell_phantom()  # 128^3, K = 6, seed 0
    assert ct.shape == truth.shape == seeds.shape == (128, 128, 128)
    assert ct.dtype == np.float32 and truth.dtype == seeds.dtype == np.uint16
    labels, report = volseg.random_walker_bone(ct, seeds, return_report=True)
    baseline = volseg.nearest_seed(ct, seeds)
    d_rw, d_ns = volseg.dice(labels, truth), volseg.dice(baseline, truth)
    # Measured (Rust and here): 0.974 vs 0.607 (the paper's values: 0.783).
    assert d_rw >= d_ns + 0.05, (d_rw, d_ns)
    assert d_rw > 0.96
    bone = ct >= 300.0
    assert report.n_nodes == int(bone.sum())
    assert report.n_labels == 6 and all(report.converged)
    assert not labels[~bone].any() and not baseline[~bone].any()
    on = seeds > 0
    np.testing.assert_array_equal(labels[on], seeds[on])
    np.testing.assert_array_equal(baseline[on], seeds[on])
    assert set(np.unique(labels)) <= set(range(7))


def test_phantom_is_deterministic_and_configurable():
    a = volseg.make_fractured_shell_phantom((32, 32, 32), 3, seed=5)
    b = volseg.make_fractured_shell_phantom((32, 32, 32), 3, seed=5)
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)
    c = volseg.make_fractured_shell_phantom((32, 32, 32), 3, seed=6)
    assert not np.array_equal(a[0], c[0])
    ct, truth, seeds, dist = volseg.make_fractured_shell_phantom(
        (16, 24, 32), 3, noise_hu=0.0, blur_sigma=0.0, return_distance=True)
    assert ct.shape == truth.shape == dist.shape == (16, 24, 32)
    assert set(np.unique(ct)) <= {-1000.0, 40.0, 450.0, 1200.0}
    assert np.array_equal(truth > 0, ct >= 300.0)
    assert seeds.max() == 3 and np.all(truth[seeds > 0] == seeds[seeds > 0])
    assert dist.dtype == np.float32 and np.all(dist >= 0)
    # Surface strokes: every seed voxel has a non-bone 6-neighbour (or the border).
    ct, truth, seeds = volseg.make_fractured_shell_phantom((48, 48, 48), 4, surface_strokes=True)
    bone = np.pad(ct >= 300.0, 1)
    inner = np.ones_like(bone)
    for ax in range(3):
        inner &= np.roll(bone, 1, ax) & np.roll(bone, -1, ax)
    inner = inner[1:-1, 1:-1, 1:-1]
    on = seeds > 0
    assert set(np.unique(seeds[on])) == {1, 2, 3, 4}
    assert np.all(truth[on] == seeds[on]) and not np.any(inner[on])
    labels = volseg.random_walker_bone(ct, seeds)
    assert volseg.dice(labels, truth) > volseg.dice(volseg.nearest_seed(ct, seeds), truth)


def test_dice_and_bone_mask():
    a = np.array([[0, 1, 1, 2]])
    assert volseg.dice(a, a) == 1.0
    assert volseg.dice(np.zeros(4), np.zeros(4)) == 1.0
    assert volseg.dice(a, [[0, 1, 2, 2]]) == pytest.approx(2 * 2 / 6)
    ct, _, _ = _phantom((32, 32, 32), 3)
    np.testing.assert_array_equal(volseg.bone_mask(ct), ct >= 300)
    assert volseg.bone_mask(ct, n_smooth_passes=1).sum() > 0


# ----------------------------------------------------------------------------------------
# Check 5: warm start
# ----------------------------------------------------------------------------------------

def test_session_warm_start_saves_iterations():
    ct, truth, seeds = _phantom((64, 64, 64), 4)
    s = volseg.RandomWalkerSession(ct)
    assert s.n_nodes == int((ct >= 300).sum()) and s.n_labels == 0
    assert s.shape == (64, 64, 64) and s.n_edges > s.n_nodes
    assert s.report() is None
    assert s.set_seeds(seeds) == int(np.count_nonzero(seeds))
    first = s.solve(warm_start=False)
    assert s.n_labels == 4 and all(first.converged)
    np.testing.assert_array_equal(s.labels(), volseg.random_walker_bone(ct, seeds))
    # One extra stroke of label 1: truth voxels 6-7 voxels from its existing stroke.
    z0 = np.argwhere(seeds == 1)[0]
    cand = np.argwhere(truth == 1)
    d2 = ((cand - z0) ** 2).sum(axis=1)
    extra = cand[(d2 >= 36) & (d2 <= 49)][:20]
    assert len(extra) == 20
    assert s.add_seeds(extra, 1) == 20
    warm = s.solve(warm_start=True)
    assert s.report() is warm
    cold_s = volseg.RandomWalkerSession(ct)
    cold_s.set_seeds(seeds)
    cold_s.add_seeds(extra, 1)
    cold = cold_s.solve(warm_start=False)
    w, c = sum(warm.n_iter), sum(cold.n_iter)
    assert w <= 0.6 * c, (w, c)  # measured 78 vs 334
    np.testing.assert_array_equal(s.seeds(), cold_s.seeds())
    assert np.mean(s.labels() == cold_s.labels()) > 0.99
    assert np.all(s.labels()[tuple(extra.T)] == 1)


def test_session_with_mask_and_strokes():
    ct, truth, seeds = _phantom((32, 32, 32), 3)
    mask = ct >= 300
    s = volseg.RandomWalkerSession(ct, mask=mask, precision="f64")
    for lab in (1, 2, 3):
        assert s.add_seeds(np.argwhere(seeds == lab), lab) == int((seeds == lab).sum())
    with pytest.warns(UserWarning, match="not bone"):
        assert s.add_seeds([0, 0, 0], 1) == 0  # a corner of air
    s.solve()
    np.testing.assert_array_equal(
        s.labels(), volseg.random_walker_bone(ct, seeds, precision="f64"))
    ns = s.nearest_seed()
    np.testing.assert_array_equal(ns, volseg.nearest_seed(ct, seeds))
    np.testing.assert_array_equal(ns, volseg.nearest_seed(ct, seeds, mask=mask))


def test_label_values_need_not_be_consecutive():
    ct, truth, seeds = _phantom((32, 32, 32), 3)
    ref, ref_p, ref_r = volseg.random_walker_bone(ct, seeds, return_prob=True,
                                                  return_report=True)
    assert ref_r.labels == [1, 2, 3]
    lut = np.array([0, 300, 7, 65534])
    labels, probs, r = volseg.random_walker_bone(ct, lut[seeds], return_prob=True,
                                                 return_report=True)
    np.testing.assert_array_equal(labels, lut[ref])
    assert r.labels == [7, 300, 65534] and r.n_labels == 3
    np.testing.assert_array_equal(probs, ref_p[[1, 0, 2]])
    # The session keeps a label's number across set_seeds and add_seeds.
    s = volseg.RandomWalkerSession(ct)
    s.set_seeds(lut[seeds])
    s.solve()
    np.testing.assert_array_equal(s.labels(), lut[ref])
    np.testing.assert_array_equal(s.seeds(), lut[seeds])
    np.testing.assert_array_equal(s.probabilities(300), ref_p[0])
    np.testing.assert_array_equal(s.probabilities(), ref_p[[1, 0, 2]])
    np.testing.assert_array_equal(s.nearest_seed(), lut[volseg.nearest_seed(ct, seeds)])
    with pytest.raises(ValueError, match="no probabilities for label 5"):
        s.probabilities(5)
    stroke = np.argwhere(truth == 2)[:5]
    s.add_seeds(stroke, 5)
    r = s.solve()
    assert r.labels == [5, 7, 300, 65534] and len(r.n_iter) == 4
    assert np.all(s.labels()[tuple(stroke.T)] == 5)
    assert s.probabilities().shape == (4, 32, 32, 32)
    np.testing.assert_array_equal(s.probabilities()[0], s.probabilities(5))
    s.set_seeds(seeds * 100)  # labels 100, 200, 300: 300 keeps its number
    r = s.solve()
    assert r.labels == [5, 7, 100, 200, 300, 65534]
    assert set(np.unique(s.labels())) == {0, 100, 200, 300}


def test_large_label_values_are_refused_by_the_native_solver():
    """The native random walker numbers labels 1..K; a native session (which keeps the
    numbers it is given) with label 65534 would need 65534 vectors and is refused instead of
    exhausting memory."""
    ct = np.full((32, 32, 32), 1000.0, np.float32)
    seeds = np.zeros(ct.shape, np.uint16)
    seeds[0, 0, 0], seeds[-1, -1, -1] = 60000, 65534
    labels, _, rep = _native.random_walker(ct, seeds, **_NATIVE_DEFAULTS, return_prob=False)
    assert set(np.unique(labels)) == {60000, 65534} and rep["labels"] == [60000, 65534]
    labels = volseg.random_walker_bone(ct, seeds)
    assert set(np.unique(labels)) == {60000, 65534}
    s = _native.Session(ct, None, **_NATIVE_DEFAULTS)
    s.set_seeds(seeds)
    with pytest.raises(ValueError, match="GiB"):
        s.solve(False)


# ----------------------------------------------------------------------------------------
# Probabilities
# ----------------------------------------------------------------------------------------

def test_probabilities_shape_and_range():
    ct, truth, seeds = _phantom((40, 40, 40), 3)
    labels, probs = volseg.random_walker_bone(ct, seeds, preset="paper", return_prob=True)
    assert probs.shape == (3, 40, 40, 40) and probs.dtype == np.float32
    assert probs.min() >= 0.0 and probs.max() <= 1.0
    bone = ct >= 300
    assert not probs[:, ~bone].any()
    for k in (1, 2, 3):
        assert np.all(probs[k - 1][seeds == k] == 1.0)
    # Labels are the argmax of the probabilities (ties to the lowest label).
    reached = probs.max(axis=0) > 1e-12
    np.testing.assert_array_equal(labels[reached & (seeds == 0)],
                                  (np.argmax(probs, axis=0) + 1)[reached & (seeds == 0)])
    # With kappa > 0 they decay away from the seeds and do not sum to 1; with kappa = 0
    # (Grady's plain problem) they do, to the solver's tolerance.
    assert probs.sum(axis=0)[bone].mean() < 0.9
    _, p0 = volseg.random_walker_bone(ct, seeds, kappa=0.0, tol=1e-8, precision="f64",
                                      return_prob=True)
    on = p0.max(axis=0) > 0
    assert np.abs(p0.sum(axis=0)[on] - 1.0).max() < 1e-5
    s = volseg.RandomWalkerSession(ct, preset="paper")
    s.set_seeds(seeds)
    with pytest.raises(ValueError):
        s.probabilities()
    s.solve()
    np.testing.assert_array_equal(s.probabilities(), probs)
    np.testing.assert_array_equal(s.probabilities(2), probs[1])
    with pytest.raises(ValueError, match="label"):
        s.probabilities(4)


def test_solver_variants_agree():
    ct, _, seeds = _phantom((32, 32, 32), 3)
    base = volseg.random_walker_bone(ct, seeds, tol=1e-6, precision="f64")
    for opts in [dict(solver="per_label"), dict(precision="f32"), dict(n_threads=1),
                 dict(jacobi=False, max_iter=20_000)]:
        other = volseg.random_walker_bone(ct, seeds, tol=1e-6, **{"precision": "f64", **opts})
        assert np.mean(other == base) > 0.999, opts


def test_presets_set_beta_eps_and_kappa():
    """``preset`` picks the values of ``beta``, ``eps`` and ``kappa`` left at None: the
    defaults ``1e4, 2e-3, 3e-5`` or the paper's ``3000, 0.01, 1e-3``; a value given wins."""
    ct, truth, seeds = _phantom((32, 32, 32), 3)
    rw = volseg.random_walker_bone
    kw = dict(tol=1e-6, precision="f64", return_prob=True)
    same = [
        (rw(ct, seeds, **kw), rw(ct, seeds, beta=1e4, eps=2e-3, kappa=3e-5, **kw)),
        (rw(ct, seeds, preset="paper", **kw),
         rw(ct, seeds, beta=3000.0, eps=0.01, kappa=1e-3, **kw)),
        (rw(ct, seeds, preset="paper", kappa=0.0, **kw),
         rw(ct, seeds, beta=3000.0, eps=0.01, kappa=0.0, **kw)),
    ]
    for (la, pa), (lb, pb) in same:
        np.testing.assert_array_equal(la, lb)
        np.testing.assert_array_equal(pa, pb)
    # The presets differ (kappa = 1e-3 drains the probabilities).
    assert not np.array_equal(same[0][0][1], same[1][0][1])
    s = volseg.RandomWalkerSession(ct, preset="paper", tol=1e-6, precision="f64")
    s.set_seeds(seeds)
    s.solve()
    np.testing.assert_array_equal(s.probabilities(), same[1][0][1])


def test_smoothing_and_normalisation_options():
    ct, truth, seeds = _phantom((32, 32, 32), 3)
    sm = volseg.smooth(ct, 1, spacing=(2.0, 1.0, 1.0))
    assert sm.shape == ct.shape and sm.dtype == np.float32
    assert sm.std() < ct.std()
    np.testing.assert_array_equal(volseg.smooth(ct, 0), ct)
    for kw in [dict(n_smooth_passes=1), dict(norm="minmax", beta=3000.0 * (4095 / 1500) ** 2),
               dict(norm=("window", -1024, 3071)), dict(spacing=(2.0, 1.0, 1.0))]:
        labels = volseg.random_walker_bone(ct, seeds, **kw)
        assert volseg.dice(labels, truth) > 0.5, kw
    np.testing.assert_array_equal(volseg.random_walker_bone(ct, seeds, norm="window"),
                                  volseg.random_walker_bone(ct, seeds,
                                                            norm=("window", -1024, 3071)))


def test_dtypes_are_converted():
    ct, _, seeds = _phantom((32, 32, 32), 3)
    ref = volseg.random_walker_bone(ct, seeds)
    # Integer CT (as stored by scanners), int64 or float seeds with whole values.
    np.testing.assert_array_equal(
        volseg.random_walker_bone(ct.astype(np.int16), seeds.astype(np.int64)), ref)
    np.testing.assert_array_equal(
        volseg.random_walker_bone(ct.astype(np.float64), seeds.astype(np.float32)), ref)
    # Non-contiguous views.
    big = np.zeros((32, 32, 64), np.float32)
    big[:, :, ::2] = ct
    bs = np.zeros((32, 32, 64), np.uint16)
    bs[:, :, ::2] = seeds
    np.testing.assert_array_equal(volseg.random_walker_bone(big[:, :, ::2], bs[:, :, ::2]), ref)


def test_off_bone_seeds_are_dropped_with_a_warning():
    ct, _, seeds = _phantom((32, 32, 32), 3)
    s2 = seeds.copy()
    s2[0, 0, 0] = 2  # air
    with pytest.warns(UserWarning, match="1 of"):
        labels = volseg.random_walker_bone(ct, s2)
    assert labels[0, 0, 0] == 0
    np.testing.assert_array_equal(labels, volseg.random_walker_bone(ct, seeds))


def test_solve_report_is_typed():
    ct, _, seeds = _phantom((32, 32, 32), 3)
    _, r = volseg.random_walker_bone(ct, np.array([0, 9, 4, 6])[seeds], return_report=True)
    text = check_result(r, volseg.SolveReport)
    assert "labels=[4, 6, 9]" in text and "n_unreached=0" in text
    assert r.n_labels == 3 and r.n_seeds == int(np.count_nonzero(seeds))
    assert len(r.n_iter) == len(r.residuals) == len(r.seconds) == 3
    assert all(res <= 3e-3 for res in r.residuals) and r.n_unreached >= 0
    s = volseg.RandomWalkerSession(ct)
    s.set_seeds(np.array([0, 9, 4, 6])[seeds])
    check_result(s.solve(), volseg.SolveReport)
    # The session reorders its per-label lists to the ascending labels, as the function.
    assert s.report().labels == r.labels and s.report().n_iter == r.n_iter


def test_unconverged_solve_warns():
    ct, _, seeds = _phantom((32, 32, 32), 3)
    with pytest.warns(RuntimeWarning, match=r"did not reach .* for labels \[1, 2, 3\]"):
        _, r = volseg.random_walker_bone(ct, seeds, max_iter=2, return_report=True)
    assert r.n_iter == [2, 2, 2] and not any(r.converged)
    # The warning names the user's labels, not their positions.
    s = volseg.RandomWalkerSession(ct, max_iter=2)
    s.set_seeds(np.array([0, 30, 7, 200])[seeds])
    with pytest.warns(RuntimeWarning, match=r"for labels \[7, 30, 200\]"):
        s.solve()


# ----------------------------------------------------------------------------------------
# Bad input
# ----------------------------------------------------------------------------------------

def test_bad_input_raises_value_error():
    ct, _, seeds = _phantom((24, 24, 24), 3)
    rw = volseg.random_walker_bone
    cases = [
        (lambda: rw(ct, seeds[:-1]), "shape mismatch"),
        (lambda: rw(ct, np.zeros_like(seeds)), "no seed"),
        (lambda: rw(ct, seeds, t_bone=5000.0), "no seed"),  # empty graph
        (lambda: rw(np.where(np.arange(ct.size).reshape(ct.shape) == 7, np.nan, ct), seeds),
         "non-finite"),
        (lambda: rw(np.where(np.arange(ct.size).reshape(ct.shape) == 7, np.inf, ct), seeds),
         "non-finite"),
        (lambda: rw(ct.astype(np.float64) * 1e300, seeds), "non-finite"),
        (lambda: rw(ct, seeds, beta=-1.0), "beta"),
        (lambda: rw(ct, seeds, eps=-0.01), "eps"),
        (lambda: rw(ct, seeds, kappa=-1e-3), "kappa"),
        (lambda: rw(ct, seeds, preset="skimage"), "preset"),
        (lambda: volseg.RandomWalkerSession(ct, preset="Paper"), "preset"),
        (lambda: rw(ct, seeds, tol=0.0), "tol"),
        (lambda: rw(ct, seeds, tol=float("nan")), "tol"),
        (lambda: rw(ct, seeds, max_iter=0), "max_iter"),
        (lambda: rw(ct, seeds, spacing=(1.0, 0.0, 1.0)), "spacing"),
        (lambda: rw(ct, seeds, spacing=(1.0, -1.0, 1.0)), "spacing"),
        (lambda: rw(ct, seeds, spacing=(1.0, 1.0)), "spacing"),
        (lambda: rw(ct[0], seeds[0]), "3-D"),
        (lambda: rw(ct[None], seeds[None]), "3-D"),
        (lambda: rw(ct > 0, seeds), "dtype"),
        (lambda: rw(ct.astype(np.complex64), seeds), "dtype"),
        (lambda: rw(ct, seeds.astype(np.float32) + 0.5), "whole-number"),
        (lambda: rw(ct, seeds.astype(np.int32) - 1), "0..65534"),
        (lambda: rw(ct, np.where(seeds > 0, 70000, 0)), "0..65534"),
        (lambda: rw(ct, seeds, norm="log"), "norm"),
        (lambda: rw(ct, seeds, norm=("window", 10, 0)), "norm"),
        (lambda: rw(ct, seeds, solver="amg"), "solver"),
        (lambda: rw(ct, seeds, precision="f16"), "precision"),
        (lambda: rw(ct, seeds, n_threads=0), "n_threads"),
        (lambda: rw(ct, seeds, n_smooth_passes=-1), "n_smooth_passes"),
        (lambda: rw(ct, seeds, n_smooth_passes=1000), "n_smooth_passes"),
        (lambda: rw(np.zeros((0, 4, 4)), np.zeros((0, 4, 4))), "empty"),
        (lambda: volseg.nearest_seed(ct, np.zeros_like(seeds)), "no seed"),
        (lambda: volseg.dice(seeds, seeds[0]), "shape mismatch"),
        (lambda: volseg.RandomWalkerSession(ct, mask=(ct > 0)[0]), "shape mismatch"),
        (lambda: volseg.RandomWalkerSession(ct).solve(), "no seed"),
        (lambda: volseg.RandomWalkerSession(ct).set_seeds(seeds[1:]), "shape mismatch"),
        (lambda: volseg.RandomWalkerSession(ct).add_seeds([[0, 0, 24]], 1), "outside"),
        (lambda: volseg.RandomWalkerSession(ct).add_seeds([[-1, 0, 0]], 1), "outside"),
        (lambda: volseg.RandomWalkerSession(ct).add_seeds([[0, 0]], 1), "(N, 3)"),
        (lambda: volseg.RandomWalkerSession(ct).add_seeds([[0, 0, 0]], 0), "label"),
        (lambda: volseg.RandomWalkerSession(ct).add_seeds([[0.5, 0, 0]], 1), "integer"),
        (lambda: volseg.make_fractured_shell_phantom((8, 32, 32)), "shape"),
        (lambda: volseg.make_fractured_shell_phantom((32, 32, 32), 1), "n_fragments"),
        (lambda: volseg.make_fractured_shell_phantom((32, 32, 32), 100), "n_fragments"),
        (lambda: volseg.make_fractured_shell_phantom((4096, 4096, 4096)), "voxels"),
        (lambda: volseg.make_fractured_shell_phantom((32, 32, 32), shell=(0.7, 0.6)), "shell"),
        (lambda: volseg.make_fractured_shell_phantom((32, 32, 32), blur_sigma=1e9), "blur_sigma"),
        (lambda: volseg.make_fractured_shell_phantom((32, 32, 32), noise_hu=float("nan")),
         "noise_hu"),
        (lambda: volseg.make_fractured_shell_phantom((32, 32, 32), stroke_margin=1e6), "fragment"),
        (lambda: volseg.smooth(ct, 1, spacing=(0, 1, 1)), "spacing"),
        (lambda: volseg.remove_small_components(seeds, -1), "min_voxels"),
    ]
    for i, (f, match) in enumerate(cases):
        with pytest.raises(ValueError, match=match):
            f()
    # The phantom's options are explicit keyword arguments: an unknown one is a TypeError.
    with pytest.raises(TypeError, match="colour"):
        volseg.make_fractured_shell_phantom((32, 32, 32), colour=1)


_NATIVE_DEFAULTS = dict(t_bone=300.0, beta=None, eps=None, kappa=None, preset="default",
                       tol=3e-3, max_iter=2000, spacing=(1.0, 1.0, 1.0), n_smooth_passes=0,
                       norm="window", spacing_in_weights=False, solver="block",
                       precision="f32", jacobi=True, n_threads=None)


def test_native_functions_refuse_bad_arguments():
    """Direct calls to the native module (the checks are the bindings' own) raise, never
    crash."""
    ct = np.full((4, 4, 4), 1000.0, np.float32)
    seeds = np.zeros((4, 4, 4), np.uint16)
    seeds[0, 0, 0] = 1

    def rw(ct=ct, seeds=seeds, **kw):
        return _native.random_walker(ct, seeds, **{**_NATIVE_DEFAULTS, **kw},
                                     return_prob=False)

    with pytest.raises(ValueError, match="3-D"):
        rw(ct[0], seeds[0])
    with pytest.raises(ValueError, match="shape mismatch"):
        rw(seeds=seeds[:2])
    with pytest.raises(TypeError, match="gamma"):
        rw(gamma=1.0)
    with pytest.raises(ValueError, match="n_threads"):
        rw(n_threads=10**6)
    with pytest.raises(ValueError, match="spacing"):
        rw(spacing=(1.0, float("nan"), 1.0))
    with pytest.raises(TypeError, match="beta"):
        rw(beta="x")
    with pytest.raises(ValueError, match="max_iter"):
        rw(max_iter=-1)
    bad = ct.copy()
    bad[1, 1, 1] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        _native.Session(bad, np.ones(ct.shape, bool), **_NATIVE_DEFAULTS)
    s = _native.Session(ct, None, **_NATIVE_DEFAULTS)
    with pytest.raises(ValueError, match="shape mismatch"):
        s.check_seeds(seeds[:2])
    with pytest.raises(ValueError, match="0..65534"):
        s.check_seeds(np.full(ct.shape, 65535))
    with pytest.raises(TypeError, match="size"):
        volseg.local_grow_edit(seeds, ct, (1.0, 1.0, 1.0), 2.0, 1, size=1.0)
    with pytest.raises(ValueError, match="gradient_scale"):
        volseg.local_grow_edit(seeds, ct, (1.0, 1.0, 1.0), 2.0, 1, gradient_scale=0.0)
    with pytest.raises(ValueError, match="tau"):
        volseg.local_grow_edit(seeds, ct, (1.0, 1.0, 1.0), 2.0, 1, tau=float("nan"))
    with pytest.raises(ValueError, match="radius"):
        volseg.local_grow_edit(seeds, ct, (1.0, 1.0, 1.0), -2.0, 1)
    with pytest.raises(ValueError, match="center_zyx"):
        volseg.local_grow_edit(seeds, ct, (1.0, 1.0), 2.0, 1)
    with pytest.raises(ValueError, match="shape mismatch"):
        volseg.dice(seeds, seeds[0])
    # One voxel, one seed: nothing to solve, no crash.
    lab, _, rep = _native.random_walker(ct[:1, :1, :1], seeds[:1, :1, :1], **_NATIVE_DEFAULTS,
                                        return_prob=True)
    assert lab.shape == (1, 1, 1) and lab[0, 0, 0] == 1 and rep["iterations"] == [0]


# ----------------------------------------------------------------------------------------
# Editing (paper section 2.6)
# ----------------------------------------------------------------------------------------

def _edit_scene():
    """A 20^3 bone block (1000 HU) with an air slab (z >= 16); label 1 on x < 10, label 2 on
    x >= 10 (similar intensity) except for a denser (2000 HU) part at y >= 14."""
    ct = np.full((20, 20, 20), 1000.0, np.float32)
    ct[:, 14:, 10:] = 2000.0
    ct[16:] = -1000.0
    labels = np.zeros(ct.shape, np.uint16)
    labels[:16, :, :10] = 1
    labels[:16, :, 10:] = 2
    return ct, labels


def test_local_grow_edit_stays_in_the_brush_and_the_bone():
    ct, labels = _edit_scene()
    before = labels.copy()
    centre, radius = (12.0, 7.0, 10.0), 5.0
    out, n = volseg.local_grow_edit(labels, ct, centre, radius, active=1)
    np.testing.assert_array_equal(labels, before)  # the input is not modified
    assert out.dtype == np.uint16 and out.shape == labels.shape
    changed = out != before
    assert n == int(changed.sum()) and n > 0
    z, y, x = np.indices(ct.shape)
    dist = np.sqrt((z - centre[0]) ** 2 + (y - centre[1]) ** 2 + (x - centre[2]) ** 2)
    assert np.all(dist[changed] <= radius)
    assert np.all(ct[changed] >= 300.0)
    assert np.all(out[changed] == 1)
    # It grew into the neighbouring label-2 region of similar intensity.
    assert np.any(changed & (x >= 10) & (ct == 1000.0))
    # Air inside the ball stays unlabelled even when the brush reaches it.
    out2, _ = volseg.local_grow_edit(labels, ct, (15.0, 7.0, 10.0), 4.0, active=1)
    assert not out2[16:].any()


def test_local_grow_edit_prefers_similar_intensity():
    ct, labels = _edit_scene()
    _, n_similar = volseg.local_grow_edit(labels, ct, (8.0, 7.0, 10.0), 3.0, active=1)
    _, n_dense = volseg.local_grow_edit(labels, ct, (8.0, 16.0, 10.0), 3.0, active=1)
    assert n_similar > n_dense
    # A brush label no voxel carries changes nothing.
    out, n = volseg.local_grow_edit(labels, ct, (8.0, 7.0, 10.0), 3.0, active=7)
    assert n == 0 and np.array_equal(out, labels)
    with pytest.raises(ValueError, match="radius"):
        volseg.local_grow_edit(labels, ct, (8.0, 7.0, 10.0), 0.0, active=1)
    with pytest.raises(ValueError, match="active"):
        volseg.local_grow_edit(labels, ct, (8.0, 7.0, 10.0), 3.0, active=0)
    with pytest.raises(ValueError, match="center_zyx"):
        volseg.local_grow_edit(labels, ct, (8.0, np.nan, 10.0), 3.0, active=1)
    with pytest.raises(ValueError, match="shape mismatch"):
        volseg.local_grow_edit(labels[1:], ct, (8.0, 7.0, 10.0), 3.0, active=1)


def test_remove_small_components_relabels_islands():
    labels = np.zeros((12, 12, 12), np.uint16)
    labels[2:10, 2:10, 2:10] = 1
    labels[5, 5, 5:7] = 2  # a 2-voxel island of label 2 inside label 1
    labels[0, 0, 0] = 3  # an island with no labelled neighbour: stays
    before = labels.copy()
    out, n = volseg.remove_small_components(labels, min_voxels=5)
    np.testing.assert_array_equal(labels, before)
    assert n == 2
    assert np.all(out[5, 5, 5:7] == 1) and out[0, 0, 0] == 3
    assert np.array_equal(out[out != before], [1, 1])
    out, n = volseg.remove_small_components(labels, min_voxels=2)
    assert n == 0 and np.array_equal(out, labels)


def test_cleanup_after_random_walks_keeps_most_labels():
    ct, truth, seeds = _phantom((48, 48, 48), 4)
    labels = volseg.random_walker_bone(ct, seeds)
    out, n = volseg.remove_small_components(labels, 20)
    assert n < 0.05 * np.count_nonzero(labels)
    assert volseg.dice(out, truth) >= volseg.dice(labels, truth) - 0.01
