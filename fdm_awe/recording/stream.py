"""A flight streamed live to a rerun viewer while it is flown (``fdm-awe fly --spawn / --connect``).

:class:`ViewerSink` is a recording sent over gRPC instead of into a file: to a viewer started
for it (``--spawn``; rerun's viewer program, found like the ``rerun`` command, on rerun's
default port) or to one already running (``--connect [ADDR]``, default
:data:`DEFAULT_URL`, rerun's own default). :class:`LiveFlight` is the step callback: it
buffers every step (:class:`~fdm_awe.recording.live.StepBuffer`, here with the velocity, the
tether force and the control commands) and sends the new rows about every ``flush_s`` seconds
of wall-clock time through the same functions that write a recording file
(:func:`~fdm_awe.recording.flight.log_flight_rows`), so the viewer shows what the file will
hold: the glider mesh in its attitude, the tether, the force arrows, every plot, the phase
lane, the mode lane, the path flown so far (every second of flight time), both timelines. A row
is sent once its successor is known (the forces use central differences); the last one with
the flight's end, followed by the whole flown path, the event log and the report.
The tracking error and the reference marker exist only in the report: the file has them, the
live view does not.

The checks (:func:`check_live_args`) run before any work and fail with one line (exit 2):
the address's form, a viewer listening there (``--connect``), the viewer program and a display
(``--spawn``).
"""

from __future__ import annotations

import argparse
import math
import os
import socket
import sys
import time
from typing import Any
from urllib.parse import urlsplit

from .live import STEP_FIELDS, StepBuffer
from .rrd import RecordingSink, new_stream

#: rerun's default viewer port and address
DEFAULT_PORT = 9876
DEFAULT_URL = f"rerun+http://127.0.0.1:{DEFAULT_PORT}/proxy"
#: URL schemes of a rerun viewer's gRPC address
SCHEMES = ("rerun", "rerun+http", "rerun+https")
#: the cumulative energies, continued from one sent slice to the next
_ENERGIES = ("E_generated", "E_thrust", "E_reel_in", "E_net")


def add_live_arguments(p: argparse.ArgumentParser) -> None:
    """``--spawn`` and ``--connect [ADDR]`` (one of them)."""
    g = p.add_mutually_exclusive_group()
    g.add_argument("--spawn", action="store_true",
                   help="stream the flight live to a rerun viewer started for it (rerun's viewer program and a display)")
    g.add_argument("--connect", metavar="ADDR", nargs="?", const=DEFAULT_URL,
                   help="stream the flight live to a running rerun viewer: rerun+http://HOST:PORT/proxy (rerun:// and "
                        f"rerun+https:// too) or a local PORT (default {DEFAULT_URL})")


def viewer_url(addr: str) -> str:
    """The gRPC URL of ``addr`` (a rerun URL whose path is ``/proxy``, or a local port); raises
    :class:`~fdm_awe.errors.InputError` (one line) for anything else."""
    from ..errors import InputError

    a = addr.strip()
    if a.isdigit():
        a = f"rerun+http://127.0.0.1:{int(a)}/proxy"
    u = urlsplit(a)
    try:
        port = u.port
    except ValueError:
        port = -1
    if u.scheme not in SCHEMES or not u.hostname or u.path != "/proxy" or port == -1 or port == 0:
        raise InputError(f"--connect {addr}: not a rerun viewer address (rerun+http://HOST:PORT/proxy, rerun://..., "
                         f"rerun+https://..., or a port 1..65535)")
    return a


def _host_port(url: str) -> tuple[str, int]:
    u = urlsplit(url)
    return str(u.hostname), u.port or (443 if u.scheme == "rerun+https" else DEFAULT_PORT)


def check_live_args(args: argparse.Namespace) -> None:
    """``--connect``: the address's form and a viewer listening there; ``--spawn``: the viewer
    program and, on Linux, a display. Sets ``args.connect`` to the full URL."""
    from ..errors import InputError

    if getattr(args, "connect", None) is not None:
        args.connect = viewer_url(args.connect)
        host, port = _host_port(args.connect)
        try:
            socket.create_connection((host, port), timeout=2.0).close()
        except OSError as exc:
            raise InputError(f"--connect {args.connect}: no viewer listens there ({exc.strerror or exc}); start one "
                             f"(rerun) or use --spawn") from None
    if getattr(args, "spawn", False):
        from .inspect import rerun_cli

        try:
            rerun_cli()
        except FileNotFoundError:
            raise InputError("--spawn: rerun's viewer program was not found (pip install rerun-sdk); stream to a viewer "
                             "started elsewhere with --connect, or record with --rrd") from None
        if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
            raise InputError("--spawn: no display for a viewer window (DISPLAY and WAYLAND_DISPLAY unset); stream to a "
                             "viewer elsewhere with --connect, or record with --rrd")


class ViewerSink(RecordingSink):
    """A recording streamed to a viewer: started for it (``spawn``, on ``port``) or running at
    ``url``; ``blueprint`` its default layout, ``name`` the recording's name."""

    def __init__(self, *, url: str | None = None, spawn: bool = False, blueprint: Any = None, name: str | None = None,
                 port: int = DEFAULT_PORT) -> None:
        import rerun as rr

        self.rr = rr
        self.rec = new_stream()
        if spawn:
            from .inspect import rerun_cli

            rr.spawn(port=port, connect=True, executable_path=rerun_cli(), default_blueprint=blueprint,
                     recording=self.rec, hide_welcome_screen=True)
        else:
            self.rec.connect_grpc(url or DEFAULT_URL, default_blueprint=blueprint)
        if name:
            self.rec.send_recording_name(name)
        self._open = True

    def close(self, timeout_s: float = 10.0) -> bool:
        """Send what is buffered (at most ``timeout_s``) and disconnect (idempotent). A viewer
        gone meanwhile is told in one warning line; returns whether everything was sent."""
        if not self._open:
            return True
        self._open = False
        try:
            try:
                self.rec.flush(timeout_sec=timeout_s)
            finally:
                self.rec.disconnect()
        except Exception as exc:  # noqa: BLE001 - the flight's own outputs do not depend on the viewer
            print(f"warning: the live view lost data: {exc}", file=sys.stderr)
            return False
        return True


class LiveFlight(StepBuffer):
    """Step callback and ``setup`` hook streaming a flight of ``reference`` to ``sink`` (the
    static scene is sent at once); :meth:`finish` sends the rest and closes the sink."""

    fields = STEP_FIELDS + ("vn", "ve", "vd", "fx", "fy", "fz", "aileron", "elevator", "rudder", "throttle", "fold_cmd")

    def __init__(self, sink: RecordingSink, reference: Any = None, *, flush_s: float = 0.2, scene_hz: float = 30.0,
                 chain: Any = None, aircraft: Any = None) -> None:
        from .flight import RowsSent, log_flight_start
        from .forces import glider_mass

        super().__init__(chain=chain)
        self.sink = sink
        self.flush_s = flush_s
        self.scene_hz = scene_hz
        self._glider: Any = None
        self._next = 0  # the first row not sent yet
        self._sent = RowsSent()
        self._energy: dict[str, float] = {}
        self._last = time.monotonic()
        self.aircraft = aircraft  #: the glider flown (an Aircraft; None: the package's glider)
        self._mass = glider_mass(aircraft)  # kg
        log_flight_start(sink, reference, aircraft=aircraft)

    @classmethod
    def open(cls, reference: Any, *, url: str | None = None, spawn: bool = False, **kw: Any) -> "LiveFlight":
        """Connect (``url``) or spawn a viewer for a flight of ``reference`` (its layout and name)."""
        from .blueprint import flight_blueprint
        from .flight import describe

        meta = dict(getattr(reference, "meta", None) or {})
        title = describe(meta, "live flight")
        return cls(ViewerSink(url=url, spawn=spawn, blueprint=flight_blueprint(title), name=title), reference, **kw)

    def setup(self, autopilot: Any, cosim: Any = None) -> None:
        self._glider = getattr(cosim, "glider", None)  # its control commands, read by _row
        super().setup(autopilot, cosim)

    def _row(self, s: Any, o: Any) -> tuple:
        nan = math.nan
        force = (nan, nan, nan) if o is None else tuple(s.tether_force_ned)  # the force of the step just flown
        c = getattr(self._glider, "controls", None)
        ctl = (nan,) * 5 if c is None else (c.aileron, c.elevator, c.rudder, c.throttle, c.fold_cmd)
        return super()._row(s, o) + tuple(s.vel_ned) + force + ctl

    def __call__(self, k: int, s: Any, o: Any) -> None:
        super().__call__(k, s, o)
        if time.monotonic() - self._last >= self.flush_s:
            self.flush()

    def flush(self, final: bool = False) -> None:
        """Send the rows whose successor is known (``final``: all of them)."""
        from .flight import log_flight_rows
        from .forces import flight_forces
        from .series import flight_series

        self._last = time.monotonic()
        n = len(self.rows)
        end = n if final else n - 1
        if end <= self._next:
            return
        first = max(self._next - 1, 0)  # one row already sent before the new ones: differences, energies
        res = self.partial_result("live", rows=slice(first, n))
        s = flight_series(res)
        s.t = s.t + (self.rows[first][0] - self.rows[0][0])  # onto the flight's time axis
        for key in _ENERGIES:
            unit, v = s.columns[key]
            s.columns[key] = (unit, v + self._energy.get(key, 0.0))
        self._sent = log_flight_rows(self.sink, res, s, flight_forces(res, self._mass), self._sent,
                                     rows=slice(self._next - first, end - first), scene_hz=self.scene_hz,
                                     aircraft=self.aircraft)
        self._energy = {key: float(s[key][end - 1 - first]) for key in _ENERGIES}
        self._next = end

    def finish(self, report: Any = None) -> None:
        """Send the last rows, then the flown path, the event log and the report of ``report``
        (the buffered steps without one), and close the sink."""
        from .flight import log_flight_end
        from .series import flight_series

        try:
            self.flush(final=True)
            flight = report if report is not None else self.partial_result("unfinished")
            log_flight_end(self.sink, flight, flight_series(flight))
        finally:
            self.close()

    def close(self) -> None:
        close = getattr(self.sink, "close", None)
        if close is not None:
            close()


def open_live(args: argparse.Namespace, reference: Any) -> LiveFlight | None:
    """The live stream ``fdm-awe fly`` asked for (``--spawn`` / ``--connect``, checked by
    :func:`check_live_args`), or None."""
    if getattr(args, "spawn", False) or getattr(args, "connect", None):
        return LiveFlight.open(reference, url=args.connect, spawn=args.spawn, aircraft=getattr(args, "aircraft_def", None))
    return None


__all__ = ["DEFAULT_PORT", "DEFAULT_URL", "LiveFlight", "ViewerSink", "add_live_arguments", "check_live_args",
           "open_live", "viewer_url"]
