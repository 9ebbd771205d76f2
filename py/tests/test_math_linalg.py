import numpy as np
import pytest
import scipy.linalg
import scipy.sparse
import scipy.sparse.linalg

import wscg.math as wm
from results_check import check_result


def random_spd_sparse(n, rng):
    a = scipy.sparse.random(n, n, density=0.02, random_state=np.random.RandomState(3))
    a = a + a.T
    d = np.abs(a).sum(axis=1).A.ravel() + 1.0 + 100 * rng.random(n)
    return (a + scipy.sparse.diags(d)).tocsr()


def test_cg_equals_spsolve(rng):
    a = random_spd_sparse(300, rng)
    b = rng.standard_normal(300)
    x, info = wm.solve_cg(a, b, tol=1e-12)
    ref = scipy.sparse.linalg.spsolve(a.tocsc(), b)
    assert info.converged
    assert np.max(np.abs(x - ref)) < 1e-9 * np.max(np.abs(ref))
    assert np.linalg.norm(a @ x - b) / np.linalg.norm(b) == pytest.approx(info.relative_residual, abs=1e-12)
    # Warm start at the solution needs no iteration; no preconditioner also converges.
    _, info2 = wm.solve_cg(a, b, x0=x, tol=1e-10)
    assert info2.n_iter == 0
    x3, info3 = wm.solve_cg(a, b, tol=1e-12, preconditioner=None)
    assert info3.n_iter > info.n_iter and np.allclose(x3, ref, atol=1e-8)


def test_laplacian_and_cg_against_scipy():
    indptr, indices, data = wm.laplacian_3d(8, 7, 6)
    n = 8 * 7 * 6
    a = scipy.sparse.csr_matrix((data, indices, indptr), shape=(n, n))
    assert (a != a.T).nnz == 0 and a.diagonal().min() == 6
    xs = np.sin(np.arange(n))
    x, info = wm.cg(indptr, indices, data, a @ xs, tol=1e-12)
    assert np.max(np.abs(x - xs)) < 1e-9


def test_cg_bad_input():
    indptr, indices, data = wm.laplacian_3d(2, 2, 2)
    with pytest.raises(ValueError, match="length"):
        wm.cg(indptr, indices, data, np.ones(7))
    with pytest.raises(ValueError, match="preconditioner"):
        wm.cg(indptr, indices, data, np.ones(8), preconditioner="ilu")
    with pytest.raises(ValueError, match="positive definite"):
        wm.cg([0, 1, 2], [0, 1], [1.0, -1.0], [0.0, 1.0], preconditioner=None)
    with pytest.raises(ValueError, match="indptr"):
        wm.cg([0, 2, 1], [0, 1], [1.0, 1.0], [1.0, 1.0])
    with pytest.raises(ValueError, match="b"):
        wm.cg(indptr, indices, data, np.full(8, np.nan))
    with pytest.warns(RuntimeWarning, match="did not converge"):
        _, info = wm.cg(*wm.laplacian_3d(6, 6, 6), np.ones(216), tol=1e-14, max_iter=2)
    assert not info.converged
    check_result(info, wm.CgInfo)
    assert info.n_iter == 2 and info.relative_residual > 1e-14
    assert repr(info).startswith("CgInfo(n_iter=2, relative_residual=")


def test_dense_decompositions_equal_numpy_and_scipy(rng):
    g = rng.standard_normal((25, 25))
    a = g + g.T
    vals, vecs = wm.eigh(a, which="smallest")
    assert np.allclose(vals, np.linalg.eigvalsh(a), atol=1e-10)
    assert np.allclose(a @ vecs, vecs * vals, atol=1e-9)
    top, tv = wm.eigh(a, k=3)
    assert np.allclose(top, np.linalg.eigvalsh(a)[::-1][:3], atol=1e-10)
    m = rng.standard_normal((30, 8))
    u, s, vt = wm.svd(m)
    assert np.allclose(s, np.linalg.svd(m, compute_uv=False), atol=1e-10)
    assert np.allclose(u @ np.diag(s) @ vt, m, atol=1e-10)
    b = rng.standard_normal(30)
    assert np.allclose(wm.lstsq(m, b), np.linalg.lstsq(m, b, rcond=None)[0], atol=1e-10)
    b2 = rng.standard_normal((30, 3))
    assert np.allclose(wm.lstsq(m, b2), np.linalg.lstsq(m, b2, rcond=None)[0], atol=1e-10)
    h = rng.standard_normal((25, 25))
    spd = h @ h.T + 25 * np.eye(25)
    gv, gvec = wm.eigh_generalized(a, spd)
    assert np.allclose(gv, scipy.linalg.eigh(a, spd, eigvals_only=True), atol=1e-10)
    assert np.allclose(gvec.T @ spd @ gvec, np.eye(25), atol=1e-9)


def test_dense_bad_input(rng):
    with pytest.raises(ValueError, match="symmetric"):
        wm.eigh(rng.standard_normal((4, 4)) + np.triu(np.ones((4, 4))))
    with pytest.raises(ValueError, match="k"):
        wm.eigh(np.eye(3), k=4)
    with pytest.raises(ValueError, match="which"):
        wm.eigh(np.eye(3), which="middle")
    with pytest.raises(ValueError, match="2-D"):
        wm.svd(np.zeros(3))
    with pytest.raises(ValueError, match="positive definite"):
        wm.eigh_generalized(np.eye(2), -np.eye(2))
    with pytest.raises(ValueError, match="rows"):
        wm.lstsq(np.eye(3), np.ones(4))


def test_random_numbers_are_seeded_and_correct():
    a = wm.normal(7, 100_000, mean=2.0, std=3.0)
    assert np.array_equal(a, wm.normal(7, 100_000, mean=2.0, std=3.0))
    assert not np.array_equal(a, wm.normal(8, 100_000, mean=2.0, std=3.0))
    assert abs(a.mean() - 2.0) < 0.05 and abs(a.std() - 3.0) < 0.05
    u = wm.uniform(1, 50_000, -1.0, 1.0)
    assert u.min() >= -1 and u.max() < 1 and abs(u.mean()) < 0.02
    p = wm.permutation(3, 100)
    assert sorted(p) == list(range(100))
    with pytest.raises(ValueError, match="std"):
        wm.normal(0, 3, std=-1)
    with pytest.raises(ValueError):
        wm.uniform(0, 3, 1.0, 1.0)
