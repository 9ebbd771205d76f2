"""Paper 04 from Python: JBMD against a numpy + scipy cKDTree reference implementation of
the same algorithm, the baselines, the metric and bad input."""

import numpy as np
import pytest
from jbmd_reference import boundary as _boundary
from jbmd_reference import normals as _normals
from jbmd_reference import reference_jbmd, reference_two_stage

from wscg import meshfilter as M


def test_jbmd_matches_the_numpy_reference():
    v, f, c = M.make_mesh("cube", 12)
    d = M.mvd(v, f)
    noisy = M.add_noise(v, f, 0.5 * d, seed=3)
    ours = M.jbmd(noisy, f, c, sigma_d=2 * d, sigma_o=0.5 * d, n_neighbors=20, n_iter=4,
                  normal_n_iter=0)
    ref = reference_jbmd(noisy, f, c, 2 * d, 0.5 * d, 30.0, 0.8, 20, 4)
    np.testing.assert_allclose(ours, ref, atol=1e-9)
    # float32 and int32 inputs are accepted.
    ours32 = M.jbmd(noisy.astype(np.float32), f.astype(np.int32), c.astype(np.uint8), n_neighbors=20,
                    n_iter=1)
    assert ours32.shape == v.shape
    # Denoising works: the error drops well below the noise.
    assert M.mean_error(ours, v) < 0.6 * M.mean_error(noisy, v)


def test_two_stage_matches_the_numpy_reference_and_keeps_edges():
    v, f, c = M.make_mesh("cube", 12)
    d = M.mvd(v, f)
    noisy = M.add_noise(v, f, 0.5 * d, seed=3)
    ours = M.jbmd(noisy, f, c, sigma_d=2 * d, n_iter=3, normal_n_iter=4, sigma_n=0.5,
                  vertex_n_iter=5)
    ref = reference_two_stage(noisy, f, c.astype(float), 2 * d, 0.5, 30.0, 3, 4, 5)
    np.testing.assert_allclose(ours, ref, atol=1e-9)
    nocol = M.jbmd(noisy, f, sigma_d=2 * d, n_iter=3, normal_n_iter=4, vertex_n_iter=5)
    np.testing.assert_allclose(nocol, reference_two_stage(noisy, f, None, 2 * d, 0.5, 30.0, 3, 4, 5),
                               atol=1e-9)
    # The default (two-stage) update is closer to the true edges than the paper's.
    edge = (np.sum((v <= 1.5 / 12) | (v >= 1 - 1.5 / 12), axis=1) >= 2)
    err = lambda x: np.linalg.norm(x[edge] - v[edge], axis=1).mean()  # noqa: E731
    assert err(M.jbmd(noisy, f, c)) < 0.7 * err(M.jbmd(noisy, f, c, normal_n_iter=0))
    with pytest.raises(ValueError):
        M.jbmd(noisy, f, c, sigma_n=0.0)
    with pytest.raises(ValueError):
        M.jbmd(noisy, f, c, normal_n_iter=-1)


def test_cad_part_and_its_labels():
    v, f, c = M.make_mesh("cad", 10)
    patch, crease = M.cad_labels(10)
    assert len(patch) == len(crease) == len(v)
    fillet = v[patch == 5]
    np.testing.assert_allclose(np.hypot(fillet[:, 0] - 0.5, fillet[:, 1] - 1.5), 0.5, atol=1e-12)
    # One colour per patch.
    for p in range(7):
        assert len(np.unique(c[patch == p], axis=0)) == 1
    # The open extrusion's boundary loops stay, JBMD equals the numpy reference there too.
    d = M.mvd(v, f)
    noisy = M.add_noise(v, f, 0.5 * d, seed=5)
    ours = M.jbmd(noisy, f, c, sigma_d=2 * d, sigma_o=0.5 * d, n_neighbors=20, n_iter=3,
                  normal_n_iter=0)
    ref = reference_jbmd(noisy, f, c, 2 * d, 0.5 * d, 30.0, 0.8, 20, 3)
    np.testing.assert_allclose(ours, ref, atol=1e-9)
    ends = (v[:, 2] == 0.0) | (v[:, 2] == 1.0)
    np.testing.assert_array_equal(ours[ends], noisy[ends])
    assert M.mean_error(ours, v) < 0.6 * M.mean_error(noisy, v)
    with pytest.raises(ValueError):
        M.cad_labels(0)


def _rings(v, f):
    """1-ring neighbour lists."""
    nb = [set() for _ in range(len(v))]
    for a, b, c in f:
        nb[a] |= {b, c}
        nb[b] |= {a, c}
        nb[c] |= {a, b}
    return [sorted(x) for x in nb]


def _umbrella(v, rings, fixed, lam):
    m = np.array([v[r].mean(0) for r in rings])
    out = v + lam * (m - v)
    out[fixed] = v[fixed]
    return out


def test_laplacian_family_matches_numpy():
    """Laplacian, Taubin and HC-Laplacian equal direct numpy implementations of their
    update rules (an open grid, so the frozen boundary is exercised)."""
    v, f, _ = M.make_mesh("plane", 8)
    v = M.add_noise(v, f, 0.02, isotropic=True, seed=2)
    rings, fixed = _rings(v, f), _boundary(v, f)
    ref = v.copy()
    for _ in range(3):
        ref = _umbrella(ref, rings, fixed, 0.4)
    np.testing.assert_allclose(M.laplacian(v, f, 0.4, 3), ref, atol=1e-14)
    ref = v.copy()
    for _ in range(3):
        ref = _umbrella(_umbrella(ref, rings, fixed, 0.5), rings, fixed, -0.53)
    np.testing.assert_allclose(M.taubin(v, f, 0.5, -0.53, 3), ref, atol=1e-14)
    # HC (Vollmer et al. 1999): p = L(q); b = p - (a o + (1 - a) q); q = p - (beta b + (1 -
    # beta) mean(b over the ring)).
    alpha, beta, q = 0.1, 0.6, v.copy()
    for _ in range(3):
        p = _umbrella(q, rings, fixed, 1.0)
        bb = p - (alpha * v + (1 - alpha) * q)
        mb = np.array([bb[r].mean(0) for r in rings])
        q = p - (beta * bb + (1 - beta) * mb)
        q[fixed] = p[fixed]
    np.testing.assert_allclose(M.hc_laplacian(v, f, alpha, beta, 3), q, atol=1e-14)


def test_bilateral_matches_numpy_and_keeps_volume():
    """One BMD iteration equals a direct implementation (neighbours within 2 sigma_c on the
    connected surface, Fleishman's weights); volume preservation keeps the volume."""
    v, f, _ = M.make_mesh("sphere", 2)
    d = M.mvd(v, f)
    noisy = M.add_noise(v, f, 0.3 * d, seed=1)
    sc, ss = 1.5 * d, 0.5 * d
    rings, n = _rings(noisy, f), _normals(noisy, f)
    ref = noisy.copy()
    for i in range(len(noisy)):
        seen, stack, sw, swh = {i}, [i], 0.0, 0.0
        while stack:
            a = stack.pop()
            for b in rings[a]:
                if b in seen:
                    continue
                seen.add(b)
                t = np.linalg.norm(noisy[i] - noisy[b])
                if t > 2 * sc:
                    continue
                stack.append(b)
                h = n[i] @ (noisy[i] - noisy[b])
                w = np.exp(-t * t / (2 * sc * sc) - h * h / (2 * ss * ss))
                sw, swh = sw + w, swh + w * h
        ref[i] = noisy[i] - n[i] * swh / sw
    np.testing.assert_allclose(M.bilateral(noisy, f, sc, ss, 1, volume_preserve=False), ref,
                               atol=1e-12)
    vol = lambda x: np.einsum("ij,ij->i", x[f[:, 0]], np.cross(x[f[:, 1]], x[f[:, 2]])).sum() / 6  # noqa: E731
    kept = M.bilateral(noisy, f, sc, ss, 5, volume_preserve=True)
    shrunk = M.bilateral(noisy, f, sc, ss, 5, volume_preserve=False)
    assert abs(vol(kept) - vol(noisy)) < 1e-9 * abs(vol(noisy))
    assert vol(shrunk) < 0.99 * vol(noisy)


def test_mean_error_matches_brute_force():
    v, _, _ = M.make_mesh("sphere", 3)
    x = np.random.default_rng(0).normal(size=(300, 3))
    brute = np.linalg.norm(x[:, None, :] - v[None, :, :], axis=2).min(1).mean()
    assert M.mean_error(x, v) == pytest.approx(brute, abs=1e-12)


def _point_triangle_distance(p, a, b, c):
    """Distance from points ``p`` (m, 3) to every triangle (t, 3) as an (m, t) array: the
    minimum over the interior (barycentric projection) and the three edges."""
    p = p[:, None, :]
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    h = np.einsum("mtj,tj->mt", p - a, n)
    q = p - h[..., None] * n
    inside = np.ones(h.shape, bool)
    for u, w in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("mtj,tj->mt", np.cross(w - u, q - u), n) >= 0
    d = np.where(inside, np.abs(h), np.inf)
    for u, w in ((a, b), (b, c), (c, a)):
        e = w - u
        t = np.clip(np.einsum("mtj,tj->mt", p - u, e) / np.einsum("tj,tj->t", e, e), 0, 1)
        d = np.minimum(d, np.linalg.norm(p - (u + t[..., None] * e), axis=2))
    return d


def test_surface_error_matches_brute_force():
    v, f, _ = M.make_mesh("sphere", 2)
    gt = M.add_noise(v, f, 0.05, seed=3)
    x = np.random.default_rng(1).normal(scale=0.7, size=(400, 3))
    brute = _point_triangle_distance(x, gt[f[:, 0]], gt[f[:, 1]], gt[f[:, 2]]).min(1).mean()
    assert M.surface_error(x, gt, f) == pytest.approx(brute, abs=2e-6)
    assert M.surface_error(gt, gt, f) < 1e-6
    assert M.surface_error(x, gt, f) < M.mean_error(x, gt)


def test_bad_input():
    v, f, c = M.make_mesh("cube", 4)
    bad = [
        lambda: M.jbmd(v, f, sigma_d=0.0),
        lambda: M.jbmd(v, f, lam=1.5),
        lambda: M.jbmd(v, f, n_neighbors=0),
        lambda: M.jbmd(v, f, n_neighbors=len(v)),
        lambda: M.jbmd(v, f, c[:5]),
        lambda: M.jbmd(v, f[:, :2]),
        lambda: M.jbmd(v, f + len(v)),
        lambda: M.jbmd(np.where(np.arange(len(v))[:, None] == 3, np.nan, v), f),
        lambda: M.jbmd(np.zeros((0, 3)), np.zeros((0, 3), int)),
        lambda: M.bilateral(v, f, -1.0, 1.0),
        lambda: M.laplacian(v, f, 0.0),
        lambda: M.make_mesh("torus"),
        lambda: M.add_noise(v, f, -1.0),
        lambda: M.surface_error(np.zeros((0, 3)), v, f),
        lambda: M.surface_error(v[:, :2], v, f),
        lambda: M.surface_error(v, v, np.zeros((0, 3), int)),
    ]
    for fn in bad:
        with pytest.raises(ValueError):
            fn()


def test_array_likes_of_any_order_and_dtype_give_the_same_result():
    """The native functions take array-likes: lists, other dtypes, Fortran order and views
    read in C order (a Fortran-ordered array is contiguous, but not in C order)."""
    v, f, _ = M.make_mesh("cube", 4)
    ref = M.laplacian(v, f, n_iter=2)
    for vv, ff in [(v.tolist(), f.tolist()), (np.asfortranarray(v), np.asfortranarray(f)),
                   (v.astype(np.float32).astype(np.float64), f.astype(np.int32)),
                   (np.hstack([v, v])[:, :3], f[::1])]:
        np.testing.assert_array_equal(M.laplacian(vv, ff, n_iter=2), ref)
    assert M.mvd(np.asfortranarray(v), f) == M.mvd(v, f)


def test_bad_arguments_are_refused_by_name():
    v, f, _ = M.make_mesh("cube", 4)
    for match, call in [("`vertices` must be real-valued", lambda: M.mvd(v.astype(complex), f)),
                        ("`faces` must be a numeric array", lambda: M.mvd(v, "abc")),
                        ("`faces` must be an integer array", lambda: M.mvd(v, f + 0.5)),
                        ("`n_iter` is out of range", lambda: M.taubin(v, f, n_iter=-1)),
                        ("`seed` is out of range", lambda: M.add_noise(v, f, 0.1, seed=2**70))]:
        with pytest.raises(ValueError, match=match):
            call()
