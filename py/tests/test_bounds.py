"""Bounded work and memory: sizes beyond the machine raise ``MemoryError`` (or a ``ValueError``
where a documented cap applies) naming the argument instead of aborting the interpreter, image
files declaring huge sizes are refused before decoding, files that never end are not read,
and Ctrl-C stops long calls with ``KeyboardInterrupt``.

Every case runs in a child interpreter: a regression that aborts (exit 134) or hangs fails
its test (with a timeout) instead of killing pytest."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
import zlib

import pytest

TIMEOUT = 120  # seconds for a child; a correct one takes well under a second

PRELUDE = """
import json, sys
import numpy as np
import wscg
from wscg import math, csmri, ear, raytrace, video, volren, cloth, octree, doe
import wscg.biometrics, wscg.isosurface, wscg.motion
a = np.zeros((8, 8))
"""

# (code, accepted exception types, a name the message must contain)
HUGE = {
    "math.normal": ("math.normal(0, 10**12)", "MemoryError", "`n`"),
    "math.uniform": ("math.uniform(0, 10**12)", "MemoryError", "`n`"),
    "math.permutation": ("math.permutation(0, 10**13)", "MemoryError", "`n`"),
    "math.gaussian_filter sigma": ("math.gaussian_filter(a, sigma=1e12)", "MemoryError",
                                   "sigma"),
    "math.gaussian_filter truncate": ("math.gaussian_filter(a, 1.0, truncate=1e15)",
                                      "MemoryError", "truncate"),
    "math.box_filter": ("math.box_filter(a, radius=10**12)", "MemoryError", "`radius`"),
    "math.resize": ("math.resize(a, (10**6, 10**6))", "MemoryError", "height, width"),
    "math.laplacian_3d": ("math.laplacian_3d(10**5, 10**5, 10**5)", "MemoryError",
                          "nx, ny, nz"),
    "csmri.mask_cartesian": ("csmri.mask_cartesian((10**7, 10**7), .4)", "MemoryError",
                             "`shape`"),
    "csmri.Udct": ("csmri.Udct((10**6, 10**6))", "MemoryError", "`shape`"),
    "ear.cmc": ("ear.cmc(np.array([0, 1, 2]), 10**10)", "MemoryError", "`max_rank`"),
    "raytrace.render_manylight": (
        "raytrace.render_manylight(raytrace.make_manylight_scene('cornell', width=8, height=8), "
        "n_vpl_paths=10**10)", "MemoryError", "n_paths"),
    "raytrace.make_manylight_scene": ("raytrace.make_manylight_scene('cornell', width=10**6, "
                                 "height=10**6)", "MemoryError", "width, height"),
    "video.make_clip": ("video.make_clip('sprite', n_frames=10**6, height=10**4, width=10**4)",
                        "MemoryError", "n_frames, height, width"),
    "volren.make_phantom": ("volren.make_phantom('head', shape=(10**5,) * 3)", "MemoryError", "`dims`"),
    "cloth.grid": ("cloth.grid(10**6, 10**6)", "MemoryError", "nx, ny"),
    "octree.voxelize": ("octree.voxelize(*octree.make_scene('square')[:2], depth=21, "
                        "domain=((0, 0, 0), 1.0))", "ValueError", "depth"),
    "octree.make_scene city": ("octree.make_scene('city', size=10**9)", "MemoryError", "`n`"),
    "math.fftfreq": ("math.fftfreq(10**12)", "MemoryError", "`n`"),
    "csmri.mask_pseudo_radial": ("csmri.mask_pseudo_radial((10**7, 10**7), .4)",
                                 "MemoryError", "`shape`"),
    "csmri.Sflct": ("csmri.Sflct((10**6, 10**6))", "MemoryError", "`shape`"),
    "biometrics.make_finger_veins": ("wscg.biometrics.make_finger_veins(n_subjects=10**9)",
                                     "MemoryError", "n_subjects"),
    "isosurface.study_exact": ("wscg.isosurface.study_exact('sphere', n=10**5)",
                               "MemoryError", "`dims`"),
    "video.complete_video hypotheses": (
        "video.complete_video(*video.make_clip('pan', n_frames=8, height=90, width=160)[1:], "
        "lowres_width=80, search='pca_kdtree', hypotheses=10**12)", "MemoryError",
        "`hypotheses`"),
    "motion.plan_steps": ("wscg.motion.plan_steps(1e15, max_steps=10**15)", "MemoryError",
                          "`goal`"),
    "octree.make_scene atrium": ("octree.make_scene('atrium', size=10**12)", "MemoryError",
                            "`pillars`"),
}


def run_child(code: str, env=None):
    """Runs `code` after PRELUDE in a fresh interpreter; returns the completed process."""
    return subprocess.run([sys.executable, "-c", PRELUDE + textwrap.dedent(code)],
                          capture_output=True, text=True, timeout=TIMEOUT, env=env)


def outcome(code: str, env=None) -> dict:
    """The exception type and message `code` raises in a child (``None`` when it returns)."""
    body = textwrap.indent(textwrap.dedent(code).strip(), "    ")
    probe = f"""
try:
{body}
    print(json.dumps({{"type": None, "msg": ""}}))
except BaseException as e:
    print(json.dumps({{"type": type(e).__name__, "msg": str(e)}}))
"""
    p = run_child(probe, env)
    assert p.returncode == 0, (
        f"{code}: the interpreter died with {p.returncode} "
        f"(-6/134 is an abort)\n{p.stderr[-2000:]}")
    return json.loads(p.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("case", sorted(HUGE))
def test_huge_sizes_raise_instead_of_aborting(case):
    code, kind, name = HUGE[case]
    got = outcome(code)
    assert got["type"] == kind, f"{code}: {got}"
    assert name in got["msg"], f"{code}: the message names no argument: {got['msg']}"


def test_the_memory_limit_can_be_lowered_and_raised():
    got = outcome("""
before = wscg.get_memory_limit()
wscg.set_memory_limit(10**6)
assert wscg.get_memory_limit() == 10**6
try:
    math.normal(0, 10**6)  # 8 MB > 1 MB
    raise AssertionError("not refused")
except MemoryError as e:
    assert "`n`" in str(e)
assert math.normal(0, 10**4).shape == (10**4,)
wscg.set_memory_limit(None)
assert wscg.get_memory_limit() == before
assert math.normal(0, 10**6).shape == (10**6,)
""")
    assert got["type"] is None, got
    env = dict(os.environ, WSCG_MAX_MEMORY="1000000")
    got = outcome("math.normal(0, 10**6)", env)
    assert got["type"] == "MemoryError" and "1000000 bytes" in got["msg"], got


def zero_png(width: int, height: int) -> bytes:
    """An all-zero 8-bit grey PNG, compressed row by row (20000 x 20000 is about 400 KB)."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return len(data).to_bytes(4, "big") + body + zlib.crc32(body).to_bytes(4, "big")

    z = zlib.compressobj(9)
    row = bytes(width + 1)  # filter byte 0 and the zero pixels
    parts = [z.compress(row) for _ in range(height)]
    idat = b"".join(parts) + z.flush()
    ihdr = width.to_bytes(4, "big") + height.to_bytes(4, "big") + bytes([8, 0, 0, 0, 0])
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", idat)
            + chunk(b"IEND", b""))


@pytest.fixture(scope="module")
def bomb(tmp_path_factory):
    path = tmp_path_factory.mktemp("bomb") / "bomb.png"
    path.write_bytes(zero_png(20000, 20000))
    assert path.stat().st_size < 2_000_000
    return path


def test_an_image_declaring_too_many_pixels_is_refused_before_decoding(bomb):
    got = outcome(f"math.load_image({str(bomb)!r})")
    assert got["type"] == "ValueError", got
    assert "bomb.png" in got["msg"] and "20000 x 20000" in got["msg"], got
    # Raised, the cap lets the same file through (checked on its header: the decode itself
    # is stopped by a smaller memory limit, so the test stays light).
    got = outcome(f"""
wscg.set_max_image_pixels(10**9)
assert wscg.get_max_image_pixels() == 10**9
math.load_image({str(bomb)!r})
""", dict(os.environ, WSCG_MAX_MEMORY=str(10**8)))
    assert got["type"] != "ValueError" or "20000 x 20000" not in got["msg"], got
    env = dict(os.environ, WSCG_MAX_IMAGE_PIXELS="100")
    small = bomb.with_name("small.png")
    small.write_bytes(zero_png(16, 16))
    got = outcome(f"math.load_image({str(small)!r})", env)
    assert got["type"] == "ValueError" and "16 x 16" in got["msg"], got


def test_a_material_library_that_never_ends_is_not_read(tmp_path):
    if not os.path.exists("/dev/zero"):
        pytest.skip("no /dev/zero")
    obj = tmp_path / "zero.obj"
    obj.write_text("mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    got = outcome(f"raytrace.load_manylight_obj({str(obj)!r})")
    assert got["type"] == "OSError" and "/dev/zero" in got["msg"], got


def test_a_design_whose_squares_overflow_is_refused():
    got = outcome("""
x = np.array([[-1.0, -1.0], [-1, 0], [-1, 1], [0, -1], [0, 0], [0, 1], [1, -1], [1, 0], [1, 1]])
x[0, 0] = 1e155
doe.fit_rsm(x, np.arange(9.0))
""")
    assert got["type"] == "ValueError" and "`x`" in got["msg"], got


# Long calls that Ctrl-C must stop: each would run for hours.
LONG = {
    "manylight spp": "raytrace.render_manylight(raytrace.make_manylight_scene('cornell', width=16, "
                     "height=16), 'power', n_vpl_paths=50, spp=10**9)",
    "octree n_ao_samples": "octree.build(*octree.make_scene('blob', size=2)[:2], depth=6)"
                         ".render((3, 3, 3), (0, 0, 0), width=16, height=16, n_ao_samples=10**9)",
    "volren slices": "volren.render(volren.make_phantom('head', shape=(32, 32, 32)), "
                     "[[0, 0, 0, 0], [1, 1, 1, 0.5]], size=(256, 256), slice_distance=1e-4)",
    "cloth n_iter": "cloth.Sim(cloth.grid(20, 20), n_iter=10**9).step(1e-3)",
    "video patchmatch_n_iter": "video.complete_video(*video.make_clip('pan', n_frames=8, "
                               "height=90, width=160)[1:], lowres_width=80, "
                               "patchmatch_n_iter=10**15)",
    "video wexler patchmatch_n_iter": "video.wexler_complete(*video.make_clip('pan', n_frames=8, "
                                      "height=90, width=160)[1:], patchmatch_n_iter=10**15)",
}


@pytest.mark.skipif(not hasattr(signal, "SIGINT") or sys.platform == "win32",
                    reason="needs POSIX signals")
@pytest.mark.parametrize("case", sorted(LONG))
def test_ctrl_c_stops_a_long_call(case):
    code = f"""
print("started", flush=True)
try:
    {LONG[case]}
    print("returned", flush=True)
except KeyboardInterrupt:
    print("interrupted", flush=True)
"""
    # A terminal's Ctrl-C reaches an interpreter with Python's own SIGINT handler; a runner
    # that ignores SIGINT passes that on to the child, where Python then installs none, so the
    # child installs it (not in a preexec_fn, which may deadlock in a threaded parent).
    parent = signal.getsignal(signal.SIGINT)
    code = "import signal\nsignal.signal(signal.SIGINT, signal.default_int_handler)\n" + code
    p = subprocess.Popen([sys.executable, "-c", PRELUDE + code], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "started", p.stderr.read()
        time.sleep(1.0)
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=30)
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    assert "interrupted" in out, f"{case}: {out!r} {err[-2000:]} (runner's SIGINT: {parent})"
    assert p.returncode == 0, err[-2000:]
