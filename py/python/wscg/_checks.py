"""Argument checks shared by the Python modules: each raises ``ValueError`` naming the
argument, before the value reaches Rust; and :func:`integer_ranges`, which every module
applies to its public functions and methods. It checks the kind of each argument against
the parameter's annotation before the call (:class:`ArgumentTypeError` naming the argument
for ``None`` where a value is required, a string, complex number or array where a real
number is, ``NaN`` where a number is; complex arrays where the parameter's documentation does
not say it takes complex values) and turns the ``OverflowError`` of an out-of-range integer
reaching a native parameter into an :class:`IntegerRangeError` naming it."""

from __future__ import annotations

import dataclasses
import functools
import inspect
import math
import numbers
import os
import re
from typing import Callable, Dict, Optional

import numpy as np


def _int(name: str, v, lo: Optional[int] = None, hi: Optional[int] = None) -> int:
    """``v`` as a Python int (integral floats accepted, bools refused), within ``[lo, hi]``."""
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Integral):
        if isinstance(v, numbers.Real) and float(v).is_integer():
            v = int(v)
        else:
            raise ValueError(f"`{name}` must be an integer, got {v!r}")
    v = int(v)
    if lo is not None and v < lo:
        raise ValueError(f"`{name}` must be >= {lo}, got {v}")
    if hi is not None and v > hi:
        raise ValueError(f"`{name}` must be <= {hi}, got {v}")
    return v


class IntegerRangeError(ValueError, OverflowError):
    """An integer argument outside the range its native parameter takes: a negative count,
    size or seed, or a value beyond 64 bits. A ``ValueError`` (the package's error for bad
    arguments) and, for code that expects what Python raises on such conversions, an
    ``OverflowError``."""


_PROCESSING = re.compile(r"while processing '([^']+)'")


def _range_error(e: OverflowError) -> IntegerRangeError:
    """``e`` as an :class:`IntegerRangeError` naming the argument where the native binding
    noted it."""
    names = [m.group(1) for n in getattr(e, "__notes__", ()) for m in [_PROCESSING.match(str(n))] if m]
    what = f"`{names[-1]}`" if names else "an integer argument"
    return IntegerRangeError(f"{what} is out of range ({e}): counts, sizes and seeds are "
                             "non-negative integers that fit the native parameter (32 or 64 bits)")


class ArgumentTypeError(ValueError, TypeError):
    """An argument of the wrong kind for its parameter: ``None`` where a value is required,
    a string, complex number or array where a real number is, a complex array where real
    values are. A ``ValueError`` (the package's error for bad arguments) and, for code that
    expects what Python raises on such conversions, a ``TypeError``."""


def _kind(v) -> str:
    if v is None:
        return "None"
    if isinstance(v, np.ndarray):
        return f"an array of shape {v.shape} and dtype {v.dtype}"
    return f"{type(v).__name__} {v!r}" if len(repr(v)) <= 60 else type(v).__name__


def _is_int(v) -> bool:
    if isinstance(v, (bool, np.bool_)):
        return False
    if isinstance(v, numbers.Integral):
        return True
    if isinstance(v, np.ndarray) and v.ndim == 0:
        return _is_int(v.item())
    # Integral floats (2.0) are converted by the functions themselves.
    return isinstance(v, numbers.Real) and math.isfinite(float(v)) and float(v).is_integer()


def _is_real(v) -> bool:
    if isinstance(v, (bool, np.bool_)) or isinstance(v, (str, bytes)):
        return False
    if isinstance(v, np.ndarray):
        return v.ndim == 0 and v.dtype.kind in "iuf"
    return isinstance(v, numbers.Real)


def _check_int(name: str, v) -> None:
    if not _is_int(v):
        if _is_real(v) and math.isnan(float(v)):
            raise ArgumentTypeError(f"`{name}` must be an integer, got NaN")
        raise ArgumentTypeError(f"`{name}` must be an integer, got {_kind(v)}")


def _check_real(name: str, v) -> None:
    if not _is_real(v):
        raise ArgumentTypeError(f"`{name}` must be a real number, got {_kind(v)}")
    if math.isnan(float(v)):
        raise ValueError(f"`{name}` must be a number, got NaN")


def _check_bool(name: str, v) -> None:
    if not isinstance(v, (bool, np.bool_)) and not (_is_int(v) and int(v) in (0, 1)):
        raise ArgumentTypeError(f"`{name}` must be True or False, got {_kind(v)}")


def _check_str(name: str, v) -> None:
    if not isinstance(v, str):
        raise ArgumentTypeError(f"`{name}` must be a string, got {_kind(v)}")


def _elements(check: Callable[[str, object], None]) -> Callable[[str, object], None]:
    def run(name: str, v) -> None:
        if isinstance(v, (str, bytes)) or not hasattr(v, "__len__"):
            raise ArgumentTypeError(f"`{name}` must be a sequence of numbers, got {_kind(v)}")
        for i, x in enumerate(v):
            check(f"{name}[{i}]", x)

    return run


def _check_real_array(name: str, v) -> None:
    if isinstance(v, (np.ndarray, np.generic)) and v.dtype.kind == "c" or isinstance(v, complex):
        raise ArgumentTypeError(f"`{name}` must hold real values, got complex input "
                                f"({_kind(v)}): pass its real part, magnitude or phase")


def _check_array(takes_complex: bool) -> Callable[[str, object], None]:
    """Check of a parameter documented as an array only: refuses strings, mappings and
    scalars (and complex values unless ``takes_complex``)."""

    def run(name: str, v) -> None:
        scalar = isinstance(v, (numbers.Number, np.generic)) or (isinstance(v, np.ndarray)
                                                                 and v.ndim == 0)
        if isinstance(v, (str, bytes, dict)) or scalar:
            raise ArgumentTypeError(f"`{name}` must be an array, got {_kind(v)}")
        if not takes_complex:
            _check_real_array(name, v)

    return run


def _check_array_or_number(takes_complex: bool) -> Callable[[str, object], None]:
    """Check of a parameter that takes an array (or a number where the function broadcasts):
    refuses strings, mappings and NaN numbers (and complex values unless ``takes_complex``)."""

    def run(name: str, v) -> None:
        if isinstance(v, (str, bytes, dict)):
            raise ArgumentTypeError(f"`{name}` must be an array, got {_kind(v)}")
        if _is_real(v) and math.isnan(float(v)):
            raise ValueError(f"`{name}` must be an array of numbers, got NaN")
        if not takes_complex:
            _check_real_array(name, v)

    return run


def _check_path(name: str, v) -> None:
    if not isinstance(v, (str, bytes, os.PathLike)):
        raise ArgumentTypeError(f"`{name}` must be a file path (str or os.PathLike), got {_kind(v)}")


def _check_bytes(name: str, v) -> None:
    if not isinstance(v, (bytes, bytearray, memoryview)):
        raise ArgumentTypeError(f"`{name}` must be bytes, got {_kind(v)}")


def _instance_of(klass: type) -> Callable[[str, object], None]:
    def run(name: str, v) -> None:
        if not isinstance(v, klass):
            raise ArgumentTypeError(f"`{name}` must be a {klass.__name__}, got {_kind(v)}")

    return run


# Annotation (as written, `from __future__ import annotations`) -> check of a given value.
_SCALARS: Dict[str, Callable[[str, object], None]] = {
    "int": _check_int, "float": _check_real, "bool": _check_bool, "str": _check_str,
}
_SEQUENCES = re.compile(r"^(?:Sequence|List|Tuple)\[(int|float)(?:, (?:int|float|\.\.\.))*\]$")
_ARRAYS = ("np.ndarray", "ArrayLike", "npt.ArrayLike", "npt.NDArray")


def _documentation(doc: str, name: str) -> str:
    """The numpydoc entry of parameter ``name`` in ``doc`` (its ``name : type`` line, which may
    list several names, and the indented lines below it), or ``""``."""
    lines = doc.splitlines()
    for i, line in enumerate(lines):
        head = line.split(" : ")[0] if " : " in line else line.strip()
        if name not in [n.strip() for n in head.split(",")]:
            continue
        indent = len(line) - len(line.lstrip())
        block = [line]
        for nxt in lines[i + 1:]:
            if nxt.strip() and len(nxt) - len(nxt.lstrip()) <= indent:
                break
            block.append(nxt)
        return "\n".join(block)
    return ""


# Parameter names that py/API.md reserves for arrays (checked where a parameter has neither
# an annotation nor a documented type).
_ARRAY_NAMES = frozenset("""
    vertices faces positions masses points origins dirs directions normal normals colors image
    images volume volumes mask masks labels curve scores y_true y_pred gt xyz spd albedo
    emission blocks kspace frames eye target left_ids right_ids lambda_nm
""".split())
_PATH_NAMES = re.compile(r"^(?:path|out_dir|directory|\w+_path|\w+_dir)$")
_SCALAR_WORDS = re.compile(r"\b(?:float|int|scalar|number|str|bool|tuple|list|sequence|pair)\b", re.I)


def _param_check(p: inspect.Parameter, doc: str, namespace: dict,
                 takes_complex: bool) -> Optional[Callable[[str, object], None]]:
    """The check of parameter ``p``'s values, from its annotation, or for unannotated
    parameters from its name (paths) and its documented type (arrays); ``None`` passes only
    where the parameter defaults to ``None`` or is annotated ``Optional``."""
    ann = p.annotation if isinstance(p.annotation, str) else ""
    optional = p.default is None or ann.startswith("Optional[") or "None" in ann
    inner = ann[len("Optional["):-1] if ann.startswith("Optional[") else ann
    entry = _documentation(doc, p.name)
    kind = entry.splitlines()[0].partition(" : ")[2] if entry else ""
    check = _SCALARS.get(inner)
    if check is None:
        m = _SEQUENCES.match(inner)
        klass = namespace.get(inner.strip("'\"")) if inner.isidentifier() or inner[1:-1].isidentifier() else None
        if m:
            check = _elements(_SCALARS[m.group(1)])
        elif "PathLike" in inner or not ann and _PATH_NAMES.match(p.name):
            check = _check_path
        elif inner == "bytes":
            check = _check_bytes
        elif isinstance(klass, type) and klass.__module__.startswith("wscg."):
            check = _instance_of(klass)
        elif inner in _ARRAYS or not ann:
            # Arrays (annotated or not): complex values only where the function's
            # documentation speaks of them.
            takes_complex = takes_complex or "complex" in doc.lower()
            pure = "array" in kind.lower() and not _SCALAR_WORDS.search(kind) and not re.search(
                r"\bor\b|[{]", kind)
            if inner in _ARRAYS or pure:
                check = _check_array(takes_complex)
            elif not kind and p.name in _ARRAY_NAMES:
                check = _check_array_or_number(takes_complex)
            else:
                check = None if takes_complex else _check_real_array
    required = p.default is inspect.Parameter.empty
    if check is None and not (required and not optional):
        return None

    def run(name: str, v) -> None:
        if v is None:
            if optional or not required and check is None:
                return
            raise ArgumentTypeError(f"`{name}` is required, got None")
        if check is not None:
            check(name, v)

    return run


def _argument_checks(f, takes_complex: bool) -> Dict[str, Callable[[str, object], None]]:
    try:
        sig = inspect.signature(f)
    except (TypeError, ValueError):
        return {}
    doc = inspect.getdoc(f) or ""
    checks = {}
    for p in sig.parameters.values():
        if p.name in ("self", "cls") or p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
            continue
        c = _param_check(p, doc, getattr(f, "__globals__", {}), takes_complex)
        if c is not None:
            checks[p.name] = c
    return checks


# pyo3's errors for a native object borrowed by a call running on another thread.
_BORROWED = ("Already borrowed", "Already mutably borrowed")


def _translating(f, check_arguments: bool = True, takes_complex: bool = False):
    """``f`` with its arguments' kinds checked before the call (see the module's docstring)
    and an argument's conversion error raised during the call re-raised as the package's
    error (:func:`_translated`)."""
    checks = _argument_checks(f, takes_complex) if check_arguments else {}
    # Positional names in order, to match arguments without inspect's (slower) binding; only
    # the arguments given are checked (defaults are valid).
    positional = [p.name for p in inspect.signature(f).parameters.values()
                  if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)] if checks else []

    @functools.wraps(f)
    def call(*args, **kwargs):
        if checks:
            for name, v in zip(positional, args):
                c = checks.get(name)
                if c is not None:
                    c(name, v)
            for name, v in kwargs.items():
                c = checks.get(name)
                if c is not None:
                    c(name, v)
        try:
            return f(*args, **kwargs)
        except (OverflowError, TypeError) as e:
            err = _translated(e)
            if err is None:
                raise
            raise err from e
        except RuntimeError as e:
            if str(e) not in _BORROWED:
                raise
            raise RuntimeError(
                f"{f.__qualname__}: the object is in use by a call from another thread that "
                "changes it; calls on one object cannot overlap when one of them changes it: "
                "give each thread its own object, or guard it with a threading.Lock") from e

    call._wscg_ranges = True
    return call


def _translated(e: Exception) -> Optional[Exception]:
    """The package's error for an ``OverflowError`` or ``TypeError`` that a native call
    raised converting an argument (an :class:`IntegerRangeError`, or an
    :class:`ArgumentTypeError` naming the argument pyo3 noted as "while processing 'name'"),
    or None when ``e`` is to be raised as it is (already the package's, or not about an
    argument's conversion)."""
    if isinstance(e, (IntegerRangeError, ArgumentTypeError)):
        return None
    if isinstance(e, OverflowError):
        return _range_error(e)
    names = [m.group(1) for n in getattr(e, "__notes__", ()) for m in [_PROCESSING.match(str(n))]
             if m]
    return ArgumentTypeError(f"`{names[-1]}`: {e}") if names else None


def integer_ranges(namespace: dict) -> None:
    """Makes the public functions of a module, and the methods of the classes it defines,
    raise :class:`IntegerRangeError` (a ``ValueError`` naming the argument) instead of the
    ``OverflowError`` that a negative or too large integer raises on its way into a native
    parameter. Functions: the names in the module's ``__all__`` defined in that module;
    classes: every class the module defines (private base classes hold public methods); the
    native functions in ``__all__`` also raise :class:`ArgumentTypeError` naming the argument
    for a value of the wrong type (see :func:`_translated`)."""
    module = namespace["__name__"]
    # A module whose arrays are complex throughout (k-space, MR images) says so.
    cx = bool(namespace.get("_TAKES_COMPLEX", False))
    for name, obj in list(namespace.items()):
        if getattr(obj, "__module__", None) != module:
            continue
        if isinstance(obj, type):
            # Result classes are built by the package from checked values; estimators take
            # any hyper-parameter in __init__ and validate in fit, as scikit-learn's protocol
            # (and its check_estimator) asks.
            checked = not dataclasses.is_dataclass(obj) and not hasattr(obj, "get_params")
            for attr, v in list(vars(obj).items()):
                if isinstance(v, (staticmethod, classmethod)) and inspect.isbuiltin(v.__func__):
                    continue  # a native function (py/src): it checks its own arguments
                if isinstance(v, (staticmethod, classmethod)):
                    setattr(obj, attr, type(v)(_translating(v.__func__, checked, cx)))
                elif inspect.isfunction(v) and (not attr.startswith("_") or attr in ("__init__", "__call__")):
                    setattr(obj, attr, _translating(v, checked, cx))
        elif inspect.isfunction(obj) and name in namespace["__all__"]:
            namespace[name] = _translating(obj, True, cx)
    # The native functions a module re-exports (defined in wscg._native).
    for name in namespace["__all__"]:
        obj = namespace.get(name)
        if inspect.isbuiltin(obj) and (getattr(obj, "__module__", None) or "").startswith(
                "wscg._native"):
            # pyo3's TypeError for an argument it cannot convert names the argument only in
            # an exception note ("while processing 'name'"; Python 3.9 and 3.10 have no
            # notes, and there the message cannot name it): re-raised as the package's
            # ArgumentTypeError with the name in the message, an OverflowError as
            # IntegerRangeError. A call with missing or unknown arguments stays a TypeError.
            wrapped = _translating(obj, check_arguments=False)
            # Pickled by reference under the module that exports it (Dask, multiprocessing).
            wrapped.__module__ = namespace["__name__"]
            namespace[name] = wrapped
