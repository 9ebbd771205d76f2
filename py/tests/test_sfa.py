"""Paper 05 from Python: class-wise SFA on scikit-learn's bundled digits (check 6, the MNIST
stand-in), k-NN parity with scikit-learn (check 7), the generalized eigenproblem against
scipy (check 1), temporal SFA (check 3), model round trips and bad input."""

import pickle

import numpy as np
import pytest
import scipy.linalg
from sklearn.datasets import load_digits
from sklearn.model_selection import train_test_split
from sklearn.neighbors import KNeighborsClassifier

from wscg import biometrics as B


@pytest.fixture(scope="module")
def digits():
    X, y = load_digits(return_X_y=True)
    X = X / 16.0
    return train_test_split(X, y, test_size=1 / 3, stratify=y, random_state=0)


def _per_digit(y_true, y_pred):
    return [100.0 * np.mean(y_pred[y_true == c] == c) for c in range(10)]


def test_digits_class_separation_and_full_dataset(digits):
    # Check 6: pca_n_components=10, m=10, shrinkage 1e-3; class-separation >= 88 %, Gaussian
    # full-data-set SFA >= 93 %; Table-1-style rows printed for both SFA variants.
    Xtr, Xte, ytr, yte = digits
    per_class = B.PerClassSFA(pca_n_components=10, m=10, shrinkage=1e-3).fit(Xtr, ytr)
    acc = per_class.score(Xte, yte)
    gauss = B.GlobalSFA(pca_n_components=10, n_components=10, shrinkage=1e-3, rule="gaussian")
    acc_g = gauss.fit(Xtr, ytr).score(Xte, yte)
    var = B.GlobalSFA(pca_n_components=10, n_components=10, shrinkage=1e-3).fit(Xtr, ytr)
    acc_v = var.score(Xte, yte)
    for name, model in [("Full dataset (variance)", var), ("Class separation", per_class)]:
        row = _per_digit(yte, model.predict(Xte))
        print(name, " ".join(f"{v:.0f}" for v in row), f"mean {np.mean(row):.1f}")
    print(f"class separation {acc:.4f}, full dataset variance {acc_v:.4f}, gaussian {acc_g:.4f}")
    assert acc >= 0.88
    assert acc_g >= 0.93


def test_knn_matches_sklearn(digits):
    # Check 7 (k-NN part): identical predictions to KNeighborsClassifier(5).
    Xtr, Xte, ytr, yte = digits
    ours = B.KNN(5, tie="smallest").fit(Xtr, ytr).predict(Xte)
    ref = KNeighborsClassifier(5, algorithm="brute").fit(Xtr, ytr).predict(Xte)
    np.testing.assert_array_equal(ours, ref)
    # The default tie rule differs only where the vote is tied.
    near = B.KNN(5).fit(Xtr, ytr).predict(Xte)
    assert np.mean(near == ref) > 0.98


def test_confusion_matrix_layout(digits):
    Xtr, Xte, ytr, yte = digits
    pred = B.PerClassSFA(pca_n_components=10, m=10, shrinkage=1e-3).fit(Xtr, ytr).predict(Xte)
    m, classes = B.confusion_matrix(yte, pred)
    np.testing.assert_array_equal(classes, np.arange(10))
    np.testing.assert_allclose(m.sum(axis=1), 100.0)
    np.testing.assert_allclose(np.diag(m), _per_digit(yte, pred))


def test_temporal_sfa_toy():
    # Check 3 through the binding.
    t = np.linspace(0, 2 * np.pi, 5000)
    X = np.column_stack([np.sin(t) + np.cos(11 * t) ** 2, np.cos(11 * t)])
    sfa = B.TemporalSFA(n_components=2).fit(X)
    y = sfa.transform(X)
    assert abs(np.corrcoef(y[:, 0], np.sin(t))[0, 1]) >= 0.999
    np.testing.assert_allclose(y.mean(0), 0, atol=1e-10)
    np.testing.assert_allclose(y.T @ y / len(y), np.eye(2), atol=1e-8)
    assert np.all(np.diff(sfa.delta_values_) >= 0)


def test_generalized_problem_matches_scipy(digits):
    # Check 1 at the level of the model: the per-class eigenvalues equal scipy's
    # eigh(A_C, B) on the same expanded data (no shrinkage, full rank).
    Xtr, _, ytr, _ = digits
    pcs = 6
    model = B.PerClassSFA(pca_n_components=pcs, m=5, shrinkage=0.0).fit(Xtr, ytr)
    Xc = Xtr - Xtr.mean(0)
    _, _, vt = np.linalg.svd(Xc, full_matrices=False)
    P = Xc @ vt[:pcs].T
    iu = np.triu_indices(pcs)
    Z = np.column_stack([P, (P[:, :, None] * P[:, None, :])[:, iu[0], iu[1]]])
    Bm = np.cov(Z.T, bias=True)
    for c in range(10):
        inc, out = Z[ytr == c], Z[ytr != c]
        Sc, Sn = np.cov(inc.T, bias=True), np.cov(out.T, bias=True)
        d = inc.mean(0) - out.mean(0)
        A = 2 * Sc - (Sc + Sn + np.outer(d, d))
        ref = scipy.linalg.eigh(A, Bm, eigvals_only=True, subset_by_index=[0, 4])
        np.testing.assert_allclose(model.eigenvalues_[c], ref, rtol=1e-8, atol=1e-10)


def test_round_trips_and_labels(digits, tmp_path):
    Xtr, Xte, ytr, _ = digits
    names = np.array(["zero", "one", "two", "three", "four", "five", "six", "seven", "eight",
                      "nine"])
    model = B.PerClassSFA(pca_n_components=10, m=5, shrinkage=1e-3).fit(Xtr, names[ytr])
    pred = model.predict(Xte)
    assert set(pred) <= set(names)
    back = pickle.loads(pickle.dumps(model))
    np.testing.assert_array_equal(back.predict(Xte), pred)
    np.testing.assert_array_equal(back.decision_function(Xte), model.decision_function(Xte))
    model.save(tmp_path / "m.json")
    np.testing.assert_array_equal(B.PerClassSFA.load(tmp_path / "m.json").predict(Xte), pred)
    # A file written before the 1.0 rename (hyper-parameter pca_dims) still loads.
    import json
    d = json.loads((tmp_path / "m.json").read_text())
    d["params"]["pca_dims"] = d["params"].pop("pca_n_components")
    (tmp_path / "old.json").write_text(json.dumps(d))
    old = B.PerClassSFA.load(tmp_path / "old.json")
    assert old.pca_n_components == 10
    np.testing.assert_array_equal(old.predict(Xte), pred)
    assert model.responses(Xte, "three").shape == (len(Xte), 5)
    g = B.GlobalSFA(pca_n_components=10, n_components=9, rule="gaussian").fit(Xtr, ytr)
    g.save(tmp_path / "g.json")
    np.testing.assert_array_equal(B.GlobalSFA.load(tmp_path / "g.json").predict(Xte),
                                  g.predict(Xte))


def test_bad_input(digits):
    Xtr, Xte, ytr, _ = digits
    bad = [
        lambda: B.PerClassSFA().fit(np.zeros((0, 64)), []),
        lambda: B.PerClassSFA(pca_n_components=10).fit(np.where(np.arange(64) == 3, np.nan, Xtr), ytr),
        lambda: B.PerClassSFA(pca_n_components=10).fit(Xtr, ytr[:-1]),
        lambda: B.PerClassSFA(pca_n_components=10).fit(Xtr, np.zeros(len(Xtr))),
        lambda: B.PerClassSFA(pca_n_components=10, m=0).fit(Xtr, ytr),
        lambda: B.PerClassSFA(pca_n_components=100).fit(Xtr, ytr),
        lambda: B.PerClassSFA(pca_n_components=10, degree=3).fit(Xtr, ytr),
        lambda: B.PerClassSFA(pca_n_components=10, objective="x").fit(Xtr, ytr),
        lambda: B.PerClassSFA(pca_n_components=3).fit(np.ones((50, 5)), np.arange(50) % 2),
        lambda: B.PerClassSFA(pca_n_components=10).fit(Xtr, ytr).predict(Xte[:, :10]),
        lambda: B.PerClassSFA(pca_n_components=10).predict(Xte),
        lambda: B.GlobalSFA(pca_n_components=10, rule="bayes").fit(Xtr, ytr),
        lambda: B.KNN(0).fit(Xtr, ytr).predict(Xte),
        lambda: B.KNN(5, tie="x").fit(Xtr, ytr).predict(Xte),
        lambda: B.TemporalSFA(n_components=50, degree=1).fit(np.random.rand(100, 3)),
        lambda: B.confusion_matrix([0, 1], [0, 2], classes=[0, 1]),
    ]
    for fn in bad:
        with pytest.raises(ValueError):
            fn()
