"""The Rust thread pool across processes and its size: worker processes started by every
``multiprocessing`` start method (``fork`` after the parent has used the pool included),
``ProcessPoolExecutor``, joblib, and the one knob ``wscg.set_num_threads`` /
``WSCG_NUM_THREADS``.

Every wait has a timeout, so a child that hangs fails the test instead of hanging it."""

import concurrent.futures as cf
import multiprocessing as mp
import os
import subprocess
import sys
import threading
import time
import warnings

import numpy as np
import pytest

import wscg
from wscg import _native

from conftest import global_pool_started

TIMEOUT = 120  # seconds for any child; a correct run takes a fraction of a second per call

START_METHODS = [m for m in ("fork", "spawn", "forkserver") if m in mp.get_all_start_methods()]


def work(seed: int):
    """Parallel calls into three modules (filter, FFT, random numbers): rayon splits each."""
    x = np.random.default_rng(seed).random((256, 256))
    return (
        wscg.math.gaussian_filter(x, 2.0),
        wscg.math.fft2(x),
        wscg.math.normal(seed, 100_000),
        wscg.get_num_threads(),
    )


def work_with_one_thread(seed: int):
    """``work`` after giving this process one thread."""
    wscg.set_num_threads(1)
    return work(seed)


def same(a, b) -> bool:
    return all(np.array_equal(x, y) for x, y in zip(a[:3], b[:3]))


@pytest.fixture
def parent_used_pool():
    """The parent's pool has started and run work (the state `fork` copies), and the
    expected results of seeds 0..3."""
    return {s: work(s) for s in range(4)}


@pytest.fixture
def restore_threads():
    yield
    wscg.set_num_threads(None)


def run_pool(ctx, fn, seeds, expected):
    pool = ctx.Pool(2)
    try:
        got = pool.map_async(fn, seeds).get(timeout=TIMEOUT)
    finally:
        pool.terminate()
        pool.join()
    for s, r in zip(seeds, got):
        assert same(r, expected[s])
    return got


@pytest.mark.parametrize("method", START_METHODS)
def test_multiprocessing_pool_after_the_parent_used_the_pool(method, parent_used_pool):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # fork of a multi-threaded process
        got = run_pool(mp.get_context(method), work, [0, 1, 2, 3], parent_used_pool)
    assert all(r[3] == wscg.get_num_threads() for r in got)


@pytest.mark.parametrize("method", START_METHODS)
def test_children_with_one_thread_each(method, parent_used_pool):
    before = wscg.get_num_threads()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        got = run_pool(mp.get_context(method), work_with_one_thread, [0, 1, 2, 3],
                       parent_used_pool)
    assert all(r[3] == 1 for r in got)
    assert wscg.get_num_threads() == before


@pytest.mark.skipif("fork" not in START_METHODS, reason="no fork on this platform")
def test_process_pool_executor_with_fork(parent_used_pool):
    ex = cf.ProcessPoolExecutor(max_workers=2, mp_context=mp.get_context("fork"))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            futures = {s: ex.submit(work, s) for s in range(4)}
            got = {s: f.result(timeout=TIMEOUT) for s, f in futures.items()}
    finally:
        for p in list(getattr(ex, "_processes", {}).values()):
            p.kill()  # only reached with live workers when a result timed out
        ex.shutdown(wait=True, cancel_futures=True)
    for s, r in got.items():
        assert same(r, parent_used_pool[s])


def test_joblib_multiprocessing_backend(parent_used_pool):
    joblib = pytest.importorskip("joblib")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        got = joblib.Parallel(n_jobs=2, backend="multiprocessing", timeout=TIMEOUT)(
            joblib.delayed(work)(s) for s in range(4))
    for s, r in enumerate(got):
        assert same(r, parent_used_pool[s])


def wait_child(pid: int, timeout: float) -> int:
    """Exit code of child `pid`, killing it (and failing) if it runs past `timeout`."""
    end = time.monotonic() + timeout
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            return os.waitstatus_to_exitcode(status)
        if time.monotonic() > end:
            os.kill(pid, 9)
            os.waitpid(pid, 0)
            pytest.fail(f"the forked child did not finish in {timeout} s")
        time.sleep(0.01)


@pytest.mark.skipif(not hasattr(os, "fork"), reason="no fork on this platform")
def test_fork_while_another_thread_runs_in_the_pool(parent_used_pool):
    """A fork taken while the parent's pool is busy: the child still gets a working pool."""
    stop = threading.Event()
    x = np.random.default_rng(5).random((512, 512))

    def busy():
        while not stop.is_set():
            wscg.math.gaussian_filter(x, 3.0)

    t = threading.Thread(target=busy)
    t.start()
    try:
        time.sleep(0.05)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            pid = os.fork()
        if pid == 0:
            code = 1
            try:
                code = 0 if same(work(0), parent_used_pool[0]) else 2
            finally:
                os._exit(code)
        assert wait_child(pid, TIMEOUT) == 0
    finally:
        stop.set()
        t.join()


def test_bindings_leave_rayons_global_pool_alone(parent_used_pool):
    """All work goes through the process's own pool: rayon's global pool (which a forked
    child could not use) is never started by the calls above. The whole test session checks
    the same after every test module has run (conftest.py)."""
    if not hasattr(os, "fork"):
        pytest.skip("no fork on this platform")
    assert not global_pool_started()


def test_thread_count_does_not_change_results(restore_threads):
    wscg.set_num_threads(1)
    assert wscg.get_num_threads() == 1
    one = work(3)
    wscg.set_num_threads(2)
    assert wscg.get_num_threads() == 2
    two = work(3)
    assert same(one, two)
    assert one[3] == 1 and two[3] == 2


def test_thread_count_does_not_change_dense_linear_algebra(restore_threads):
    # Video completion with the paper's PCA + kd-tree search: its axes come from an
    # eigendecomposition whose faer kernels used to round differently with one thread.
    _, observed, hole = wscg.video.make_clip("pan", n_frames=8, height=90, width=160, step=6.0,
                                             hole=(20, 24), seed=13)
    runs = []
    for n in (1, 2):
        wscg.set_num_threads(n)
        runs.append(wscg.video.complete_video(observed, hole, search="pca_kdtree"))
    assert np.array_equal(runs[0], runs[1])


def test_default_restored_by_none_and_zero(restore_threads):
    default = wscg.get_num_threads()
    assert default >= 1
    wscg.set_num_threads(3)
    assert wscg.get_num_threads() == 3
    wscg.set_num_threads(None)
    assert wscg.get_num_threads() == default
    wscg.set_num_threads(3)
    wscg.set_num_threads(0)
    assert wscg.get_num_threads() == default


@pytest.mark.skipif(not os.path.isdir("/proc/self/task"), reason="needs Linux /proc")
def test_the_knob_sets_the_threads_that_run(restore_threads):
    def pool_threads():
        n = 0
        for tid in os.listdir("/proc/self/task"):
            try:
                with open(f"/proc/self/task/{tid}/comm") as f:
                    n += f.read().startswith("wscg-")
            except OSError:
                pass  # a thread that just exited
        return n

    for n in (3, 1):
        wscg.set_num_threads(n)
        work(0)
        end = time.monotonic() + 10  # the threads of a replaced pool exit asynchronously
        while pool_threads() != n and time.monotonic() < end:
            time.sleep(0.01)
        assert pool_threads() == n


@pytest.mark.parametrize("bad", [-1, 1025, 2.5, "2", True, [2]])
def test_bad_thread_counts(bad, restore_threads):
    before = wscg.get_num_threads()
    with pytest.raises(ValueError, match="`n`"):
        wscg.set_num_threads(bad)
    assert wscg.get_num_threads() == before


@pytest.mark.parametrize("bad", [-1, 1025])
def test_native_knob_checks_its_argument(bad):
    with pytest.raises(ValueError, match="`n`"):
        _native.set_num_threads(bad)


def threads_in_subprocess(env_update: dict) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items()
           if k not in ("WSCG_NUM_THREADS", "RAYON_NUM_THREADS")}
    env.update(env_update)
    code = "import wscg; wscg.math.normal(0, 100000); print(wscg.get_num_threads())"
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, timeout=TIMEOUT)


def test_environment_variable_read_at_import():
    default = int(threads_in_subprocess({}).stdout)
    assert default >= 1
    r = threads_in_subprocess({"WSCG_NUM_THREADS": "3"})
    assert r.returncode == 0 and int(r.stdout) == 3, r.stderr
    assert int(threads_in_subprocess({"WSCG_NUM_THREADS": " 1 "}).stdout) == 1
    assert int(threads_in_subprocess({"WSCG_NUM_THREADS": ""}).stdout) == default
    assert int(threads_in_subprocess({"WSCG_NUM_THREADS": "0"}).stdout) == default
    # Without WSCG_NUM_THREADS, rayon's own variable.
    assert int(threads_in_subprocess({"RAYON_NUM_THREADS": "2"}).stdout) == 2
    assert int(threads_in_subprocess({"RAYON_NUM_THREADS": "2",
                                      "WSCG_NUM_THREADS": "3"}).stdout) == 3


@pytest.mark.parametrize("bad", ["abc", "-2", "1.5", "5000"])
def test_invalid_environment_variable_warns_and_keeps_the_default(bad):
    default = int(threads_in_subprocess({}).stdout)
    r = threads_in_subprocess({"WSCG_NUM_THREADS": bad})
    assert r.returncode == 0, r.stderr
    assert int(r.stdout) == default
    assert "RuntimeWarning" in r.stderr and "WSCG_NUM_THREADS" in r.stderr
