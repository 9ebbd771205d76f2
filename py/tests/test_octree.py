"""wscg.octree (paper 10): checks against NumPy references (Möller-Trumbore brute force,
separating-axis voxelization), the closed-form exact case, the file format and bad input."""

import pickle

import numpy as np
import pytest

from results_check import check_result
from wscg import octree


def _mt_brute_force(v, f, o, d):
    """Nearest hit of every ray against every triangle (NumPy Möller-Trumbore, float64)."""
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    e1, e2 = b - a, c - a
    t_best = np.full(len(o), np.inf)
    p_best = np.full(len(o), -1)
    t_second = np.full(len(o), np.inf)
    for i in range(len(f)):
        p = np.cross(d, e2[i])
        det = p @ e1[i]
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            s = o - a[i]
            u = np.einsum("ij,ij->i", s, p) * inv
            q = np.cross(s, e1[i])
            w = np.einsum("ij,ij->i", d, q) * inv
            t = (q @ e2[i]) * inv
        ok = (det != 0) & (u >= 0) & (u <= 1) & (w >= 0) & (u + w <= 1) & (t >= 0)
        t = np.where(ok, t, np.inf)
        better = t < t_best
        t_second = np.where(better, t_best, np.minimum(t_second, t))
        p_best = np.where(better, i, p_best)
        t_best = np.where(better, t, t_best)
    return t_best, p_best, t_second


def _random_rays(lo, hi, n, seed):
    r = np.random.default_rng(seed)
    size = (hi - lo).max()
    o = lo + size * r.uniform(-0.5, 1.5, (n, 3))
    target = lo + (hi - lo) * r.uniform(0.1, 0.9, (n, 3))
    return o.astype(np.float32), (target - o).astype(np.float32)


def test_triangle_mode_matches_numpy_brute_force_and_the_bvh():
    v, f, c = octree.make_scene("blob", 2)
    tree = octree.build(v, f, c, depth=8)
    o, d = _random_rays(v.min(0), v.max(0), 4000, 1)
    hits = tree.intersect(o, d, mode="triangles")
    t_ref, p_ref, t2 = _mt_brute_force(v, f, o.astype(np.float64), d.astype(np.float64))
    np.testing.assert_array_equal(np.isfinite(hits.t), np.isfinite(t_ref))
    hit = np.isfinite(t_ref)
    assert hit.mean() > 0.5
    np.testing.assert_allclose(hits.t[hit], t_ref[hit], rtol=0, atol=1e-5 * (v.max() - v.min()) * 4)
    with np.errstate(invalid="ignore"):
        untied = hit & (t2 - t_ref > 1e-4)
    same = (hits.prim[untied] == p_ref[untied]).mean()
    assert same >= 0.9999, same
    t_bvh, p_bvh = octree.bvh_intersect(v, f, o, d)
    assert (p_bvh[untied] == p_ref[untied]).mean() >= 0.9999


def test_intersect_without_shading_returns_the_same_hits():
    v, f, c = octree.make_scene("blob", 2)
    tree = octree.build(v, f, c, depth=8)
    o, d = _random_rays(v.min(0), v.max(0), 4000, 2)
    for mode, spread in [("triangles", 0.0), ("hybrid", 0.01), ("voxels", 0.0)]:
        full = tree.intersect(o, d, mode=mode, footprint_spread=spread)
        bare = tree.intersect(o, d, mode=mode, footprint_spread=spread, shading=False)
        assert bare.normal is None and bare.color is None
        assert full.normal.shape == full.color.shape == (len(o), 3)
        assert np.isfinite(full.t).mean() > 0.5
        for k in ("t", "prim", "level"):
            np.testing.assert_array_equal(getattr(bare, k), getattr(full, k))
        if mode == "hybrid":
            # At this spread it stops at voxels for some rays and at triangles for others.
            assert (full.level >= 0).any() and (full.prim >= 0).any()


def test_build_stats_and_hits_are_typed():
    v, f, c = octree.make_scene("atrium", 2)
    tree = octree.build(v, f, c, depth=6)
    st = tree.stats
    check_result(st, octree.BuildStats)
    assert st.n_nodes == tree.n_nodes and st.n_voxels == tree.n_voxels
    assert st.n_fragments >= len(f) - st.n_degenerate_triangles
    assert st.n_early_leaves + st.n_finest_leaves > 0 and st.voxelize_seconds >= 0
    assert octree.from_bytes(tree.to_bytes()).stats is None
    o, d = _random_rays(v.min(0), v.max(0), 50, 3)
    hits = tree.intersect(o, d)
    text = check_result(hits, octree.RayHits)
    assert "t=array(shape=(50,), dtype=float32)" in text
    assert hits.level.dtype == np.int8 and hits.color.shape == (50, 3)
    check_result(tree.intersect(o, d, shading=False), octree.RayHits)


def _sat_overlap(tri, centres, h):
    """Separating-axis test of one triangle against many cubes (NumPy)."""
    v = tri[None, :, :] - centres[:, None, :]
    keep = np.all((v.min(1) <= h) & (v.max(1) >= -h), axis=1)
    e = np.stack([tri[1] - tri[0], tri[2] - tri[1], tri[0] - tri[2]])
    n = np.cross(e[0], e[2])
    dist = v[:, 0, :] @ n
    keep &= np.abs(dist) <= h * np.abs(n).sum()
    for ed in e:
        for ax in np.eye(3):
            a = np.cross(ax, ed)
            p = v @ a
            r = h * np.abs(a).sum()
            keep &= (p.min(1) <= r) & (p.max(1) >= -r)
    return keep


def test_voxelize_equals_a_numpy_separating_axis_reference():
    r = np.random.default_rng(4)
    tris = r.uniform(0, 16, (40, 3, 3))
    tris[:10, :, 2] = 8.0  # on a cell plane
    tris[10:20] = np.round(tris[10:20])  # lattice vertices
    v = tris.reshape(-1, 3)
    f = np.arange(len(v)).reshape(-1, 3)
    cells, prims = octree.voxelize(v, f, 4, ((0, 0, 0), 16.0))
    g = np.stack(np.meshgrid(np.arange(16), np.arange(16), np.arange(16), indexing="ij"), -1).reshape(-1, 3)
    ours = set(zip(map(tuple, cells.tolist()), prims.tolist()))
    ref = set()
    for i, t in enumerate(tris):
        hit = _sat_overlap(t, g + 0.5, 0.5 + 1e-7)
        # g holds cells (x, y, z); voxelize returns them in array axis order (k, j, i).
        ref |= {(tuple(x[::-1]), i) for x in g[hit].tolist()}
    assert ours == ref


def test_exact_square_counts_and_occupancy():
    v, f, _ = octree.make_scene("square")
    for level in range(1, 6):
        early = octree.build(v, f, depth=level, domain=((0, 0, 0), 1.0))
        assert early.n_nodes == 1
        full = octree.build(v, f, depth=level, early_stop=False, domain=((0, 0, 0), 1.0))
        assert full.n_nodes == 1 + 8 * (4 ** level - 1) // 3
        assert full.n_voxels == (4 ** (level + 1) - 1) // 3
    # Occupancy of the full tree at every level = the voxelization's cells coarsened.
    cells, _ = octree.voxelize(v, f, 5, ((0, 0, 0), 1.0))
    # The square lies in the plane z = 1/3: every cell has the array index k = 32 / 3 // 1
    # (the first column, array axis order), and covers the 32 x 32 cells of that slab.
    assert np.all(cells[:, 0] == 10) and len({tuple(c) for c in cells[:, 1:].tolist()}) == 1024
    for k in range(6):
        occ = {tuple(c) for c in full.occupancy(k).tolist()}
        assert occ == {tuple(c) for c in (cells >> (5 - k)).tolist()}


def test_memory_report_full_against_early_stop():
    v, f, c = octree.make_scene("atrium", 4)
    full = octree.build(v, f, c, depth=8, early_stop=False).memory_report()
    early = octree.build(v, f, c, depth=8).memory_report()
    check_result(full, octree.MemoryReport)
    assert full.total == full.nodes + full.triangles + full.tri_index + full.voxels
    assert full.triangles == early.triangles == 48 * len(f)
    assert full.nodes > early.nodes and full.voxels > early.voxels
    assert 1 - early.total / full.total >= 0.35


def test_render_modes_and_lod():
    v, f, c = octree.make_scene("blob", 6)
    tree = octree.build(v, f, c, depth=9)
    (mn, side) = tree.cube
    centre = np.array(mn) + side / 2
    near_eye = centre + side * np.array([0.56, -0.35, 0.25])
    tri, st_t = tree.render(near_eye, centre, mode="triangles", width=128, height=96, return_stats=True)
    assert tri.shape == (96, 128, 3) and tri.dtype == np.float32 and np.isfinite(tri).all()
    assert st_t.n_voxel_hits == 0 and st_t.n_triangle_hits > 1000
    far_eye = centre + 5 * side * np.array([0.8, -0.5, 0.35])
    _, st = tree.render(far_eye, centre, mode="hybrid", width=256, height=256, return_stats=True)
    assert st.n_voxel_hits >= 0.9 * (st.n_voxel_hits + st.n_triangle_hits)
    check_result(st, octree.RenderStats)
    assert st.n_voxel_hits + st.n_triangle_hits + st.n_misses == 256 * 256
    assert 0.0 <= st.blend_min <= st.blend_max <= 1.0
    vox = tree.render(far_eye, centre, mode="voxels", level=4, width=64, height=64)
    assert np.isfinite(vox).all()
    # Display-wall focus: triangles inside the ellipse, voxels well outside it.
    mid_eye = centre + 1.5 * side * np.array([0.8, -0.5, 0.35])
    _, st_f = tree.render(mid_eye, centre, width=128, height=128, focus=(64, 64, 10, 10, 3),
                          return_stats=True)
    _, st_h = tree.render(mid_eye, centre, width=128, height=128, return_stats=True)
    assert st_f.n_voxel_hits > st_h.n_voxel_hits
    img_ao = tree.render(near_eye, centre, mode="triangles", width=64, height=48, n_ao_samples=4)
    assert np.isfinite(img_ao).all()
    with pytest.raises(ValueError, match="focus"):
        tree.render(mid_eye, centre, width=16, height=16, focus=(8, 8, 0, 4, 2))


def test_voxel_attributes_of_a_constant_colour_plane():
    x, y = np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 9))
    v = np.stack([x.ravel(), y.ravel(), 0.3 + 0.2 * x.ravel()], 1)
    q = np.arange(81).reshape(9, 9)[:-1, :-1].ravel()
    f = np.concatenate([np.stack([q, q + 1, q + 10], 1), np.stack([q, q + 10, q + 9], 1)])
    col = np.tile([0.1, 0.5, 0.7], (81, 1))
    tree = octree.build(v, f, col, depth=6, early_stop=False)
    colors, normals, levels = tree.voxels()
    assert np.abs(colors - [0.1, 0.5, 0.7]).max() <= 1 / 255 + 1e-6
    n = np.array([-0.2, 0.0, 1.0]) / np.hypot(0.2, 1.0)
    assert np.arccos(np.clip(normals @ n, -1, 1)).max() <= 1e-3
    assert set(levels.tolist()) == set(range(7))


def test_save_load_pickle_and_damaged_files(tmp_path):
    v, f, c = octree.make_scene("blob", 3)
    tree = octree.build(v, f, c, depth=6)
    p = tmp_path / "t.oct"
    tree.save(p)
    back = octree.load(p)
    assert back.to_bytes() == p.read_bytes() == tree.to_bytes()
    assert pickle.loads(pickle.dumps(tree)).to_bytes() == tree.to_bytes()
    data = bytearray(p.read_bytes())
    data[len(data) // 2] ^= 1
    (tmp_path / "bad.oct").write_bytes(bytes(data))
    with pytest.raises(OSError, match="checksum"):
        octree.load(tmp_path / "bad.oct")
    with pytest.raises(OSError):
        octree.load(tmp_path / "missing.oct")
    with pytest.raises(OSError):
        octree.from_bytes(b"WSCGOCT1")


def test_bad_input_raises_value_error_and_strided_arrays_work():
    v, f, c = octree.make_scene("blob", 1)
    with pytest.raises(ValueError):
        octree.build(v, f[:, :2])
    with pytest.raises(ValueError):
        octree.build(v, f.astype(np.float64))
    with pytest.raises(ValueError, match="faces"):
        octree.build(v, np.where(f == 0, 10_000, f))
    bad = v.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        octree.build(bad, f)
    with pytest.raises(ValueError, match="max_depth"):
        octree.build(v, f, depth=22)
    with pytest.raises(ValueError):
        octree.build(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64))
    with pytest.raises(ValueError):
        octree.build(v, f, c[:5])
    tree = octree.build(v, f, depth=5)
    with pytest.raises(ValueError, match="mode"):
        tree.intersect(np.zeros((1, 3)), np.ones((1, 3)), mode="cones")
    with pytest.raises(ValueError):
        tree.intersect(np.zeros((2, 3)), np.ones((3, 3)))
    with pytest.raises(ValueError):
        tree.render((0, 0, 3), (0, 0, 0), up=(0, 0, 1))
    # Strided and Fortran-ordered inputs are accepted and give the same tree.
    vf = np.asfortranarray(v)
    fs = np.repeat(f, 2, axis=1)[:, ::2]
    assert octree.build(vf, fs, depth=5).to_bytes() == tree.to_bytes()
    # A zero direction misses.
    h = tree.intersect(np.zeros((1, 3)), np.zeros((1, 3)))
    assert np.isinf(h.t[0]) and h.prim[0] == -1
