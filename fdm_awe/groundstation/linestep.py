"""The compile wrapper the line models share (:mod:`.linemodels`): a line model's station step
has the arguments and returns of :func:`.substeps.station_step`, so one numba signature and one
on-disk cache rule serve them all."""

from __future__ import annotations

from typing import Callable

from ..jitcache import compile_cached
from .substeps import CALLED, compiled_station


def compile_line_step(step: Callable, called: tuple, sources: tuple, name: str) -> Callable | None:
    """A line model's station ``step`` compiled by numba and cached on disk under ``name``, with
    the functions it ``called`` (and the station step's relations, :data:`.substeps.CALLED`) and
    the modules whose code or constants it holds (``sources``);
    None where the station step itself does not compile (numba missing, ``FDM_AWE_JIT=0``, a
    broken install): the Python function runs instead."""
    if compiled_station() is None:
        return None

    def signature(nb):
        f8, b1, a = nb.float64, nb.boolean, nb.float64[::1]
        return (a, a, nb.int64, f8, f8, f8, f8, f8, f8, f8, b1, f8, f8, f8, f8)

    return compile_cached(step, signature, CALLED + tuple(called), sources, name)


__all__ = ["compile_line_step"]
