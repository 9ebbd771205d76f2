"""Paper 05 from Python, data side: Isomap parity with scikit-learn (check 7), Python against
the Rust command line and thread-count independence (check 9), the hand-pose generator,
physical features, split and comparison, and bad input."""

import os
import pickle
import subprocess
import sys

import numpy as np
import pytest
from sklearn.datasets import make_swiss_roll
from sklearn.manifold import Isomap as SkIsomap

from results_check import check_result
from wscg import biometrics as B


def _same_up_to_sign(a, b):
    """max |a - s b| / std(b) per column, with the sign s that fits best."""
    worst = 0.0
    for j in range(b.shape[1]):
        s = 1.0 if np.dot(a[:, j], b[:, j]) >= 0 else -1.0
        worst = max(worst, np.max(np.abs(a[:, j] - s * b[:, j])) / np.std(b[:, j]))
    return worst


def test_isomap_matches_sklearn_on_the_swiss_roll():
    # Check 7: exact Isomap(n_neighbors=10, 2) on make_swiss_roll(1500, noise=0,
    # random_state=0), and transform of 100 held-out points.
    X, _ = make_swiss_roll(1600, noise=0.0, random_state=0)
    Xtr, Xho = X[:1500], X[1500:]
    ref = SkIsomap(n_neighbors=10, n_components=2).fit(Xtr)
    ours = B.Isomap(n_neighbors=10, n_components=2).fit(Xtr)
    assert _same_up_to_sign(ours.embedding_, ref.embedding_) < 1e-6
    assert _same_up_to_sign(ours.transform(Xho), ref.transform(Xho)) < 1e-6
    # A pickled model projects identically.
    again = pickle.loads(pickle.dumps(ours))
    np.testing.assert_array_equal(again.transform(Xho), ours.transform(Xho))


def test_landmark_isomap_recovers_the_roll_parameter():
    X, t = make_swiss_roll(1200, noise=0.0, random_state=1)
    emb = B.Isomap(n_neighbors=8, n_components=2, n_landmarks=300).fit_transform(X)
    assert abs(np.corrcoef(emb[:, 0], t)[0, 1]) > 0.98


@pytest.fixture(scope="module")
def hands():
    return B.make_hand_poses(n_per_class=150, seed=0)


def test_generator_shapes_and_determinism(hands):
    masks, depth, labels, subjects = hands
    assert masks.shape == (750, 165, 120) and masks.dtype == np.uint8
    assert depth.shape == masks.shape and depth.dtype == np.float32
    assert set(np.unique(masks)) == {0, 1}
    np.testing.assert_array_equal(np.bincount(labels), [150] * 5)
    assert set(np.unique(subjects)) == {0, 1, 2}
    on = depth[masks == 1]
    assert np.all(depth[masks == 0] == 0) and np.all((on > 200) & (on < 400))
    again = B.make_hand_poses(n_per_class=150, seed=0)
    np.testing.assert_array_equal(again[0], masks)
    tight = B.make_hand_poses(n_per_class=5, jitter=B.hand_pose_jitter("tight"))
    assert tight[0].shape == (25, 165, 120)
    assert B.hand_pose_jitter("tight")["translation_px"] == 8.0
    with pytest.warns(DeprecationWarning):
        assert B.hand_pose_jitter("spec") == B.hand_pose_jitter("tight")


def test_physical_features_of_a_disc():
    yy, xx = np.mgrid[:80, :80]
    disc = ((xx - 40) ** 2 + (yy - 40) ** 2 <= 400).astype(np.uint8)
    f = B.physical_features(disc)
    assert f.shape == (1, 8)
    assert abs(f[0, 2] - 40) <= 1 and abs(f[0, 3] - 40) <= 1  # palm centre
    assert f[0, 5] >= 0.98  # convex ratio
    assert f[0, 6] <= 1.0  # concave depth
    # A horizontal bar turned by 90 degrees about its centroid becomes a vertical one.
    bar = np.zeros((61, 61), dtype=np.uint8)
    bar[28:33, 10:51] = 1  # 5 rows x 41 columns, centroid (30, 30)
    rows, cols = np.nonzero(B.rotate_mask(bar, 90.0))
    assert (rows.min(), rows.max(), cols.min(), cols.max()) == (10, 50, 28, 32)
    small = B.downscale_mask(disc, 3)
    assert small.shape == (27, 27)
    assert abs(small.sum() * 9 - disc.sum()) < 1e-9


def test_split_and_comparison(hands):
    masks, depth, labels, _ = hands
    s = B.hand_pose_split(masks, labels, n_test_per_class=30, n_augment_per_class=40,
                          seed=0)
    assert s.X_train.shape == (5 * 160, 55 * 40) and s.X_test.shape == (150, 2200)
    assert np.sum(s.train_rotation != 0) == 200
    assert not set(s.test_index) & set(s.train_index)
    check_result(s, B.HandPoseSplit)
    assert s.shape == (55, 40) and s.X_test.shape[1] == s.shape[0] * s.shape[1]
    r = B.hand_pose_comparison(masks, labels, depth=depth, n_test_per_class=30,
                               n_augment_per_class=40, methods=("sfa", "physical", "pca",
                                                                "global"),
                               pca_n_components=10, m=4, physical_n_per_class=100)
    np.testing.assert_array_equal(r.y_test, s.y_test)
    check_result(r, B.HandPoseComparison)
    assert list(r.results) == ["sfa", "physical", "pca", "global"]
    for run in r.results.values():
        check_result(run, B.ClassifierRun)
        assert run.fit_seconds >= 0 and run.predict_seconds >= 0
    for name, res in r.results.items():
        np.testing.assert_allclose(res.confusion.sum(axis=1), 100.0)
        acc = 100 * np.mean(res.predictions == r.y_test)
        assert abs(acc - res.accuracy) < 1e-9  # equal class sizes: mean diagonal
    # The comparison's class-wise SFA is PerClassSFA on the split's rows.
    model = B.PerClassSFA(pca_n_components=10, m=4).fit(s.X_train, s.y_train)
    np.testing.assert_array_equal(model.predict(s.X_test), r.results["sfa"].predictions)
    # Rotated test rows: no rotation gives the split's rows exactly; a rotation keeps each
    # hand's area (within resampling error) but moves its pixels.
    same = B.hand_pose_rotated_test(masks, s.test_index, angles=(0.0, 0.0))
    np.testing.assert_array_equal(same, s.X_test)
    rot = B.hand_pose_rotated_test(masks, s.test_index)
    area, area_rot = s.X_test.sum(axis=1), rot.sum(axis=1)
    assert np.max(np.abs(area_rot / area - 1)) < 0.05
    moved = np.abs(rot - s.X_test).sum(axis=1) / area
    assert np.min(moved) > 0.05


def _rows(masks):
    return np.stack([B.downscale_mask(m, 3).ravel() for m in masks])


def test_python_equals_the_rust_command_line(hands, tmp_path):
    # Check 9: the same model fitted through the binding and by the `wscg` binary gives
    # identical predictions and scores within 1e-12.
    exe = os.environ.get("WSCG_BIN")
    if not exe or not os.path.exists(exe):
        pytest.skip("WSCG_BIN (the wscg binary built by cargo test) is not set")
    masks, _, labels, _ = hands
    np.save(tmp_path / "m.npy", masks)
    np.save(tmp_path / "y.npy", labels)
    model = tmp_path / "model.json"
    base = [exe, "biometrics", "sfa"]
    subprocess.run(base + ["fit", "--npy", str(tmp_path / "m.npy"), "--labels",
                           str(tmp_path / "y.npy"), "--pca-dims", "10", "--m", "4",
                           "--out", str(model)], check=True, capture_output=True)
    out = subprocess.run(base + ["predict", "--model", str(model), "--npy",
                                 str(tmp_path / "m.npy"), "--scores",
                                 str(tmp_path / "s.npy")],
                         check=True, capture_output=True, text=True).stdout
    rust_pred = np.array([int(line.split("\t")[1]) for line in out.splitlines()[1:]])
    rust_scores = np.load(tmp_path / "s.npy")
    py = B.PerClassSFA(pca_n_components=10, m=4).fit(_rows(masks), labels)
    X = _rows(masks)
    np.testing.assert_array_equal(py.predict(X), rust_pred)
    scores = py.class_scores(X)  # the paper's scores, as the command line writes them
    assert np.max(np.abs(scores - rust_scores)) <= 1e-12 * np.max(np.abs(rust_scores))
    np.testing.assert_array_equal(py.decision_function(X), -scores)
    # Save / load round trip: bit-identical.
    py.save(tmp_path / "py.json")
    again = B.PerClassSFA.load(tmp_path / "py.json")
    np.testing.assert_array_equal(again.class_scores(X), scores)


def test_results_do_not_depend_on_the_thread_count(hands, tmp_path):
    masks, _, labels, _ = hands
    np.save(tmp_path / "X.npy", _rows(masks))
    np.save(tmp_path / "y.npy", labels)
    code = (
        "import numpy as np, sys\n"
        "from wscg import biometrics as B\n"
        f"X = np.load(r'{tmp_path / 'X.npy'}'); y = np.load(r'{tmp_path / 'y.npy'}')\n"
        "m = B.PerClassSFA(pca_n_components=10, m=4).fit(X, y)\n"
        "np.save(sys.argv[1], m.decision_function(X))\n"
    )
    outs = []
    for threads in ("1", "2"):
        env = dict(os.environ, RAYON_NUM_THREADS=threads)
        path = tmp_path / f"s{threads}.npy"
        subprocess.run([sys.executable, "-c", code, str(path)], check=True, env=env)
        outs.append(np.load(path))
    # Identical decisions; the scores differ only by the rounding of parallel reductions
    # (measured: 2.5e-11 relative at most).
    assert np.array_equal(np.argmin(outs[0], axis=1), np.argmin(outs[1], axis=1))
    np.testing.assert_allclose(outs[0], outs[1], rtol=1e-9, atol=1e-12 * np.max(np.abs(outs[0])))


def test_bad_input_raises_value_error(hands):
    masks, depth, labels, _ = hands
    with pytest.raises(ValueError):
        B.make_hand_poses(n_per_class=0)
    with pytest.raises(ValueError):
        B.make_hand_poses(n_per_class=2, jitter={"wiggle": 1.0})
    with pytest.raises(ValueError):
        B.physical_features(np.zeros((10, 10), dtype=np.uint8))  # empty mask
    with pytest.raises(ValueError):
        B.physical_features(masks[:2].astype(np.float64))  # wrong dtype
    with pytest.raises(ValueError):
        B.physical_features(masks[:2], depth[:1])  # shape mismatch
    with pytest.raises(ValueError):
        B.hand_pose_split(masks, labels[:-1])
    with pytest.raises(ValueError):
        B.hand_pose_split(masks, labels, n_test_per_class=150)
    with pytest.raises(ValueError):
        B.hand_pose_comparison(masks, labels, methods=("cnn",), n_test_per_class=10,
                               n_augment_per_class=0)
    with pytest.raises(ValueError):
        B.Isomap(n_neighbors=0).fit(np.random.default_rng(0).normal(size=(20, 3)))
    with pytest.raises(ValueError):
        B.Isomap().transform(np.zeros((2, 3)))
    two_blobs = np.vstack([np.zeros((10, 2)), np.full((10, 2), 100.0)])
    two_blobs += np.random.default_rng(0).normal(scale=0.01, size=two_blobs.shape)
    with pytest.raises(ValueError, match="disconnected|n_neighbors"):
        B.Isomap(n_neighbors=3, n_components=2).fit(two_blobs)
    with pytest.raises(ValueError):
        B.rotate_mask(masks[0], float("nan"))
