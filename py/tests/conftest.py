import os
import warnings

import numpy as np
import pytest


def global_pool_started() -> bool:
    """Whether rayon's global pool was ever started in this process: the bindings run all
    their work in wscg's own pool, which a forked child rebuilds, and must never touch the
    global one, which a forked child cannot use. Asked in a forked child, because asking
    starts the global pool."""
    from wscg import _native

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # fork of a multi-threaded process
        pid = os.fork()
    if pid == 0:
        code = 1
        try:
            code = 3 if _native._global_pool_started() else 0
        finally:
            os._exit(code)
    _, status = os.waitpid(pid, 0)
    code = os.waitstatus_to_exitcode(status)
    assert code in (0, 3), f"the checking child failed with exit code {code}"
    return code == 3


@pytest.fixture(scope="session", autouse=True)
def _global_pool_left_alone():
    """After the whole session: no binding the tests called used rayon's global pool."""
    yield
    if hasattr(os, "fork"):
        assert not global_pool_started(), (
            "a binding ran rayon work outside wscg's pool (crate::pool::detach), so a "
            "forked child would hang in it")


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
