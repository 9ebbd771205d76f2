"""The result classes' shared behaviour (py/API.md, section Results).

A function that returns several values returns a documented result class instead of a
``dict``. :func:`result` makes a class a frozen dataclass with a short ``repr`` (arrays shown
as ``array(shape=..., dtype=...)``, never dumped), equality that compares arrays element-wise,
and pickling; :func:`tuple_repr` gives a ``typing.NamedTuple`` the same ``repr`` where the
result is naturally a tuple that users unpack (a NamedTuple takes no mixin base on Python
3.9, so the class assigns ``__repr__ = tuple_repr`` in its body, and ``__eq__ = tuple_eq``,
``__ne__ = tuple_ne`` when it holds arrays).
"""

from __future__ import annotations

import dataclasses
import sys
import textwrap
from typing import Any, Callable, Dict, Iterable, Optional, Tuple, TypeVar

import numpy as np

__all__ = ["result", "tuple_repr", "tuple_eq", "tuple_ne", "from_mapping", "summary"]

T = TypeVar("T")

if sys.version_info >= (3, 11):
    from typing import dataclass_transform
else:  # the marker only informs type checkers
    def dataclass_transform(**_kwargs: Any) -> Callable[[T], T]:
        return lambda f: f

# Containers longer than this are shown by their length, not their items.
_MAX_ITEMS = 6
# A repr longer than this puts one field per line.
_WIDTH = 88


def summary(v: Any) -> str:
    """A bounded description of ``v`` for a result's ``repr`` (one line, but for a nested
    result too long for one)."""
    if type(v).__repr__ in (_dataclass_repr, tuple_repr):
        return repr(v)
    if isinstance(v, np.ndarray):
        if v.ndim == 0:
            return summary(v.item())
        return f"array(shape={v.shape}, dtype={v.dtype})"
    if isinstance(v, (bool, np.bool_)):
        return repr(bool(v))
    if isinstance(v, (float, np.floating)):
        return f"{float(v):.6g}"
    if isinstance(v, (int, np.integer)):
        return repr(int(v))
    if isinstance(v, (list, tuple)):
        return _sequence(v)
    if isinstance(v, dict):
        keys = list(v)
        shown = ", ".join(repr(k) for k in keys[:_MAX_ITEMS])
        if len(keys) > _MAX_ITEMS:
            shown += ", ..."
        if len(keys) <= _MAX_ITEMS and all(_scalar(x) for x in v.values()):
            return "{" + ", ".join(f"{k!r}: {summary(x)}" for k, x in v.items()) + "}"
        return f"dict(len={len(keys)}, keys=[{shown}])"
    text = repr(v)
    return text if len(text) <= 80 else text[:77] + "..."


def _scalar(v: Any) -> bool:
    return v is None or isinstance(v, (str, bool, int, float, np.generic))


def _sequence(v) -> str:
    open_, close = ("(", ")") if isinstance(v, tuple) else ("[", "]")
    n = len(v)
    if n and all(isinstance(x, np.ndarray) for x in v):
        shapes = {(x.shape, x.dtype) for x in v}
        if len(shapes) == 1:
            return f"{open_}{n} x {summary(v[0])}{close}"
    if n <= _MAX_ITEMS:
        inner = ", ".join(summary(x) for x in v)
        if n == 1 and open_ == "(":
            inner += ","
        return f"{open_}{inner}{close}"
    kind = "tuple" if open_ == "(" else "list"
    return f"{kind}(len={n})"


def _fields_repr(name: str, items: Iterable[Tuple[str, Any]]) -> str:
    """``name(field=..., ...)`` on one line when it fits in ``_WIDTH`` characters, else one
    field per line."""
    parts = [f"{k}={summary(v)}" for k, v in items]
    one = f"{name}(" + ", ".join(parts) + ")"
    if len(one) <= _WIDTH and "\n" not in one:
        return one
    return f"{name}(\n" + "".join(textwrap.indent(p, "    ") + ",\n" for p in parts) + ")"


def _equal(a: Any, b: Any) -> bool:
    """Equality that compares arrays element-wise (NaN equal to NaN) and recurses into
    containers and results."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        if a.shape != b.shape:
            return False
        try:
            return bool(np.array_equal(a, b, equal_nan=True))
        except TypeError:  # object or string arrays
            return bool(np.array_equal(a, b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_equal(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return (type(a) is type(b) and len(a) == len(b)
                and all(_equal(x, y) for x, y in zip(a, b)))
    if isinstance(a, float) and isinstance(b, float) and a != a and b != b:
        return True
    return bool(a == b)


def _dataclass_repr(self) -> str:
    return _fields_repr(type(self).__name__,
                        ((f.name, getattr(self, f.name)) for f in dataclasses.fields(self)
                         if f.repr))


def _dataclass_eq(self, other) -> bool:
    if type(other) is not type(self):
        return NotImplemented
    return all(_equal(getattr(self, f.name), getattr(other, f.name))
               for f in dataclasses.fields(self))


@dataclass_transform(frozen_default=True, eq_default=False)
def result(cls: type) -> type:
    """Class decorator of the result classes: a frozen dataclass (fields in annotation
    order, set once by the constructor) whose ``repr`` summarises arrays and long
    containers, whose ``==`` compares arrays element-wise, and which is not hashable
    (its fields hold arrays)."""
    cls = dataclasses.dataclass(frozen=True, repr=False, eq=False)(cls)
    cls.__repr__ = _dataclass_repr
    cls.__eq__ = _dataclass_eq
    cls.__hash__ = None
    return cls


def tuple_repr(self) -> str:
    """``__repr__`` of a ``typing.NamedTuple`` result (assigned in the class body)."""
    return _fields_repr(type(self).__name__, zip(self._fields, self))


def tuple_eq(self, other) -> bool:
    """``__eq__`` of a ``typing.NamedTuple`` result that holds arrays (assigned in the class
    body; the class is then not hashable): element-wise as :func:`result`'s."""
    if not isinstance(other, tuple):
        return NotImplemented
    return len(self) == len(other) and all(_equal(a, b) for a, b in zip(self, other))


def tuple_ne(self, other) -> bool:
    """``__ne__`` to go with :func:`tuple_eq` (a tuple's own would compare the arrays)."""
    eq = tuple_eq(self, other)
    return eq if eq is NotImplemented else not eq


def from_mapping(cls: Callable[..., T], d: dict, rename: Optional[Dict[str, str]] = None,
                 **extra: Any) -> T:
    """``cls`` built from the dict ``d`` that the native module returns: every key becomes
    the field of its name (or of ``rename[key]``), ``extra`` adds or replaces fields. An
    unknown key raises ``TypeError``, so the class and the native side cannot drift."""
    rename = rename or {}
    kw = {rename.get(k, k): v for k, v in d.items()}
    kw.update(extra)
    return cls(**kw)
