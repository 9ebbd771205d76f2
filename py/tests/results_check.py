"""The checks every result class of py/API.md (section Results) passes, shared by the module
tests: its type, a short readable ``repr`` that summarises arrays instead of dumping them,
immutability, and a pickle round trip that gives an equal result."""

from __future__ import annotations

import dataclasses
import pickle

import numpy as np
import pytest


def check_result(r, cls, max_repr: int = 4000):
    """Asserts that ``r`` is a well-behaved ``cls`` and returns its ``repr``."""
    assert type(r) is cls, f"expected {cls.__name__}, got {type(r).__name__}"
    assert cls.__doc__ and "Attributes" in cls.__doc__
    names = cls._fields if hasattr(cls, "_fields") else [f.name for f in dataclasses.fields(cls)]
    text = repr(r)
    assert text.startswith(f"{cls.__name__}("), text[:200]
    for name in names:
        assert f"{name}=" in text, f"{cls.__name__}'s repr lacks {name}"
    # Arrays are summarised, never printed: numpy's dump would show "array([" and, for
    # large arrays, its "..." ellipsis.
    assert "array([" not in text and "\n       [" not in text, text
    assert len(text) <= max_repr, f"repr of {len(text)} characters"
    if any(isinstance(getattr(r, n), np.ndarray) and getattr(r, n).ndim for n in names):
        assert "array(shape=" in text
    # Immutable: a field cannot be reassigned.
    with pytest.raises(AttributeError):
        setattr(r, names[0], None)
    back = pickle.loads(pickle.dumps(r))
    assert type(back) is cls and back == r
    return text
