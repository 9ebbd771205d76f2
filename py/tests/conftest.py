import numpy as np
import pytest


@pytest.fixture
def rng():
    return np.random.default_rng(1234)


@pytest.fixture
def camera():
    from skimage import data
    return data.camera().astype(np.float64) / 255.0


@pytest.fixture
def astronaut():
    from skimage import data
    return data.astronaut().astype(np.float64) / 255.0
