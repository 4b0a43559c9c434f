"""Compiling a module's pure functions with numba for the compiled-equals-Python tests."""

from __future__ import annotations

import math
import struct
from typing import Any, Callable

import pytest

_REGISTERED: set[Callable] = set()  # helpers already registered with numba (once each)


def compiled(fn: Callable, *helpers: Callable) -> Any:
    """``fn`` compiled by numba (``helpers``, the pure functions it calls, registered as numba
    compiles them into a kernel); the test is skipped when numba is not importable."""
    try:
        import numba
        from numba.extending import register_jitable
    except ImportError:
        pytest.skip("numba is not importable: the compiled form cannot be compared")
    for g in helpers:
        if g not in _REGISTERED:
            register_jitable(g)
            _REGISTERED.add(g)
    return numba.njit(fn)


def same_bits(a: Any, b: Any) -> bool:
    """``a`` and ``b`` (floats, ints, or tuples of them) bit for bit (any NaN equals any NaN;
    0.0 and -0.0 differ)."""
    if isinstance(a, tuple) or isinstance(b, tuple):
        return len(a) == len(b) and all(same_bits(x, y) for x, y in zip(a, b))
    if isinstance(a, float) or isinstance(b, float):
        a, b = float(a), float(b)
        return (math.isnan(a) and math.isnan(b)) or struct.pack("<d", a) == struct.pack("<d", b)
    return a == b and type(a) is type(b)
