"""Safe output files: checked before the work starts, written atomically, JSON without NaN.

Every file the package writes goes through this module:

- :func:`check_output_file` / :func:`check_output_dir` run before any work: the parent folder
  must exist (or be creatable, for ``--out`` folders) and be writable, the path must not be an
  existing folder (for a file) or file (for a folder), and it must not be one of the run's
  inputs. A failure raises :class:`~fdm_awe.errors.InputError` with a one-line message naming the
  option and the path; the command line turns it into exit code 2.
- :func:`atomic_path` yields a temporary name in the target's folder; on success the file is
  renamed onto the target (``os.replace``, atomic on POSIX), on any exception (Ctrl-C included)
  the temporary file is removed. A reader never sees a truncated file.
- :func:`json_text` writes NaN and infinities as ``null`` (JSON has no NaN), recursively, and
  turns NumPy scalars and arrays into plain numbers and lists.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import tempfile
from pathlib import Path
from typing import Any, Iterable, Iterator

from .errors import InputError


def _same_file(a: Path, b: Path) -> bool:
    try:
        if a.exists() and b.exists():
            return os.path.samefile(a, b)
    except OSError:
        pass
    return a.resolve() == b.resolve()


def check_output_file(path: str | os.PathLike, option: str, inputs: Iterable[str | os.PathLike | None] = ()) -> Path:
    """Check that ``path`` can be written as a file by this run; returns it as a Path.

    ``option`` names the command-line option (e.g. ``--json``) for the message; ``inputs`` are
    the run's input files, none of which may be overwritten.
    """
    p = Path(path)
    if str(path) == "" or p.name in ("", ".", ".."):
        raise InputError(f"{option} {str(path)!r}: not a file name")
    for i in inputs:
        if i is not None and _same_file(p, Path(i)):
            raise InputError(f"{option} {p}: is an input of this run ({i}); choose another output path")
    if p.is_dir():
        raise InputError(f"{option} {p}: is a folder, a file name is needed")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(f"{option} {p}: folder {parent} does not exist")
    _probe(parent, f"{option} {p}: folder {parent}")
    return p


def _probe(folder: Path, what: str) -> None:
    """Create and remove a temporary file in ``folder``: the one sure test that the files this
    run will write (temporary name + rename) can be written there (root ignores mode bits,
    some file systems refuse new files)."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=".fdm-awe-probe.", dir=folder)
    except OSError as exc:
        raise InputError(f"{what} is not writable ({exc.strerror or exc})") from None
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(tmp)


def check_output_dir(path: str | os.PathLike, option: str, inputs: Iterable[str | os.PathLike | None] = ()) -> Path:
    """Check that ``path`` is (or can be created as) a writable folder; creates it. Returns it."""
    p = Path(path)
    if str(path) == "":
        raise InputError(f"{option} '': not a folder name")
    for i in inputs:
        if i is not None and _same_file(p, Path(i)):
            raise InputError(f"{option} {p}: is an input of this run ({i}); choose another output folder")
    if p.exists() and not p.is_dir():
        raise InputError(f"{option} {p}: exists and is not a folder")
    # the nearest existing ancestor must be a writable folder
    anc = p
    while not anc.exists():
        if anc.parent == anc:
            break
        anc = anc.parent
    if not anc.is_dir():
        raise InputError(f"{option} {p}: {anc} is not a folder")
    try:
        p.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"{option} {p}: cannot create the folder ({exc.strerror or exc})") from None
    _probe(p, f"{option} {p}: folder")
    return p


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike, suffix: str | None = None) -> Iterator[Path]:
    """A temporary path beside ``path``; renamed onto ``path`` when the block ends normally.

    ``suffix`` is the temporary file's ending (default: the target's), for writers that choose
    the format by the ending (matplotlib). On an exception the temporary file is removed and the
    target is left as it was.
    """
    p = Path(path)
    parent = p.parent if str(p.parent) else Path(".")
    end = p.suffix if suffix is None else suffix
    fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".part" + end, dir=parent)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        mask = os.umask(0)  # mkstemp makes the file private (0600): give it an ordinary file's mode
        os.umask(mask)
        os.chmod(tmp_path, 0o666 & ~mask)
        yield tmp_path
        os.replace(tmp_path, p)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp_path.unlink()
        raise


def atomic_write_text(path: str | os.PathLike, text: str) -> Path:
    """Write ``text`` to ``path`` atomically (temporary file + rename)."""
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
    return Path(path)


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically (temporary file + rename)."""
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
    return Path(path)


def jsonable(obj: Any) -> Any:
    """``obj`` with non-finite floats as None and NumPy values as plain Python values."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, (str, int, bool)) or obj is None:
        return obj
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    tolist = getattr(obj, "tolist", None)  # NumPy scalars and arrays
    if callable(tolist):
        return jsonable(tolist())
    try:
        return jsonable(float(obj))
    except (TypeError, ValueError):
        raise TypeError(f"cannot write {type(obj).__name__} as JSON") from None


def json_text(doc: Any, indent: int | None = 2) -> str:
    """JSON text of ``doc``; NaN and infinities become ``null`` (never invalid JSON)."""
    return json.dumps(jsonable(doc), indent=indent, allow_nan=False) + "\n"


def write_json(path: str | os.PathLike, doc: Any, indent: int | None = 2) -> Path:
    """Write ``doc`` as JSON (:func:`json_text`) to ``path`` atomically."""
    return atomic_write_text(path, json_text(doc, indent))


__all__ = ["atomic_path", "atomic_write_bytes", "atomic_write_text", "check_output_dir", "check_output_file",
           "json_text", "jsonable", "write_json"]
