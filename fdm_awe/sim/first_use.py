"""Compile the flight's kernels, or fly on the Python path: the choice of ``fdm-awe fly --compiled``.

A flight's compiled loop (:mod:`fdm_awe.sim.kernel`, :mod:`fdm_awe.sim.autopilot_kernel`) runs
the same functions as its Python loop, bit for bit, only faster. Numba keeps the compiled kernels
on disk; a fresh install (or an edit of their sources) has none, and compiling them costs about
:data:`COMPILE_S` seconds, while a short flight on the straight line takes about a second as
Python (JSBSim's own step is most of a flight's time either way). So a first flight that waits
for the compiler waits for nothing it needs.

``auto`` (the default): the kernels load from the cache when it holds them; otherwise the flight
compiles them only when that pays, i.e. when its estimated Python time, the simulated time times
the line's :attr:`~fdm_awe.groundstation.linemodels.LineKind.python_cost`, exceeds the compiled
flight's by more than :data:`COMPILE_S`; else it flies on the Python path and says so on the
standard error, with the way to compile once (``--compiled yes``). ``yes`` compiles (or loads)
whatever the flight; ``no`` flies on the Python path.
"""

from __future__ import annotations

import contextlib
import sys
from dataclasses import dataclass
from typing import Any, Iterator

from ..errors import InputError
from ..jitcache import jit_off, python_path

#: the policies of ``--compiled``
POLICIES = ("auto", "yes", "no")
#: seconds numba takes to compile both flight kernels in one process, on a quiet 2-core machine
#: (measured: the first ``fdm-awe fly --cycles 1 --compiled yes`` of a fresh cache, 19 s the
#: co-simulation kernel and 15 s the autopilot's, which reuses the first's functions)
COMPILE_S = 34.0
#: wall seconds a compiled flight takes per simulated second on the same machine (JSBSim's step
#: and the Python bookkeeping per block; the line's step is then a small part)
COMPILED_COST = 0.025


@dataclass(frozen=True)
class LoopChoice:
    """The loop a flight runs: ``compiled`` (True: numba's kernels, loaded or compiled now),
    ``why`` (the reason of the Python path, kept in the report's ``loop.reason``) and ``say``
    (said on the standard error: ``auto`` chose the Python path)."""

    compiled: bool
    why: str = ""
    say: bool = False


def kernels_cached() -> bool | None:
    """Whether both flight kernels would load from numba's on-disk cache (None: compiled code does
    not run here, :func:`fdm_awe.jitcache.jit_off`). Nothing compiles."""
    if jit_off() is not None:
        return None
    from . import autopilot_kernel, kernel  # imports numba (about 1 s): only when compiled code may run

    return bool(kernel.kernel_cached()) and bool(autopilot_kernel.kernel_cached())


def python_seconds(tether: Any, simulated_s: float) -> float:
    """Estimated wall time [s] of ``simulated_s`` seconds of flight on the Python path on line
    ``tether`` (a :class:`~fdm_awe.groundstation.linemodels.TetherModel`)."""
    return simulated_s * tether.kind.python_cost(tether.param)


def choose(policy: str, tether: Any, simulated_s: float, cached: bool | None = None) -> LoopChoice:
    """The loop of a flight of ``simulated_s`` seconds on line ``tether`` under ``policy`` (one of
    :data:`POLICIES`); ``cached``: whether the kernels are cached (None: asked,
    :func:`kernels_cached`)."""
    if policy not in POLICIES:
        raise InputError(f"--compiled: {policy!r} is not a policy (allowed: {', '.join(POLICIES)})")
    if policy == "no":
        return LoopChoice(False, "--compiled no")
    off = jit_off()
    if off is not None:
        return LoopChoice(False, off)
    if policy == "yes":
        return LoopChoice(True)
    if cached is None:
        cached = kernels_cached()
    if cached:
        return LoopChoice(True)
    py = python_seconds(tether, simulated_s)
    saved = py - simulated_s * COMPILED_COST
    if saved > COMPILE_S:
        return LoopChoice(True)
    return LoopChoice(False, f"no compiled kernels cached yet; this flight takes about {py:.0f} s as Python, "
                             f"compiling them about {COMPILE_S:.0f} s", say=True)


#: what the standard error says when a flight of a fresh install flies on the Python path
PYTHON_MESSAGE = ("fdm-awe: flying on the Python path ({why}); `fdm-awe fly --compiled yes` compiles the kernels "
                  "once, for long flights")


@contextlib.contextmanager
def flight_loop(choice: LoopChoice, stream: Any = None) -> Iterator[None]:
    """The block a flight runs in under ``choice``: on the Python path (said on ``stream``, None:
    the standard error, where ``choice.say``) or as it is."""
    if choice.compiled:
        yield
        return
    if choice.say:
        print(PYTHON_MESSAGE.format(why=choice.why), file=stream if stream is not None else sys.stderr, flush=True)
    with python_path(choice.why):
        yield


__all__ = ["COMPILE_S", "COMPILED_COST", "LoopChoice", "POLICIES", "choose", "flight_loop", "kernels_cached",
           "python_seconds"]
