"""Parameters over MAVLink: the wire's float32 values of the autopilot's
:class:`~fdm_awe.autopilot.params.ParamStore` (defined by the autopilot).

On the wire a parameter is ``MAV_PARAM_TYPE_INT32`` (whole-number and on/off parameters) or
``REAL32``, its value always carried as a float (ArduPilot's encoding: no byte-wise int).

Values as set: MAVLink carries a parameter as a 32-bit float, so a ground station's
``PARAM_SET`` of 1.1 arrives as 1.100000023841858. :func:`from_wire` turns a received float32
back into the shortest decimal that rounds to it (1.1), the number the operator typed; the store
keeps that (a Python float) and the wire gets ``float32(value)`` again, which is exactly what was
received. :func:`param_text` prints a value the same way (float32's shortest repr).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["from_wire", "param_text"]


def from_wire(value: float) -> float:
    """The value a ground station set, from the float32 it sent: the shortest decimal that
    float32 rounds to ``value`` (``from_wire(float32(1.1)) == 1.1``); non-finite values pass."""
    v = float(value)
    if not math.isfinite(v) or abs(v) > float(np.finfo(np.float32).max):
        return v
    return float(str(np.float32(v)))


def param_text(value: float) -> str:
    """A parameter value as text, rounded to float32's shortest repr (what the wire can carry):
    ``param_text(1.1) == "1.1"``, ``param_text(3.0) == "3"``."""
    v = float(value)
    if not math.isfinite(v) or abs(v) > float(np.finfo(np.float32).max):
        return repr(v)
    t = str(np.float32(v))
    return t[:-2] if t.endswith(".0") else t
