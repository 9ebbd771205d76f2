"""Paper 01 (FDKECA) from Python: the acceptance checks against scikit-learn and
scikit-image, the estimator protocol, persistence and bad input."""

import pickle

import numpy as np
import pytest
from sklearn.base import clone
from sklearn.datasets import load_digits
from sklearn.decomposition import PCA as SkPCA
from sklearn.decomposition import KernelPCA as SkKernelPCA
from sklearn.metrics.pairwise import euclidean_distances, polynomial_kernel, rbf_kernel
from sklearn.model_selection import train_test_split
from sklearn.neighbors import KNeighborsClassifier

from results_check import check_result
from wscg import biometrics as B


@pytest.fixture(scope="module")
def digits():
    d = load_digits()
    return d.data.astype(np.float64), d.target


def rel_err(a, b):
    return np.max(np.abs(a - b)) / np.max(np.abs(b))


# ------------------------------------------------------------ check 1: kernel exactness


def test_feature_kernel_equals_sklearn_kernels(digits):
    X = digits[0][:500]
    Xc = X - X.mean(axis=0)
    K, info = B.feature_kernel(X, kernel="rbf")
    assert K.shape == (64, 64)
    gamma = 1.0 / (2.0 * info.sigma ** 2)
    assert rel_err(K, rbf_kernel(Xc.T, gamma=gamma)) <= 1e-10
    K, info = B.feature_kernel(X, kernel="poly", degree=2, coef0=1.0)
    assert info.gamma == pytest.approx(1.0 / 500)
    ref = polynomial_kernel(Xc.T, degree=2, gamma=1.0 / 500, coef0=1.0)
    assert rel_err(K, ref) <= 1e-10


def test_feature_kernel_reports_a_resolved_kernel(digits):
    X = digits[0][:200]
    _, rbf = B.feature_kernel(X, kernel="rbf", sigma=3.0)
    assert check_result(rbf, B.ResolvedKernel) == (
        "ResolvedKernel(kernel='rbf', sigma=3, degree=None, gamma=None, coef0=None)")
    _, poly = B.feature_kernel(X, kernel="poly", degree=3, gamma=0.5, coef0=2.0)
    check_result(poly, B.ResolvedKernel)
    assert (poly.kernel, poly.degree, poly.gamma, poly.coef0, poly.sigma) == ("poly", 3, 0.5,
                                                                               2.0, None)
    assert B.feature_kernel(X, kernel="linear")[1] == B.ResolvedKernel("linear")


def test_median_sigma_is_median_feature_distance(digits):
    X = digits[0][:300]
    Xc = X - X.mean(axis=0)
    D = euclidean_distances(Xc.T)
    iu = np.triu_indices(64, 1)
    med = np.median(D[iu][D[iu] > 1e-9])
    _, info = B.feature_kernel(X, kernel="rbf", sigma_scale=2.0)
    assert info.sigma == pytest.approx(2.0 * med, rel=1e-9)


# ------------------------------------------------------------ check 2: entropy identity


@pytest.mark.parametrize("kernel", ["rbf", "poly", "linear"])
def test_entropy_terms_sum_to_kernel_sum(digits, kernel):
    X = digits[0][:400]
    m = B.FDKECA(kernel=kernel).fit(X)
    K, _ = B.feature_kernel(X, kernel=kernel)
    assert np.sum(m.entropy_) == pytest.approx(K.sum(), rel=1e-10)
    assert m.kernel_sum_ == pytest.approx(K.sum(), rel=1e-12)
    assert np.all(np.diff(m.entropy_) <= 1e-12 * m.entropy_[0])
    if kernel == "rbf":
        assert 0.0 < m.renyi_entropy_ <= 1.0


# ------------------------------------------------------------ check 3: linear kernel = PCA


def test_linear_fdkeca_reduces_to_pca(digits):
    X = digits[0]
    n = X.shape[0]
    sk = SkPCA(svd_solver="full").fit(X)
    m = B.FDKECA(kernel="linear", ordering="eigenvalue").fit(X)
    np.testing.assert_allclose(m.eigenvalues_[:40], (n - 1) * sk.explained_variance_[:40],
                               rtol=1e-10, atol=1e-9 * m.eigenvalues_[0])
    cos = np.abs(np.sum(m.components_[:30] * sk.components_[:30], axis=1))
    assert np.all(cos >= 1 - 1e-8), cos.min()
    ours = B.PCA().fit(X)
    np.testing.assert_allclose(ours.variances_[:40] * n / (n - 1), sk.explained_variance_[:40],
                               rtol=1e-10, atol=1e-12)
    cos = np.abs(np.sum(ours.components_[:30] * sk.components_[:30], axis=1))
    assert np.all(cos >= 1 - 1e-8)


# ------------------------------------------------------------ check 4: rotation invariance


def test_full_rotation_agrees_with_raw_pixel_nn(digits):
    X, y = digits
    Xtr, Xte, ytr, yte = train_test_split(X, y, test_size=0.5, stratify=y, random_state=0)
    raw = KNeighborsClassifier(1).fit(Xtr, ytr).predict(Xte)
    D = euclidean_distances(Xte, Xtr, squared=True)
    for model in (B.FDKECA(), B.PCA()):
        pred = model.fit(Xtr, ytr).predict(Xte)
        assert model.n_components_ == 64
        agree = np.mean(pred == raw)
        assert agree >= 0.995, (type(model).__name__, agree)
        for i in np.nonzero(pred != raw)[0]:
            best = D[i].min()
            tied = np.nonzero(D[i] == best)[0]
            assert len(tied) > 1, "a disagreement that is not an exact distance tie"
            assert pred[i] in ytr[tied]


# ------------------------------------------------------------ check 5: KPCA = scikit-learn


def test_kernel_pca_equals_sklearn(digits):
    X = digits[0][:600]
    Xtr, Xte = X[:400], X[400:]
    gamma = 1e-3
    sigma = np.sqrt(1.0 / (2.0 * gamma))
    sk = SkKernelPCA(n_components=20, kernel="rbf", gamma=gamma, eigen_solver="dense")
    ref = sk.fit(Xtr).transform(Xte)
    ours = B.KernelPCA(n_components=20, sigma=sigma).fit(Xtr)
    Z = ours.transform(Xte)
    signs = np.sign(np.sum(Z * ref, axis=0))
    assert np.max(np.abs(Z * signs - ref)) <= 1e-8 * np.max(np.abs(ref))
    np.testing.assert_allclose(ours.eigenvalues_, sk.eigenvalues_, rtol=1e-10)
    ref_train = sk.transform(Xtr)
    assert np.max(np.abs(ours.embedding_ * signs - ref_train)) <= 1e-8 * np.max(np.abs(ref_train))


# ------------------------------------------------------------ check 6: KECA analytic case


def test_keca_two_clusters_on_orthogonal_rays():
    rng = np.random.default_rng(0)
    sigma = 1.0
    a, b = np.zeros(3), np.array([50.0, 0.0, 0.0])
    X = np.vstack([np.tile(a, (30, 1)), np.tile(b, (20, 1))]) + 1e-9 * rng.standard_normal((50, 3))
    m = B.KECA(n_components=2, sigma=sigma).fit(X)
    np.testing.assert_allclose(m.entropy_, [900.0, 400.0], rtol=1e-9)
    assert m.renyi_entropy_ == pytest.approx(0.52, rel=1e-9)
    Z = m.embedding_
    ua, ub = Z[:30].mean(axis=0), Z[30:].mean(axis=0)
    angle = np.degrees(np.arccos(ua @ ub / np.linalg.norm(ua) / np.linalg.norm(ub)))
    assert abs(angle - 90.0) <= 0.5
    kp = B.KernelPCA(n_components=1, sigma=sigma).fit(X).embedding_[:, 0]
    assert np.ptp(np.sign(kp[:30])) == 0 and np.ptp(np.sign(kp[30:])) == 0
    assert np.sign(kp[0]) == -np.sign(kp[30])


# ------------------------------------------------------------ check 9: lfw ranks, eigen-images


def test_lfw_ranks_and_eigen_images():
    from skimage.data import lfw_subset

    faces = lfw_subset()[:10]
    X = faces.reshape(10, -1).astype(np.float64)

    def rank(v):
        return int(np.sum(v > 1e-10 * v.max()))

    assert rank(B.PCA().fit(X).variances_) == 9
    for coef0, expect in [(1.0, 55), (0.0, 45)]:
        m = B.FDKECA(kernel="poly", degree=2, coef0=coef0, ordering="eigenvalue").fit(faces)
        assert rank(m.eigenvalues_) == expect, coef0
    m = B.FDKECA(kernel="poly", degree=2).fit(faces)
    imgs = m.axis_images(63)
    assert imgs.shape == (63, 25, 25) and imgs.dtype == np.float32
    assert imgs.min() >= 0.0 and imgs.max() <= 1.0
    np.testing.assert_allclose(imgs.reshape(63, -1).max(axis=1), 1.0)


# ------------------------------------------------------------ recognition, four methods


def test_four_methods_on_digits(digits):
    X, y = digits
    Xtr, Xte, ytr, yte = train_test_split(X, y, test_size=0.5, stratify=y, random_state=0)
    rows = {}
    for model in (B.PCA(), B.FDKECA(), B.KernelPCA(n_components=64), B.KECA(n_components=64)):
        curve = B.accuracy_curve(model, Xtr, ytr, Xte, yte, dims=range(1, 65))
        rows[type(model).__name__] = B.best_dimension(curve)
    print("digits max accuracy (l):", rows)
    raw = np.mean(KNeighborsClassifier(1).fit(Xtr, ytr).predict(Xte) == yte)
    assert rows["PCA"][1] >= raw - 0.005
    assert rows["FDKECA"][1] >= rows["PCA"][1] - 0.03
    assert rows["KernelPCA"][1] >= 0.9 and rows["KECA"][1] >= 0.9


def test_accuracy_curve_matches_truncated_prediction(digits):
    X, y = digits
    Xtr, Xte, ytr, yte = X[:900], X[900:], y[:900], y[900:]
    m = B.FDKECA()
    curve = B.accuracy_curve(m, Xtr, ytr, Xte, yte, dims=[3, 10, 25])
    for l, acc in curve:
        t = B.FDKECA().fit(Xtr, ytr).truncated(int(l))
        assert t.score(Xte, yte) == pytest.approx(acc)
        ref = KNeighborsClassifier(1).fit(t.transform(Xtr), ytr).predict(t.transform(Xte))
        assert np.mean(ref == yte) == pytest.approx(acc, abs=2 / len(yte))
    l, cv = B.select_dimension_cv(B.PCA(), Xtr, ytr, dims=[2, 8, 30], n_folds=3)
    assert l in (2, 8, 30) and cv.shape == (3, 2) and np.all(cv[:, 1] <= 1.0)


def test_finger_veins_recognition():
    X, y = B.make_finger_veins(n_subjects=40, n_per_subject=10, seed=1)
    assert X.shape == (400, 10, 20) and np.all(np.bincount(y) == 10)
    tr, te = B.split_per_subject(y, 5, seed=0)
    assert len(tr) == 200 and len(te) == 200 and not set(tr) & set(te)
    acc = {}
    for model in (B.PCA(), B.FDKECA()):
        acc[type(model).__name__] = B.best_dimension(
            B.accuracy_curve(model, X[tr], y[tr], X[te], y[te]))[1]
    assert acc["PCA"] >= 0.85 and acc["FDKECA"] >= acc["PCA"] - 0.03, acc


# ------------------------------------------------------------ estimator protocol


def test_reconstruction_is_exact_at_full_dimension(digits):
    X = digits[0][:300]
    for model in (B.FDKECA(), B.PCA(), B.PCA(whiten=True, n_components=40)):
        Z = model.fit_transform(X)
        Xr = model.inverse_transform(Z)
        err = np.abs(Xr - X).max()
        if model.n_components_ == 64:
            assert err <= 1e-9 * np.abs(X).max()
    m = B.FDKECA(ordering="eigenvalue", kernel="linear").fit(X)
    errs = [np.linalg.norm(m.truncated(l).inverse_transform(m.truncated(l).transform(X)) - X)
            for l in (5, 20, 60)]
    assert errs[0] > errs[1] > errs[2]
    with pytest.raises(ValueError, match="pre-image"):
        kp = B.KernelPCA(n_components=3).fit(X)
        kp._model.inverse_transform(kp.transform(X))


def test_pickle_clone_and_string_labels(digits):
    X, y = digits
    names = np.array(["zero", "one", "two", "three", "four", "five", "six", "seven", "eight",
                      "nine"])[y]
    for model in (B.FDKECA(n_components=30), B.PCA(n_components=30),
                  B.KernelPCA(n_components=30), B.KECA(n_components=30)):
        model.fit(X[:600], names[:600])
        pred = model.predict(X[600:700])
        assert pred.dtype.kind == "U" and set(pred) <= set(names)
        back = pickle.loads(pickle.dumps(model))
        np.testing.assert_array_equal(back.predict(X[600:700]), pred)
        np.testing.assert_array_equal(back.transform(X[:5]), model.transform(X[:5]))
        c = clone(model)
        assert c.get_params() == model.get_params() and not hasattr(c, "_model")
        dist, idx = model.kneighbors(X[:3])
        np.testing.assert_array_equal(idx, [0, 1, 2])
        np.testing.assert_allclose(dist, 0.0, atol=1e-6)


def test_nn_classify_matches_sklearn(digits):
    X, y = digits
    pred = B.nn_classify(X[:1000], y[:1000], X[1000:])
    ref = KNeighborsClassifier(1).fit(X[:1000], y[:1000]).predict(X[1000:])
    assert np.mean(pred == ref) >= 0.995


# ------------------------------------------------------------ bad input


def test_bad_input_raises_value_error():
    rng = np.random.default_rng(0)
    X = rng.standard_normal((20, 8))
    cases = [
        (lambda: B.FDKECA().fit(np.zeros((0, 8))), "0 sample"),
        (lambda: B.FDKECA().fit(X[:1]), "minimum of 2"),
        (lambda: B.FDKECA().fit(np.zeros((5, 0))), "0 feature"),
        (lambda: B.FDKECA().fit(np.where(np.eye(20, 8) > 0, np.nan, X)), "NaN|non-finite|finite"),
        (lambda: B.FDKECA().fit(np.where(np.eye(20, 8) > 0, np.inf, X)), "infinity"),
        (lambda: B.FDKECA().fit(X).transform(X[:, :5]), "X has 5 features, but FDKECA is expecting 8"),
        (lambda: B.FDKECA(sigma=0.0).fit(X), "sigma"),
        (lambda: B.FDKECA(sigma=-1.0).fit(X), "sigma"),
        (lambda: B.FDKECA(sigma_scale=np.nan).fit(X), "sigma|scale"),
        (lambda: B.FDKECA(kernel="poly", degree=0).fit(X), "degree"),
        (lambda: B.FDKECA(n_components=0).fit(X), "n_components"),
        (lambda: B.FDKECA(n_components=9).fit(X), "n_components"),
        (lambda: B.KernelPCA(n_components=500).fit(X), "n_components"),
        (lambda: B.FDKECA().fit(X, np.arange(19)), "labels"),
        (lambda: B.FDKECA().fit(np.ones((10, 4))), "all features identical"),
        (lambda: B.KECA().fit(np.ones((10, 4))), "identical"),
        (lambda: B.FDKECA(kernel="sigmoid").fit(X), "kernel"),
        (lambda: B.FDKECA(metric="manhattan").fit(X), "metric"),
        (lambda: B.FDKECA(ordering="random").fit(X), "ordering"),
        (lambda: B.FDKECA().fit(X).predict(X), "without labels"),
        (lambda: B.FDKECA().transform(X), "not fitted"),
        (lambda: B.FDKECA().fit(np.zeros((2, 3, 4, 5))), "4-D"),
        (lambda: B.FDKECA().fit([["a", "b"], ["c", "d"]]), "numeric"),
        (lambda: B.nn_classify(X, np.arange(20), X[:, :3]), "columns"),
        (lambda: B.make_finger_veins(n_subjects=0), "`n_subjects`"),
        (lambda: B.make_finger_veins(n_per_subject=0), "`n_per_subject`"),
        (lambda: B.split_per_subject(np.zeros(4, dtype=int), 4), "samples"),
        (lambda: B.PCA().fit(X).axis_images(3), "shape"),
    ]
    for fn, pattern in cases:
        with pytest.raises(ValueError, match=pattern):
            fn()
