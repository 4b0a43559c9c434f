"""Numba's on-disk cache, tied to every source a compiled kernel holds.

Numba checks a cached kernel only against the file that defines it. A kernel that compiles
functions of other modules into itself (the co-simulation loop holds the ground station's step,
the lumped line holds the wind profile) would then run stale code after an edit of those
modules. :func:`follow_sources` adds their modification times and sizes to the cache's stamp,
so an edit of any of them compiles the kernel anew. Where numba's cache object does not look as
expected (another numba version), nothing changes.
"""

from __future__ import annotations

import os
from types import ModuleType
from typing import Any, Iterable


def follow_sources(kern: Any, modules: Iterable[ModuleType]) -> None:
    """Tie the on-disk cache of the numba dispatcher ``kern`` also to the files of ``modules``."""
    cache_file = getattr(getattr(kern, "_cache", None), "_cache_file", None)
    stamp = getattr(cache_file, "_source_stamp", None)
    if stamp is None:
        return
    deps = tuple((st.st_mtime, st.st_size) for st in (os.stat(m.__file__) for m in modules))
    cache_file._source_stamp = (stamp, deps)


def compile_cached(fn: Any, signature: Any, helpers: Iterable[Any], sources: Iterable[ModuleType], what: str) -> Any:
    """``fn`` compiled by numba for its one ``signature`` (a callable of the ``numba`` module
    returning the signature), cached on disk and tied to ``sources`` (:func:`follow_sources`),
    with ``helpers`` (plain functions it calls) compiled into it. Returns the dispatcher, or None
    after one :class:`RuntimeWarning` naming ``what`` when numba fails (a broken numba install
    must not stop a simulation: the caller runs the Python function instead)."""
    import warnings

    try:
        import numba
        from numba.extending import register_jitable

        for g in helpers:
            register_jitable(g)
        kern = numba.njit(cache=True)(fn)
        follow_sources(kern, sources)
        kern.compile(signature(numba))  # its one signature, compiled or loaded from the cache here
        kern.disable_compile()
        return kern
    except Exception as exc:
        warnings.warn(f"{what}: numba failed ({exc}); the Python code runs instead", RuntimeWarning, stacklevel=3)
        return None
