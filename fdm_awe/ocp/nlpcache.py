"""On-disk cache of built cycle NLPs (CasADi serialisation), shared between processes.

Building the NLP of a problem (the collocation transcription in Python, then the derivative
functions IPOPT needs: objective gradient, constraint Jacobian, Hessian of the Lagrangian)
costs seconds at the default mesh. :func:`load` and :func:`save` keep a built
:class:`~fdm_awe.ocp.collocation.CycleNLP` on disk: the NLP function, its energy and
constraint functions, the derivative functions and the decision-vector layout, in one file
written by CasADi's ``FileSerializer``.

Where: ``$FDM_AWE_CACHE_DIR/nlp`` if that variable is set, else ``$XDG_CACHE_HOME/fdm-awe/nlp``,
else ``~/.cache/fdm-awe/nlp`` (created private, mode 0700). ``FDM_AWE_NLP_CACHE=off`` (or ``0``)
turns the cache off. At most :data:`MAX_BYTES` are kept (``FDM_AWE_NLP_CACHE_MAX_MB``); the least
recently used entries are removed first.

Key: a hash of everything that defines the NLP: the problem without its wind (a parameter of
the NLP), the model's values (glider, winch, drive, scenario: the definitions' numbers), the
CasADi and package versions, the file format and a hash of the package's Python sources. Any
change of these makes a new entry; an entry is never reused for another NLP.

Safety: each file's name carries the CRC-32 of its content; a file whose CRC, header or CasADi
content does not check out is ignored with one warning line and rebuilt (overwritten). Files
are written atomically (:func:`fdm_awe.fileio.atomic_path`); a file not owned by the user or
writable by others is never loaded (a CasADi file can name a shared library to load).
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import multiprocessing
import os
import stat
import sys
import time
import zlib
from importlib.metadata import version
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np

from ..fileio import atomic_path
from .collocation import CycleNLP
from .layout import PhaseLayout

#: file format of an entry (part of the key)
FORMAT = "fdm-awe-nlp-cache"
FORMAT_VERSION = 1
#: environment variables: the cache folder's parent, the switch, the size limit [MB]
DIR_ENV = "FDM_AWE_CACHE_DIR"
SWITCH_ENV = "FDM_AWE_NLP_CACHE"
MAX_MB_ENV = "FDM_AWE_NLP_CACHE_MAX_MB"
#: default size limit of the cache folder [bytes] (a default-mesh entry is about 150 MB, its
#: coarse mesh about 40 MB)
MAX_BYTES = 2**30
#: the dataclasses a CycleNLP holds (stored field by field, by class name)
_DATACLASSES = {cls.__name__: cls for cls in (PhaseLayout,)}


class NotCacheable(Exception):
    """The NLP holds something the cache cannot store (it is then simply not cached)."""


def enabled() -> bool:
    return os.environ.get(SWITCH_ENV, "on").strip().lower() not in ("0", "off", "no", "false")


def cache_dir() -> Path:
    """The cache folder (see the module docstring); not created here."""
    base = os.environ.get(DIR_ENV)
    if base:
        return Path(base).expanduser() / "nlp"
    xdg = os.environ.get("XDG_CACHE_HOME")
    root = Path(xdg).expanduser() if xdg else Path.home() / ".cache"
    return root / "fdm-awe" / "nlp"


def max_bytes() -> int:
    try:
        return int(float(os.environ[MAX_MB_ENV]) * 2**20)
    except (KeyError, ValueError):
        return MAX_BYTES


@functools.lru_cache(maxsize=1)
def source_hash() -> str:
    """SHA-256 of the package's Python sources (every ``*.py`` under ``fdm_awe/``, by path)."""
    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for p in sorted(root.rglob("*.py")):
        h.update(str(p.relative_to(root)).encode())
        h.update(b"\0")
        h.update(p.read_bytes())
        h.update(b"\0")
    return h.hexdigest()


def _package_version() -> str:
    try:
        return version("fdm-awe")
    except Exception:  # not installed (a source checkout on the path)
        return "unknown"


def entry_key(problem: Any, model: Any) -> str:
    """Hash of everything that defines the NLP of ``problem`` built with ``model``."""
    neutral = dataclasses.replace(problem, wind_speed=0.0, wind_from_deg=0.0)
    parts = {"format": FORMAT, "version": FORMAT_VERSION, "casadi": ca.__version__, "package": _package_version(),
             "python": f"{sys.version_info.major}.{sys.version_info.minor}", "sources": source_hash(),
             "problem": repr(neutral), "model": repr(model)}
    text = json.dumps(parts, sort_keys=True)
    if " at 0x" in text:  # an object without a value representation: no stable key
        raise NotCacheable("the problem or model has no value representation")
    return hashlib.sha256(text.encode()).hexdigest()[:32]


# ------------------------------------------------------------------ state <-> JSON + functions
def _encode(v: Any, fns: list[Any]) -> Any:
    if isinstance(v, ca.Function):
        fns.append(v)
        return {"__fn__": len(fns) - 1}
    if isinstance(v, (ca.SX, ca.MX)):
        raise NotCacheable("symbolic expression outside the NLP function")
    if isinstance(v, np.ndarray):
        if v.dtype.kind not in "biuf":
            raise NotCacheable(f"array of dtype {v.dtype}")
        return {"__nd__": [v.dtype.str, list(v.shape), v.ravel().tolist()]}
    if isinstance(v, (np.integer, np.floating, np.bool_)):
        return v.item()
    if v is None or isinstance(v, (bool, int, float, str)):
        return v
    if isinstance(v, tuple):
        return {"__tuple__": [_encode(x, fns) for x in v]}
    if isinstance(v, list):
        return [_encode(x, fns) for x in v]
    if isinstance(v, dict) and all(isinstance(k, str) for k in v):
        return {"__dict__": {k: _encode(x, fns) for k, x in v.items()}}
    if dataclasses.is_dataclass(v) and not isinstance(v, type) and _DATACLASSES.get(type(v).__name__) is type(v):
        out = {}
        for f in dataclasses.fields(v):
            x = getattr(v, f.name)
            symbolic = isinstance(x, (ca.SX, ca.MX)) or (isinstance(x, list) and _has_symbols(x))
            out[f.name] = None if symbolic else _encode(x, fns)  # symbols only serve the build
        return {"__dc__": type(v).__name__, "fields": out}
    raise NotCacheable(f"value of type {type(v).__name__}")


def _has_symbols(x: Any) -> bool:
    if isinstance(x, (ca.SX, ca.MX)):
        return True
    return isinstance(x, (list, tuple)) and any(_has_symbols(y) for y in x)


def _decode(v: Any, fns: list[Any]) -> Any:
    if isinstance(v, list):
        return [_decode(x, fns) for x in v]
    if not isinstance(v, dict):
        return v
    if "__fn__" in v:
        return fns[v["__fn__"]]
    if "__nd__" in v:
        dt, shape, data = v["__nd__"]
        return np.array(data, dtype=np.dtype(dt)).reshape(shape)
    if "__tuple__" in v:
        return tuple(_decode(x, fns) for x in v["__tuple__"])
    if "__dict__" in v:
        return {k: _decode(x, fns) for k, x in v["__dict__"].items()}
    if "__dc__" in v:
        cls = _DATACLASSES[v["__dc__"]]
        obj = cls.__new__(cls)
        for k, x in v["fields"].items():
            object.__setattr__(obj, k, _decode(x, fns))
        return obj
    raise ValueError(f"unknown encoded object {sorted(v)[:3]}")


# ------------------------------------------------------------------ files
def _entry_paths(folder: Path, key: str) -> list[Path]:
    return sorted(folder.glob(f"{key}.*.casadi"))


def _crc(path: Path) -> str:
    c = 0
    with open(path, "rb") as fh:
        while chunk := fh.read(1 << 22):
            c = zlib.crc32(chunk, c)
    return f"{c:08x}"


def _warn(msg: str) -> None:
    print(f"fdm-awe: NLP cache: {msg}", file=sys.stderr, flush=True)


def _safe_file(path: Path) -> bool:
    """Owned by this user and not writable by others (a CasADi file can name a library)."""
    try:
        st = path.stat()
    except OSError:
        return False
    return (not hasattr(os, "getuid") or st.st_uid == os.getuid()) and not (st.st_mode & (stat.S_IWGRP | stat.S_IWOTH))


def load(problem: Any, model: Any) -> Any | None:
    """The cached :class:`~fdm_awe.ocp.collocation.CycleNLP` of ``problem``/``model``, or None
    (no entry, cache off, or an unusable entry: one warning line, the entry is removed)."""
    if not enabled():
        return None
    try:
        key = entry_key(problem, model)
    except NotCacheable:
        return None
    folder = cache_dir()
    paths = _entry_paths(folder, key) if folder.is_dir() else []
    if not paths:
        return None
    t0 = time.perf_counter()
    path = paths[-1]
    try:
        if not _safe_file(path):
            _warn(f"{path}: not owned by this user or writable by others; ignored")
            return None
        want = path.name.split(".")[1]
        if _crc(path) != want:
            raise ValueError("content does not match its checksum (truncated or damaged)")
        ds = ca.FileDeserializer(str(path))
        header = json.loads(ds.unpack())
        if header.get("format") != FORMAT or header.get("version") != FORMAT_VERSION or header.get("key") != key:
            raise ValueError("header does not match this NLP")
        fns = [ds.unpack() for _ in range(int(header["n_functions"]))]
        del ds
        if not all(isinstance(f, ca.Function) for f in fns):
            raise ValueError("a stored function did not load as a CasADi Function")
        nlp = _restore(problem, model, header, fns)
    except Exception as exc:  # any damage: ignore the entry, it is rebuilt and overwritten
        _warn(f"{path}: unusable entry ignored and rebuilt ({str(exc).splitlines()[0] if str(exc) else type(exc).__name__})")
        for p in paths:
            try:
                p.unlink()
            except OSError:
                pass
        return None
    try:
        os.utime(path)  # recently used (the size limit removes the oldest first)
    except OSError:
        pass
    nlp.build_s = time.perf_counter() - t0
    nlp.loaded_from = str(path)
    return nlp


def _restore(problem: Any, model: Any, header: dict[str, Any], fns: list[Any]) -> Any:
    state = {name: _decode(v, fns) for name, v in header["state"].items()}
    return CycleNLP.from_cache(problem, model, state, fns[header["nlp"]],
                               {k: fns[i] for k, i in header["derivatives"].items()})


def save(nlp: Any, background: bool = False) -> Path | None:
    """Store ``nlp`` (its derivative functions are generated first if no IPOPT instance did so
    yet); returns the file, or None when the cache is off or the NLP cannot be stored. A write
    failure (disk full, read-only folder) gives one warning line, never an exception.

    ``background``: write from a forked process (detached: a double fork leaves it to the
    system to reap) and return None at once; the caller goes on solving while the file is
    serialised (as long as building the NLP). In the foreground where ``fork`` is not
    available; not at all inside a daemonic process (a pool's or a Dask worker: often
    threaded, so not forked, and a sweep's design variants are rarely solved again, while
    writing one costs as much as building it)."""
    if not enabled():
        return None
    daemon = multiprocessing.current_process().daemon
    if background and daemon:
        return None
    nlp.derive()  # here, not in a forked writer: this process keeps the derivative functions
    if background and hasattr(os, "fork"):
        pid = os.fork()
        if pid == 0:  # child: start the writer and leave at once
            try:
                if os.fork() == 0:
                    try:
                        save(nlp)
                    finally:
                        os._exit(0)
            finally:
                os._exit(0)
        os.waitpid(pid, 0)
        return None
    try:
        key = entry_key(nlp.problem, nlp.model)
        fns: list[Any] = []
        parts, fn, derivatives = nlp.to_cache()
        state = {name: _encode(v, fns) for name, v in parts.items()}
        nlp_fn = fn if isinstance(fn, ca.Function) else ca.Function(
            "nlp", [fn["x"], fn["p"]], [fn["f"], fn["g"]], ["x", "p"], ["f", "g"])
        fns.append(nlp_fn)
        i_nlp = len(fns) - 1
        derivs = {}
        for k, f in derivatives.items():
            fns.append(f)
            derivs[k] = len(fns) - 1
    except NotCacheable:
        return None
    header = {"format": FORMAT, "version": FORMAT_VERSION, "key": key, "n_functions": len(fns), "nlp": i_nlp,
              "derivatives": derivs, "state": state}
    folder = cache_dir()
    try:
        folder.mkdir(parents=True, exist_ok=True, mode=0o700)
        tmp_target = folder / f".{key}.writing"  # not an entry's name: readers never see it
        with atomic_path(tmp_target) as tmp:
            s = ca.FileSerializer(str(tmp))
            s.pack(json.dumps(header))
            for f in fns:
                s.pack(f)
            del s  # closes the file
            os.chmod(tmp, 0o600)
            final = folder / f"{key}.{_crc(tmp)}.casadi"
        os.replace(tmp_target, final)
        for p in _entry_paths(folder, key):
            if p != final:
                p.unlink(missing_ok=True)
        _trim(folder, keep=final)
        return final
    except OSError as exc:
        _warn(f"{folder}: entry not written ({exc.strerror or exc})")
        return None


def _trim(folder: Path, keep: Path) -> None:
    """Remove the least recently used entries beyond :func:`max_bytes`."""
    entries = []
    for p in folder.glob("*.casadi"):
        try:
            st = p.stat()
        except OSError:
            continue
        entries.append((st.st_mtime, st.st_size, p))
    total = sum(e[1] for e in entries)
    limit = max_bytes()
    for _, size, p in sorted(entries):
        if total <= limit:
            break
        if p == keep:
            continue
        try:
            p.unlink()
            total -= size
        except OSError:
            pass


def clear() -> int:
    """Remove every entry of the cache folder; returns how many files were removed."""
    folder = cache_dir()
    n = 0
    for p in folder.glob("*.casadi") if folder.is_dir() else []:
        try:
            p.unlink()
            n += 1
        except OSError:
            pass
    return n
