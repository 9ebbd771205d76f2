import numpy as np
import pytest
from skimage.metrics import mean_squared_error, peak_signal_noise_ratio, structural_similarity

import wscg.math as wm

SK = dict(gaussian_weights=True, sigma=1.5, use_sample_covariance=False)


def test_ssim_equals_scikit_image_gray(camera, rng):
    noisy = np.clip(camera + 0.08 * rng.standard_normal(camera.shape), 0, 1)
    ours = wm.ssim(camera, noisy, data_range=1.0)
    ref = structural_similarity(camera, noisy, data_range=1.0, **SK)
    assert abs(ours - ref) < 1e-4
    assert 0.1 < ours < 0.9


def test_ssim_equals_scikit_image_rgb_and_other_ranges(astronaut, rng):
    a = astronaut[:200, :180]
    b = a + 0.03 * rng.standard_normal(a.shape)
    ours = wm.ssim(a, b, data_range=1.0)
    ref = structural_similarity(a, b, data_range=1.0, channel_axis=-1, **SK)
    assert abs(ours - ref) < 1e-4
    a255, b255 = a * 255, b * 255
    assert abs(wm.ssim(a255, b255, data_range=255) - ours) < 1e-9


def test_psnr_and_mse_equal_scikit_image(camera, rng):
    noisy = camera + 0.05 * rng.standard_normal(camera.shape)
    assert wm.mse(camera, noisy) == pytest.approx(mean_squared_error(camera, noisy), rel=1e-12)
    assert wm.rmse(camera, noisy) == pytest.approx(np.sqrt(mean_squared_error(camera, noisy)), rel=1e-12)
    assert wm.psnr(camera, noisy, data_range=1.0) == pytest.approx(
        peak_signal_noise_ratio(camera, noisy, data_range=1.0), rel=1e-12)
    assert wm.psnr(camera, camera) == float("inf")


def test_dice():
    a = np.array([[1, 1], [0, 0]], bool)
    b = np.array([[1, 0], [1, 0]], bool)
    assert wm.dice(a, b) == pytest.approx(0.5)
    assert wm.dice(np.array([1, 2, 2]), np.array([2, 2, 1]), label=2) == pytest.approx(0.5)
    assert wm.dice(np.zeros(3, bool), np.zeros(3, bool)) == 1.0


def test_inputs_are_not_modified_and_layout_does_not_matter(camera, rng):
    noisy = camera + 0.05 * rng.standard_normal(camera.shape)
    before = noisy.copy()
    s1 = wm.ssim(camera, noisy)
    assert np.array_equal(noisy, before)
    # Transposed and strided views give the same result as their contiguous copies.
    s_t = wm.ssim(camera.T, noisy.T)
    assert s_t == pytest.approx(wm.ssim(np.ascontiguousarray(camera.T), np.ascontiguousarray(noisy.T)), abs=1e-15)
    sub = wm.ssim(camera[::2, ::2], noisy[::2, ::2])
    assert sub == pytest.approx(wm.ssim(camera[::2, ::2].copy(), noisy[::2, ::2].copy()), abs=1e-15)
    assert s1 != sub
    # Integer input is accepted.
    u8 = (camera * 255).astype(np.uint8)
    assert wm.psnr(u8, u8, data_range=255) == float("inf")


@pytest.mark.parametrize("call", [
    lambda: wm.ssim(np.zeros((20, 20)), np.zeros((20, 21))),
    lambda: wm.ssim(np.zeros((5, 5)), np.zeros((5, 5))),
    lambda: wm.ssim(np.zeros((20, 20)), np.full((20, 20), np.nan)),
    lambda: wm.ssim(np.zeros(20), np.zeros(20)),
    lambda: wm.psnr(np.zeros(3), np.zeros(3), data_range=0),
    lambda: wm.mse(np.zeros(0), np.zeros(0)),
    lambda: wm.mse(np.zeros(3), np.zeros(3) + 1j),
    lambda: wm.dice(np.zeros(3, bool), np.zeros(4, bool)),
])
def test_bad_input_raises_value_error(call):
    with pytest.raises(ValueError):
        call()


def test_error_messages_name_the_argument():
    with pytest.raises(ValueError, match="data_range"):
        wm.psnr(np.zeros(3), np.ones(3), data_range=-1)
    with pytest.raises(ValueError, match="`b`"):
        wm.mse(np.zeros(3), np.array([0, np.inf, 0]))
    with pytest.raises(ValueError, match="shape mismatch"):
        wm.mse(np.zeros(3), np.zeros(4))
