"""Argument checks shared by the Python modules: each raises ``ValueError`` naming the
argument, before the value reaches Rust."""

from __future__ import annotations

import numbers
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
