import numpy as np
import pytest
import scipy.ndimage as ndi

import wscg.math as wm

MODES = ["reflect", "mirror", "nearest", "wrap", "constant"]


@pytest.mark.parametrize("mode", MODES)
def test_gaussian_filter_equals_scipy(camera, mode):
    img = camera[100:220, 50:210]
    for sigma in (0.7, 2.0):
        ours = wm.gaussian_filter(img, sigma, mode=mode, cval=0.3)
        ref = ndi.gaussian_filter(img, sigma, mode=mode, cval=0.3)
        assert np.max(np.abs(ours - ref)) < 1e-5


def test_gaussian_filter_colour_filters_channels_independently(astronaut):
    img = astronaut[:90, :70]
    ours = wm.gaussian_filter(img, 1.5, truncate=3.0)
    ref = ndi.gaussian_filter(img, sigma=(1.5, 1.5, 0), truncate=3.0)
    assert ours.shape == img.shape
    assert np.max(np.abs(ours - ref)) < 1e-5


@pytest.mark.parametrize("mode", MODES)
def test_box_filter_equals_uniform_filter(camera, mode):
    img = camera[:64, :80]
    ours = wm.box_filter(img, 2, mode=mode)
    ref = ndi.uniform_filter(img, size=5, mode=mode)
    assert np.max(np.abs(ours - ref)) < 1e-6


def test_resize_area_is_block_mean_and_bilinear_matches_half_pixel_centres(camera):
    img = camera[:120, :96]
    small = wm.resize(img, (40, 32), method="area")
    ref = img.reshape(40, 3, 32, 3).mean(axis=(1, 3))
    assert small.dtype == np.float32 and small.shape == (40, 32)
    assert np.max(np.abs(small - ref)) < 1e-5
    # Bilinear upscale of an affine image is exact away from the clamped border.
    yy, xx = np.mgrid[0:16, 0:20]
    f = 0.1 + 0.02 * yy - 0.03 * xx
    up = wm.resize(f, (48, 60), method="bilinear")
    sy = (np.arange(48) + 0.5) / 3 - 0.5
    sx = (np.arange(60) + 0.5) / 3 - 0.5
    exact = 0.1 + 0.02 * sy[:, None] - 0.03 * sx[None, :]
    assert np.max(np.abs(up[3:-3, 3:-3] - exact[3:-3, 3:-3])) < 1e-5
    try:
        import cv2
    except ImportError:
        return
    ref_cv = cv2.resize(img.astype(np.float32), (32, 40), interpolation=cv2.INTER_AREA)
    assert np.max(np.abs(small - ref_cv)) < 1e-5


def test_filter_bad_input():
    with pytest.raises(ValueError, match="mode"):
        wm.gaussian_filter(np.zeros((4, 4)), 1.0, mode="bogus")
    with pytest.raises(ValueError, match="sigma"):
        wm.gaussian_filter(np.zeros((4, 4)), 0.0)
    with pytest.raises(ValueError, match="image"):
        wm.gaussian_filter(np.zeros((2, 2, 2, 2)), 1.0)
    with pytest.raises(ValueError, match="image"):
        wm.box_filter(np.array([[np.nan]]), 1)
    with pytest.raises(ValueError, match="method"):
        wm.resize(np.zeros((4, 4)), (2, 2), method="cubic")
    with pytest.raises(ValueError, match="shape"):
        wm.resize(np.zeros((4, 4)), (0, 2))
