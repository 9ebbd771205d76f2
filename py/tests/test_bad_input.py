"""Bad input through every public function and constructor: ``None`` where a value is
required, ``NaN``, a string and a complex array, each in every required argument. Every call
must raise ``ValueError``, ``TypeError`` or ``OSError`` naming one of its arguments (or the
file), never another exception, a crash or a hang. The functions are enumerated from the
modules' ``__all__``, so a new function is covered when it is exported.

A second table passes one bad value to one named argument of calls that are otherwise valid
(the cases from the field: ``fresnel_conductor(None, ...)``, ``NaN`` angles, ``dice`` on
``NaN``, complex images, array-likes)."""

import importlib
import inspect
import re
import signal

import numpy as np
import pytest

import wscg

BAD = {
    "none": None,
    "nan": float("nan"),
    "string": "not a value",
    "complex": np.full((8, 8), 1 + 1j),
}


def _callables():
    out = []
    for n in wscg.__all__:
        mod = getattr(wscg, n)
        if not inspect.ismodule(mod):
            continue
        mod = importlib.import_module(f"wscg.{n}")
        for name in mod.__all__:
            obj = getattr(mod, name)
            if not callable(obj) or getattr(obj, "__dataclass_fields__", None) is not None:
                continue
            if isinstance(obj, type) and (issubclass(obj, BaseException)
                                          or tuple in obj.__mro__):
                continue  # exceptions and result tuples
            try:
                sig = inspect.signature(obj)
            except (TypeError, ValueError):
                continue
            req = [p.name for p in sig.parameters.values()
                   if p.default is p.empty and p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
            if req:
                out.append((f"{n}.{name}", obj, req))
    return out


CALLABLES = _callables()


class _Timeout(Exception):
    pass


def _alarm(*_):
    raise _Timeout


def _message(e: BaseException) -> str:
    """The error's message and its notes (pyo3 notes "while processing 'name'" on a native
    argument it could not convert; a traceback prints the notes under the message)."""
    return "\n".join([str(e), *getattr(e, "__notes__", ())])


def _names(message: str, names) -> bool:
    return any(re.search(r"[`'\"]%s[`'\"\[]" % re.escape(n), message) for n in names)


def test_the_enumeration_finds_the_public_api():
    names = {q for q, _, _ in CALLABLES}
    assert len(CALLABLES) > 150
    for q in ("math.dice", "raytrace.fresnel_conductor", "volseg.random_walker_bone", "cloth.grid",
              "isosurface.marching_cubes", "csmri.reconstruct"):
        assert q in names or any(n.startswith(q) for n in names), q


@pytest.mark.parametrize("kind", sorted(BAD))
def test_every_function_names_the_bad_argument(kind):
    value = BAD[kind]
    problems = []
    old = signal.signal(signal.SIGALRM, _alarm)
    try:
        for qual, f, req in CALLABLES:
            file_args = [n for n in req if n in ("path", "directory") or n.endswith(("_path", "_dir"))]
            signal.alarm(20)
            try:
                f(*[value] * len(req))
                # Accepting the value is right only where it is meaningful for every
                # required argument: complex arrays in the k-space and FFT functions.
                if kind != "complex":
                    problems.append(f"{qual}: accepted {kind}")
            except _Timeout:
                problems.append(f"{qual}: no answer within 20 s")
            except OSError as e:
                if kind == "string" and file_args:
                    continue  # "cannot access 'not a value'": the file is named
                if not _names(_message(e), req) and "not a value" not in str(e):
                    problems.append(f"{qual}: OSError names no argument: {e}")
            except (ValueError, TypeError) as e:
                m = _message(e)
                if not _names(m, req) and not re.search(r"\b(%s)\b" % "|".join(map(re.escape, req)), m):
                    problems.append(f"{qual}: {type(e).__name__} names no argument: {e}")
            except Exception as e:  # noqa: BLE001 - the point of the test
                problems.append(f"{qual}: {type(e).__name__}: {e}")
            finally:
                signal.alarm(0)
    finally:
        signal.signal(signal.SIGALRM, old)
    assert not problems, "\n".join(problems)


def _model():
    return wscg.cloth.grid(3, 3)


IMAGE = np.linspace(0, 1, 32 * 32).reshape(32, 32)
NAN_IMAGE = IMAGE.copy()
NAN_IMAGE[3, 4] = np.nan
INF_VOLUME = np.zeros((6, 6, 6))  # NaN marks a missing sample there; infinity is refused
INF_VOLUME[2, 2, 2] = np.inf

def _fdct_with_text_band():
    f = wscg.csmri.Fdct((32, 32))
    c = f.forward(np.zeros((32, 32)))
    c[0][0] = np.array(["x"])
    return f.backward(c)


# (argument named in the error, call with one bad argument in an otherwise valid call)
ONE_BAD_ARGUMENT = [
    ("cos_i", lambda: wscg.raytrace.fresnel_conductor(None, 1.2, 6.9)),
    ("cos_i", lambda: wscg.raytrace.fresnel_conductor(np.array([0.5, np.nan]), 1.2, 6.9)),
    ("n", lambda: wscg.raytrace.fresnel_conductor(0.5, float("nan"), 6.9)),
    ("k", lambda: wscg.raytrace.fresnel_conductor(0.5, 1.2, None)),
    ("cos_i", lambda: wscg.raytrace.fresnel_dielectric(np.full(3, 0.5 + 0.1j), 1.5)),
    ("a", lambda: wscg.math.dice(np.array([1.0, np.nan]), np.ones(2))),
    ("b", lambda: wscg.math.dice(np.ones(3), np.array([0.0, 0.5, 1.0]))),
    ("image", lambda: wscg.math.gaussian_filter(IMAGE + 0j, 1.0)),
    ("sigma", lambda: wscg.math.gaussian_filter(IMAGE, float("nan"))),
    ("sigma", lambda: wscg.math.gaussian_filter(IMAGE, None)),
    ("image", lambda: wscg.math.gaussian_filter(NAN_IMAGE, 1.0)),
    ("image", lambda: wscg.deblur.deconv_krishnan(IMAGE + 0j, np.ones((3, 3)))),
    ("lam", lambda: wscg.deblur.deconv_krishnan(IMAGE, np.ones((3, 3)), lam=float("nan"))),
    ("level", lambda: wscg.isosurface.marching_cubes(np.zeros((4, 4, 4)), None)),
    ("volume", lambda: wscg.isosurface.marching_cubes(INF_VOLUME, 0.5)),
    ("n_iter", lambda: wscg.meshfilter.laplacian(*wscg.octree.make_scene("square")[:2], n_iter=None)),
    ("velocities", lambda: _model().set_velocities(np.zeros((9, 3)) + 1j)),
    ("velocities", lambda: _model().set_velocities(np.full((9, 3), np.nan))),
    ("velocities", lambda: _model().set_velocities([[0.0, 0.0]] * 9)),
    ("positions", lambda: _model().set_positions(np.zeros((8, 3)))),
    ("n_frames", lambda: wscg.video.make_clip("pan", n_frames=None)),
    ("seed", lambda: wscg.math.normal("x", 4)),
    ("n", lambda: wscg.math.normal(0, float("nan"))),
    # Counts and seeds, checked by the bindings since the wrappers stopped converting them.
    ("seed", lambda: wscg.biometrics.split_per_subject(np.repeat(np.arange(3), 4), 2, seed=1.5)),
    ("n_train_per_subject", lambda: wscg.biometrics.split_per_subject(np.repeat(np.arange(3), 4), -1)),
    ("seed", lambda: wscg.biometrics.make_hand_poses(n_per_class=2, seed=0.5)),
    ("size", lambda: wscg.biometrics.make_hand_poses(n_per_class=2, size=(165, 120, 3))),
    ("dims[0]", lambda: wscg.biometrics.select_dimension_cv(
        wscg.biometrics.PCA(), np.random.default_rng(0).random((12, 4)),
        np.repeat(np.arange(3), 4), dims=[1.5])),
    # Ranges and pairs are any array-like of two numbers, checked by name.
    ("range1", lambda: wscg.motion.plan_steps(2.5, range1=(0.7, 0.8, 0.9))),
    ("leader[0]", lambda: wscg.motion.hopf_simulate(1.0, leader=[np.nan, 0.0])),
    ("speed", lambda: wscg.gait.make_walkers(2, 2, speed=(1.1, 0.9))),
    ("up", lambda: wscg.gait.detect_cycle(np.zeros((40, 25, 3)), up=[0.0, np.inf, 0.0])),
    ("shifts", lambda: wscg.ear.EarMatcher(shifts=np.zeros((2, 3))).fit(np.zeros((1, 80, 25)))),
    ("canvas", lambda: wscg.ear.make_ears(1, 1, canvas=(200,))),
    ("labels", lambda: wscg.ear.evaluate(np.zeros((1, 100, 80, 3), np.uint8),
                                         np.zeros((1, 100, 80, 3), np.uint8), [[0]])),
    ("layers[0]['rect']", lambda: wscg.hdr.make_scene(height=16, width=16,
                                                       layers=[dict(disparity=2.0, rect=(0, 1))])),
    ("layers[1]['seed']", lambda: wscg.hdr.make_scene(height=16, width=16, layers=[
        dict(disparity=2.0), dict(disparity=3.0, seed=-1)])),
    ("emitter_peak", lambda: wscg.hdr.make_scene(height=16, width=16, emitter_peak=0.5)),
    # The imaginary part of a UDCT low-pass is refused, not dropped.
    ("lowpass", lambda: wscg.csmri.Udct((32, 32)).backward(
        np.zeros((16, 16), complex) + 1j, wscg.csmri.Udct((32, 32)).forward(np.zeros((32, 32)))[1])),
    ("bands[0]", lambda: _fdct_with_text_band()),
    # Triangle faces are integers (a float array was truncated by a cast before).
    ("faces", lambda: wscg.raytrace.manylight_from_arrays(
        np.eye(3), np.array([[0.0, 1.0, 2.0]]), [[0.5] * 3], [[0.0] * 3])),
]


@pytest.mark.parametrize("name,call", ONE_BAD_ARGUMENT,
                         ids=[f"{i}-{n}" for i, (n, _) in enumerate(ONE_BAD_ARGUMENT)])
def test_one_bad_argument_is_named(name, call):
    with pytest.raises((ValueError, TypeError)) as e:
        call()
    m = _message(e.value)
    assert f"`{name}`" in m or f"'{name}'" in m, m


def test_array_likes_are_converted():
    m = _model()
    v = [[0.0, 0.0, 0.1]] * 9
    for given in (v, np.asarray(v, dtype=np.float32), np.zeros((9, 3), dtype=np.int32)):
        m.set_velocities(given)
        np.testing.assert_allclose(m.velocities, np.asarray(given, dtype=np.float64))
    x = m.positions * 1.1
    m.set_positions(x.tolist())
    np.testing.assert_allclose(m.positions, x)
    # A list and an array give the same Fresnel curve; a scalar keeps its shape.
    cos = [0.1, 0.5, 1.0]
    np.testing.assert_array_equal(wscg.raytrace.fresnel_conductor(cos, 1.2, 6.9),
                                  wscg.raytrace.fresnel_conductor(np.array(cos), 1.2, 6.9))
    assert wscg.math.dice([True, False], [True, True]) == pytest.approx(2 / 3)


def test_arguments_converted_by_the_bindings_take_any_array_like():
    # Transforms: a list image and list bands give what the arrays give.
    u = wscg.csmri.Udct((32, 32), wedges=[[6, 6]])
    img = np.random.default_rng(1).random((32, 32))
    lp, bands = u.forward(img)
    lp2, bands2 = u.forward(img.tolist())
    np.testing.assert_array_equal(lp, lp2)
    np.testing.assert_array_equal(u.backward(lp.tolist(), [b.tolist() for b in bands]),
                                  u.backward(lp, bands))
    # The ear pipeline's block shifts as a list of pairs or an (n, 2) array.
    ears = wscg.ear.make_ears(2, 1, seed=3)
    t = wscg.ear.enroll_many(ears.enrol)
    probe = ears.probes[0]
    a = wscg.ear.EarMatcher(shifts=[(0, 0), (1, 0), (0, -1)]).fit(t).scores(probe)
    b = wscg.ear.EarMatcher(shifts=np.array([[0, 0], [1, 0], [0, -1]])).fit(t).scores(probe)
    np.testing.assert_array_equal(a, b)
    # Planner ranges as tuples, lists or arrays.
    p1 = wscg.motion.plan_steps(2.5, range1=(0.670, 0.901))
    p2 = wscg.motion.plan_steps(2.5, range1=np.array([0.670, 0.901]))
    assert p1.actions == p2.actions


def test_big_endian_volumes_render_as_native_ones():
    # Paper 15's renders convert a non-native byte order (some file readers give it).
    vol = wscg.volren.make_marschner_lobb(24).astype(np.float32)
    tf = wscg.volren.marschner_lobb_tf()
    a = wscg.volren.render(vol, tf, size=(16, 16))
    b = wscg.volren.render(vol.astype(">f4"), tf, size=(16, 16))
    np.testing.assert_array_equal(a, b)


def test_overlapping_calls_that_change_one_object_get_a_clear_error():
    import threading

    sim = wscg.cloth.Sim(wscg.cloth.grid(30, 30))
    errors = []

    def run():
        try:
            for _ in range(200):  # until two calls overlap (the step runs without the GIL)
                if errors:
                    return
                sim.step(n_steps=5)
        except RuntimeError as e:
            errors.append(str(e))

    threads = [threading.Thread(target=run) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors, "four threads stepping one Sim never overlapped"
    for e in errors:
        assert "Sim.step" in e and "another thread" in e and "threading.Lock" in e, e
