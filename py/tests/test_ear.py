"""wscg.ear (paper 14): the acceptance checks that involve peer libraries (Haar LL
against PyWavelets, grey / equalisation / resize against OpenCV, disk closing against
scikit-image, hole filling against SciPy, the skin model against known Gaussians and the
Mahalanobis values of (E7)), numpy references of the skin decision and the block layout,
an end-to-end run on synthetic ears (identification, occlusion estimate, rejection), the
agreement of the fast gallery path with the reference scorer and the experiment protocol,
the baseline equivalence (check 9), bad input and the docstrings."""

import inspect
import pickle
import warnings

import cv2
import numpy as np
import pytest
import pywt
import scipy.ndimage as ndi
import skimage.morphology as skm

import wscg
from results_check import check_result
from wscg import ear


def _blocks_from_ll(ll, rows=10, cols=8, hb=5):
    """A ``(rows * hb, cols * hb)`` LL band cut into ``(rows * cols, hb * hb)`` block rows."""
    return ll.reshape(rows, hb, cols, hb).transpose(0, 2, 1, 3).reshape(rows * cols, hb * hb)


def _gray_e2(rgb):
    """The library's grey, OpenCV's 15-bit fixed point (COLOR_RGB2GRAY since OpenCV 4.0):
    ``(9798 R + 19235 G + 3735 B + 16384) >> 15``. OpenCV 3.4's 14-bit weights
    ``(4899 R + 9617 G + 1868 B + 8192) >> 14`` differ from it by one level on 43,864 of the
    2^24 RGB colours (0.26 %)."""
    x = rgb.astype(np.int64)
    return ((9798 * x[..., 0] + 19235 * x[..., 1] + 3735 * x[..., 2] + 16384) >> 15).astype(
        np.uint8)


def _pywt_ll(x):
    return pywt.dwt2(np.asarray(x, dtype=np.float64), "haar")[0]


# ----------------------------------------------------------------------------------------
# Check 1: Haar LL exactness
# ----------------------------------------------------------------------------------------

def test_check1_haar_ll_of_blocks_equals_pywt(rng):
    worst = 0.0
    for _ in range(1000):
        b = rng.uniform(0.0, 1.0, (10, 10))
        worst = max(worst, np.abs(ear.haar_ll(b) - _pywt_ll(b)).max())
    assert worst <= 1e-12


def test_check1_block_lls_are_the_whole_image_ll(rng):
    img = rng.uniform(0.0, 1.0, (100, 80))
    ll = _pywt_ll(img)
    np.testing.assert_allclose(ear.haar_ll(img), ll, rtol=0, atol=1e-12)
    feats = ear.block_features(img)
    assert feats.shape == (80, 25) and feats.dtype == np.float32
    np.testing.assert_allclose(feats, _blocks_from_ll(ll), rtol=0, atol=1e-6)
    # Block b is grid cell (b // 8, b % 8): its features are pywt's LL of that 10 x 10 tile.
    for b in (0, 7, 8, 41, 79):
        i, j = divmod(b, 8)
        tile = img[10 * i:10 * i + 10, 10 * j:10 * j + 10]
        np.testing.assert_allclose(feats[b], _pywt_ll(tile).ravel(), rtol=0, atol=1e-6)
    # Another block size: 4 x 4 blocks of a 20 x 12 plane.
    small = rng.uniform(0.0, 1.0, (20, 12))
    f4 = ear.block_features(small, height=20, width=12, block=4)
    np.testing.assert_allclose(f4, _blocks_from_ll(_pywt_ll(small), 5, 3, 2), atol=1e-6)


def test_check1_enroll_equals_the_opencv_pywt_pipeline(rng):
    # A grey image already at the normalised size: enrol = pywt LL of equalizeHist / 255.
    gray = rng.integers(0, 256, (100, 80), dtype=np.uint8)
    t = ear.enroll(gray, gray_enrolment=True)
    ref = _blocks_from_ll(_pywt_ll(cv2.equalizeHist(gray) / 255.0))
    assert t.shape == (80, 25) and t.dtype == np.float32
    np.testing.assert_allclose(t, ref, rtol=0, atol=1e-6)
    # A colour crop of another size: resize (ours, compared with OpenCV in check 2), the
    # library's grey formula (E2), equalisation as OpenCV, Haar LL as pywt.
    img = rng.integers(0, 256, (173, 141, 3), dtype=np.uint8)
    small = ear.resize(img, 100, 80)
    ref = _blocks_from_ll(_pywt_ll(cv2.equalizeHist(_gray_e2(small)) / 255.0))
    np.testing.assert_allclose(ear.enroll(img), ref, rtol=0, atol=1e-6)


# ----------------------------------------------------------------------------------------
# Check 2: grey, equalisation and resize exactness against OpenCV
# ----------------------------------------------------------------------------------------

def _random_u8(rng, k, shape):
    """Image ``k`` of a family cycling through constant, two-level, full-range, narrow-range,
    skewed and sparse-level images."""
    kind = k % 6
    if kind == 0:
        return np.full(shape, rng.integers(0, 256), dtype=np.uint8)
    if kind == 1:
        lv = rng.choice(256, 2, replace=False)
        return lv[rng.integers(0, 2, shape)].astype(np.uint8)
    if kind == 2:
        return rng.integers(0, 256, shape, dtype=np.uint8)
    if kind == 3:
        lo = rng.integers(0, 200)
        return rng.integers(lo, lo + 40, shape).astype(np.uint8)
    if kind == 4:
        return np.clip(rng.exponential(20.0, shape), 0, 255).astype(np.uint8)
    lv = rng.choice(256, rng.integers(3, 12), replace=False)
    return lv[rng.integers(0, len(lv), shape)].astype(np.uint8)


def test_check2_gray_and_equalisation_are_bit_exact(rng):
    for k in range(200):
        h, w = rng.integers(1, 120, 2)
        rgb = _random_u8(rng, k, (h, w, 3))
        g = ear.rgb_to_gray(rgb)
        assert g.dtype == np.uint8 and g.shape == (h, w)
        np.testing.assert_array_equal(g, _gray_e2(rgb))
        np.testing.assert_array_equal(g, cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY))
        gray = _random_u8(rng, k, (h, w))
        np.testing.assert_array_equal(ear.equalize_hist(gray), cv2.equalizeHist(gray))
        np.testing.assert_array_equal(ear.equalize_hist(g), cv2.equalizeHist(g))


def test_gray_against_opencv_on_every_colour():
    """All 2^24 RGB colours: bit-exact with the installed OpenCV; the 14-bit weights of
    OpenCV 3.4 (the library's grey before) differ on 43,864 of them."""
    v = np.arange(1 << 24, dtype=np.uint32)
    img = np.stack([(v >> 16) & 255, (v >> 8) & 255, v & 255], -1).astype(np.uint8)
    img = img.reshape(4096, 4096, 3)
    ref = cv2.cvtColor(img, cv2.COLOR_RGB2GRAY)
    np.testing.assert_array_equal(ear.rgb_to_gray(img), ref)
    x = img.astype(np.int64)
    old = (4899 * x[..., 0] + 9617 * x[..., 1] + 1868 * x[..., 2] + 8192) >> 14
    assert np.count_nonzero(old != ref) == 43864


@pytest.mark.parametrize("name", ["coffee", "chelsea", "rocket", "retina", "hubble_deep_field"])
def test_gray_equals_opencv_on_photographs(name):
    """Photographs shipped with scikit-image, and images made from them in the test (odd
    crops that leave SIMD tails, channel permutations, a brightness ramp): every pixel equal
    to ``cv2.cvtColor(..., COLOR_RGB2GRAY)``."""
    data = pytest.importorskip("skimage.data")
    photo = np.ascontiguousarray(getattr(data, name)()[..., :3])
    assert photo.dtype == np.uint8 and photo.ndim == 3
    h, w = photo.shape[:2]
    ramp = np.linspace(0.3, 1.0, w)[None, :, None]
    made = [photo, photo[1:h - 2, 3:w - 6], photo[..., ::-1], photo[..., [1, 2, 0]],
            (photo * ramp).astype(np.uint8), photo[::3, ::5]]
    for img in made:
        img = np.ascontiguousarray(img)
        np.testing.assert_array_equal(ear.rgb_to_gray(img), cv2.cvtColor(img, cv2.COLOR_RGB2GRAY),
                                      err_msg=name)


def test_equalisation_within_a_mask_is_the_lut_of_the_masked_histogram(rng):
    gray = rng.integers(0, 256, (60, 50), dtype=np.uint8)
    within = rng.random((60, 50)) < 0.4
    out = ear.equalize_hist(gray, within)
    # Reference: the OpenCV LUT of the selected pixels, levels below the lowest one -> 0.
    sel = gray[within]
    lut = np.zeros(256, np.uint8)
    eq = cv2.equalizeHist(sel.reshape(1, -1)).ravel()
    lut[sel] = eq
    lo = sel.min()
    for v in range(256):
        if v > lo and not np.any(sel == v):
            lut[v] = lut[v - 1]
    np.testing.assert_array_equal(out, lut[gray])
    np.testing.assert_array_equal(ear.equalize_hist(gray, np.ones_like(within)),
                                  cv2.equalizeHist(gray))


@pytest.mark.parametrize("shape", [(200, 160), (300, 240), (173, 141)],
                         ids=["factor2", "factor3", "non-integer"])
def test_check2_area_resize_matches_opencv_within_one_level(rng, shape):
    worst = 0
    for _ in range(20):
        img = rng.integers(0, 256, shape + (3,), dtype=np.uint8)
        ours = ear.resize(img, 100, 80)
        ref = cv2.resize(img, (80, 100), interpolation=cv2.INTER_AREA)
        assert ours.shape == ref.shape == (100, 80, 3) and ours.dtype == np.uint8
        worst = max(worst, int(np.abs(ours.astype(int) - ref).max()))
    assert worst <= 1
    if shape != (173, 141):
        # Integer factors are bit-identical (halving uses OpenCV's round-half-up fast path).
        assert worst == 0
    # A grey (H, W) image stays 2-D.
    assert ear.resize(img[..., 0], 100, 80).shape == (100, 80)


def test_resize_up_is_bilinear_like_opencv(rng):
    img = rng.integers(0, 256, (50, 40, 3), dtype=np.uint8)
    ours = ear.resize(img, 100, 80).astype(int)
    ref = cv2.resize(img, (80, 100), interpolation=cv2.INTER_LINEAR).astype(int)
    assert np.abs(ours - ref).max() <= 1


# ----------------------------------------------------------------------------------------
# Check 3: morphology exactness
# ----------------------------------------------------------------------------------------

def _random_mask(rng, k):
    """Masks 100 x 80 of density 0.3-0.9: iid noise for a quarter, thresholded smoothed
    noise (blobs, thin gaps and holes, at several scales) for the rest."""
    density = rng.uniform(0.3, 0.9)
    if k % 4 == 0:
        return rng.random((100, 80)) < density
    sigma = (1.5, 3.0, 6.0)[k % 3]
    field = ndi.gaussian_filter(rng.standard_normal((100, 80)), sigma)
    return field < np.quantile(field, density)


def _skimage_closing(m, radius):
    fp = skm.disk(radius)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", category=FutureWarning)
        warnings.simplefilter("ignore", category=DeprecationWarning)
        if hasattr(skm, "binary_closing"):
            ref = skm.binary_closing(m, footprint=fp)
        else:  # scikit-image >= 0.28
            ref = skm.closing(m, footprint=fp, mode="ignore")
    return ref


def test_check3_disk_closing_equals_skimage(rng):
    for k in range(200):
        m = _random_mask(rng, k)
        ours = ear.close_disk(m, 10)
        assert ours.dtype == np.bool_ and ours.shape == m.shape
        np.testing.assert_array_equal(ours, _skimage_closing(m, 10), err_msg=f"mask {k}")
    # The non-deprecated replacement agrees too, and so do smaller radii.
    m = _random_mask(rng, 1)
    np.testing.assert_array_equal(ear.close_disk(m, 10),
                                  skm.closing(m, footprint=skm.disk(10), mode="ignore"))
    for r in (1, 3, 5):
        np.testing.assert_array_equal(ear.close_disk(m, r), _skimage_closing(m, r))


def test_dilation_and_erosion_follow_the_border_conventions(rng):
    for k in range(20):
        m = _random_mask(rng, k + 1)
        fp = skm.disk(4)
        np.testing.assert_array_equal(ear.dilate_disk(m, 4),
                                      ndi.binary_dilation(m, fp, border_value=0))
        np.testing.assert_array_equal(ear.erode_disk(m, 4),
                                      ndi.binary_erosion(m, fp, border_value=1))


def test_check3_fill_holes_equals_scipy(rng):
    holes = 0
    for k in range(200):
        m = _random_mask(rng, k)
        ref = ndi.binary_fill_holes(m)
        holes += int((ref & ~m).sum())
        np.testing.assert_array_equal(ear.fill_holes(m), ref, err_msg=f"mask {k}")
        # The closed masks of the pipeline too.
        c = ear.close_disk(m, 3)
        np.testing.assert_array_equal(ear.fill_holes(c), ndi.binary_fill_holes(c))
    assert holes > 0  # the set does exercise hole filling


# ----------------------------------------------------------------------------------------
# Check 4: skin model
# ----------------------------------------------------------------------------------------

def test_check4_fit_recovers_a_known_gaussian(rng):
    mean = np.array([0.45, 0.32])
    cov = np.array([[1.6e-3, 3.0e-4], [3.0e-4, 2.5e-4]])
    pts = rng.multivariate_normal(mean, cov, 100_000)
    m = ear.SkinModel().fit_rg(pts)
    assert np.abs(m.mean_ - mean).max() <= 1e-3
    assert np.all(np.abs(np.diag(m.cov_) / np.diag(cov) - 1) <= 0.03)
    assert np.linalg.norm(m.cov_ - cov) <= 0.03 * np.linalg.norm(cov)
    assert m.cov_[0, 1] == m.cov_[1, 0]
    # ML estimate, covariance divided by n.
    np.testing.assert_allclose(m.mean_, pts.mean(0), atol=1e-12)
    np.testing.assert_allclose(m.cov_, np.cov(pts.T, bias=True), rtol=1e-9, atol=1e-15)
    # Joint rule with tau = 0.05: the 95 % ellipse (chi^2 with 2 dof, threshold 5.991).
    inside = np.mean(m.likelihood_rg(pts[:, 0], pts[:, 1]) >= 0.05)
    assert abs(inside - 0.95) <= 0.005


def test_fit_on_rgb_pixels_is_fit_on_their_chromaticities(rng):
    px = rng.integers(0, 256, (5000, 3), dtype=np.uint8)
    px[:50] = 0  # black pixels: undefined chromaticity, skipped
    s = px.astype(np.float64).sum(1)
    ok = s > 0
    rg = px[ok, :2] / s[ok, None]
    a, b = ear.SkinModel().fit(px), ear.SkinModel().fit_rg(rg)
    np.testing.assert_allclose(a.mean_, b.mean_, atol=1e-12)
    np.testing.assert_allclose(a.cov_, b.cov_, rtol=1e-9)
    # An image works as a pixel list too.
    c = ear.SkinModel().fit(px[:4800].reshape(60, 80, 3))
    assert np.all(np.isfinite(c.cov_))


# (label, (r, g) or RGB, Mahalanobis^2 under the default skin model (E7), skin?)
E7 = [
    ("light skin", (0.392, 0.337), 3.26, True),
    ("medium skin", (0.496, 0.336), 2.35, True),
    ("dark skin", (0.539, 0.325), 5.05, True),
    ("neutral grey", (1 / 3, 1 / 3), 9.22, False),
    ("orange", (0.584, 0.259), 26.1, False),
    ("gold", (212, 175, 55), 23.6, False),
    ("dark-brown hair", (0.464, 0.309), 0.61, True),
    ("blond hair", (0.417, 0.354), 5.30, True),
]


@pytest.mark.parametrize("label,x,m2,skin", E7, ids=[e[0] for e in E7])
def test_check4_mahalanobis_values_of_e7(label, x, m2, skin):
    m = ear.SkinModel()
    if len(x) == 3:
        r, g = x[0] / sum(x), x[1] / sum(x)
        rgb = np.array(x, dtype=np.uint8)
        assert m.likelihood(rgb) == pytest.approx(np.exp(-0.5 * m.mahalanobis2_rg(r, g)),
                                                  rel=1e-12)
    else:
        r, g = x
    d2 = m.mahalanobis2_rg(r, g)
    assert isinstance(d2, float)
    assert abs(d2 - m2) <= 0.01, (label, d2)
    assert (m.likelihood_rg(r, g) >= 0.05) == skin
    assert (d2 <= 5.991) == skin


def test_mahalanobis_of_blue_and_green_is_large_and_black_is_not_skin():
    m = ear.SkinModel()
    px = np.array([[0, 0, 255], [0, 255, 0], [30, 60, 200], [40, 160, 60]], dtype=np.uint8)
    s = px.sum(1).astype(float)
    assert np.all(m.mahalanobis2_rg(px[:, 0] / s, px[:, 1] / s) > 80)
    assert m.likelihood(np.zeros(3, np.uint8)) == 0.0
    assert m.likelihood(px).shape == (4,)


def test_skin_model_is_vectorised_and_matches_the_formula(rng):
    m = ear.SkinModel((0.44, 0.31), ((2e-3, 2e-4), (2e-4, 3e-4)))
    r = rng.uniform(0.2, 0.6, (7, 5))
    g = rng.uniform(0.2, 0.5, (5,))
    d = np.stack(np.broadcast_arrays(r - 0.44, g - 0.31), -1)
    ref = np.einsum("...i,ij,...j->...", d, np.linalg.inv(m.cov_), d)
    np.testing.assert_allclose(m.mahalanobis2_rg(r, g), ref, rtol=1e-10)
    np.testing.assert_allclose(m.likelihood_rg(r, g), np.exp(-0.5 * ref), rtol=1e-10)
    pr, pg = m.marginal_likelihoods_rg(r, g)
    np.testing.assert_allclose(pr, np.exp(-0.5 * (r - 0.44) ** 2 / 2e-3), rtol=1e-12)
    np.testing.assert_allclose(pg, np.broadcast_to(np.exp(-0.5 * (g - 0.31) ** 2 / 3e-4),
                                                   (7, 5)), rtol=1e-12)
    assert m == pickle.loads(pickle.dumps(m))
    assert "SkinModel" in repr(m)


def test_skin_pixels_match_a_numpy_reference(rng):
    img = rng.integers(0, 256, (40, 30, 3), dtype=np.uint8)
    img[:8] = (150, 105, 75)  # skin-coloured rows, some of them dark below
    img[:4] = (30, 21, 15)
    m = ear.SkinModel()
    x = img.astype(np.float64)
    s = x.sum(-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        r, g = x[..., 0] / s, x[..., 1] / s
    lik = np.where(s > 0, m.likelihood_rg(np.nan_to_num(r), np.nan_to_num(g)), 0.0)
    np.testing.assert_array_equal(ear.skin_pixels(img, skin_rule="joint"),
                                  (lik >= 0.05) & (s > 0))
    gated = ear.skin_pixels(img, skin_rule="joint", min_intensity=35)
    np.testing.assert_array_equal(gated, (lik >= 0.05) & (s >= 105))
    np.testing.assert_array_equal(ear.skin_pixels(img, skin_rule="joint", min_likelihood=0.2),
                                  (lik >= 0.2) & (s > 0))
    # The default is the paper's AND of the marginals, threshold exp(-2).
    pr, pg = m.marginal_likelihoods_rg(np.nan_to_num(r), np.nan_to_num(g))
    t = np.exp(-2.0)
    marginal = (pr >= t) & (pg >= t) & (s > 0)
    np.testing.assert_array_equal(ear.skin_pixels(img), marginal)
    np.testing.assert_array_equal(ear.skin_pixels(img, skin_rule="marginal-and"), marginal)
    np.testing.assert_array_equal(ear.skin_pixels(img, min_likelihood=0.5),
                                  (pr >= 0.5) & (pg >= 0.5) & (s > 0))
    assert not np.array_equal(marginal, (lik >= 0.05) & (s > 0))
    # A given model passes through the parameters, and so does a fitted one.
    given = ear.SkinModel((0.4, 0.33), ((1e-3, 0), (0, 1e-3)))
    np.testing.assert_array_equal(
        ear.skin_pixels(img, skin_model=given),
        ear.skin_pixels(img, skin_mean=(0.4, 0.33), skin_cov=((1e-3, 0), (0, 1e-3))))
    fitted = ear.SkinModel().fit(img[:8])
    np.testing.assert_array_equal(
        ear.skin_pixels(img, skin_model=fitted),
        ear.skin_pixels(img, skin_mean=fitted.mean_, skin_cov=fitted.cov_))
    assert not np.allclose(fitted.mean_, ear.SkinModel().mean_)


# ----------------------------------------------------------------------------------------
# End to end on synthetic ears
# ----------------------------------------------------------------------------------------

N_SUBJECTS = 20
SEED = 5


@pytest.fixture(scope="module")
def clean():
    return ear.make_ears(N_SUBJECTS, 1, seed=SEED)


@pytest.fixture(scope="module")
def occluded():
    # Same seed: the same subjects and enrolment captures, probes with colour occluders.
    return ear.make_ears(N_SUBJECTS, 1, seed=SEED, occlusion="colour", min_pct=10,
                          max_pct=50)


@pytest.fixture(scope="module")
def matcher(clean):
    return ear.EarMatcher().fit(ear.enroll_many(clean.enrol))


def test_make_ears_shapes_and_ground_truth(clean, occluded):
    n = N_SUBJECTS
    assert clean.enrol.shape == (n, 200, 160, 3) and clean.enrol.dtype == np.uint8
    assert clean.probes.shape == (n, 200, 160, 3)
    np.testing.assert_array_equal(clean.labels, np.arange(n))
    assert clean.occluder_masks.shape == (n, 200, 160)
    assert not clean.occluder_masks.any() and not clean.occluded_blocks.any()
    np.testing.assert_array_equal(clean.enrol, occluded.enrol)
    assert occluded.occluded_blocks.shape == (n, 10, 8)
    np.testing.assert_allclose(occluded.occluded_pct,
                               100 * occluded.occluded_blocks.mean((1, 2)))
    assert np.all((occluded.occluded_pct >= 5) & (occluded.occluded_pct <= 55))
    again = ear.make_ears(2, 1, seed=SEED, occlusion="colour", min_pct=10, max_pct=50)
    np.testing.assert_array_equal(again.probes, occluded.probes[:2])
    assert clean.skin_rg.shape == (n, 2)


def test_clean_probes_are_identified(clean, matcher):
    assert len(matcher) == N_SUBJECTS
    hits = 0
    for img, sub in zip(clean.probes, clean.labels):
        r = matcher.identify(img)
        assert not r.rejected and r.occluded_pct <= 10
        assert r.order.dtype == np.int64 and r.scores.dtype == np.float64
        assert sorted(r.order.tolist()) == list(range(N_SUBJECTS))
        assert np.all(np.diff(r.scores) <= 0)
        hits += r.order[0] == sub
    assert hits >= 0.9 * N_SUBJECTS


def test_colour_occluded_probes_give_a_mask_and_are_identified(occluded, matcher):
    # Identification equalises on the detected skin by default (``equalize_on_skin=True``):
    # with the paper's whole-image equalisation (``equalize_on_skin=False``) a large occluder
    # shifts the grey levels of the visible ear (measured on this set: S_B rank-1 0.50 vs
    # 0.90 equalised on skin, baseline 0.75).
    on_skin = matcher
    paper = ear.EarMatcher(equalize_on_skin=False).fit(matcher.templates_)
    close, hits, paper_hits = 0, 0, 0
    for img, sub, om, pct in zip(occluded.probes, occluded.labels,
                                 occluded.occluder_masks, occluded.occluded_pct):
        d = ear.detect_occlusion(img)
        assert d.mask.shape == (100, 80) and d.mask.dtype == np.bool_
        assert d.blocks.shape == (10, 8) and d.block_skin_fraction.shape == (10, 8)
        np.testing.assert_array_equal(d.blocks, d.block_skin_fraction >= 0.5)
        np.testing.assert_array_equal(np.flatnonzero(d.blocks), d.index)
        assert d.occluded_pct == pytest.approx(100 * (1 - d.blocks.mean()))
        assert d.rejected == (d.occluded_pct > 60)
        if abs(d.occluded_pct - pct) <= 7.5:
            close += 1
            # Where the estimate is right, the skin mask is the complement of the occluder
            # on >= 95 % of the pixels (measured: 96.8-99.9 %; the closing fills concave
            # bays of the wavy occluder edge).
            r = ear.resize(om.astype(np.uint8) * 255, 100, 80) >= 128
            assert np.mean(d.mask == r) <= 0.05
            assert np.mean(d.mask[~r]) >= 0.99
        res = on_skin.identify(img)
        assert res.occluded_pct == d.occluded_pct
        hits += (not res.rejected) and res.order[0] == sub
        pr = paper.identify(img)
        paper_hits += (not pr.rejected) and pr.order[0] == sub
    # Measured: 19 of 20 within 7.5 points (the miss is a dark-grey occluder whose noisy
    # chromaticity speckles into the skin ellipse and is closed over); rank-1 18 of 20.
    assert close >= 0.85 * N_SUBJECTS
    assert hits >= 0.8 * N_SUBJECTS
    assert paper_hits < hits


def test_heavily_occluded_probes_are_rejected_not_ranked(matcher):
    heavy = ear.make_ears(12, 1, seed=11, occlusion="colour", min_pct=70, max_pct=80)
    rejected = 0
    for img, pct in zip(heavy.probes, heavy.occluded_pct):
        r = matcher.identify(img)
        d = ear.detect_occlusion(img)
        assert r.rejected == d.rejected and r.occluded_pct == d.occluded_pct
        if abs(d.occluded_pct - pct) <= 7.5:
            assert r.rejected  # a detected 70-80 % occlusion is always rejected
        if r.rejected:
            rejected += 1
            assert r.occluded_pct > 60
            assert r.order.shape == (0,) and r.scores.shape == (0,)
            # The raw scores and the baseline still answer (no reject path there).
            assert matcher.scores(img).shape == (len(matcher),)
            assert matcher.identify_baseline(img).order.shape == (len(matcher),)
        else:
            assert r.order.shape == (len(matcher),)
    # Measured: 9 of 12; the others are dark-grey occluders taken for skin (see above).
    assert rejected >= 0.6 * len(heavy.probes)
    # The threshold is a parameter: nothing is rejected at 100 %.
    lax = ear.EarMatcher(reject_above_pct=100).fit(matcher.templates_)
    assert not lax.identify(heavy.probes[0]).rejected


def test_gallery_scores_equal_the_reference_scorer(occluded, matcher):
    tpl = matcher.templates_
    for img in occluded.probes[:4]:
        per = [ear.score(img, t) for t in tpl]
        for rule in ear.RULES:
            m = ear.EarMatcher(score=rule).fit(tpl)
            ref = np.array([p.rules[rule] for p in per])
            np.testing.assert_allclose(m.scores(img), ref, rtol=0, atol=1e-5)
        assert per[0].score == per[0].rules["blockwise-max"]


def test_score_breakdown_is_consistent(occluded, matcher):
    img, t = occluded.probes[0], matcher.templates_[0]
    # The paper's pre-processing, so that the probe's features are its enrolment features
    # (the whole image equalised; the default equalises on the detected skin).
    s = ear.score(img, t, equalize_on_skin=False)
    m = len(s.index)
    assert s.distances.shape == (9, m) and s.per_shift.shape == (9,)
    np.testing.assert_array_equal(s.shifts, np.array(ear.SHIFTS_NINE))
    d = s.distances
    # Blockwise max: mean over blocks of 1 - the smallest valid distance (float32 sums).
    best = np.nanmin(d, axis=0)
    assert s.rules["blockwise-max"] == pytest.approx(np.mean(1 - best), abs=1e-6)
    assert s.rules["literal-eq18"] == pytest.approx(np.max(1 - best), abs=1e-6)
    bm = np.nanmean(1 - d, axis=0)
    assert s.rules["blockwise-mean"] == pytest.approx(np.mean(bm), abs=1e-6)
    ok = ~np.isnan(s.per_shift)
    ref = 1 - np.sqrt(np.nanmean(d ** 2, axis=1))
    cnt = np.sum(~np.isnan(d), axis=1)
    np.testing.assert_allclose(s.per_shift[ok], ref[ok], atol=1e-6)
    np.testing.assert_array_equal(ok, cnt >= np.ceil(m / 2))
    assert s.rules["overall-max"] == pytest.approx(np.max(s.per_shift[ok]), abs=1e-12)
    assert s.rules["overall-mean"] == pytest.approx(np.mean(s.per_shift[ok]), abs=1e-12)
    np.testing.assert_array_equal(s.best_shift, np.nanargmin(np.where(np.isnan(d), np.inf, d),
                                                                axis=0))
    # Partners outside the 10 x 8 grid are undefined: block 0 has no partner to the left/up.
    if s.index[0] == 0:
        assert np.isnan(d[5, 0]) and np.isnan(d[6, 0]) and np.isnan(d[7, 0])
    # The normalised distance is |t - r| / 10 for B0.
    feats = ear.enroll(img)  # the probe's own unmasked features (equalised on the image)
    on_skin = ear.score(img, t)
    assert not np.allclose(on_skin.distances[0], d[0], equal_nan=True)
    np.testing.assert_allclose(
        d[0], np.linalg.norm(feats[s.index] - t[s.index], axis=1) / 10, atol=1e-6)


def test_check9_baseline_is_the_pipeline_with_all_blocks_b0_overall_max(clean, matcher):
    tpl = matcher.templates_
    img = clean.probes[3]
    assert ear.detect_occlusion(img).occluded_pct == 0  # every block kept
    base = matcher.identify_baseline(img)
    b = np.array([ear.baseline_score(img, t) for t in tpl])
    np.testing.assert_allclose(base.scores, b[base.order], atol=1e-6)
    piped = ear.EarMatcher(shifts=[(0, 0)], score="overall-max").fit(tpl).scores(img)
    np.testing.assert_allclose(piped, b, atol=1e-6)


def test_evaluate_agrees_with_the_matcher(occluded, matcher):
    ev = ear.evaluate(occluded.enrol, occluded.probes, occluded.labels,
                      true_pct=occluded.occluded_pct, max_rank=5, edges=[0, 20, 40, 60])
    n = N_SUBJECTS
    assert ev.rules == list(ear.RULES)
    assert set(ev.cmc) == set(ear.RULES)
    for c in list(ev.cmc.values()) + [ev.baseline_cmc, ev.baseline_cmc_all]:
        assert c.shape == (5,) and np.all(np.diff(c) >= 0) and c[-1] <= 1
    assert ev.ranks.shape == (n, 5) and ev.ranks.dtype == np.int64
    np.testing.assert_array_equal(ev.true_pct, occluded.occluded_pct)
    assert ev.rejection_rate == pytest.approx(np.mean(ev.rejected))
    for k, img in enumerate(occluded.probes):
        r = matcher.identify(img)
        assert r.rejected == ev.rejected[k]
        assert r.occluded_pct == ev.estimated_pct[k]
        if r.rejected:
            assert np.all(ev.ranks[k] == -1)
        else:
            assert ev.ranks[k, 0] == np.flatnonzero(r.order == k)[0]
        base = matcher.identify_baseline(img).order
        assert ev.baseline_rank[k] == np.flatnonzero(base == k)[0]
    acc = ev.ranks[~ev.rejected, 0]
    np.testing.assert_allclose(ev.cmc["blockwise-max"], ear.cmc(acc, 5))
    deg = ev.degradation["blockwise-max"]
    assert deg.shape == (3, 4) and deg[:, 2].sum() == np.sum(~ev.rejected)


def test_results_are_typed(clean, occluded, matcher):
    check_result(clean, ear.EarDataset)
    img = occluded.probes[0]
    d = ear.detect_occlusion(img)
    check_result(d, ear.OcclusionReport)
    r = matcher.identify(img)
    text = check_result(r, ear.Identification)
    assert f"order=array(shape=({len(matcher)},), dtype=int64)" in text or r.rejected
    base = matcher.identify_baseline(img)
    check_result(base, ear.Ranking)
    assert base.order.shape == base.scores.shape == (len(matcher),)
    s = ear.score(img, matcher.templates_[0])
    check_result(s, ear.MatchScore)
    assert set(s.rules) == set(ear.RULES) and s.score == s.rules["blockwise-max"]
    assert (s.occluded_pct, s.rejected) == (d.occluded_pct, d.rejected)
    ev = ear.evaluate(occluded.enrol[:3], occluded.probes[:3], occluded.labels[:3], max_rank=2)
    check_result(ev, ear.EarEvaluation)
    assert ev.degradation is None  # no `edges`
    assert np.isnan(ev.true_pct).all()  # no `true_pct`


def test_cmc():
    c = ear.cmc([0, 1, -1, 3, 0], 4)
    np.testing.assert_allclose(c, [0.5, 0.75, 0.75, 1.0])
    assert ear.cmc(np.array([2]), 2).tolist() == [0.0, 0.0]


def test_matcher_pickles_and_reports(matcher, clean):
    m2 = pickle.loads(pickle.dumps(matcher))
    np.testing.assert_array_equal(m2.templates_, matcher.templates_)
    img = clean.probes[0]
    np.testing.assert_array_equal(m2.scores(img), matcher.scores(img))
    assert len(m2) == len(matcher) == 20
    assert repr(matcher) == "EarMatcher()"
    assert repr(ear.EarMatcher(score="overall-max")) == "EarMatcher(score='overall-max')"


def test_module_is_reachable_from_biometrics():
    assert wscg.biometrics.ear is ear and wscg.ear is ear
    assert "ear" in wscg.__all__


# ----------------------------------------------------------------------------------------
# Bad input
# ----------------------------------------------------------------------------------------

def _img(h=40, w=32):
    return np.full((h, w, 3), (170, 120, 85), np.uint8)


@pytest.mark.parametrize("call", [
    lambda: ear.enroll(np.zeros((0, 10, 3), np.uint8)),
    lambda: ear.enroll(np.zeros((10, 0, 3), np.uint8)),
    lambda: ear.enroll(np.zeros((1, 1, 3), np.uint8)),
    lambda: ear.enroll(np.zeros((10,), np.uint8)),
    lambda: ear.enroll(np.zeros((4, 4, 3, 1), np.uint8)),
    lambda: ear.enroll(_img().astype(np.float64)),
    lambda: ear.enroll(_img()[..., 0]),  # grey without gray_enrolment
    lambda: ear.enroll(_img()[..., :2]),
    lambda: ear.detect_occlusion(_img()[..., 0]),
    # Probes need colour even where grey enrolment is allowed.
    lambda: ear.EarMatcher(gray_enrolment=True).fit(ear.enroll(_img())[None]).identify(_img()[..., 0]),
    lambda: ear.detect_occlusion(np.zeros((0, 0, 3), np.uint8)),
    lambda: ear.detect_occlusion(np.zeros((5, 5, 4), np.uint8)),
    lambda: ear.enroll_many([]),
    lambda: ear.enroll_many([_img(), np.zeros((3, 0, 3), np.uint8)]),
    lambda: ear.skin_pixels(_img()[..., 0]),
], ids=lambda f: "")
def test_bad_images_raise_value_error(call):
    with pytest.raises(ValueError):
        call()


def test_bad_templates_raise_value_error():
    t = ear.enroll(_img())
    with pytest.raises(ValueError, match="shape mismatch"):
        ear.EarMatcher().fit(t[None, :40])
    with pytest.raises(ValueError, match="3-D"):
        ear.EarMatcher().fit(t)
    with pytest.raises(ValueError, match="empty"):
        ear.EarMatcher().fit(np.zeros((0, 80, 25), np.float32))
    bad = np.stack([t, t])
    bad[1, 3, 4] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        ear.EarMatcher().fit(bad)
    with pytest.raises(ValueError, match="shape mismatch"):
        ear.score(_img(), t[:, :20])
    with pytest.raises(ValueError):
        ear.score(_img(), t.ravel())
    with pytest.raises(ValueError, match="non-finite"):
        ear.score(_img(), np.where(np.arange(25) == 3, np.inf, t))
    with pytest.raises(ValueError):
        ear.baseline_score(_img(), t[:79])
    with pytest.raises(ValueError):
        ear.EarMatcher().fit(np.array([["a"]]))
    # Templates of one block size do not fit parameters of another.
    with pytest.raises(ValueError, match="shape mismatch"):
        ear.EarMatcher(block=20).fit(t[None])


@pytest.mark.parametrize("params,match", [
    (dict(block_skin_fraction=0), "block_skin_fraction"),
    (dict(block_skin_fraction=1.5), "block_skin_fraction"),
    (dict(shifts=[]), "shifts"),
    (dict(shifts=[(0, 0.5)]), "shifts"),
    (dict(shifts=[1, 2, 3]), "shifts"),
    (dict(block=7), "block"),
    (dict(block=0), "block"),
    (dict(block=30), "block"),
    (dict(height=0), "block"),
    (dict(height=1 << 20, width=1 << 20, block=1 << 18), "too large"),
    (dict(score="best"), "score"),
    (dict(skin_rule="or"), "skin_rule"),
    (dict(min_likelihood=0), "skin_rule"),
    (dict(min_likelihood=2.0), "skin_rule"),
    (dict(skin_cov=((1e-3, 0), (0, -1e-3))), "positive definite"),
    (dict(skin_cov=((1e-3, 1e-4), (0, 1e-3))), "symmetric"),
    (dict(skin_cov=((np.nan, 0), (0, 1e-3))), "finite"),
    (dict(skin_cov=(1e-3, 0, 0, 1e-3)), "skin_cov"),
    (dict(skin_mean=(0.4,)), "skin_mean"),
    (dict(close_radius=-1), "close_radius"),
    (dict(close_radius=np.inf), "close_radius"),
    (dict(reject_above_pct=np.nan), "reject_above_pct"),
    (dict(min_intensity=300), "min_intensity"),
    (dict(min_intensity=-1), "min_intensity"),
    (dict(fill_holes=1), "fill_holes"),
    (dict(skin_model=(0.4, 0.3)), "skin_model"),
], ids=lambda v: str(v) if isinstance(v, str) else "")
def test_bad_parameters_raise_value_error(params, match):
    # The matcher takes every pipeline parameter; the functions that take a parameter check
    # it the same way.
    tpl = ear.enroll(_img())[None]
    with pytest.raises(ValueError, match=match):
        ear.EarMatcher(**params).fit(tpl)
    takes = [f for f in (ear.detect_occlusion, ear.score, ear.evaluate)
             if set(params) <= set(inspect.signature(f).parameters)]
    assert takes, params
    with pytest.raises(ValueError, match=match):
        if takes[0] is ear.detect_occlusion:
            ear.detect_occlusion(_img(), **params)
        else:
            ear.score(_img(), tpl[0], **params)


def test_parameters_are_explicit_keywords():
    # Every pipeline function names its parameters: an unknown one is a TypeError, and a
    # parameter the function does not use is not accepted either.
    with pytest.raises(TypeError, match="colour"):
        ear.detect_occlusion(_img(), colour="red")
    with pytest.raises(TypeError, match="score"):
        ear.enroll(_img(), score="sum")
    with pytest.raises(TypeError):
        ear.detect_occlusion(_img(), 100)  # keyword-only
    assert set(inspect.signature(ear.EarMatcher).parameters) == set(ear.PARAMS)
    assert set(inspect.signature(ear.evaluate).parameters) >= set(ear.PARAMS)
    for f in (ear.enroll, ear.detect_occlusion, ear.score, ear.make_ears, ear.EarMatcher):
        doc = inspect.getdoc(f if f is not ear.EarMatcher else f.__init__)
        for name, p in inspect.signature(f).parameters.items():
            if name in ear.PARAMS:
                assert p.kind is p.KEYWORD_ONLY, (f.__name__, name)
                assert f"\n{name} : " in doc, (f.__name__, name)
    # The defaults are the paper's values and give the same template as no argument.
    img = _img()
    np.testing.assert_array_equal(ear.enroll(img, height=100, width=80, block=10),
                                  ear.enroll(img))


def test_other_bad_input_raises_value_error():
    # The parameters are checked when the model is used (scikit-learn's protocol: not in
    # __init__).
    bad_cov = ear.SkinModel(cov=((1e-3, 0), (0, 0)))
    with pytest.raises(ValueError):
        bad_cov.likelihood_rg(0.4, 0.3)
    with pytest.raises(ValueError):
        ear.skin_pixels(_img(), skin_model=bad_cov)
    with pytest.raises(ValueError):
        ear.SkinModel(mean=(0.4, 0.3, 0.2)).mean_
    with pytest.raises(ValueError, match="at least 3"):
        ear.SkinModel().fit(np.zeros((10, 3), np.uint8))  # all black
    with pytest.raises(ValueError):
        ear.SkinModel().fit_rg(np.full((5, 2), 0.4))  # singular
    with pytest.raises(ValueError):
        ear.SkinModel().fit_rg(np.zeros((5, 3)))
    with pytest.raises(ValueError, match="non-finite"):
        ear.SkinModel().fit_rg(np.array([[0.4, 0.3], [np.nan, 0.3], [0.5, 0.2], [0.45, 0.3]]))
    with pytest.raises(ValueError):
        ear.cmc([-1, -1], 3)  # every probe rejected
    with pytest.raises(ValueError):
        ear.cmc([0, 1], 0)
    with pytest.raises(ValueError):
        ear.cmc([0, -2], 3)
    with pytest.raises(ValueError):
        ear.cmc([0.5], 3)
    with pytest.raises(ValueError):
        ear.make_ears(0, 1)
    with pytest.raises(ValueError):
        ear.make_ears(2, 1, occlusion="paint")
    with pytest.raises(ValueError):
        ear.make_ears(2, 1, occlusion="colour", min_pct=50, max_pct=20)
    with pytest.raises(ValueError):
        ear.make_ears(2, 1, noise_sigma=-1)
    with pytest.raises(ValueError):
        ear.make_ears(10 ** 6, 10 ** 6)
    with pytest.raises(ValueError):
        ear.equalize_hist(np.zeros((0, 4), np.uint8))
    with pytest.raises(ValueError):
        ear.equalize_hist(np.zeros((4, 4, 3), np.uint8))
    with pytest.raises(ValueError, match="shape mismatch"):
        ear.equalize_hist(np.zeros((4, 4), np.uint8), np.ones((4, 5), bool))
    with pytest.raises(ValueError):
        ear.rgb_to_gray(np.zeros((4, 4), np.uint8))
    with pytest.raises(ValueError):
        ear.resize(_img(), 0, 10)
    with pytest.raises(ValueError):
        ear.resize(_img(), 1 << 20, 1 << 20)
    with pytest.raises(ValueError):
        ear.haar_ll(np.zeros((5, 4)))
    with pytest.raises(ValueError):
        ear.haar_ll(np.zeros((4, 4, 2)))
    with pytest.raises(ValueError, match="shape mismatch"):
        ear.block_features(np.zeros((80, 100)))
    with pytest.raises(ValueError):
        ear.close_disk(np.zeros((0, 5), bool))
    with pytest.raises(ValueError):
        ear.close_disk(np.zeros((5, 5), bool), -1)
    with pytest.raises(ValueError):
        ear.close_disk(np.zeros((5, 5), bool), np.nan)
    with pytest.raises(ValueError):
        ear.fill_holes(np.zeros(5, bool))
    tpl = ear.enroll(_img())[None]
    with pytest.raises(ValueError, match="as many labels"):
        ear.evaluate([_img()], [_img(), _img()], [0])
    with pytest.raises(ValueError):
        ear.evaluate([_img()], [_img()], [1])  # identity outside the gallery
    with pytest.raises(ValueError):
        ear.evaluate([], [_img()], [0])
    with pytest.raises(ValueError):
        ear.evaluate([_img()], [_img()], [0], edges=[10, 5])
    m = ear.EarMatcher().fit(tpl)
    with pytest.raises(ValueError):
        m.identify(_img()[..., 0])
    # A probe with nothing un-occluded cannot be scored (but is rejected by identify).
    blue = np.zeros((40, 32, 3), np.uint8)
    blue[..., 2] = 200
    assert m.identify(blue).rejected
    with pytest.raises(ValueError, match="un-occluded"):
        m.scores(blue)


def test_docstrings():
    for name in ear.__all__:
        obj = getattr(ear, name)
        if callable(obj):
            assert inspect.getdoc(obj), name
    for meth in ("fit", "identify", "scores", "identify_baseline", "templates_", "params"):
        assert inspect.getdoc(getattr(ear.EarMatcher, meth)), meth
    for meth in ("fit", "fit_rg", "likelihood", "likelihood_rg", "mahalanobis2_rg", "mean_",
                 "cov_", "marginal_likelihoods_rg"):
        assert inspect.getdoc(getattr(ear.SkinModel, meth)), meth
    assert len(ear.__doc__) > 1000
