"""Paper 08 from Python: many-light rendering with adaptive importance caching."""

import numpy as np
import pytest

from results_check import check_result
from wscg import raytrace as rt


def test_plane_under_a_tiny_light_is_the_closed_form():
    # Emitter VPLs only, no clamping: the tiny square light of power pi acts as a point light
    # at height 1, so L = 0.5 h^2 / (pi d^4) on the plane.
    s = rt.make_manylight_scene("plane", width=48, height=36)
    img, st = rt.render_manylight(s, "reference", n_vpl_paths=64, max_bounces=0, clamp_dist=0.0,
                                  pixel_filter="center")
    assert st.n_vpls == 64
    cam = s.camera
    eye, target = np.array(cam["eye"]), np.array(cam["target"])
    f = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(f, cam["up"]); right /= np.linalg.norm(right)
    up = np.cross(right, f)
    t = np.tan(np.radians(cam["fov_deg"]) / 2)
    checked = 0
    for y in range(0, 36, 5):
        for x in range(0, 48, 5):
            sx = (2 * (x + 0.5) / 48 - 1) * t * 48 / 36
            sy = (1 - 2 * (y + 0.5) / 36) * t
            d = f + right * sx + up * sy
            d /= np.linalg.norm(d)
            if d[1] >= 0:
                continue
            p = eye + d * (-eye[1] / d[1])
            if abs(p[0]) > 9.9 or abs(p[2]) > 9.9:
                continue
            dist = np.linalg.norm(p - np.array([0.0, 1.0, 0.0]))
            want = 0.5 / (np.pi * dist ** 4)
            np.testing.assert_allclose(img[y, x], want, rtol=2e-3)
            checked += 1
    assert checked > 20


def test_methods_agree_with_the_reference_on_average():
    s = rt.make_manylight_scene("cornell", width=48, height=36)
    # At the pixel centres: the estimators against the all-VPL sum at the same points.
    kw = dict(n_vpl_paths=300, n_cache=60, spp=8, pixel_filter="center")
    ref, _ = rt.render_manylight(s, "reference", **kw)
    lum = lambda im: float((im @ np.array([0.2126, 0.7152, 0.0722])).mean())
    for method in ["adaptive", "adaptive_uniform", "ic", "power"]:
        imgs = [rt.render_manylight(s, method, seed=k, **kw)[0] for k in range(12)]
        mean = np.mean(imgs, axis=0)
        assert abs(lum(mean) / lum(ref) - 1) < 0.03, method
    img, st = rt.render_manylight(s, "adaptive", **kw)
    assert img.shape == (36, 48, 3) and img.dtype == np.float32
    assert st.n_records == st.records.shape[0] <= 60
    assert st.record_inserted.sum() == st.n_inserted
    assert np.all(st.record_pixels >= 0)
    text = check_result(st, rt.ManyLightStats)
    assert st.method == "adaptive" and "records=array(shape=(" in text
    assert st.n_passes >= 1 and st.cache_bytes > 0 and st.n_cache_shadow_rays > 0
    _, power = rt.render_manylight(s, "power", **kw)
    check_result(power, rt.ManyLightStats)
    assert power.n_records is None and power.records.shape == (0, 3)


def test_user_mesh_and_obj(tmp_path):
    v = np.array([[-5, 0, -5], [5, 0, -5], [5, 0, 5], [-5, 0, 5],
                  [-0.5, 2, -0.5], [0.5, 2, -0.5], [0.5, 2, 0.5], [-0.5, 2, 0.5]], float)
    f = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7]])
    albedo = np.full((4, 3), 0.5)
    emission = np.zeros((4, 3)); emission[2:] = 5.0
    cam = dict(eye=[0, 4, -6], target=[0, 0, 0], up=[0, 1, 0], fov_deg=50, width=32, height=24)
    s = rt.manylight_from_arrays(v, f, albedo, emission, camera=cam)
    assert (s.n_triangles, s.n_emitters) == (4, 2)
    img, _ = rt.render_manylight(s, "adaptive", n_vpl_paths=50, n_cache=20, spp=4)
    assert img.shape == (24, 32, 3) and img.max() > 0
    obj = tmp_path / "scene.obj"
    (tmp_path / "scene.mtl").write_text("newmtl lamp\nKd 0.5 0.5 0.5\nKe 5 5 5\n"
                                        "newmtl floor\nKd 0.5 0.5 0.5\n")
    obj.write_text("mtllib scene.mtl\n" + "".join(f"v {a} {b} {c}\n" for a, b, c in v)
                   + "usemtl floor\nf 1 3 2\nf 1 4 3\nusemtl lamp\nf 5 6 7\nf 5 7 8\n")
    before = obj.read_bytes()
    t = rt.load_manylight_obj(obj, camera=cam)
    assert (t.n_triangles, t.n_emitters) == (4, 2)
    a, _ = rt.render_manylight(t, "reference", n_vpl_paths=50)
    b, _ = rt.render_manylight(s, "reference", n_vpl_paths=50)
    np.testing.assert_allclose(a, b, rtol=1e-5, atol=1e-7)
    assert obj.read_bytes() == before


def test_bad_input():
    s = rt.make_manylight_scene("cornell", width=16, height=12)
    with pytest.raises(ValueError):
        rt.render_manylight(s, "magic")
    with pytest.raises(ValueError):
        rt.render_manylight(s, "adaptive", spp=0)
    with pytest.raises(ValueError):
        rt.render_manylight(s, "adaptive", n_cache=0)
    with pytest.raises(ValueError):
        rt.render_manylight(s, "adaptive", n_cache=10_000)
    with pytest.raises(ValueError):
        rt.render_manylight(s, "adaptive", theta_max=4.0)
    with pytest.raises(ValueError):
        rt.render_manylight(s, "adaptive", camera=dict(width=0))
    with pytest.raises(ValueError, match="defensive"):
        rt.render_manylight(s, "adaptive", defensive=1.5)
    with pytest.raises(ValueError, match="filter"):
        rt.render_manylight(s, "adaptive", pixel_filter="gauss")
    with pytest.raises(ValueError, match="pixel_samples"):
        rt.render_manylight(s, "adaptive", n_pixel_samples=0)
    for share in (-0.1, 1.0, float("nan")):
        with pytest.raises(ValueError, match="near_share"):
            rt.render_manylight(s, "adaptive", near_share=share)
    with pytest.raises(ValueError, match="n_near_vpls"):
        rt.render_manylight(s, "adaptive", n_near_vpls=0)
    with pytest.raises(ValueError, match="record_pos"):
        rt.manylight_record_weight([0, 0, 0], [0, 0, 1], np.zeros((2, 2)), np.zeros((2, 3)), 1.0)
    with pytest.raises(ValueError, match="unit"):
        rt.manylight_record_weight([0, 0, 0], [0, 0, 2], np.zeros((1, 3)), [[0, 0, 1]], 1.0)
    with pytest.raises(ValueError, match="d_max"):
        rt.manylight_record_weight([0, 0, 0], [0, 0, 1], np.zeros((1, 3)), [[0, 0, 1]], 0.0)
    with pytest.raises(ValueError):
        rt.make_manylight_scene("sponza")
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    with pytest.raises(ValueError):
        rt.manylight_from_arrays(v, [[0, 1, 5]], [[0.5] * 3], [[0.0] * 3])
    with pytest.raises(ValueError):
        rt.manylight_from_arrays(np.where(v == 1, np.nan, v), [[0, 1, 2]], [[0.5] * 3], [[0.0] * 3])
    with pytest.raises(ValueError):
        rt.manylight_from_arrays(v, [[0, 1]], [[0.5] * 3], [[0.0] * 3])
    dark = rt.manylight_from_arrays(v, [[0, 1, 2]], [[0.5] * 3], [[0.0] * 3])
    with pytest.raises(ValueError, match="emissive"):
        rt.render_manylight(dark, "reference")
    with pytest.raises(OSError, match="missing.obj"):
        rt.load_manylight_obj("/nonexistent/missing.obj")


def test_record_weight_is_eqs_2_to_4():
    # In the plane of the shading point sqrt(1 - |n . v|) = 1, so the weight is
    # w_hat = (w - w0) / (1 - w0), w = (1 - theta / pi)(1 - d' / (1 + lam d')).
    def w(d, theta, lam=5.0, theta_max=np.pi / 6):
        f = lambda d, t: (1 - t / np.pi) * (1 - d / (1 + lam * d))
        w0 = f(1.0, theta_max)
        return np.clip((f(d, theta) - w0) / (1 - w0), 0, 1)
    d = np.array([0.0, 0.1, 0.3, 0.6, 0.9, 1.2])
    theta = np.array([0.0, 0.2, 0.1, 0.3, 0.0, 0.0])
    pos = np.stack([d, np.zeros_like(d), np.zeros_like(d)], axis=1)
    nrm = np.stack([np.sin(theta), np.zeros_like(d), np.cos(theta)], axis=1)
    got = rt.manylight_record_weight([0, 0, 0], [0, 0, 1], pos, nrm, d_max=1.0)
    np.testing.assert_allclose(got, w(d, theta), atol=1e-12)
    assert got[0] == 1.0 and got[-1] > 0  # past d_max only the lookup drops a record
    # Straight above: the first factor of eq. (3) is 0; at 45 degrees sqrt(1 - cos 45).
    up = rt.manylight_record_weight([0, 0, 0], [0, 0, 1], [[0, 0, 0.3], [0.3, 0, 0.3]],
                                    [[0, 0, 1], [0, 0, 1]], d_max=1.0)
    assert up[0] == 0.0
    np.testing.assert_allclose(up[1], np.sqrt(1 - np.sqrt(0.5)) * w(0.3 * np.sqrt(2), 0.0))


def test_filters_defensive_share_and_record_statistics():
    s = rt.make_manylight_scene("cornell", width=48, height=36)
    kw = dict(n_vpl_paths=200, n_cache=40, spp=8)
    centre, _ = rt.render_manylight(s, "reference", pixel_filter="center", **kw)
    box, _ = rt.render_manylight(s, "reference", n_pixel_samples=16, **kw)
    tent, _ = rt.render_manylight(s, "reference", pixel_filter="tent", n_pixel_samples=16, **kw)
    lum = np.array([0.2126, 0.7152, 0.0722])
    # The light's edge: box-filtered pixels there mix light and ceiling, the centres do not.
    edge = np.abs(box @ lum - centre @ lum) > 0.1 * (centre @ lum)
    assert 0 < edge.mean() < 0.2
    assert abs((box @ lum).mean() / (tent @ lum).mean() - 1) < 0.05
    paper, st = rt.render_manylight(s, "adaptive", defensive=0.0, **kw)
    default, st2 = rt.render_manylight(s, "adaptive", **kw)
    assert not np.array_equal(paper, default)
    # The near-VPL share reaches the renderer: 0 (the paper's strategies) and another count
    # of nearest VPLs change the image; the same settings repeat it bit for bit.
    no_near, _ = rt.render_manylight(s, "adaptive", near_share=0.0, **kw)
    fewer, _ = rt.render_manylight(s, "adaptive", n_near_vpls=4, **kw)
    again, _ = rt.render_manylight(s, "adaptive", near_share=0.25, n_near_vpls=32, **kw)
    assert not np.array_equal(no_near, default) and not np.array_equal(fewer, default)
    assert np.array_equal(again, default)
    k = st.n_records
    assert st.record_normals.shape == (k, 3) and st.record_radii.shape == (k,)
    np.testing.assert_allclose(np.linalg.norm(st.record_normals, axis=1), 1.0, atol=1e-9)
    assert np.all(st.record_radii > 0)
    assert st.n_initial + st.n_inserted == st.n_records
