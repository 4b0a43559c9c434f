"""Named slots of the compiled core's arrays: each block's layout declared once.

The compiled core (the ground station's step, the co-simulation kernel, the autopilot's AUTO
step) keeps its state, constants, parameters and outputs in float64 arrays, the one array type
numba compiles fast. A block's layout is declared here once, as a field list::

    MEM = declare("AutoMemory", ("sref", "t_last", "err", ("rj_dp", 3)))

:func:`declare` returns a named tuple whose fields are the offsets (``MEM.sref == 0``,
``MEM.rj_dp == 3`` the first of three slots); :func:`size` is the array's length, :func:`new`
makes one, :func:`check` checks one, :func:`names` lists the slot names (a field of width ``k``
gives ``name[0]`` .. ``name[k-1]``) and :func:`as_dict` reads an array by name.

Compiled code reads ``mem[MEM.sref]``: numba freezes a global named tuple of integers into
constants, so the read compiles to the same load as ``mem[0]`` (no cost; a test compares the
compiled code of both). In plain Python a named read costs a global and an attribute lookup
more than a number; a Python-only hot path reads several slots in one call of a
:func:`reader` (``operator.itemgetter`` of their offsets, made once), faster than reading them
one by one. ``start`` lets a block continue another in the same array (the
station's ledger terms follow its states).
"""

from __future__ import annotations

from collections import namedtuple
from operator import itemgetter
from typing import Any, Callable, Iterable, NamedTuple, Union

import numpy as np

#: one field: a name (one slot) or ``(name, width)`` (``width`` slots from its offset)
Field = Union[str, tuple[str, int]]


def declare(name: str, fields: Iterable[Field], start: int = 0) -> Any:
    """The layout ``name`` (a named tuple of offsets, ints): the fields in order from ``start``.

    Field names must be valid identifiers, unique, widths >= 1; raises ``ValueError`` else."""
    names: list[str] = []
    offsets: list[int] = []
    widths: list[int] = []
    at = int(start)
    if at < 0:
        raise ValueError(f"layout {name}: start must be >= 0, got {start}")
    for f in fields:
        key, width = (f, 1) if isinstance(f, str) else (str(f[0]), int(f[1]))
        if not key.isidentifier() or key.startswith("_"):
            raise ValueError(f"layout {name}: field {key!r} is not a public identifier")
        if key in names:
            raise ValueError(f"layout {name}: field {key!r} twice")
        if width < 1:
            raise ValueError(f"layout {name}: field {key!r} has width {width} (allowed: >= 1)")
        names.append(key)
        offsets.append(at)
        widths.append(width)
        at += width
    base = namedtuple(name, names)  # type: ignore[misc]
    cls = type(name, (base,), {"__slots__": (), "_start": int(start), "_end": at, "_widths": tuple(widths)})
    return cls(*offsets)


def _shape(layout: NamedTuple) -> tuple[int, int, tuple[int, ...]]:
    try:
        return layout._start, layout._end, layout._widths  # type: ignore[attr-defined]
    except AttributeError:
        raise TypeError(f"{type(layout).__name__} was not made by slots.declare") from None


def size(layout: NamedTuple) -> int:
    """The end offset of ``layout``: the length of an array that holds it (from offset 0)."""
    return _shape(layout)[1]


def start(layout: NamedTuple) -> int:
    """The first offset of ``layout`` (0 unless it continues another block)."""
    return _shape(layout)[0]


def width(layout: NamedTuple, field: str) -> int:
    """How many slots ``field`` of ``layout`` takes."""
    return _shape(layout)[2][layout._fields.index(field)]


def names(layout: NamedTuple) -> tuple[str, ...]:
    """Every slot's name, in order (``name[i]`` for a field of width above 1)."""
    out: list[str] = []
    for key, w in zip(layout._fields, _shape(layout)[2]):
        out.extend([key] if w == 1 else [f"{key}[{i}]" for i in range(w)])
    return tuple(out)


def reader(layout: NamedTuple, *fields: str) -> Callable[[Any], tuple]:
    """A function that reads ``fields`` (names of one-slot fields of ``layout``) from an array or
    list in one call and returns their values as a tuple (Python paths only; numba does not
    compile it). Raises ``ValueError`` for an unknown or wider field."""
    if len(fields) < 2:
        raise ValueError(f"{type(layout).__name__}: a reader reads at least two fields")
    at = []
    for f in fields:
        if f not in layout._fields:
            raise ValueError(f"{type(layout).__name__}: no field {f!r}")
        if width(layout, f) != 1:
            raise ValueError(f"{type(layout).__name__}: field {f!r} has {width(layout, f)} slots")
        at.append(getattr(layout, f))
    return itemgetter(*at)


def new(layout: NamedTuple, fill: float = 0.0, dtype: Any = np.float64) -> np.ndarray:
    """An array of :func:`size` ``(layout)`` slots, every one ``fill`` (float64, or ``dtype``:
    e.g. ``np.int64`` for a block of handles)."""
    return np.full(size(layout), fill, dtype=dtype)


def check(layout: NamedTuple, array: np.ndarray, what: str) -> np.ndarray:
    """``array`` if it is a 1-D float64 array of :func:`size` ``(layout)`` slots; raises
    ``ValueError`` naming ``what`` else."""
    a = np.asarray(array)
    if a.ndim != 1 or a.shape[0] != size(layout) or a.dtype != np.float64:
        raise ValueError(f"{what}: expected {size(layout)} float64 slots of {type(layout).__name__}, "
                         f"got shape {a.shape} dtype {a.dtype}")
    return a


def as_dict(layout: NamedTuple, array: np.ndarray) -> dict[str, Any]:
    """``array`` read by field: a float per one-slot field, an array per wider field."""
    out: dict[str, Any] = {}
    for key, at, w in zip(layout._fields, layout, _shape(layout)[2]):
        out[key] = float(array[at]) if w == 1 else np.array(array[at:at + w])
    return out
