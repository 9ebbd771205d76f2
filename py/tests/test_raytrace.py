"""Paper 07 from Python: the paint renderer, the microstructure, the observer's statistics,
the optics, the stereo rig and the study statistics, checked against independent numpy /
scipy / scikit-image computations."""

import numpy as np
import pytest
from scipy import stats
from skimage.measure import label

from results_check import check_result
from wscg import doe, raytrace as rt

SMALL = dict(region_mm=(-1.5, -1.5, 1.5, 1.5), magnification=4.0, spp=4)


def test_pair_shares_the_microstructure_and_is_deterministic():
    (l, li), (r, ri) = rt.render_plate("pair", return_info=True, light_deg=4.0,
                                       light_elevation_deg=75.0, **SMALL)
    assert l.shape == r.shape == (43, 43, 3) and l.dtype == np.float32
    assert li.mm_per_px == pytest.approx(3.0 / 43)
    ov = rt.binocular_overlap(li.glint_ids, ri.glint_ids)
    assert 0.05 < ov < 0.95
    again, info = rt.render_plate("left", return_info=True, light_deg=4.0,
                                  light_elevation_deg=75.0, **SMALL)
    np.testing.assert_array_equal(again, l)
    # Every pixel's glinting flake is among the image's glinting flakes.
    ids = info.flake_id[info.flake_id != np.iinfo(np.uint64).max]
    assert np.isin(ids, info.glint_ids).all() and ids.size > 0
    # No pixel brighter than the lamp.
    assert l[..., 1].max() <= info.lamp_y * (1 + 1e-6)
    text = check_result(info, rt.PlateInfo)
    assert "flake_id=array(shape=(43, 43), dtype=uint64)" in text and info.spectrum is None
    assert info.region_mm == pytest.approx((-1.5, -1.5, 1.5, 1.5))


def test_white_plate_is_srgb_white_under_d65():
    from wscg.raytrace import daylight
    img = rt.render_plate("cyclopean", color_space="srgb", coat_ior=1.0, binder_ior=1.0, base_albedo=1.0,
                          density=0.0, light_cct=6504.0, light_elevation_deg=60.0,
                          light_deg=2.0, **SMALL)
    # CIE D65 is the daylight spectrum at 6504 K: the white plate is sRGB white.
    assert np.abs(img.mean(axis=(0, 1)) - 1.0).max() < 0.01
    assert daylight(6504.0).shape == (81,)


def test_glint_stats_against_skimage_labels(rng):
    y = (rng.random((60, 80)) < 0.03).astype(np.float32) * 5.0 + 0.1
    s = rt.glint_stats(y, 0.05)
    lab, n = label(y > 4 * np.median(y), connectivity=2, return_num=True)
    check_result(s, rt.GlintStats)
    assert s.n_glints == n
    assert s.glint_density_per_mm2 == pytest.approx(n / (60 * 80 * 0.05 ** 2))
    assert s.mean_glint_area_mm2 == pytest.approx((lab > 0).sum() / n * 0.05 ** 2)
    assert s.threshold == pytest.approx(4 * np.median(y))
    with pytest.raises(ValueError):
        rt.glint_stats(np.full((4, 4), np.nan), 0.1)


def test_tile_statistics():
    counts = []
    for seed in range(40):
        tile, clamped = rt.make_tile(radius_um=20.0, density=3.0, seed=seed)
        counts.append(len(tile))
        assert clamped == 0
        assert np.allclose(tile["nx"] ** 2 + tile["ny"] ** 2 + tile["nz"] ** 2, 1.0)
    lam = 3.0 * 450.0 ** 2 / (np.pi * 400.0 * (1 + 0.15 ** 2))
    assert abs(np.mean(counts) - lam) < 3 * np.sqrt(lam / 40)
    tilts = np.degrees(np.arccos(tile["nz"]))
    # Half-normal tilts of sigma 8 degrees (the default).
    assert stats.kstest(tilts, stats.halfnorm(scale=8.0).cdf).pvalue > 0.001


def test_fresnel_against_complex_formula():
    cos = np.linspace(0.05, 1.0, 50)
    n, k = 1.1, 6.0
    eta = n + 1j * k
    sin2 = 1 - cos ** 2
    ct = np.sqrt(eta ** 2 - sin2) / eta
    rs = (cos - eta * ct) / (cos + eta * ct)
    rp = (eta * cos - ct) / (eta * cos + ct)
    ref = 0.5 * (abs(rs) ** 2 + abs(rp) ** 2)
    np.testing.assert_allclose(rt.fresnel_conductor(cos, n, k), ref, rtol=1e-10)
    # Total internal reflection from glass to air beyond the critical angle.
    assert rt.fresnel_dielectric([0.5], 1 / 1.5)[0] == pytest.approx(1.0)
    nk = rt.aluminium_nk([550.0])
    assert 0.5 < nk[0, 0] < 1.5 and 5.5 < nk[0, 1] < 7.0


def test_stereo_parallax():
    pts = np.array([[0.01, 0.02, 0.77], [0.05, -0.03, 1.2]])
    l, r = rt.project(pts, "left"), rt.project(pts, "right")
    np.testing.assert_allclose(l[0], r[0], atol=1e-9)
    pitch = 0.53136 / 1920
    assert r[1, 0] - l[1, 0] == pytest.approx(0.065 * (1.2 - 0.77) / 1.2 / pitch)


def test_rgb_baseline_matches_spectral_for_a_grey_metal():
    kw = dict(light_deg=3.0, light_elevation_deg=75.0, metal_nk=(1.2, 7.0), **SMALL)
    a = rt.render_plate("cyclopean", **kw)
    b = rt.render_plate("cyclopean", color_mode="rgb", **kw)
    np.testing.assert_allclose(a.mean(axis=(0, 1)), b.mean(axis=(0, 1)), rtol=1e-5)


def test_bad_paint_input():
    for bad in [dict(radius_um=-1.0), dict(density=np.nan), dict(spp=0),
                dict(region_mm=(1, 1, 1, 2)), dict(coat_ior=0.9), dict(model="foam"),
                dict(metal="gold"), dict(light_cct=1000.0)]:
        with pytest.raises(ValueError):
            rt.render_plate("left", **{**SMALL, **bad})
    with pytest.raises(ValueError):
        rt.render_plate("nose")
    with pytest.raises(ValueError):
        rt.make_tile(thickness_um=30.0)


def test_caustics_on_a_diffuse_base():
    # A sparse paint over a white-ish base: the photon map adds the light the flakes send
    # down (via the top surface); without photons only the direct light reaches the base.
    kw = dict(SMALL, density=0.7, base_albedo=0.5)
    with_c = rt.render_plate("cyclopean", n_photons=200_000, **kw)
    without = rt.render_plate("cyclopean", n_photons=0, **kw)
    assert with_c[..., 1].mean() > 1.005 * without[..., 1].mean()
    black = dict(SMALL, density=0.7)
    np.testing.assert_array_equal(rt.render_plate("cyclopean", n_photons=200_000, **black),
                                  rt.render_plate("cyclopean", n_photons=0, **black))
    with pytest.raises(ValueError):
        rt.render_plate("cyclopean", n_photons=100, n_photon_neighbors=0, **kw)


def test_ccd_is_the_papers_design():
    x = doe.ccd(2, "inscribed", "rotatable", (3, 2))
    phys = doe.decode(x, [15.0, 3.5], [45.0, 9.5])
    rows = {tuple(np.round(r, 2)) for r in phys}
    assert {(19.39, 4.38), (40.61, 8.62), (15.0, 6.5), (30.0, 9.5), (30.0, 6.5)} <= rows
    assert (np.abs(phys - [30.0, 6.5]).sum(axis=1) < 1e-9).sum() == 5
    np.testing.assert_allclose(doe.encode(phys, [15.0, 3.5], [45.0, 9.5]), x, atol=1e-12)


def test_rsm_against_numpy_least_squares(rng):
    x = doe.ccd(2, "inscribed", "rotatable", (3, 2))
    y = 3 + x[:, 0] - 2 * x[:, 1] + 5 * x[:, 0] ** 2 + 2 * x[:, 1] ** 2 + rng.normal(0, 0.3, 13)
    f = doe.fit_rsm(x, y, interaction=False)
    a = np.column_stack([np.ones(13), x, x ** 2])
    coef, *_ = np.linalg.lstsq(a, y, rcond=None)
    np.testing.assert_allclose(f.coef, coef, rtol=1e-9, atol=1e-12)
    h = np.diag(a @ np.linalg.solve(a.T @ a, a.T))
    np.testing.assert_allclose(f.leverage, h, rtol=1e-9)
    # PRESS by refitting without each run.
    press = 0.0
    for i in range(13):
        keep = np.arange(13) != i
        c, *_ = np.linalg.lstsq(a[keep], y[keep], rcond=None)
        press += (y[i] - a[i] @ c) ** 2
    assert f.press == pytest.approx(press, rel=1e-9)
    resid = y - a @ coef
    s2 = resid @ resid / (13 - 5)
    se = np.sqrt(np.diag(np.linalg.inv(a.T @ a)) * s2)
    np.testing.assert_allclose(f.p, 2 * stats.t.sf(np.abs(coef / se), 8), rtol=1e-7)
    assert all(e > 0 for e in f.canonical_eigs)


def test_anova_lsd_williams_panel(rng):
    subj = rng.normal(0, 1, (26, 1, 1))
    scores = 5 + subj + rng.normal(0, 1, (26, 2, 13))
    scores[:, 1] -= 0.5
    t = doe.rm_anova(scores)
    # Two conditions: F of the condition equals the paired t statistic squared.
    tt = stats.ttest_rel(scores[:, 0].mean(axis=1), scores[:, 1].mean(axis=1))
    assert t.condition.F == pytest.approx(tt.statistic ** 2, rel=1e-9)
    assert t.condition.p == pytest.approx(tt.pvalue, rel=1e-6)
    l = doe.lsd(scores[:, 0], 0.05)
    one = doe.rm_anova_oneway(scores[:, 0])
    assert l.lsd == pytest.approx(stats.t.ppf(0.975, one.df_error) * np.sqrt(2 * one.ms_error / 26))
    w = doe.williams(13)
    assert w.shape == (26, 13)
    assert all(sorted(r) == list(range(13)) for r in w)
    ratios = doe.panel_pca(scores[:, 0].T)
    ev = np.sort(np.linalg.eigvalsh(np.corrcoef(scores[:, 0].T, rowvar=False)))[::-1]
    np.testing.assert_allclose(ratios[:3], (ev / ev.sum())[:3], rtol=1e-8)
    with pytest.raises(ValueError):
        doe.rm_anova(scores[0])
    with pytest.raises(ValueError):
        doe.fit_rsm(x=np.zeros((3, 2)), y=[1, 2, 3])
    with pytest.raises(ValueError):
        doe.ccd(1, "inscribed", "rotatable", 2)


def test_doe_results_are_typed(rng):
    x = doe.ccd(2, "inscribed", "rotatable", (3, 2))
    y = 3 + x[:, 0] - 2 * x[:, 1] + 5 * x[:, 0] ** 2 + 2 * x[:, 1] ** 2 + rng.normal(0, 0.3, 13)
    f = doe.fit_rsm(x, y)
    check_result(f, doe.RsmFit)
    assert f.names == ["b0", "b1", "b2", "b11", "b22", "b12"]
    assert f.coef.shape == f.p.shape == (6,) and f.residuals.shape == (13,)
    np.testing.assert_allclose(f.fitted + f.residuals, y, atol=1e-12)
    assert f.stationary.shape == (2,) and f.canonical_axes.shape == (2, 2)
    blocked = doe.fit_rsm_blocked(x, y + rng.normal(0, 0.3, (4, 13)))
    check_result(blocked, doe.RsmFit)
    assert blocked.names[-3:] == ["subject0", "subject1", "subject2"]
    # Three conditions tell the effects apart by their degrees of freedom: condition 2,
    # stimulus 12, their interaction 24 (the native "condition:stimulus").
    scores = 5 + rng.normal(0, 1, (10, 3, 13))
    t = doe.rm_anova(scores)
    check_result(t, doe.AnovaTable)
    check_result(t.interaction, doe.AnovaEffect)
    assert (t.condition.df, t.stimulus.df, t.interaction.df) == (2, 12, 24)
    assert t.interaction.df_error == 24 * 9
    total = t.condition.ss + t.stimulus.ss + t.interaction.ss + t.ss_subject
    total += t.condition.ss_error + t.stimulus.ss_error + t.interaction.ss_error
    assert total == pytest.approx(t.ss_total, rel=1e-10)
    one = doe.rm_anova_oneway(scores[:, 0])
    assert type(one) is doe.AnovaEffect and one.df == 12
    l = doe.lsd(scores[:, 0])
    check_result(l, doe.LeastSignificantDifference)
    assert len(l.pairs) == 78 and l.n_separated == sum(sep for _, _, sep in l.pairs)
    assert l.means.shape == (13,) and l.df_error == one.df_error


def test_plate_layout_places_the_pool_on_the_cells():
    tiles, cells = rt.plate_layout((-0.5, -0.5, 0.5, 0.5), seed=4)
    assert len(tiles) == 16 and all(t.dtype == rt.FLAKE_DTYPE for t in tiles)
    # 1 x 1 mm at the plate's centre spans 3 x 3 cells of 450 µm (corners at -75 mm + 450 k).
    assert len(cells) == 9
    for x0, y0, t, k in cells:
        assert 0 <= t < 16 and 0 <= k < 4
        assert abs((x0 + 75000.0) / 450.0 - round((x0 + 75000.0) / 450.0)) < 1e-9
    # Reproducible from the seed.
    again, cells2 = rt.plate_layout((-0.5, -0.5, 0.5, 0.5), seed=4)
    assert cells2 == cells and all(np.array_equal(a, b) for a, b in zip(tiles, again))


def test_workshop_scores_the_reference_above_a_far_plate():
    res = rt.workshop(reference=(26.0, 7.3), runs=[(26.0, 7.3), (45.0, 3.5)], condition="mono",
                      n_reference_renders=2, spp=4)
    check_result(res, rt.WorkshopScores)
    assert res.runs == [(26.0, 7.3), (45.0, 3.5)]
    # Mono: the four sparkle statistics, no binocular overlap.
    assert res.feature_names == ["glint density", "mean luminance", "mean glint peak / lamp",
                                 "mean glint area"]
    assert res.features.shape == res.reference_features.shape == (2, 4)
    assert res.scale_log.shape == (4,)
    near, far = res.scores
    assert 0.0 <= near < far <= 10.0
    with pytest.raises(ValueError):
        rt.workshop(runs=[(26.0, 7.3)], condition="both")


def test_spectrum_output_integrates_to_the_xyz_image():
    img, info = rt.render_plate("left", return_info=True, keep_spectrum=True, light_deg=3.0,
                                light_elevation_deg=75.0, **SMALL)
    spec = info.spectrum
    assert spec.shape == img.shape[:2] + (81,) and info.bands_nm[0] == 380.0
    y, x = np.unravel_index(np.argmax(img[..., 1]), img.shape[:2])
    assert img[y, x, 1] > 0
    np.testing.assert_allclose(rt.spectrum_to_xyz(spec[y, x]), img[y, x], rtol=1e-4)


# ---------------------------------------------------------------- study and paint files


def test_a_study_round_trips_and_feeds_the_anova(tmp_path):
    rng = np.random.default_rng(3)
    scores = rng.uniform(0, 10, size=(4, 2, 5))
    st = doe.Study(subject_names=["s1", "s2", "s3", "s4"], condition_names=["mono", "stereo"],
                   scores=scores)
    p = tmp_path / "scores.csv"
    doe.save_study(p, st)
    back = doe.load_study(p)
    assert back == st
    assert doe.rm_anova(back.scores) == doe.rm_anova(scores)


def test_study_rows_in_any_order_and_errors_name_the_line(tmp_path):
    p = tmp_path / "scores.csv"
    p.write_text("Score,stimulus,condition,subject\n2,1,c,a\n1,0,c,a\n")
    st = doe.load_study(p)
    assert st.subject_names == ["a"] and st.condition_names == ["c"]
    np.testing.assert_array_equal(st.scores, [[[1.0, 2.0]]])
    for text, words in [("subject,condition,score\n", "`stimulus`"),
                        ("subject,condition,stimulus,score\na,c,0,1\na,c,0,2\n", "line 3"),
                        ("subject,condition,stimulus,score\na,c,0,1\na,c,2,1\n", "stimulus 1"),
                        ("subject,condition,stimulus,score\na,c,x,1\n", "line 2"),
                        ("", "empty")]:
        p.write_text(text)
        with pytest.raises(OSError, match="scores.csv") as e:
            doe.load_study(p)
        assert words in str(e.value), (text, str(e.value))
    # A huge stimulus index over one row is a missing cell, not an allocation.
    p.write_text("subject,condition,stimulus,score\na,c,18446744073709551614,1\n")
    with pytest.raises(OSError, match="missing cell"):
        doe.load_study(p)
    with pytest.raises(OSError):
        doe.load_study(tmp_path / "none.csv")
    with pytest.raises(TypeError, match="`study`"):
        doe.save_study(p, {"subject_names": []})


def test_runs_round_trip_into_the_same_fit(tmp_path):
    x = doe.ccd(2, "inscribed", "rotatable", (3, 2))
    y = 5 + x[:, 0] - 0.5 * x[:, 1] ** 2
    p = tmp_path / "runs.csv"
    doe.save_runs(p, x, y)
    runs = doe.load_runs(p)
    xr, yr = runs
    np.testing.assert_array_equal(xr, x)
    np.testing.assert_array_equal(yr, y)
    assert doe.fit_rsm(*runs).coef == pytest.approx(doe.fit_rsm(x, y).coef)
    np.testing.assert_array_equal(doe.load_design(p), np.column_stack([x, y]))
    p.write_text("x1,y\n1,2\n3\n")
    with pytest.raises(OSError, match=r"runs\.csv.*line 3"):
        doe.load_runs(p)
    p.write_text("y\n1\n2\n")
    with pytest.raises(OSError, match="two columns"):
        doe.load_runs(p)
    with pytest.raises(ValueError):
        doe.save_runs(p, x, y[:-1])


def test_a_paint_description_round_trips_and_is_checked(tmp_path):
    paint = rt.PaintDescription(radius_um=26.0, density=7.3, model="deposit", seed=1)
    p = tmp_path / "paint.json"
    rt.save_paint(p, paint)
    assert rt.load_paint(p) == paint
    assert rt.load_paint(p).tilt_deg is None
    for text in ['{"radius_um": 26,', '{"radius": 26}', '{"density": "high"}',
                 '{"model": "sprayed"}', '{"radius_um": -1}', '[1]']:
        p.write_text(text)
        with pytest.raises(OSError, match="paint.json"):
            rt.load_paint(p)
    with pytest.raises(ValueError, match="radius_um"):
        rt.save_paint(p, rt.PaintDescription(radius_um=-1.0))
    with pytest.raises(ValueError, match="paint"):
        rt.save_paint(p, rt.PaintDescription(density="high"))
    # numpy scalars are written as numbers.
    rt.save_paint(p, rt.PaintDescription(radius_um=np.float32(20.0), seed=np.int64(3)))
    assert rt.load_paint(p) == rt.PaintDescription(radius_um=20.0, seed=3)
    with pytest.raises(OSError):
        rt.load_paint(tmp_path / "none.json")
    p.write_bytes(b" " * (2 << 20))
    with pytest.raises(ValueError, match="refused"):
        rt.load_paint(p)
