"""Argument checks shared by the Python modules: each raises ``ValueError`` naming the
argument, before the value reaches Rust; and :func:`integer_ranges`, which turns the
``OverflowError`` of an out-of-range integer reaching a native parameter into one."""

from __future__ import annotations

import functools
import inspect
import numbers
import re
from typing import Optional

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


def _real(name: str, v) -> float:
    """``v`` as a Python float (bools refused)."""
    if isinstance(v, (bool, np.bool_)):
        raise ValueError(f"`{name}` must be a real number, got {v!r}")
    try:
        return float(v)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be a real number, got {v!r}") from None


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


def _translating(f):
    """``f`` with an ``OverflowError`` raised during the call re-raised as
    :class:`IntegerRangeError`."""

    @functools.wraps(f)
    def call(*args, **kwargs):
        try:
            return f(*args, **kwargs)
        except IntegerRangeError:
            raise
        except OverflowError as e:
            raise _range_error(e) from e

    call._wscg_ranges = True
    return call


def integer_ranges(namespace: dict) -> None:
    """Makes the public functions of a module, and the methods of the classes it defines,
    raise :class:`IntegerRangeError` (a ``ValueError`` naming the argument) instead of the
    ``OverflowError`` that a negative or too large integer raises on its way into a native
    parameter. Functions: the names in the module's ``__all__`` defined in that module;
    classes: every class the module defines (private base classes hold public methods)."""
    module = namespace["__name__"]
    for name, obj in list(namespace.items()):
        if getattr(obj, "__module__", None) != module:
            continue
        if isinstance(obj, type):
            for attr, v in list(vars(obj).items()):
                if isinstance(v, (staticmethod, classmethod)):
                    setattr(obj, attr, type(v)(_translating(v.__func__)))
                elif inspect.isfunction(v) and (not attr.startswith("_") or attr in ("__init__", "__call__")):
                    setattr(obj, attr, _translating(v))
        elif inspect.isfunction(obj) and name in namespace["__all__"]:
            namespace[name] = _translating(obj)
