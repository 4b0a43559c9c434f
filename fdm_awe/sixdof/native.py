"""Direct calls into the JSBSim library behind the Python bindings, for compiled step loops.

The co-simulation's hot path (set the tether force, ``FGFDMExec::Run()``, read the state's
properties) costs about as much in Python call overhead as JSBSim's own step. This module finds
the C++ objects behind the bindings' Python objects so that a numba-compiled loop
(:mod:`fdm_awe.sim.kernel`) can make the same calls without Python in between:

- ``JSBSim::FGFDMExec::Run()``, ``SGPropertyNode::getDoubleValue() const`` and
  ``SGPropertyNode::setDoubleValue(double)``: their addresses from the bindings' shared
  library (exported symbols, Itanium C++ ABI: a non-virtual member function is called like a C
  function with the object pointer as first argument);
- the ``FGFDMExec*`` and ``SGPropertyNode*`` that the bindings' ``FGFDMExec`` and
  ``FGPropertyNode`` objects hold (Cython extension types: the pointers follow the object
  header).

Nothing is trusted without checks. Object layout: the ``FGFDMExec`` object holds its pointer
twice (base and derived class fields, adjacent and equal); ``FGPropertyNode`` objects share a
method-table word and hold distinct node pointers (the same node fetched twice gives the same
pointer). Behaviour: every node read through the library call must return exactly what the
bindings return, a write must read back through the bindings, and the simulation time read
through ``FGFDMExec::GetSimTime()`` must equal the bindings'. Anything unexpected (another
platform, another JSBSim layout, a missing symbol) gives ``None`` with the reason, and the caller
keeps the Python path. ``FDM_AWE_JIT=0`` disables it, as it does the ground station's compiled
step.

Its interface is two functions: :func:`native_jsbsim` (the checked handles of one JSBSim
instance) and :func:`native_calls` (the compiled calls that use them). The intrinsics call a
function by address (an ``int``, passed at run time): compiled
functions that use them can be cached on disk, since no address is baked into the code.
"""

from __future__ import annotations

import ctypes
import functools
import math
import sys
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from ..jitcache import jit_off

# exported symbols of the bindings' library (Itanium C++ ABI mangling)
_SYM_RUN = "_ZN6JSBSim9FGFDMExec3RunEv"  # bool JSBSim::FGFDMExec::Run()
_SYM_SIMTIME = "_ZNK6JSBSim9FGFDMExec10GetSimTimeEv"  # double JSBSim::FGFDMExec::GetSimTime() const
_SYM_GET = "_ZNK14SGPropertyNode14getDoubleValueEv"  # double SGPropertyNode::getDoubleValue() const
_SYM_SET = "_ZN14SGPropertyNode14setDoubleValueEd"  # bool SGPropertyNode::setDoubleValue(double)

_WORD = ctypes.sizeof(ctypes.c_void_p)


@dataclass(frozen=True)
class NativeJSBSim:
    """Addresses for compiled calls into one JSBSim instance.

    ``calls`` = (Run, getDoubleValue, setDoubleValue, FGFDMExec*) and ``getters`` (node pointers,
    0 for a constant 0.0), ``setters`` (node pointers) as int64 arrays, in the orders the caller
    asked for.
    """

    calls: np.ndarray
    getters: np.ndarray
    setters: np.ndarray


def _word(obj: Any, i: int) -> int:
    """The i-th pointer-size word of a Python object's memory (0, 1: the object header)."""
    return ctypes.c_size_t.from_address(id(obj) + _WORD * i).value


def _supported_platform() -> str | None:
    why = jit_off()
    if why:
        return why
    if sys.platform == "win32" or _WORD != 8:
        return f"platform {sys.platform} ({8 * _WORD}-bit) not supported"
    return None


@functools.lru_cache(maxsize=None)
def _library(path: str) -> tuple[int, int, int, int] | str:
    """Addresses of Run, GetSimTime, getDoubleValue, setDoubleValue in ``path``, or a reason."""
    try:
        lib = ctypes.CDLL(path)
        return tuple(ctypes.cast(getattr(lib, s), ctypes.c_void_p).value  # type: ignore[return-value]
                     for s in (_SYM_RUN, _SYM_SIMTIME, _SYM_GET, _SYM_SET))
    except (OSError, AttributeError) as exc:
        return f"JSBSim library symbols not found ({exc})"


def _fdm_pointer(fdm: Any) -> int | str:
    """``FGFDMExec*`` held by the bindings' object: two equal adjacent words after the header."""
    words = [_word(fdm, i) for i in range(2, 6)]
    for a, b in zip(words, words[1:]):
        if a == b and a > 0x10000:
            return a
    return "FGFDMExec object layout not recognised"


def _node_pointers(pm: Any, paths: Sequence[str]) -> list[int] | str:
    """``SGPropertyNode*`` of each path (the word after the shared method table)."""
    nodes = [pm.get_node(p, False) for p in paths]
    if any(n is None for n in nodes) or len(nodes) < 2:
        return "property node missing"
    again = pm.get_node(paths[0], False)
    for i in (2, 3, 4):
        tab = {_word(n, i) for n in nodes}
        ptrs = [_word(n, i + 1) for n in nodes]
        if (len(tab) == 1 and len(set(ptrs)) == len(set(paths)) and min(ptrs) > 0x10000
                and _word(again, i + 1) == ptrs[0] and _word(again, i) in tab):
            return ptrs
    return "FGPropertyNode object layout not recognised"


def native_jsbsim(fdm: Any, getters: Sequence[str | None], setters: Sequence[str]) -> tuple[NativeJSBSim | None, str]:
    """Native handles for ``fdm`` (a ``jsbsim.FGFDMExec``), reading the properties ``getters``
    (None: a constant 0.0) and writing ``setters``; ``(None, reason)`` when not available.
    Every handle is checked against the bindings (see the module docstring) before use."""
    why = _supported_platform()
    if why:
        return None, why
    try:
        import jsbsim
        import jsbsim._jsbsim as ext
    except ImportError as exc:  # pragma: no cover - jsbsim is a dependency
        return None, f"jsbsim not importable ({exc})"
    if type(fdm) is not jsbsim.FGFDMExec:
        return None, f"not a jsbsim.FGFDMExec: {type(fdm).__name__}"
    addrs = _library(ext.__file__)
    if isinstance(addrs, str):
        return None, addrs
    run, simtime, get, set_ = addrs
    fptr = _fdm_pointer(fdm)
    if isinstance(fptr, str):
        return None, fptr
    pm = fdm.get_property_manager()
    named = [p for p in getters if p is not None] + list(setters)
    ptrs = _node_pointers(pm, named)
    if isinstance(ptrs, str):
        return None, ptrs
    by_path = dict(zip(named, ptrs))
    # behaviour checks through the library calls (ctypes: slow, once)
    c_get = ctypes.CFUNCTYPE(ctypes.c_double, ctypes.c_void_p)(get)
    c_set = ctypes.CFUNCTYPE(ctypes.c_bool, ctypes.c_void_p, ctypes.c_double)(set_)
    c_time = ctypes.CFUNCTYPE(ctypes.c_double, ctypes.c_void_p)(simtime)
    if c_time(fptr) != fdm.get_sim_time():
        return None, "FGFDMExec::GetSimTime() differs from the bindings' sim time"
    for path in named:
        a, b = c_get(by_path[path]), pm.get_node(path, False).get_double_value()
        if not (a == b or (math.isnan(a) and math.isnan(b))):
            return None, f"native read of {path} differs from the bindings ({a!r} vs {b!r})"
    for path in setters:
        node = pm.get_node(path, False)
        old = node.get_double_value()
        probe = old + 1.25 if math.isfinite(old) else 1.25
        c_set(by_path[path], probe)
        back = node.get_double_value()
        node.set_double_value(old)
        if back != probe:
            return None, f"native write of {path} did not read back through the bindings"
    h = NativeJSBSim(
        calls=np.array([run, get, set_, fptr], dtype=np.int64),
        getters=np.array([0 if p is None else by_path[p] for p in getters], dtype=np.int64),
        setters=np.array([by_path[p] for p in setters], dtype=np.int64))
    return h, ""


# ---------------------------------------------------------------------------------------- calls
def native_calls() -> tuple[Any, Any, Any]:
    """numba intrinsics ``run(fn, obj) -> bool``, ``get(fn, obj) -> float``,
    ``set(fn, obj, value) -> bool``: calls by address (int64) of ``bool f(void*)``,
    ``double f(void*)`` and ``bool f(void*, double)``."""
    from llvmlite import ir
    from numba import types
    from numba.extending import intrinsic

    i8p = ir.IntType(8).as_pointer()

    def _call(builder, ret, argtys, fn, args):
        fnty = ir.FunctionType(ret, argtys)
        return builder.call(builder.inttoptr(fn, fnty.as_pointer()), args)

    @intrinsic
    def native_run(typingctx, fn, obj):
        def codegen(context, builder, sig, args):
            r = _call(builder, ir.IntType(8), [i8p], args[0], [builder.inttoptr(args[1], i8p)])
            return builder.icmp_unsigned("!=", r, ir.Constant(ir.IntType(8), 0))
        return types.boolean(types.int64, types.int64), codegen

    @intrinsic
    def native_get(typingctx, fn, obj):
        def codegen(context, builder, sig, args):
            return _call(builder, ir.DoubleType(), [i8p], args[0], [builder.inttoptr(args[1], i8p)])
        return types.float64(types.int64, types.int64), codegen

    @intrinsic
    def native_set(typingctx, fn, obj, value):
        def codegen(context, builder, sig, args):
            r = _call(builder, ir.IntType(8), [i8p, ir.DoubleType()], args[0],
                      [builder.inttoptr(args[1], i8p), args[2]])
            return builder.icmp_unsigned("!=", r, ir.Constant(ir.IntType(8), 0))
        return types.boolean(types.int64, types.int64, types.float64), codegen

    return native_run, native_get, native_set


__all__ = ["NativeJSBSim", "native_calls", "native_jsbsim"]
