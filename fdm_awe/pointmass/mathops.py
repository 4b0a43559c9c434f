"""Backend-neutral math: the same model code evaluates on floats/NumPy arrays and on CasADi
symbols.

Each function looks at its argument's type: CasADi objects (SX, MX, DM) go to ``casadi``,
everything else to ``numpy``. CasADi is imported only when a CasADi object is seen, so
NumPy-only users never pay its import time.
"""

from __future__ import annotations

from typing import Any

import numpy as np


def _is_casadi(*xs: Any) -> bool:
    return any(type(x).__module__.startswith("casadi") for x in xs)


def _ca():  # lazy import
    import casadi

    return casadi


def sin(x: Any) -> Any:
    return _ca().sin(x) if _is_casadi(x) else np.sin(x)


def cos(x: Any) -> Any:
    return _ca().cos(x) if _is_casadi(x) else np.cos(x)


def tan(x: Any) -> Any:
    return _ca().tan(x) if _is_casadi(x) else np.tan(x)


def sqrt(x: Any) -> Any:
    return _ca().sqrt(x) if _is_casadi(x) else np.sqrt(x)


def log(x: Any) -> Any:
    """Natural logarithm."""
    return _ca().log(x) if _is_casadi(x) else np.log(x)


def atan2(y: Any, x: Any) -> Any:
    return _ca().atan2(y, x) if _is_casadi(y, x) else np.arctan2(y, x)


def fmax(a: Any, b: Any) -> Any:
    return _ca().fmax(a, b) if _is_casadi(a, b) else np.maximum(a, b)


def fmin(a: Any, b: Any) -> Any:
    return _ca().fmin(a, b) if _is_casadi(a, b) else np.minimum(a, b)


def stack(items: list[Any]) -> Any:
    """Column of expressions: ``casadi.vertcat`` for symbols, ``numpy.array`` otherwise."""
    if _is_casadi(*items):
        return _ca().vertcat(*items)
    return np.array(items, dtype=float) if all(np.ndim(i) == 0 for i in items) else np.stack(np.broadcast_arrays(*items))
