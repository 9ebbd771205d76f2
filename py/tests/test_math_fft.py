import numpy as np
import pytest

import wscg.math as wm


@pytest.mark.parametrize("shape", [(17,), (12, 7), (5, 6, 9), (4, 3, 2, 5)])
@pytest.mark.parametrize("norm", ["backward", "ortho", "forward"])
def test_fftn_and_ifftn_equal_numpy(shape, norm, rng):
    x = rng.standard_normal(shape) + 1j * rng.standard_normal(shape)
    assert np.max(np.abs(wm.fftn(x, norm=norm) - np.fft.fftn(x, norm=norm))) < 1e-9
    assert np.max(np.abs(wm.ifftn(x, norm=norm) - np.fft.ifftn(x, norm=norm))) < 1e-9


def test_fft2_partial_axes_real_input_and_shifts(rng):
    x = rng.standard_normal((6, 8, 10))
    assert np.allclose(wm.fft2(x), np.fft.fft2(x), atol=1e-9)
    assert np.allclose(wm.ifft2(x, axes=(0, 2)), np.fft.ifft2(x, axes=(0, 2)), atol=1e-9)
    assert np.allclose(wm.fftn(x, axes=[1]), np.fft.fftn(x, axes=[1]), atol=1e-9)
    for shape in [(5,), (4, 7), (3, 4, 5)]:
        a = rng.standard_normal(shape)
        assert np.array_equal(wm.fftshift(a), np.fft.fftshift(a))
        assert np.array_equal(wm.ifftshift(a), np.fft.ifftshift(a))
        c = a + 1j * a
        assert np.array_equal(wm.fftshift(c), np.fft.fftshift(c))
    assert np.allclose(wm.fftfreq(7, 0.1), np.fft.fftfreq(7, 0.1))
    # Non-contiguous input.
    y = x[:, ::2, :]
    assert np.allclose(wm.fftn(y), np.fft.fftn(y), atol=1e-9)


def test_fft_bad_input():
    with pytest.raises(ValueError, match="norm"):
        wm.fftn(np.zeros(4), norm="unitary")
    with pytest.raises(ValueError, match="axes"):
        wm.fftn(np.zeros((2, 2)), axes=[0, 0])
    with pytest.raises(ValueError, match="axes"):
        wm.fftn(np.zeros((2, 2)), axes=[2])
    with pytest.raises(ValueError):
        wm.fftn(np.zeros((0, 3)))
    with pytest.raises(ValueError):
        wm.fftfreq(0)
