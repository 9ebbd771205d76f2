"""Paper 16 (predictive human movement synthesis) from Python: PCA quality against
scikit-learn, anechoic demixing against PCA, the epsilon-SVR against scikit-learn's SVR, the
regression statistics against scipy, the planner's split, a whole synthesis, BVH round trips
(and the `bvh` package's parser), the Hopf network's closed form and bad input."""

import dataclasses
import math

import numpy as np
import pytest

from results_check import check_result
from wscg import motion as M


@pytest.fixture(scope="module")
def data():
    return M.make_synthetic_dataset(n_trials=16, seed=0, noise=0.01)


@pytest.fixture(scope="module")
def clean_action1(data):
    """Noise-free periodic part of action 1, ``(R, I, N)``."""
    return data.truth.periodic[0]


@pytest.fixture(scope="module")
def lib(data):
    return M.fit_stepwise(data, n_restarts=3, max_iter=300).library_


@pytest.fixture(scope="module")
def synthesis(lib):
    syn = M.Synthesizer().fit(lib)
    return syn.run(goal=2.6, fps=120)


# --------------------------------------------------------------------------------------------
# Data


def test_dataset_shapes_and_truth(data):
    R, N = 16, 100
    assert data.angles.shape == (R, 3, 51, N)
    assert data.step_length.shape == (R, 3)
    assert data.duration.shape == (R, 3)
    assert data.root.shape == (R, 3, N)
    assert data.distances.shape == (R,)
    t = data.truth
    assert t.periodic.shape == (3, R, 51, N)
    assert t.delays.shape == (51, 5)
    assert t.weights.shape == (3, R, 51, 5)
    assert t.sources.shape == (5, N)
    # D = 0.6 + L1 + L2 in the learning set, the reach carries the length of step 2.
    sl = data.step_length
    np.testing.assert_allclose(data.distances, 0.6 + sl[:, 0] + sl[:, 1], atol=1e-12)
    np.testing.assert_array_equal(sl[:, 2], sl[:, 1])
    assert np.all((sl[:, 0] >= 0.670) & (sl[:, 0] <= 0.901))
    # The periodic part is the truth's weights times the delayed sources (action 1: 3 sources).
    assert np.all(t.weights[0][:, :, 3:] == 0)
    # Seeded: the same call gives the same data.
    again = M.make_synthetic_dataset(n_trials=16, seed=0, noise=0.01)
    np.testing.assert_array_equal(again.angles, data.angles)
    # Sources at unit RMS.
    np.testing.assert_allclose(np.sqrt((t.sources ** 2).mean(axis=1)), 1.0, atol=1e-12)


# --------------------------------------------------------------------------------------------
# PCA and anechoic demixing


def test_pca_quality_matches_sklearn(clean_action1):
    from sklearn.decomposition import PCA

    X = clean_action1
    R, I, N = X.shape
    X2 = X.reshape(R * I, N)
    qs = M.pca_qualities(X)
    assert qs.shape == (min(R * I, N),)
    for j in range(1, 7):
        ref = PCA(j, svd_solver="full").fit(X2.T).explained_variance_ratio_.sum()
        assert abs(M.pca_quality(X, j) - ref) < 1e-10, (j, M.pca_quality(X, j), ref)
        assert abs(qs[j - 1] - ref) < 1e-10
        # The 2-D (rows, N) form is the same matrix.
        assert abs(M.pca_quality(X2, j) - ref) < 1e-10
    assert np.all(np.diff(qs) >= -1e-15) and abs(qs[-1] - 1.0) < 1e-12


def test_anechoic_beats_pca(clean_action1):
    X = clean_action1
    for j in (1, 2, 3):
        fit = M.fit_anechoic(X, j, delays="shared", n_restarts=3, max_iter=300)
        q_pca = M.pca_quality(X, j)
        assert fit.q_ >= q_pca - 1e-9, (j, fit.q_, q_pca)
        hist = fit.q_history_
        assert np.all(np.diff(hist) >= -1e-10)
        # The reported Q is the quality of the reported reconstruction.
        assert abs(M.quality(X, fit.reconstruction_) - fit.q_) < 1e-8
        R, I, N = X.shape
        assert fit.sources_.shape == (j, N)
        assert fit.delays_.shape == (I, j)
        assert fit.weights_.shape == (R, I, j)
    # Three sources with shared delays are the generating model of action 1: a near-exact
    # fit (within the sweep budget), where PCA with three components is far from it (the
    # delays make it a rank-6 signal for PCA).
    assert fit.q_ > 0.99
    assert M.pca_quality(X, 3) < fit.q_ - 0.03


def _best_circular_similarity(a, b):
    """Largest |normalised circular cross-correlation| of two sampled periodic signals."""
    xc = np.fft.irfft(np.fft.rfft(a) * np.conj(np.fft.rfft(b)), n=len(a))
    return np.abs(xc).max() / (np.linalg.norm(a) * np.linalg.norm(b))


def test_orbit_start_identifies_the_generating_sources(data, clean_action1):
    X = clean_action1
    fit = M.fit_anechoic(X, 3, delays="shared", n_restarts=1, init="orbit")
    assert fit.q_ > 1 - 1e-6
    truth = data.truth.sources[:3]
    for t in truth:
        best = max(_best_circular_similarity(e, t) for e in fit.sources_)
        assert best > 0.999, best


def test_delay_search_moves_delays_to_a_better_fit(clean_action1):
    # Two sources for a three-source signal: the sweeps stop where two delays of a channel
    # would have to move together; the per-channel search after them finds a clearly better
    # fit (measured Q 0.98557 without, 0.99273 with it). A search that does nothing fails.
    X = clean_action1
    off = M.fit_anechoic(X, 2, delay_search=0)
    on = M.fit_anechoic(X, 2)
    assert on.q_ > off.q_ + 1e-3, (on.q_, off.q_)
    assert abs(M.quality(X, on.reconstruction_) - on.q_) < 1e-8
    # 1 % noise per channel RMS (this draw moves delays by up to 0.44 periods): Q still only
    # rises along the history, and the reported Q is the reconstruction's.
    rms = np.sqrt((X ** 2).mean(axis=2, keepdims=True))
    Xn = X + 0.01 * rms * np.random.default_rng(4).standard_normal(X.shape)
    off = M.fit_anechoic(Xn, 3, delay_search=0)
    on = M.fit_anechoic(Xn, 3)
    moved = np.abs((on.delays_ - off.delays_ + 0.5) % 1.0 - 0.5).max()
    assert moved > 0.01 and on.q_ > off.q_, (moved, on.q_, off.q_)
    assert abs(M.quality(Xn, on.reconstruction_) - on.q_) < 1e-8
    assert np.all(np.diff(on.q_history_) >= -1e-10)


def test_anechoic_delay_modes(clean_action1):
    X = clean_action1
    R, I, _ = X.shape
    per = M.fit_anechoic(X, 2, delays="per_trial", n_restarts=1, max_iter=20)
    assert per.delays_.shape == (R, I, 2)
    zero = M.fit_anechoic(X, 2, delays="zero", n_restarts=1, max_iter=20)
    assert np.all(zero.delays_ == 0)
    assert 0 < zero.q_ <= 1


# --------------------------------------------------------------------------------------------
# Regression statistics and SVR


def test_results_are_typed(data, lib, synthesis, clean_action1, tmp_path):
    check_result(data, M.MotionDataset)
    check_result(data.truth, M.MotionTruth)
    assert data.truth.source_coeffs.dtype == np.complex128
    fit = M.fit_anechoic(clean_action1, 2, n_restarts=1, max_iter=5)
    assert isinstance(fit, M.AnechoicModel)
    assert len(fit.q_history_) >= 2 and fit.q_ == pytest.approx(fit.q_history_[-1])
    af = lib.action_fit(2)
    check_result(af, M.ActionFit)
    assert af.n_sources == 5 and af.means.shape == (16, 51)
    plan = M.plan_steps(2.6)
    assert "actions=[('step', 0.77), ('short_step', 1.23), ('reach', 0)]," in check_result(
        plan, M.StepPlan)
    syn = M.Synthesizer().fit(lib)
    p = syn.planner
    assert syn.plan(2.6) == M.plan_steps(2.6, p["comfort"], p["gamma"], p["range1"],
                                         p["range2"])
    check_result(synthesis, M.Synthesis)
    M.save_bvh(tmp_path / "s.bvh", synthesis.angles[:5], synthesis.root_x[:5])
    back = M.load_bvh(tmp_path / "s.bvh")
    check_result(back, M.BvhMotion)
    assert back.angles.shape == (5, 51)
    check_result(M.skeleton(), M.Skeleton)
    line = M.fit_line([0.0, 1.0, 2.0, 3.0], [1.0, 3.0, 5.0, 7.0])
    check_result(line, M.LineFit)
    assert (line.slope, line.intercept, line.n_points) == (pytest.approx(2.0),
                                                           pytest.approx(1.0), 4)
    x = np.random.default_rng(0).random((30, 2))
    pred, info = M.svr_fit_predict(x, x.sum(axis=1), x[:3], return_info=True)
    assert check_result(info, M.SvrInfo).startswith(f"SvrInfo(n_support={info.n_support}, ")
    assert pred.shape == (3,) and info.n_iter > 0
    hopf = M.hopf_simulate(0.1, dt=0.01, followers=[[0.5, 0.0]])
    check_result(hopf, M.HopfTrajectory)
    assert hopf.followers.shape == (11, 1, 2)


def test_svr_matches_sklearn():
    from sklearn.svm import SVR

    th = np.linspace(0, 2 * np.pi, 120, endpoint=False)
    xs, ys = [], []
    for r in (0.9, 1.0, 1.1):
        xs.append(np.c_[r * np.cos(th), r * np.sin(th)])
        ys.append(np.sin(th) + 0.4 * np.cos(2 * th + 0.3))
    x, y = np.vstack(xs), np.concatenate(ys)
    rng = np.random.default_rng(3)
    ang = rng.uniform(0, 2 * np.pi, 200)
    rad = rng.uniform(0.8, 1.2, 200)
    xt = np.c_[rad * np.cos(ang), rad * np.sin(ang)]
    ours, info = M.svr_fit_predict(x, y, xt, C=10, epsilon=0.01, gamma=2.0, return_info=True)
    ref = SVR(kernel="rbf", C=10, epsilon=0.01, gamma=2.0).fit(x, y)
    diff = np.abs(ours - ref.predict(xt)).max()
    assert diff < 2e-3, diff
    assert 0 < info.n_support <= len(x)
    assert abs(info.n_support - len(ref.support_)) <= 0.05 * len(x)


def test_regression_p_value_and_linregress():
    from scipy import stats

    p = M.regression_p_value(0.08, 10)
    assert abs(p - 0.428) < 0.002, p
    # Data with exactly R^2 = 0.08 on 10 points.
    rng = np.random.default_rng(0)
    x = rng.normal(size=10)
    e = rng.normal(size=10)
    xc = x - x.mean()
    e = e - e.mean()
    e -= xc * (e @ xc) / (xc @ xc)
    r = math.sqrt(0.08)
    y = r * xc / np.linalg.norm(xc) + math.sqrt(1 - r * r) * e / np.linalg.norm(e) + 2.0
    ref = stats.linregress(x, y)
    assert abs(ref.rvalue ** 2 - 0.08) < 1e-12
    assert abs(p - ref.pvalue) < 1e-10
    fit = M.fit_line(x, y)
    assert abs(fit.p_value - ref.pvalue) < 1e-10
    assert abs(fit.r2 - 0.08) < 1e-12
    assert M.regression_p_value(1.0, 5) == 0.0


def test_fit_line_matches_linregress():
    from scipy import stats

    rng = np.random.default_rng(7)
    x = rng.uniform(2.34, 2.94, 25)
    y = 0.4 * x - 0.2 + rng.normal(0, 0.03, 25)
    f = M.fit_line(x, y)
    ref = stats.linregress(x, y)
    assert abs(f.slope - ref.slope) < 1e-12
    assert abs(f.intercept - ref.intercept) < 1e-12
    assert abs(f.r2 - ref.rvalue ** 2) < 1e-12
    assert abs(f.p_value - ref.pvalue) < 1e-10 * max(1.0, ref.pvalue) + 1e-300
    assert f.n_points == 25


# --------------------------------------------------------------------------------------------
# Planning, learning and synthesis


def test_plan_steps_paper_split():
    plan = M.plan_steps(2.7)
    acts = plan.actions
    assert [a[0] for a in acts] == ["step", "short_step", "reach"]
    assert abs(acts[0][1] - 0.385 * 2.1) < 1e-12
    assert abs(acts[1][1] - 0.615 * 2.1) < 1e-12
    assert acts[2][1] == 0.0
    assert not plan.too_short and plan.violation == 0.0
    assert abs(plan.distance - 2.1) < 1e-12
    # Long goals get more normal steps, short ones are flagged.
    long = M.plan_steps(5.0)
    assert long.n_steps >= 3 and abs(long.distance - 4.4) < 1e-9
    assert M.plan_steps(0.9).too_short and M.plan_steps(0.9).actions == []
    # The non-predictive variant keeps the normal step fixed.
    hl = M.plan_steps(2.7, human_like=0.78)
    assert abs(hl.actions[0][1] - 0.78) < 1e-12


def test_library(lib, data):
    assert lib.n_sources == 5
    assert lib.n_channels == 51 and lib.n_samples == 100
    assert lib.sources.shape == (5, 100)
    assert lib.delays.shape == (51, 5)
    q = lib.q_actions
    assert len(q) == 3 and all(0.9 < v <= 1.0 for v in q), q
    assert 0.9 < lib.q_total <= 1.0
    assert lib.params(0).shape == (16, 2)
    np.testing.assert_allclose(lib.params(0)[:, 0], data.step_length[:, 0])
    f = lib.action_fit(1)
    assert f.weights.shape == (16, 51, 5) and f.n_sources == 5
    assert lib.action_fit(0).n_sources == 3
    p = lib.progress
    assert p[0] == 0.0 and p[-1] == 1.0 and np.all(np.diff(p) >= 0)


def test_synthesis_reaches_comfort_distance(synthesis, lib):
    out = synthesis
    T = out.angles.shape[0]
    assert out.angles.shape == (T, 51)
    for k in ("root_x", "time", "phase", "action"):
        assert getattr(out, k).shape == (T,)
    assert np.all(np.isfinite(out.angles))
    assert np.all(np.diff(out.time) > 0) and abs(out.time[1] - 1 / 120) < 1e-9
    assert np.all(np.diff(out.root_x) >= -1e-12)
    assert [a[0] for a in out.executed] == ["step", "short_step", "reach"]
    assert out.action[0] == 0 and out.action[-1] == 2
    assert np.all(np.diff(out.action) >= 0)
    assert not out.too_short
    final = 2.6 - out.root_x[-1]
    assert abs(final - 0.6) < 0.02, final
    assert out.transitions.shape == (2, 51)


def test_synthesis_every_action_gets_frames(lib):
    syn = M.Synthesizer().fit(lib)
    for goal, fps in ((2.4, 120), (2.6, 120), (2.85, 60), (3.3, 60)):
        out = syn.run(goal=goal, fps=fps)
        counts = np.bincount(out.action, minlength=3)
        # Each action lasts more than half a second.
        assert np.all(counts[:2] > 0.5 * fps), (goal, fps, counts, out.executed)
        assert counts[2] > 0.5 * fps, (goal, fps, counts)
        # Smooth: no frame-to-frame jump beyond what a walk at this frame rate produces.
        assert np.abs(np.diff(out.angles, axis=0)).max() < 24.0 / fps


def test_synthesis_goal_change_and_maps(lib):
    syn = M.Synthesizer(map="fourier").fit(lib)
    moved = syn.run(goal=2.6, fps=60, goal_changes=[(0.2, 3.4)])
    assert abs(3.4 - moved.root_x[-1] - 0.6) < 0.02
    assert len(moved.executed) > 3
    short = syn.run(goal=0.8, fps=60)
    assert short.too_short and [a[0] for a in short.executed] == ["reach"]
    assert syn.planner["comfort"] == 0.6
    assert syn.plan(2.6).n_steps == 2


# --------------------------------------------------------------------------------------------
# Skeleton and BVH


def test_bvh_round_trip_small_angles(tmp_path):
    rng = np.random.default_rng(5)
    T = 12
    angles = rng.uniform(-0.5, 0.5, (T, 51))
    root_x = np.linspace(0, 1.3, T)
    path = tmp_path / "small.bvh"
    M.save_bvh(path, angles, root_x, fps=120)
    back = M.load_bvh(path)
    assert back.angles.shape == (T, 51)
    assert abs(back.frame_time - 1 / 120) < 1e-8
    np.testing.assert_allclose(back.angles, angles, atol=1e-6)
    np.testing.assert_allclose(back.root[:, 2], root_x, atol=1e-7)
    np.testing.assert_allclose(back.root[:, 1], 0.92, atol=1e-7)


def test_bvh_round_trip_synthesis(tmp_path, synthesis):
    from scipy.spatial.transform import Rotation

    a, x = synthesis.angles, synthesis.root_x
    path = tmp_path / "synth.bvh"
    M.save_bvh(str(path), a, x, fps=120)
    back = M.load_bvh(str(path))
    T = a.shape[0]
    # Compare rotations, not exponential-map representations.
    r0 = Rotation.from_rotvec(a.reshape(-1, 3)).as_matrix()
    r1 = Rotation.from_rotvec(back.angles.reshape(-1, 3)).as_matrix()
    assert np.abs(r0 - r1).max() < 1e-6
    # Forward kinematics agree too.
    p0 = M.forward_kinematics(a, x)
    p1 = M.forward_kinematics(back.angles, back.root)
    assert p0.shape == (T, 22, 3)
    assert np.abs(p0 - p1).max() < 1e-6


def test_bvh_package_parses_file(tmp_path, synthesis):
    bvh = pytest.importorskip("bvh")
    a, x = synthesis.angles, synthesis.root_x
    path = tmp_path / "synth.bvh"
    M.save_bvh(path, a, x, fps=120)
    mocap = bvh.Bvh(path.read_text())
    names = mocap.get_joints_names()
    assert len(names) == 17
    assert names == M.skeleton().names
    assert mocap.nframes == a.shape[0]
    assert abs(mocap.frame_time - 1 / 120) < 1e-8
    z = np.array(mocap.frames_joint_channels("Hips", ["Zposition"]), dtype=float)[:, 0]
    np.testing.assert_allclose(z / 100.0, x, atol=1e-7)


def test_skeleton_rest_pose():
    sk = M.skeleton()
    assert len(sk.names) == 17 and sk.parents[0] == -1
    p = M.forward_kinematics(np.zeros((1, 51)), np.zeros(1))
    # Hips at the rest height, ankles 7 cm above the floor.
    assert abs(p[0, 0, 1] - 0.92) < 1e-12
    assert abs(p[0, 13, 1] - 0.07) < 1e-12
    assert sk.bones.shape == (21, 2)


# --------------------------------------------------------------------------------------------
# Hopf network


def test_hopf_closed_form_and_contraction():
    out = M.hopf_simulate(3.0, dt=1e-3, omega=2 * np.pi, coupling=0.0, leader=(0.1, 0.0))
    t = out.time
    r = np.hypot(out.leader[:, 0], out.leader[:, 1])
    ref = (1 + (0.1 ** -2 - 1) * np.exp(-2 * t)) ** -0.5
    assert np.abs(r - ref).max() < 1e-8
    fol = M.hopf_simulate(4.0, dt=1e-2, coupling=2.0, followers=[[-0.8, 0.9], [1.5, 1.5]])
    d = np.linalg.norm(fol.followers - fol.leader[:, None, :], axis=2)
    assert d[-1].max() < 1e-3 * d[0].max()
    assert fol.leader_phase.shape == fol.time.shape


# --------------------------------------------------------------------------------------------
# Bad input


def test_bad_input(tmp_path, clean_action1, lib, data):
    X = clean_action1.copy()
    X[0, 0, 0] = np.nan
    with pytest.raises(ValueError):
        M.fit_anechoic(X, 2)
    with pytest.raises(ValueError):
        M.pca_quality(X, 1)
    with pytest.raises(ValueError):
        M.quality(X, clean_action1)
    good = clean_action1
    with pytest.raises(ValueError):
        M.fit_anechoic(good[0], 2)  # 2-D
    with pytest.raises(ValueError):
        M.fit_anechoic(good, 10_000)  # too many sources
    with pytest.raises(ValueError):
        M.fit_anechoic(good, 2, n_harmonics=60)  # above N / 2
    with pytest.raises(ValueError):
        M.fit_anechoic(good, 2, delays="sometimes")
    for grid in (4, 5000, -1):
        with pytest.raises(ValueError, match="delay_search"):
            M.fit_anechoic(good, 2, delay_search=grid)
    with pytest.raises(ValueError):
        M.fit_anechoic(np.zeros((2, 3, 20)), 1)
    with pytest.raises(ValueError):
        M.pca_quality(good, 0)
    with pytest.raises(ValueError):
        M.quality(good, good[:, :, :5])
    with pytest.raises(ValueError):
        M.make_synthetic_dataset(n_samples=4)
    with pytest.raises(ValueError):
        M.make_synthetic_dataset(n_trials=-1)
    with pytest.raises(ValueError):
        M.make_synthetic_dataset(noise=float("nan"))
    # Datasets: too few trials, NaN, wrong shapes, missing keys.
    small = {k: getattr(data, k)[:2] for k in ("angles", "step_length", "duration")}
    with pytest.raises(ValueError):
        M.fit_stepwise(small)
    bad = dataclasses.replace(data, angles=data.angles.copy())
    bad.angles[1, 2, 3, 4] = np.inf
    with pytest.raises(ValueError):
        M.fit_stepwise(bad)
    with pytest.raises(ValueError):
        M.fit_stepwise({"angles": data.angles[:, :2], "step_length": data.step_length,
                        "duration": data.duration})
    with pytest.raises(ValueError):
        M.fit_stepwise({"angles": data.angles})
    # Planner and synthesis goals.
    for g in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError):
            M.plan_steps(g)
    with pytest.raises(ValueError):
        M.plan_steps(2.7, gamma=1.5)
    with pytest.raises(ValueError):
        M.plan_steps(2.7, range1=(0.9, 0.1))
    syn = M.Synthesizer().fit(lib)
    with pytest.raises(ValueError):
        syn.run(goal=0)
    with pytest.raises(ValueError):
        syn.run(goal=2.6, fps=0)
    with pytest.raises(ValueError):
        syn.run(goal=2.6, goal_changes=[(0.1, -2.0)])
    with pytest.raises(ValueError):
        syn.run(goal=1e6, max_seconds=2.0)  # does not finish in time
    with pytest.raises(ValueError):
        M.Synthesizer(map="spline").fit(lib)
    with pytest.raises(ValueError):
        M.Synthesizer(beta=4.0).fit(lib)
    with pytest.raises(ValueError):
        M.Synthesizer(coupling=-1.0).fit(lib)
    for size in (3, 65537):
        with pytest.raises(ValueError, match="lut_size"):
            M.Synthesizer(lut_size=size).fit(lib)
    with pytest.raises(ValueError):
        M.Synthesizer().fit(object())
    # The synthesizer still works after the errors.
    assert abs(2.6 - syn.run(goal=2.6, fps=30).root_x[-1] - 0.6) < 0.02
    # Files.
    with pytest.raises(OSError):
        M.load_bvh(tmp_path / "missing.bvh")
    junk = tmp_path / "junk.bvh"
    junk.write_text("HIERARCHY\nROOT Nobody\n{\n}\nMOTION\n")
    with pytest.raises(OSError):
        M.load_bvh(junk)
    with pytest.raises(OSError):
        M.save_bvh(tmp_path / "no" / "dir.bvh", np.zeros((2, 51)), np.zeros(2))
    with pytest.raises(ValueError):
        M.save_bvh(tmp_path / "x.bvh", np.zeros((2, 50)), np.zeros(2))
    with pytest.raises(ValueError):
        M.save_bvh(tmp_path / "x.bvh", np.full((2, 51), np.nan), np.zeros(2))
    with pytest.raises(ValueError):
        M.save_bvh(tmp_path / "x.bvh", np.zeros((2, 51)), np.zeros(3))
    # Statistics and SVR.
    with pytest.raises(ValueError):
        M.regression_p_value(1.5, 10)
    with pytest.raises(ValueError):
        M.regression_p_value(0.5, 2)
    with pytest.raises(ValueError):
        M.fit_line([1, 1, 1], [1, 2, 3])
    with pytest.raises(ValueError):
        M.fit_line([1, 2, np.nan], [1, 2, 3])
    with pytest.raises(ValueError):
        M.svr_fit_predict(np.zeros((5, 3)), np.zeros(5), np.zeros((1, 2)))
    with pytest.raises(ValueError):
        M.svr_fit_predict(np.array([[0.0, np.nan]]), np.zeros(1), np.zeros((1, 2)))
    with pytest.raises(ValueError):
        M.svr_fit_predict(np.zeros((5, 2)), np.zeros(5), np.zeros((1, 2)), C=0)
    with pytest.raises(ValueError):
        M.hopf_simulate(1.0, dt=0.0)
    with pytest.raises(ValueError):
        M.hopf_simulate(1e9, dt=1e-6)  # too many steps


# ----------------------------------------------------------------------------------------
# BVH files of other skeletons
# ----------------------------------------------------------------------------------------

# name, parent, offset (inches), channels, end site: a CMU-style skeleton in a T-pose.
_R3 = ["Zrotation", "Yrotation", "Xrotation"]
_CMU = [
    ("Hips", None, (0, 0, 0), ["Xposition", "Yposition", "Zposition"] + _R3, None),
    ("LHipJoint", 0, (0, 0, 0), _R3, None),
    ("LeftUpLeg", 1, (3.5, -1, 0.5), _R3, None),
    ("LeftLeg", 2, (0, -17, 0), _R3, None),
    ("LeftFoot", 3, (0, -16.5, 0), _R3, (0, -2, 5)),
    ("RHipJoint", 0, (0, 0, 0), _R3, None),
    ("RightUpLeg", 5, (-3.5, -1, 0.5), _R3, None),
    ("RightLeg", 6, (0, -17, 0), _R3, None),
    ("RightFoot", 7, (0, -16.5, 0), _R3, (0, -2, 5)),
    ("LowerBack", 0, (0, 1, 0), ["Xrotation", "Yrotation", "Zrotation"], None),
    ("Spine", 9, (0, 5, 0), _R3, None),
    ("Spine1", 10, (0, 6, 0), _R3, None),
    ("Neck", 11, (0, 8, 0), _R3, None),
    ("Neck1", 12, (0, 2, 0), _R3, None),
    ("Head", 13, (0, 2.5, 0), _R3, (0, 4, 0)),
    ("LeftShoulder", 11, (1.5, 7, 0), _R3, None),
    ("LeftArm", 15, (6, 0, 0), ["Yrotation", "Xrotation", "Zrotation"], None),
    ("LeftForeArm", 16, (11, 0, 0), _R3, None),
    ("LeftHand", 17, (9.5, 0, 0), _R3, (3, 0, 0)),
    ("RightShoulder", 11, (-1.5, 7, 0), _R3, None),
    ("RightArm", 19, (-6, 0, 0), _R3, None),
    ("RightForeArm", 20, (-11, 0, 0), _R3, None),
    ("RightHand", 21, (-9.5, 0, 0), _R3, (-3, 0, 0)),
]


def _bvh_text(skel, frames, frame_time=1 / 120):
    lines = ["HIERARCHY"]

    def visit(j, depth):
        name, parent, off, chans, end = skel[j]
        pad = "  " * depth
        lines.append(f"{pad}{'ROOT' if parent is None else 'JOINT'} {name}")
        lines.append(pad + "{")
        lines.append(f"{pad}  OFFSET {off[0]} {off[1]} {off[2]}")
        lines.append(f"{pad}  CHANNELS {len(chans)} {' '.join(chans)}")
        for c, s in enumerate(skel):
            if s[1] == j:
                visit(c, depth + 1)
        if end is not None:
            lines.extend([pad + "  End Site", pad + "  {",
                          f"{pad}    OFFSET {end[0]} {end[1]} {end[2]}", pad + "  }"])
        lines.append(pad + "}")

    visit(0, 0)
    lines += ["MOTION", f"Frames: {len(frames)}", f"Frame Time: {frame_time}"]
    lines += [" ".join(f"{v:.10f}" for v in f) for f in frames]
    return "\n".join(lines) + "\n"


def _reference_fk(skel, frame):
    """World positions by scipy's intrinsic Euler rotations (an independent FK)."""
    from scipy.spatial.transform import Rotation

    vals = list(frame)
    rot, pos = {}, {}
    for j, (name, parent, off, chans, _) in enumerate(skel):
        t = np.array(off, dtype=float)
        axes, angles = "", []
        for c in chans:
            v = vals.pop(0)
            if c.endswith("position"):
                t["XYZ".index(c[0])] += v
            else:
                axes += c[0]
                angles.append(v)
        local = Rotation.from_euler(axes, angles, degrees=True)
        if parent is None:
            rot[j], pos[j] = local, t
        else:
            rot[j], pos[j] = rot[parent] * local, pos[parent] + rot[parent].apply(t)
    return np.array([pos[j] for j in range(len(skel))])


def _cmu_frames(n, seed):
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        f = []
        for _, _, _, chans, _ in _CMU:
            f += [rng.uniform(-30, 30) if c.endswith("position") else rng.uniform(-60, 60)
                  for c in chans]
        out.append(f)
    return out


def test_bvh_of_any_skeleton_reads_back_against_scipy_forward_kinematics(tmp_path):
    frames = _cmu_frames(4, 0)
    path = tmp_path / "cmu.bvh"
    path.write_text(_bvh_text(_CMU, frames))
    s = M.load_bvh_skeleton(path)
    check_result(s, M.BvhSkeleton)
    assert s.names == [j[0] for j in _CMU]
    assert s.parents == [-1 if j[1] is None else j[1] for j in _CMU]
    assert s.channels[16] == ["Yrotation", "Xrotation", "Zrotation"]
    assert s.motion.shape == (4, 6 + 3 * 22) and s.positions.shape == (4, 23, 3)
    assert s.end_sites[4] == [[0.0, -2.0, 5.0]]
    for f, frame in enumerate(frames):
        np.testing.assert_allclose(s.positions[f], _reference_fk(_CMU, frame), atol=1e-7)


def test_bvh_of_a_cmu_skeleton_drives_the_model_bone_for_bone(tmp_path):
    frames = _cmu_frames(3, 1)
    path = tmp_path / "cmu.bvh"
    path.write_text(_bvh_text(_CMU, frames))
    inches = 100 / 2.54
    names = [j[0] for j in _CMU]
    # (model joint, model child, file joint, file child) of bones driven by one file bone.
    limbs = [(4, 5, "LeftArm", "LeftForeArm"), (5, 6, "LeftForeArm", "LeftHand"),
             (11, 12, "LeftUpLeg", "LeftLeg"), (15, 16, "RightLeg", "RightFoot")]
    for joint_map in (None, "cmu", "mixamo"):
        m = M.load_bvh(path, joint_map=joint_map, units_per_metre=inches)
        assert m.angles.shape == (3, 51)
        for f, frame in enumerate(frames):
            want = _reference_fk(_CMU, frame)
            np.testing.assert_allclose(m.root[f], want[0] / inches, atol=1e-9)
            got = M.forward_kinematics(m.angles[f:f + 1], m.root[f:f + 1])[0]
            for mj, mc, sj, sc in limbs:
                dm = got[mc] - got[mj]
                ds = want[names.index(sc)] - want[names.index(sj)]
                np.testing.assert_allclose(dm / np.linalg.norm(dm), ds / np.linalg.norm(ds),
                                           atol=1e-6)
    # Renamed joints: an error listing them, then a user map (dict or JSON file).
    renamed = [list(j) for j in _CMU]
    renamed[3][0] = "calf_l"
    renamed[17][0] = "lowerarm_l"
    path2 = tmp_path / "renamed.bvh"
    path2.write_text(_bvh_text([tuple(j) for j in renamed], frames))
    with pytest.raises(OSError, match="LeftKnee.*LeftElbow|LeftElbow.*LeftKnee"):
        M.load_bvh(path2, joint_map="cmu")
    user = {"Spine": "Spine1", "Head": "Neck1", "LeftCollar": "LeftShoulder",
            "LeftShoulder": "LeftArm", "LeftElbow": "lowerarm_l", "LeftWrist": "LeftHand",
            "RightCollar": "RightShoulder", "RightShoulder": "RightArm",
            "RightElbow": "RightForeArm", "RightWrist": "RightHand", "LeftHip": "LeftUpLeg",
            "LeftKnee": "calf_l", "LeftAnkle": "LeftFoot", "RightHip": "RightUpLeg",
            "RightKnee": "RightLeg", "RightAnkle": "RightFoot"}
    a = M.load_bvh(path2, joint_map=user, units_per_metre=inches)
    b = M.load_bvh(path, joint_map="cmu", units_per_metre=inches)
    np.testing.assert_allclose(a.angles, b.angles, atol=1e-12)
    import json

    jpath = tmp_path / "map.json"
    jpath.write_text(json.dumps(user))
    c = M.load_bvh(path2, joint_map=jpath, units_per_metre=inches)
    np.testing.assert_allclose(c.angles, a.angles, atol=0)
    with pytest.raises(ValueError, match="Knee"):
        M.load_bvh(path2, joint_map={"Knee": "calf_l"})
    with pytest.raises(ValueError):
        M.load_bvh(path2, joint_map={"LeftKnee": 3})
    with pytest.raises(ValueError):
        M.load_bvh(path2, joint_map=3)
    with pytest.raises(ValueError):
        M.load_bvh(path, units_per_metre=0.0)
    with pytest.raises(OSError):
        M.load_bvh(path2, joint_map=tmp_path / "missing.json")
    # Malformed files name the file.
    text = path.read_text()
    for bad in (text[: len(text) // 3], text.replace("HIERARCHY", "HIERARCH"),
                text.replace("Frames: 3", "Frames: 99999999999999999999"),
                text.replace("Frames: 3", "Frames: 4")):
        p = tmp_path / "bad.bvh"
        p.write_text(bad)
        with pytest.raises(OSError, match="bad.bvh"):
            M.load_bvh_skeleton(p)


# ---------------------------------------------------------------- training folders


def test_a_training_folder_round_trips(tmp_path):
    ds = M.make_synthetic_dataset(n_trials=3, seed=2, n_samples=16)
    M.save_dataset(tmp_path / "walk", ds)
    back = M.load_dataset(tmp_path / "walk")
    for name in ("angles", "step_length", "duration", "root"):
        np.testing.assert_array_equal(getattr(back, name), getattr(ds, name))
    assert back.truth is None and back.distances.shape == (0,)
    # Without root curves the folder has no root.npy and loads with root None.
    M.save_dataset(tmp_path / "bare", {"angles": ds.angles, "step_length": ds.step_length,
                                       "duration": ds.duration})
    assert not (tmp_path / "bare" / "root.npy").exists()
    assert M.load_dataset(tmp_path / "bare").root is None


def test_training_folder_errors_name_the_file_and_the_line(tmp_path):
    ds = M.make_synthetic_dataset(n_trials=3, seed=2, n_samples=16)
    d = tmp_path / "walk"
    M.save_dataset(d, ds)
    steps = (d / "steps.csv").read_text().splitlines()
    (d / "steps.csv").write_text("\n".join(steps[:3] + ["0,2,x,1"] + steps[4:]) + "\n")
    with pytest.raises(OSError, match=r"steps\.csv.*line 4"):
        M.load_dataset(d)
    (d / "steps.csv").write_text("\n".join(steps[:-1]) + "\n")
    with pytest.raises(OSError, match="no row for trial 2 action 3"):
        M.load_dataset(d)
    (d / "angles.npy").write_bytes(b"\x93NUMPY")
    with pytest.raises(OSError, match="angles.npy"):
        M.load_dataset(d)
    with pytest.raises(OSError):
        M.load_dataset(tmp_path / "none")
    with pytest.raises(ValueError, match="`angles`"):
        M.save_dataset(d, {"angles": np.zeros((2, 3)), "step_length": np.zeros((2, 3)),
                           "duration": np.ones((2, 3))})
