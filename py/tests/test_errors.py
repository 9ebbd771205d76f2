"""Integer arguments out of range: a negative or too large count, size or seed raises
``wscg.IntegerRangeError``, a ``ValueError`` naming the argument, instead of the bare
``OverflowError`` of the conversion into an unsigned native parameter."""

import importlib
import inspect
import pickle

import numpy as np
import pytest

import wscg
from wscg import cloth, csmri, doe, video
from wscg import math as wm


def _modules():
    names = [n for n in wscg.__all__ if inspect.ismodule(getattr(wscg, n))]
    return [importlib.import_module(f"wscg.{n}") for n in names] + [
        importlib.import_module("wscg._manylight")]


def _python_defined(obj) -> bool:
    m = getattr(obj, "__module__", None) or ""
    return m.startswith("wscg.") and not m.startswith("wscg._native")


CASES = [
    ("max_iter", lambda: csmri.reconstruct(*_kspace(), max_iter=-1)),
    ("n_iter", lambda: csmri.fcsa(*_kspace(), n_iter=-1)),
    ("n", lambda: csmri.make_shepp_logan_kspace(-4)),
    ("seed", lambda: csmri.mask_cartesian((32, 32), 0.4, seed=2 ** 70)),
    ("n_frames", lambda: video.make_clip("g1", n_frames=-2)),
    ("level", lambda: wm.wavedec2(np.zeros((16, 16)), "db2", level=-1)),
    ("nx", lambda: cloth.grid(-3, 4)),
    ("n_iter", lambda: cloth.Sim(cloth.grid(3, 3), n_iter=-1)),
    ("n_steps", lambda: cloth.Sim(cloth.grid(3, 3)).step(n_steps=-1)),
    ("k", lambda: doe.ccd(-2)),
]


def _kspace():
    m = csmri.mask_cartesian((32, 32), 0.4)
    return csmri.make_shepp_logan_kspace(32) * m, m


@pytest.mark.parametrize("name,call", CASES, ids=[f"{i}-{n}" for i, (n, _) in enumerate(CASES)])
def test_out_of_range_integers_raise_a_value_error_naming_the_argument(name, call):
    with pytest.raises(ValueError, match=f"`{name}` is out of range") as e:
        call()
    assert isinstance(e.value, wscg.IntegerRangeError)
    # Code written against the conversion's own error still catches it.
    assert isinstance(e.value, OverflowError)


def test_every_public_function_and_method_translates():
    missing = []
    for mod in _modules():
        for name in mod.__all__:
            obj = getattr(mod, name)
            if inspect.isfunction(obj) and _python_defined(obj):
                if not getattr(obj, "_wscg_ranges", False):
                    missing.append(f"{mod.__name__}.{name}")
            elif isinstance(obj, type) and _python_defined(obj):
                for klass in obj.__mro__:
                    if not _python_defined(klass):
                        continue
                    for attr, v in vars(klass).items():
                        f = v.__func__ if isinstance(v, (staticmethod, classmethod)) else v
                        public = not attr.startswith("_") or attr in ("__init__", "__call__")
                        if inspect.isfunction(f) and public and not getattr(f, "_wscg_ranges", False):
                            missing.append(f"{mod.__name__}.{klass.__name__}.{attr}")
    assert not missing, missing


def test_other_errors_pass_through_unchanged():
    with pytest.raises(ValueError) as e:
        csmri.noise_epsilon(float("nan"), 3)
    assert not isinstance(e.value, wscg.IntegerRangeError)
    with pytest.raises(TypeError):
        csmri.reconstruct()


def test_wrapped_functions_keep_their_signature_doc_and_identity():
    sig = inspect.signature(csmri.reconstruct)
    assert list(sig.parameters)[:2] == ["kspace", "mask"]
    assert sig.parameters["max_iter"].default == 70
    assert csmri.reconstruct.__doc__.startswith("Reconstruct")
    assert csmri.reconstruct.__name__ == "reconstruct"
    assert pickle.loads(pickle.dumps(csmri.reconstruct)) is csmri.reconstruct


def test_native_class_methods_refuse_negative_indices_by_name():
    model = cloth.grid(3, 3)
    links = model.counts[0]
    for name, call in [("i", lambda: model.add_link(-1, 0, 10.0)),
                       ("j", lambda: model.add_link(0, -2, 10.0)),
                       ("p", lambda: model.add_roller(-1, (0.0, 0.0, 1.0), 0.0)),
                       ("indices", lambda: model.pin([0, -1]))]:
        with pytest.raises(ValueError, match=f"`{name}` must be an index >= 0"):
            call()
    # The refused calls added nothing; valid indices still work.
    assert model.counts[0] == links
    model.add_link(0, 4, 10.0)
    model.pin([0])
    assert model.counts[0] == links + 1


def test_negative_indices_in_arrays_are_refused_by_name():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=float)
    with pytest.raises(ValueError, match="`faces` must be an index >= 0, got -1"):
        cloth.mesh_collider(v, [[0, 1, -1]])
    eye = dict(data=[1.0, 1.0], b=[1.0, 2.0])
    with pytest.raises(ValueError, match="`indices` must be an index >= 0, got -1"):
        wm.cg([0, 1, 2], [0, -1], **eye)
    x, _ = wm.cg([0, 1, 2], [0, 1], **eye)
    np.testing.assert_allclose(x, [1.0, 2.0], atol=1e-8)


def test_native_functions_raise_the_packages_errors():
    # A value of the wrong type for a native function's parameter: pyo3's TypeError becomes
    # the package's ArgumentTypeError (a ValueError and a TypeError) naming the argument.
    with pytest.raises(wscg.ArgumentTypeError, match="`n`") as e:
        wm.normal(0, "x")
    assert isinstance(e.value, ValueError) and isinstance(e.value, TypeError)
    with pytest.raises(ValueError, match="`window`"):
        wscg.gait.dtw([1.0, 2.0], [1.0, 2.0], window="a")
    with pytest.raises(ValueError, match="`n_passes`"):
        wscg.volseg.smooth(np.zeros((4, 4, 4)), n_passes=1.5)
    # A call with an unknown keyword is a mistake in the calling code: a plain TypeError.
    with pytest.raises(TypeError) as e:
        wscg.gait.dtw([1.0], [1.0], foo=1)
    assert not isinstance(e.value, ValueError)
    # Wrapped functions keep their signature, documentation and pickling by reference.
    assert str(inspect.signature(wscg.gait.dtw)).startswith("(a, b")
    assert wscg.gait.dtw.__doc__ == wscg.gait.dtw.__wrapped__.__doc__
    assert pickle.loads(pickle.dumps(wscg.gait.dtw)) is wscg.gait.dtw


def test_no_module_exports_an_untranslated_native_function():
    raw = [f"{mod.__name__}.{name}" for mod in _modules() for name in mod.__all__
           if inspect.isbuiltin(getattr(mod, name))]
    assert not raw, raw


@pytest.mark.parametrize("name,make,fit_y", [
    ("n_components", lambda B: B.GlobalSFA(n_components=2.5, pca_n_components=5), True),
    ("m", lambda B: B.PerClassSFA(m=2.5, pca_n_components=5), True),
    ("n_components", lambda B: B.TemporalSFA(n_components=2.5), False),
    ("n_neighbors", lambda B: B.Isomap(n_neighbors=5.5, n_components=2), False),
    ("degree", lambda B: B.FDKECA(kernel="poly", degree=2.5), False),
])
def test_estimators_refuse_fractional_integer_hyper_parameters(name, make, fit_y):
    # Hyper-parameters reach the bindings as given: 2.5 used to be truncated to 2 by int().
    from wscg import biometrics as B
    X = np.random.default_rng(0).random((40, 6))
    y = np.repeat(np.arange(4), 10)
    est = make(B)
    with pytest.raises(ValueError, match=f"`{name}`"):
        est.fit(X, y) if fit_y else est.fit(X)
