"""Paper 09 (sparse-grid isosurfaces with tetrahedral-spline normals) from Python, against
scikit-image's marching cubes on full grids."""

import numpy as np
import pytest
from scipy.spatial import cKDTree
from skimage import measure

from results_check import check_result
from wscg import isosurface as iso


def _sphere(n=40, c=(19.37, 20.21, 18.83), r=12.0):
    z, y, x = np.mgrid[:n, :n, :n].astype(np.float64)
    return (np.sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2) - r).astype(np.float32)


def _match(a, b):
    """Distance from every row of ``a`` to the nearest row of ``b`` and that row's index."""
    return cKDTree(np.asarray(b, dtype=np.float64)).query(np.asarray(a, dtype=np.float64))


@pytest.mark.parametrize("name,level", [("marschner_lobb", 0.5013), ("genus3", 0.0113)])
def test_vertices_equal_scikit_image_on_full_grids(name, level):
    vol, spacing, _ = iso.fields.sample(name, 48)
    assert not np.any(vol == np.float32(level))  # no sample on the level: > and >= agree
    v, f, n, info = iso.marching_cubes(vol, level, spacing=spacing, normals=None)
    # scikit-image returns vertices in array order (z, y, x); spacing is (dz, dy, dx) in both.
    sv, sf, _, _ = measure.marching_cubes(vol, level, spacing=spacing, method="lorensen")
    assert len(v) == len(sv)
    d, idx = _match(v[:, ::-1], sv)
    assert d.max() < 1e-5 and len(set(idx)) == len(v)  # a one-to-one match
    assert len(f) == len(sf)
    # Lewiner's MC33 adds interior vertices in some cases; every one of ours is among its.
    lv, _, _, _ = measure.marching_cubes(vol, level, spacing=spacing, method="lewiner")
    assert _match(v[:, ::-1], lv)[0].max() < 1e-5


def test_sparse_grid_matches_full_mesh_and_spline_is_never_zero():
    vol = _sphere()
    sparse, inside = iso.sparsify(vol, 0.0)
    assert np.isnan(sparse).mean() > 0.8
    assert not np.isnan(vol).any()  # the input is untouched
    v0, f0, _, _ = iso.marching_cubes(vol, 0.0, normals=None)
    v1, f1, n1, info = iso.marching_cubes(sparse, 0.0, side_hint=inside)
    np.testing.assert_array_equal(v0, v1)
    np.testing.assert_array_equal(f0, f1)
    assert info.n_undefined == 0 and np.all(np.linalg.norm(n1, axis=1) > 0.999)
    cd, stats = iso.estimate_normals(sparse, 0.0, info.edges, normals="central",
                                     side_hint=inside)
    assert stats.n_undefined > 0.99 * len(v1)
    # Against the exact normals of the sphere (gradient = radial direction).
    c = np.array([19.37, 20.21, 18.83], dtype=np.float32)
    exact = (v1 - c) / np.linalg.norm(v1 - c, axis=1, keepdims=True)
    rms, count, undefined = iso.angular_rms(n1, exact)
    lsn, _ = iso.estimate_normals(sparse, 0.0, info.edges, normals="lsn", side_hint=inside)
    rms_lsn, _, _ = iso.angular_rms(lsn, exact)
    assert count == len(v1) and undefined == 0
    assert rms < rms_lsn < 0.05


def test_normals_agree_with_scikit_image_direction():
    # scikit-image's normals point toward decreasing values; ours point along the gradient.
    vol = _sphere()
    v, f, n, _ = iso.marching_cubes(vol, 0.0, normals="central")
    sv, sf, sn, _ = measure.marching_cubes(vol, 0.0, method="lewiner")
    d, idx = _match(v[:, ::-1], sv)
    assert d.max() < 1e-5
    theirs = sn[idx][:, ::-1]
    cos = np.sum(n * theirs, axis=1)
    assert np.median(cos) < -0.999


def test_spline_beats_lsn_on_the_noisy_8bit_sphere():
    vol = iso.fields.make_noisy_sphere(48, radius=15.0, seed=3)
    res = iso.study_full_cd(vol, 40.0)
    assert res.n_spline_undefined == 0
    assert res.n_lsn_undefined > 0
    assert res.spline.rms < res.lsn.rms


def test_fields_and_study_exact():
    res = iso.study_exact("sphere", 64)
    assert res.central.rms < 1e-3
    assert res.spline.rms <= 0.015 and res.lsn.rms <= 0.03
    vol, spacing, origin = iso.fields.sample("marschner_lobb", 33)
    assert vol.shape == (33, 33, 33) and spacing == pytest.approx((1 / 16,) * 3)
    assert origin == pytest.approx((-1, -1, -1))
    # The field's exact normals at the vertices agree with central differences on a fine
    # grid of the smooth genus-3 surface; the vertices are field points with the field's
    # spacing and origin.
    vol, spacing, origin = iso.fields.sample("genus3", 96)
    v, f, n, _ = iso.marching_cubes(vol, 0.0, spacing=spacing, origin=origin, normals="central")
    exact = iso.fields.exact_normals("genus3", 96, v)
    assert exact.shape == v.shape
    assert iso.angular_rms(n, exact)[0] < 0.05


def test_rotation_classes_and_enumeration():
    classes = {iso.rotation_class(c) for c in range(256)}
    assert classes == set(range(23))
    assert iso.at_risk_configurations(0.0) == list(range(256))


def test_dropouts_and_bad_input():
    vol = _sphere()
    d = iso.random_dropouts(vol, 0.1, seed=1)
    assert 0.08 < np.isnan(d).mean() < 0.12
    v, f, n, info = iso.marching_cubes(d, 0.0)
    assert info.n_skipped_cells > 0 and info.n_undefined == 0
    with pytest.raises(ValueError):
        iso.marching_cubes(np.zeros((4, 4)), 0.0)
    with pytest.raises(ValueError):
        iso.marching_cubes(np.zeros((1, 4, 4)), 0.0)
    with pytest.raises(ValueError):
        iso.marching_cubes(vol, float("nan"))
    with pytest.raises(ValueError):
        iso.marching_cubes(vol, 0.0, spacing=(1, 0, 1))
    with pytest.raises(ValueError):
        iso.marching_cubes(vol, 0.0, normals="sobel")
    with pytest.raises(ValueError):
        iso.marching_cubes(vol, 0.0, side_hint=np.zeros((3, 3, 3), bool))
    with pytest.raises(ValueError):
        iso.estimate_normals(vol, 5.0, np.array([[0, 0, 0, 0]]))
    with pytest.raises(ValueError):
        iso.fields.sample("teapot")
    with pytest.raises(ValueError):
        iso.marching_cubes(vol, 0.0, selection="random")
    with pytest.raises(ValueError):
        iso.marching_cubes(vol, 0.0, normals="lsn", ambiguous_face="both")
    v, f, n, info = iso.marching_cubes(np.full((3, 3, 3), np.nan), 0.0)
    assert len(v) == 0 and len(f) == 0
    v, f, n, info = iso.marching_cubes(vol, 1e6)
    assert len(v) == 0


def test_spline_options_on_a_linear_field():
    # Every tetrahedron choice and averaging is exact on a linear field; the literal eq. 8
    # is not (it scales the components across the edge).
    vol, spacing, _ = iso.fields.sample("linear", 16)
    exact = np.array([0.3, 0.5, 0.7])
    for kw in ({}, {"selection": "nearest"}, {"selection": "both"},
               {"normalize_before_mean": True}):
        v, f, n, _ = iso.marching_cubes(vol, 9.37, spacing=spacing, **kw)
        rms, count, undefined = iso.angular_rms(n, np.tile(exact, (len(n), 1)))
        assert rms < 1e-5 and count == len(n) and undefined == 0, kw
    v, f, n, _ = iso.marching_cubes(vol, 9.37, spacing=spacing, eq8_literal=True)
    assert iso.angular_rms(n, np.tile(exact, (len(n), 1)))[0] > 0.05


def test_results_are_typed():
    vol = _sphere(24, c=(11.3, 12.1, 10.8), r=7.0)
    sparse, inside = iso.sparsify(vol, 0.0)
    v, f, n, info = iso.marching_cubes(sparse, 0.0, side_hint=inside)
    text = check_result(info, iso.MeshInfo)
    assert "edges=array(shape=(%d, 4), dtype=int64)" % len(v) in text
    assert info.cells.shape[1] == 2 and info.n_fallback >= 0
    # Each cell's configuration has bit c set when its corner (c & 1, c >> 1 & 1, c >> 2)
    # (x, y, z offsets from the low corner) is inside.
    flat, config = info.cells.T
    k, j, i = np.unravel_index(flat, vol.shape)
    bits = sum(inside[k + (c >> 2), j + (c >> 1 & 1), i + (c & 1)].astype(np.int64) << c
               for c in range(8))
    np.testing.assert_array_equal(bits, config)
    # Every vertex's edge crosses the level: its low end is inside on exactly one side.
    k, j, i, a = info.edges.T
    step = np.eye(3, dtype=np.int64)[a]
    hi = (k + step[:, 0], j + step[:, 1], i + step[:, 2])
    assert np.all(inside[k, j, i] != inside[hi])
    _, stats = iso.estimate_normals(sparse, 0.0, info.edges, normals="lsn", side_hint=inside)
    check_result(stats, iso.NormalStats)
    assert stats.n_skipped_cells == info.n_skipped_cells
    exact = (v - [11.3, 12.1, 10.8]) / np.linalg.norm(v - [11.3, 12.1, 10.8], axis=1)[:, None]
    r = iso.angular_rms(n, exact)
    check_result(r, iso.AngularRms)
    rms, n_defined, n_undefined = r  # still a tuple
    assert n_defined == len(v) and n_undefined == 0 and rms == r.rms < 0.1
    empty = iso.angular_rms(np.zeros((2, 3)), np.zeros((2, 3)))
    assert np.isnan(empty.rms) and empty.n_undefined == 2
    check_result(empty, iso.AngularRms)  # NaN == NaN after pickling
    full = iso.study_full_cd(vol, 0.0)
    check_result(full, iso.SparseComparison)
    assert full.n_vertices == len(v) and full.n_triangles == len(f)
    assert type(full.spline) is iso.AngularRms and full.spline.n_defined > 0
    assert 0 < full.kept_fraction < 1 and 0 <= full.cd_defined_on_sparse <= 1
    exact_study = iso.study_exact("sphere", 24)
    check_result(exact_study, iso.ExactComparison)
    assert exact_study.central.n_defined == exact_study.n_vertices
