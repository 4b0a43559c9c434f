"""Safe output files: checked before the work starts, written atomically, JSON without NaN.

Every file the package writes goes through this module:

- :func:`check_output_file` / :func:`check_output_dir` run before any work: every name in the
  path fits the file system (at most ``NAME_MAX`` bytes), the parent folder must exist (or be
  creatable, for ``--out`` folders) and be writable, an existing file must be a regular file (not
  a device, a FIFO or a socket: those would be replaced by a file), the path must not be an
  existing folder (for a file) or file (for a folder), and it must not be one of the run's
  inputs (compared after resolving symbolic links). :func:`check_input_file` /
  :func:`check_input_dir` do the same for inputs (a regular file, a folder). A failure raises
  :class:`~fdm_awe.errors.InputError` with a one-line message naming the option and the path; the
  command line turns it into exit code 2.
- :func:`atomic_path` yields a temporary name in the target's folder; on success the file is
  renamed onto the target (``os.replace``, atomic on POSIX), on any exception (Ctrl-C included)
  the temporary file is removed. A reader never sees a truncated file. The temporary name,
  ``.<name>.<pid>@<host>.<random>.part<ending>``, says which process writes it: a run killed
  before it could remove its file (SIGKILL, power loss) leaves it behind, and the next check of
  an output in that folder removes it (:func:`remove_stale_parts`: this host's, of processes
  that no longer exist).
- :func:`lock_folder` takes an exclusive lock on an ``--out`` folder for the run (``flock`` on
  ``<folder>/.fdm-awe.lock``, released and removed when the run ends, released by the kernel
  when the process dies): a second run into the same folder while the first is running is
  refused (one line, exit 2); a later run writes over the earlier run's files.
- :func:`json_text` writes NaN and infinities as ``null`` (JSON has no NaN), recursively, and
  turns NumPy scalars and arrays into plain numbers and lists.
"""

from __future__ import annotations

import contextlib
import errno
import json
import math
import os
import re
import socket
import stat
import tempfile
from pathlib import Path
from typing import Any, Iterable, Iterator

from .errors import InputError

#: the lock file of an output folder (:func:`lock_folder`)
LOCK_NAME = ".fdm-awe.lock"
#: longest target name [bytes] kept in a temporary file's name (the rest of that name is < 60 bytes)
_TMP_STEM_BYTES = 80
#: longest target ending [characters] a temporary file keeps (format-sniffing writers need ``.png``)
_TMP_SUFFIX_CHARS = 16
#: a temporary file of :func:`atomic_path` or of the writability probe: stem, process id, host
_PART_RE = re.compile(r"^\.(?P<stem>.*)\.(?P<pid>[0-9]+)@(?P<host>[A-Za-z0-9-]+)\.[a-z0-9_]+\.part(\.[^/]*)?$")


def _host() -> str:
    """This machine's name as it appears in temporary file names (letters, digits, ``-``)."""
    name = re.sub(r"[^A-Za-z0-9-]", "-", socket.gethostname().split(".")[0])[:32]
    return name or "localhost"


def _tag() -> str:
    """``<pid>@<host>``: the writer of a temporary file."""
    return f"{os.getpid()}@{_host()}"


def _show(path: str | os.PathLike, limit: int = 60) -> str:
    """``path`` for a message, shortened in the middle when it is longer than ``limit`` characters."""
    s = os.fspath(path)
    return s if len(s) <= limit else f"{s[:limit // 2 - 2]}...{s[-(limit // 2 - 2):]}"


def _existing_ancestor(p: Path) -> Path:
    """The nearest folder above ``p`` (or ``p``) that exists, ``.`` for a relative path without one."""
    a = Path(os.path.abspath(p))
    while True:
        try:
            if a.exists():
                return a
        except OSError:
            pass
        if a.parent == a:
            return a
        a = a.parent


def check_name_length(path: str | os.PathLike, option: str) -> None:
    """InputError (one line naming ``option``) when a name in ``path`` is longer than the file
    system allows (``NAME_MAX``, 255 bytes on most) or the whole path longer than ``PATH_MAX``."""
    raw = os.fsencode(path)
    anc = _existing_ancestor(Path(os.fsdecode(raw) or "."))
    try:
        name_max = os.pathconf(anc, "PC_NAME_MAX")
        path_max = os.pathconf(anc, "PC_PATH_MAX")
    except (OSError, ValueError):
        name_max, path_max = 255, 4096
    for part in raw.split(b"/"):
        if len(part) > name_max:
            raise InputError(f"{option} {_show(path)}: a name of {len(part)} bytes is too long "
                             f"(allowed <= {name_max} bytes per name)")
    full = os.fsencode(os.path.abspath(os.fsdecode(raw) or "."))
    if len(full) >= path_max:
        raise InputError(f"{option} {_show(path)}: the path of {len(full)} bytes is too long "
                         f"(allowed < {path_max} bytes)")


#: what a file that is not regular is, by its ``stat`` type
_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISSOCK, "a socket"))


def file_kind(path: str | os.PathLike) -> str | None:
    """None when ``path`` does not exist; ``"a regular file"``, ``"a folder"``, ``"a character
    device"``, ... otherwise (symbolic links followed; a dangling link counts as missing)."""
    try:
        st = os.stat(path)
    except (FileNotFoundError, NotADirectoryError):
        return None
    for test, kind in _KINDS:
        if test(st.st_mode):
            return kind
    return "a regular file"


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
    check_name_length(p, option)
    for i in inputs:
        if i is not None and _same_file(p, Path(i)):
            raise InputError(f"{option} {p}: is an input of this run ({i}); choose another output path")
    kind = _kind_or_error(p, option)
    if kind == "a folder":
        raise InputError(f"{option} {p}: is a folder, a file name is needed")
    if kind not in (None, "a regular file"):
        raise InputError(f"{option} {p}: is {kind}, not a regular file (an output is a regular file or a new name)")
    parent = p.parent if str(p.parent) else Path(".")
    if _kind_or_error(parent, option) != "a folder":
        raise InputError(f"{option} {p}: folder {parent} does not exist")
    _probe(parent, f"{option} {p}: folder {parent}")
    remove_stale_parts(parent)
    return p


def _kind_or_error(p: Path, option: str) -> str | None:
    """:func:`file_kind`, an OSError (permission, a loop of links) as a one-line InputError."""
    try:
        return file_kind(p)
    except OSError as exc:
        raise InputError(f"{option} {_show(p)}: cannot be examined ({exc.strerror or exc})") from None


def _check_existing(path: str | os.PathLike, option: str, kind_wanted: str, noun: str) -> Path:
    """Check that ``path`` names an existing ``kind_wanted`` (a :func:`file_kind` answer;
    ``noun`` names it in messages); returns it as a Path."""
    p = Path(path)
    if str(path) == "":
        raise InputError(f"{option} '': not a {noun} name")
    check_name_length(p, option)
    kind = _kind_or_error(p, option)
    if kind is None:
        raise InputError(f"{option} {p}: no such {noun}")
    if kind != kind_wanted:
        raise InputError(f"{option} {p}: is {kind}, not {kind_wanted}")
    return p


def check_input_file(path: str | os.PathLike, option: str) -> Path:
    """Check that ``path`` names an existing regular file (not a folder, a device, a FIFO or a
    socket, which a run would block on or read without end); returns it as a Path."""
    return _check_existing(path, option, "a regular file", "file")


def check_input_dir(path: str | os.PathLike, option: str) -> Path:
    """Check that ``path`` names an existing folder; returns it as a Path."""
    return _check_existing(path, option, "a folder", "folder")


def _probe(folder: Path, what: str) -> None:
    """Create and remove a temporary file in ``folder``: the one sure test that the files this
    run will write (temporary name + rename) can be written there (root ignores mode bits,
    some file systems refuse new files)."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".fdm-awe-probe.{_tag()}.", suffix=".part", dir=folder)
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
    check_name_length(p, option)
    for i in inputs:
        if i is not None and _same_file(p, Path(i)):
            raise InputError(f"{option} {p}: is an input of this run ({i}); choose another output folder")
    kind = _kind_or_error(p, option)
    if kind not in (None, "a folder"):
        raise InputError(f"{option} {p}: exists and is not a folder (it is {kind})")
    # the nearest existing ancestor must be a writable folder
    anc = _existing_ancestor(p)
    if _kind_or_error(anc, option) != "a folder":
        raise InputError(f"{option} {p}: {anc} is not a folder")
    try:
        p.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"{option} {p}: cannot create the folder ({exc.strerror or exc})") from None
    _probe(p, f"{option} {p}: folder")
    remove_stale_parts(p)
    return p


def _alive(pid: int) -> bool:
    """Whether a process ``pid`` exists on this machine (one of another user's counts)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return True
    return True


def remove_stale_parts(folder: str | os.PathLike) -> list[Path]:
    """Remove the temporary files in ``folder`` that runs killed on this machine left behind
    (:func:`atomic_path`'s names of processes that no longer exist); returns them. Temporary
    files of running processes, of other machines and every other file stay."""
    removed = []
    host = _host()
    try:
        names = os.listdir(folder)
    except OSError:
        return removed
    for name in names:
        m = _PART_RE.match(name)
        if m is None or m["host"] != host or _alive(int(m["pid"])):
            continue
        f = Path(folder) / name
        with contextlib.suppress(OSError):
            if stat.S_ISREG(os.lstat(f).st_mode):
                f.unlink()
                removed.append(f)
    return removed


class FolderLock:
    """An exclusive lock on an output folder for one run (:func:`lock_folder`); :meth:`close`
    (or the end of a ``with`` block) releases it and removes the lock file."""

    def __init__(self, folder: Path, fd: int) -> None:
        self.folder = folder
        self.path = folder / LOCK_NAME
        self._fd: int | None = fd

    def close(self) -> None:
        """Remove the lock file and release the lock (idempotent)."""
        if self._fd is None:
            return
        with contextlib.suppress(OSError):
            if os.fstat(self._fd).st_ino == os.stat(self.path).st_ino:
                self.path.unlink()  # while still locked: no other run holds this file
        os.close(self._fd)  # releases the flock
        self._fd = None

    def __enter__(self) -> "FolderLock":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def lock_folder(folder: str | os.PathLike, option: str) -> FolderLock:
    """Lock ``folder`` (an existing output folder) for this run: ``flock`` on its
    :data:`LOCK_NAME` file, which holds the process id. InputError (one line naming ``option``)
    when another run holds it; the kernel releases the lock of a process that dies."""
    import fcntl

    d = Path(folder)
    lock = d / LOCK_NAME
    for _ in range(100):
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o666)
        except OSError as exc:
            raise InputError(f"{option} {d}: cannot create the lock file {LOCK_NAME} ({exc.strerror or exc})") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            holder = ""
            with contextlib.suppress(OSError, ValueError):
                holder = f" (process {int(os.read(fd, 32).split()[0])})"
            os.close(fd)
            if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                raise InputError(f"{option} {d}: another fdm-awe run{holder} is writing into this folder; wait until "
                                 f"it ends or choose another folder") from None
            raise InputError(f"{option} {d}: cannot lock the folder ({exc.strerror or exc})") from None
        try:
            same = os.fstat(fd).st_ino == os.stat(lock).st_ino
        except OSError:
            same = False
        if not same:  # the run before removed the file between our open and our lock: lock the new one
            os.close(fd)
            continue
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()}\n".encode())
        return FolderLock(d, fd)
    raise InputError(f"{option} {d}: cannot lock the folder (its lock file keeps changing)")


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
    end = end if len(end) <= _TMP_SUFFIX_CHARS else ""
    fd, tmp = tempfile.mkstemp(prefix=f".{_stem(p.name)}.{_tag()}.", suffix=".part" + end, dir=parent)
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


def _stem(name: str) -> str:
    """``name`` cut to at most :data:`_TMP_STEM_BYTES` bytes on a character boundary, so that a
    temporary name stays within ``NAME_MAX`` whatever the target's length."""
    out, n = [], 0
    for ch in name:
        n += len(os.fsencode(ch))
        if n > _TMP_STEM_BYTES:
            break
        out.append(ch)
    return "".join(out)


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


__all__ = ["FolderLock", "LOCK_NAME", "atomic_path", "atomic_write_bytes", "atomic_write_text", "check_input_dir",
           "check_input_file", "check_name_length", "check_output_dir", "check_output_file", "file_kind", "json_text",
           "jsonable", "lock_folder", "remove_stale_parts", "write_json"]
