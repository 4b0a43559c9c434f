"""Compiled code: whether it runs (the ``FDM_AWE_JIT`` switch), compiling it, and numba's
on-disk cache, tied to every source a compiled kernel holds. The one module that decides and
compiles: every other module asks it (:func:`jit_off`) and hands it its functions
(:func:`compile_cached` for a kernel of one signature, :func:`compile_lazy` for a function
compiled for the types of its first call, :func:`register_helpers` for the plain functions a
kernel calls).

The switch: ``FDM_AWE_JIT=0`` in the environment runs every compiled function's one source as
plain Python (numba is then not even imported); without numba the same. It is read at every
question, so a process (or a test) that sets it before building a model gets the Python path.

Numba checks a cached kernel only against the file that defines it. A kernel that compiles
functions of other modules into itself (the co-simulation loop holds the ground station's step,
the lumped line holds the wind profile) would then run stale code after an edit of those
modules. :func:`follow_sources` adds their modification times and sizes to the cache's stamp,
so an edit of any of them compiles the kernel anew. Where numba's cache object does not look as
expected (another numba version), nothing changes.

First use: a fresh install has no cached kernels, and compiling them takes tens of seconds.
:func:`compile_cached` says so on the standard error (:data:`COMPILE_MESSAGE`) when a kernel has
no cached copy, so the first flight does not sit in silence, and :data:`SLOW_MESSAGE` when a
cached one takes longer than :data:`COMPILE_NOTICE_S` (a stale copy compiles anew); a kernel
loaded from the cache in time prints nothing.
"""

from __future__ import annotations

import contextlib
import functools
import importlib.util
import os
import sys
import threading
import time
from types import ModuleType
from typing import Any, Callable, Iterable, Iterator

#: the environment variable of the switch: ``0`` runs the plain Python functions
JIT_SWITCH = "FDM_AWE_JIT"
#: the environment variable that says why the switch is off, set with it by :func:`python_path`
JIT_WHY = "FDM_AWE_PYTHON_WHY"


def jit_off() -> str | None:
    """Why compiled code does not run (``"FDM_AWE_JIT=0"``: the Python path asked for, or the
    reason :func:`python_path` gave; numba not installed), or None when it may. The environment
    is read at every call."""
    if os.environ.get(JIT_SWITCH, "1") == "0":
        return os.environ.get(JIT_WHY) or f"{JIT_SWITCH}=0"
    if importlib.util.find_spec("numba") is None:
        return "numba is not installed"
    return None


@contextlib.contextmanager
def python_path(why: str) -> Iterator[None]:
    """Within the block every compiled function runs as its plain Python source, :func:`jit_off`
    answering ``why`` (the switch and its reason set in the environment and restored after, so
    a model built inside the block takes the Python path; e.g. a short first flight of a fresh
    install, :mod:`fdm_awe.sim.first_use`)."""
    old = {k: os.environ.get(k) for k in (JIT_SWITCH, JIT_WHY)}
    os.environ[JIT_SWITCH], os.environ[JIT_WHY] = "0", why
    try:
        yield
    finally:
        for k, v in old.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def compiled_once(fn: Callable) -> Callable:
    """``functools.lru_cache`` for a function that returns something compiled (a dispatcher, or
    None / the plain function where compiled code does not run): the answer is kept only while
    compiled code may run (:func:`jit_off`), so an answer given on the Python path (inside
    :func:`python_path`) is never served after it."""
    kept = functools.lru_cache(maxsize=None)(fn)

    @functools.wraps(fn)
    def once(*args: Any) -> Any:
        return fn(*args) if jit_off() is not None else kept(*args)

    once.cache_clear = kept.cache_clear  # type: ignore[attr-defined]
    return once


@functools.lru_cache(maxsize=None)
def _register(fn: Callable) -> None:
    from numba.extending import register_jitable

    register_jitable(fn)


def register_helpers(helpers: Iterable[Callable]) -> None:
    """Let numba compile calls of the plain functions ``helpers`` inside compiled functions
    (each registered once; only when compiled code runs, :func:`jit_off`)."""
    if jit_off() is None:
        for g in helpers:
            _register(g)


def follow_sources(kern: Any, modules: Iterable[ModuleType]) -> None:
    """Tie the on-disk cache of the numba dispatcher ``kern`` also to the files of ``modules``."""
    cache_file = getattr(getattr(kern, "_cache", None), "_cache_file", None)
    stamp = getattr(cache_file, "_source_stamp", None)
    if stamp is None:
        return
    deps = tuple((st.st_mtime, st.st_size) for st in (os.stat(m.__file__) for m in modules))
    cache_file._source_stamp = (stamp, deps)


#: seconds a kernel whose cached copy exists may take to load before :data:`SLOW_MESSAGE` is
#: printed (a stale copy is compiled anew; a loaded machine loads slowly)
COMPILE_NOTICE_S = 5.0
#: what the standard error says when a kernel has no cached copy ({what}: the kernel's name)
COMPILE_MESSAGE = ("fdm-awe: compiling {what} with numba (first use after an install or an update; "
                   "cached for the next runs) ...")
#: ... and when loading a kernel takes longer than :data:`COMPILE_NOTICE_S`
SLOW_MESSAGE = "fdm-awe: preparing {what} with numba (compiled anew after a change of its sources) ..."


def has_cached_copy(kern: Any) -> bool | None:
    """Whether numba's on-disk cache holds a current copy for dispatcher ``kern`` (False: it
    certainly compiles; True: it loads, unless the copy was made for another CPU; None: unknown,
    another numba version). Current: the index exists and carries the source stamp of today's
    files (:func:`follow_sources`), as numba checks it when it loads."""
    cache_file = getattr(getattr(kern, "_cache", None), "_cache_file", None)
    path = getattr(cache_file, "_index_path", None)
    if path is None:
        return None
    if not os.path.exists(path):
        return False
    load_index = getattr(cache_file, "_load_index", None)
    if load_index is None:
        return True
    try:
        return bool(load_index())
    except Exception:  # an unreadable index: numba compiles anew
        return False


def is_cached(fn: Callable, sources: Iterable[ModuleType]) -> bool | None:
    """Whether ``fn`` compiled by :func:`compile_cached` with ``sources`` would load from numba's
    on-disk cache (:func:`has_cached_copy`; None also where compiled code does not run). Nothing
    compiles."""
    if jit_off() is not None:
        return None
    try:
        import numba

        kern = numba.njit(cache=True)(fn)
        follow_sources(kern, sources)
        return has_cached_copy(kern)
    except Exception:
        return None


def compile_with_notice(kern: Any, sig: Any, what: str, stream: Any = None) -> float:
    """``kern.compile(sig)``, saying so on ``stream`` (None: the standard error at the call):
    :data:`COMPILE_MESSAGE` at once when the kernel has no cached copy
    (:func:`has_cached_copy`), :data:`SLOW_MESSAGE` when it takes longer than
    :data:`COMPILE_NOTICE_S` otherwise, and the time it took after either. Returns the time [s]."""
    out = stream if stream is not None else sys.stderr
    said = threading.Event()

    def notice(text: str) -> None:
        said.set()
        print(text.format(what=what), file=out, flush=True)

    timer = None
    if has_cached_copy(kern) is False:
        notice(COMPILE_MESSAGE)
    else:
        timer = threading.Timer(COMPILE_NOTICE_S, notice, (SLOW_MESSAGE,))
        timer.daemon = True
        timer.start()
    t0 = time.perf_counter()
    try:
        kern.compile(sig)
    finally:
        if timer is not None:
            timer.cancel()
    dt = time.perf_counter() - t0
    if said.is_set():
        print(f"fdm-awe: {what} ready in {dt:.0f} s", file=out, flush=True)
    return dt


def compile_cached(fn: Any, signature: Any, helpers: Iterable[Any], sources: Iterable[ModuleType], what: str) -> Any:
    """``fn`` compiled by numba for its one ``signature`` (a callable of the ``numba`` module
    returning the signature), cached on disk and tied to ``sources`` (:func:`follow_sources`),
    with ``helpers`` (plain functions it calls) compiled into it. Returns the dispatcher; None
    where compiled code does not run (:func:`jit_off`), or after one :class:`RuntimeWarning`
    naming ``what`` when numba fails (a broken numba install must not stop a simulation): the
    caller runs the Python function instead."""
    import warnings

    if jit_off() is not None:
        return None
    try:
        import numba

        register_helpers(helpers)
        kern = numba.njit(cache=True)(fn)
        follow_sources(kern, sources)
        # its one signature, compiled or loaded from the cache here (a note while it compiles)
        compile_with_notice(kern, signature(numba), what)
        kern.disable_compile()
        return kern
    except Exception as exc:
        warnings.warn(f"{what}: numba failed ({exc}); the Python code runs instead", RuntimeWarning, stacklevel=3)
        return None


def compile_lazy(fn: Callable, helpers: Iterable[Callable], sources: Iterable[ModuleType]) -> Callable:
    """``fn`` compiled by numba for the types of its first call (cached on disk, tied to
    ``sources``, ``helpers`` compiled into it), or ``fn`` itself where compiled code does not
    run (:func:`jit_off`): for studies and tests of a model's functions alone."""
    if jit_off() is not None:
        return fn
    try:
        import numba
    except ImportError:
        return fn
    register_helpers(helpers)
    kern = numba.njit(cache=True)(fn)
    follow_sources(kern, sources)
    return kern
