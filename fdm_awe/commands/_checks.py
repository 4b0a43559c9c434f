"""Checks the commands run on their options before any work starts.

Every function raises :class:`~fdm_awe.errors.InputError` with one line naming the option, the
value and the allowed range; the command line turns it into ``fdm-awe CMD: error: ...`` and exit
code 2. Only the standard library, :mod:`fdm_awe.fileio` and :mod:`fdm_awe.turbulence` (the
forms of ``--turbulence``) are imported here, so the checks cost nothing at start-up.
"""

from __future__ import annotations

import contextlib
import math
import os
import socket
import stat
from pathlib import Path
from typing import Iterable, Sequence

from ..errors import InputError
from ..fileio import (check_input_dir, check_input_file, check_name_length, check_output_dir, check_output_file,
                      lock_folder)
from ..turbulence import Turbulence

#: the named turbulence levels of ``fly --turbulence`` (JSBSim's Milspec severities with a fixed
#: wind at 20 ft; the other forms: :mod:`fdm_awe.turbulence`)
TURBULENCE_LEVELS = ("light", "moderate", "severe")

#: connection kinds of ``fly --mavlink`` (pymavlink connection strings with HOST:PORT)
MAVLINK_KINDS = ("udpout", "udpin", "udp", "tcp", "tcpin")

#: address schemes of ``sweep --scheduler`` (Dask comm protocols with HOST:PORT)
SCHEDULER_SCHEMES = ("tcp", "tls", "ws", "wss", "ucx")


def _interval(lo: float | None, hi: float | None, lo_open: bool, hi_open: bool, unit: str) -> str:
    u = f" {unit}" if unit else ""
    if lo is not None and hi is not None and not lo_open and not hi_open:
        return f"{lo:g}..{hi:g}{u}"
    parts = []
    if lo is not None:
        parts.append(f"{'>' if lo_open else '>='} {lo:g}")
    if hi is not None:
        parts.append(f"{'<' if hi_open else '<='} {hi:g}")
    return " and ".join(parts) + u if parts else "a finite number" + u


def number(value: float | None, option: str, lo: float | None = None, hi: float | None = None, *,
           lo_open: bool = False, hi_open: bool = False, unit: str = "", what: str = "") -> float | None:
    """``value`` if it is finite and within ``lo``..``hi`` (open ends where asked); None passes.

    ``what`` names the quantity in the message (e.g. ``wind speed``), ``unit`` its SI unit.
    """
    if value is None:
        return None
    v = float(value)
    ok = math.isfinite(v) and (lo is None or (v > lo if lo_open else v >= lo)) and (
        hi is None or (v < hi if hi_open else v <= hi))
    if not ok:
        desc = f" ({what})" if what else ""
        raise InputError(f"{option} {value!r}{desc} out of range (allowed {_interval(lo, hi, lo_open, hi_open, unit)})")
    return v


def integer(value: int | None, option: str, lo: int, hi: int | None = None, *, what: str = "") -> int | None:
    """``value`` if it is an integer within ``lo``..``hi``; None passes."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int) or value < lo or (hi is not None and value > hi):
        desc = f" ({what})" if what else ""
        allowed = f"integer {lo}..{hi}" if hi is not None else f"integer >= {lo}"
        raise InputError(f"{option} {value!r}{desc} out of range (allowed {allowed})")
    return value


def outputs(files: Sequence[tuple[str, str | os.PathLike | None]] = (),
            dirs: Sequence[tuple[str, str | os.PathLike | None]] = (),
            inputs: Iterable[str | os.PathLike | None] = (),
            dir_files: Sequence[tuple[str, str | os.PathLike]] = ()) -> contextlib.ExitStack:
    """Check every output of a run before the work starts; returns the locks of the output
    folders, to be held (``with``) until the run's last file is written.

    ``files`` and ``dirs`` are ``(option, path)`` pairs (None: not asked for); ``dir_files``
    are the files the run will write inside those folders (``option`` there names the folder's
    option). Every path must differ from every other after symbolic links are resolved (a file
    an output folder writes is that folder option's, even when another option names it); the
    files are checked first (no side effects), then the folders (created when missing, then
    locked: :func:`fdm_awe.fileio.lock_folder`, a second run into the same folder is refused
    while the first runs), then the files whose folder that made. No path may be an input of
    the run (``inputs``, and always the definition files, :func:`definition_files`) or the
    output of another option.
    """
    ins = [i for i in inputs if i is not None] + definition_files()
    seen: dict[Path, str] = {}
    seen_ids: dict[tuple[int, int], str] = {}

    def distinct(option: str, p: Path) -> None:
        check_name_length(p, option)
        key = Path(os.path.realpath(p))
        if key in seen:
            raise InputError(f"{option} {p}: also the output of {seen[key]}; choose another path")
        seen[key] = option
        try:
            st = os.stat(p)
        except OSError:
            return
        ident = (st.st_dev, st.st_ino)
        if ident in seen_ids and stat.S_ISREG(st.st_mode):  # two names of one file (a hard link)
            raise InputError(f"{option} {p}: the same file as the output of {seen_ids[ident]}; choose another path")
        seen_ids[ident] = option

    for option, path in dirs:
        if path is not None:
            check_name_length(path, option)
    folders = [Path(os.path.realpath(d)) for _, d in dirs if d is not None]

    def in_folder(path: str | os.PathLike) -> bool:
        a = Path(os.path.realpath(path))
        return any(f in a.parents for f in folders)

    # a file inside an output folder that does not exist yet is checked once the folder is made;
    # every other path first (no side effects)
    outside = [(o, p) for o, p in files if p is not None and not in_folder(p)]
    pending = list(dir_files) + [(o, p) for o, p in files if p is not None and in_folder(p)]
    for option, path in outside + pending:
        distinct(option, Path(path))
    for option, path in dirs:
        if path is not None:
            distinct(option, Path(path))
    later = []
    for option, path in outside + pending:
        parent = Path(os.path.realpath(path)).parent
        if parent in folders and not parent.is_dir():
            later.append((option, path))  # the folder option creates it
        else:
            check_output_file(path, option, ins)
    locks = contextlib.ExitStack()
    try:
        for option, path in dirs:
            if path is not None:
                check_output_dir(path, option, ins)
                locks.enter_context(lock_folder(path, option))
        for option, path in later:
            check_output_file(path, option, ins)
    except BaseException:
        locks.close()
        raise
    return locks


def io_file(path: str | os.PathLike | None, option: str, inputs: Iterable[str | os.PathLike | None] = ()) -> None:
    """A file the run reads and writes back (``fly --params``): a regular file or a new name in
    a writable folder, not another input (``inputs`` and the definition files); None passes."""
    if path is None:
        return
    check_output_file(path, option, [i for i in inputs if i is not None] + definition_files())


def input_file(path: str | os.PathLike | None, option: str) -> None:
    """An input file: an existing regular file (not a folder, a device or a FIFO); None passes."""
    if path is not None:
        check_input_file(path, option)


def input_dir(path: str | os.PathLike | None, option: str) -> None:
    """An input folder: an existing folder; None passes."""
    if path is not None:
        check_input_dir(path, option)


def definition_files() -> list[Path]:
    """Every file of the definition folders (``aircraft/``, ``engine/``, ``tether/`` under
    :data:`fdm_awe.ROOT`): inputs of every run, never to be overwritten by an output."""
    from .. import DEFINITION_FOLDERS
    from .. import ROOT

    return [p for folder in DEFINITION_FOLDERS for p in sorted((ROOT / folder).rglob("*")) if p.is_file()]


def turbulence(text: str | None, option: str = "--turbulence") -> Turbulence | None:
    """``LEVEL[:SEED]``, ``milspec:SEVERITY[:SEED]`` or ``iec:CLASS[:SEED]`` -> the
    :class:`~fdm_awe.turbulence.Turbulence` form; the seed defaults to 1, allowed 1..2**31-1."""
    if text is None:
        return None
    return Turbulence.parse(text, option)


def _host_port(rest: str, text: str, option: str, form: str) -> tuple[str, int]:
    """HOST and PORT of ``rest`` (the HOST:PORT part of the option's value ``text``)."""
    host, colon, port = rest.rpartition(":")
    if not colon or not host or not port:
        raise InputError(f"{option} {text!r}: expected {form}")
    host = host[1:-1] if host.startswith("[") and host.endswith("]") else host  # [IPv6]
    try:
        p = int(port)
    except ValueError:
        raise InputError(f"{option} {text!r}: port {port!r} is not an integer (allowed 1..65535)") from None
    if not 1 <= p <= 65535:
        raise InputError(f"{option} {text!r}: port {p} out of range (allowed 1..65535)")
    return host, p


def _resolve(host: str, port: int, option: str, text: str, kind: int = 0) -> None:
    try:
        socket.getaddrinfo(host, port, type=kind)
    except (OSError, UnicodeError) as exc:
        reason = getattr(exc, "strerror", None) or str(exc)
        raise InputError(f"{option} {text!r}: host {host!r} does not resolve ({reason})") from None


#: MAVLink connection kinds that listen on HOST:PORT (pymavlink's ``udp`` is ``udpin``)
MAVLINK_LISTEN_KINDS = ("udpin", "udp", "tcpin")


def mavlink_url(url: str | None, option: str = "--mavlink") -> str | None:
    """``KIND:HOST:PORT`` with KIND one of :data:`MAVLINK_KINDS`, port 1..65535 and a host with
    an IPv4 address (pymavlink's UDP and TCP links are IPv4; ``socket.getaddrinfo``); a listening
    kind (:data:`MAVLINK_LISTEN_KINDS`) must be able to bind HOST:PORT on this machine (tried at
    once, the socket closed again); None passes. A ``tcp`` client's connection is tried when
    the link opens (:func:`fdm_awe.mavlink.transport.open_link`), before the work."""
    if url is None:
        return None
    form = f"KIND:HOST:PORT with KIND one of {', '.join(MAVLINK_KINDS)} (e.g. udpout:127.0.0.1:14550)"
    kind, colon, rest = url.partition(":")
    if not colon or kind not in MAVLINK_KINDS:
        raise InputError(f"{option} {url!r}: expected {form}")
    host, port = _host_port(rest, url, option, form)
    kind_type = socket.SOCK_STREAM if kind.startswith("tcp") else socket.SOCK_DGRAM
    _resolve(host, port, option, url, kind_type)
    try:
        socket.getaddrinfo(host, port, family=socket.AF_INET, type=kind_type)
    except (OSError, UnicodeError):
        raise InputError(f"{option} {url!r}: host {host!r} has no IPv4 address (MAVLink's UDP and TCP links are "
                         f"IPv4; e.g. 127.0.0.1 or 0.0.0.0)") from None
    if kind in MAVLINK_LISTEN_KINDS:
        _bindable(host, port, kind_type, option, url)
    return url


def _bindable(host: str, port: int, kind: int, option: str, text: str) -> None:
    """InputError unless a socket of type ``kind`` binds ``host:port`` (as pymavlink binds a
    listening link: IPv4, address reuse); the socket is closed again."""
    sock = socket.socket(socket.AF_INET, kind)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind((host, port))
    except OSError as exc:
        raise InputError(f"{option} {text!r}: cannot listen on {host}:{port} ({exc.strerror or exc}); allowed: an "
                         f"address of this machine and a free port, e.g. 0.0.0.0 or 127.0.0.1") from None
    finally:
        sock.close()


def scheduler_address(address: str | None, option: str = "--scheduler") -> str | None:
    """A Dask scheduler address ``[SCHEME://]HOST:PORT`` (scheme one of
    :data:`SCHEDULER_SCHEMES`, default tcp) whose host resolves; None passes."""
    if address is None:
        return None
    form = f"[SCHEME://]HOST:PORT with SCHEME one of {', '.join(SCHEDULER_SCHEMES)} (e.g. tcp://127.0.0.1:8786)"
    scheme, sep, rest = address.partition("://")
    if not sep:
        scheme, rest = "tcp", address
    if scheme not in SCHEDULER_SCHEMES:
        raise InputError(f"{option} {address!r}: scheme {scheme!r} unknown (expected {form})")
    host, port = _host_port(rest, address, option, form)
    _resolve(host, port, option, address, socket.SOCK_STREAM)
    return address


__all__ = ["MAVLINK_KINDS", "MAVLINK_LISTEN_KINDS", "SCHEDULER_SCHEMES", "TURBULENCE_LEVELS",
           "definition_files", "input_dir", "input_file", "integer", "io_file", "mavlink_url", "number", "outputs",
           "scheduler_address", "turbulence"]
