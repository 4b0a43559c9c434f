"""The MAVLink transport: a pymavlink connection opened from a ``KIND:HOST:PORT`` address, with a
TCP client that connects once, bounded in time.

``open_link(url)`` opens ``udpout``/``udpin``/``udp``/``tcpin`` as pymavlink does and ``tcp``
(client) with :class:`BoundedTcp`: pymavlink's own TCP client retries a refused connection
with a 1 s sleep and a "Connection refused sleeping" line per attempt, and a connection to an
unreachable host waits for the operating system's timeout (minutes). Here a connection is
tried once, within :data:`TCP_CONNECT_TIMEOUT_S`, and a failure is one
:class:`~fdm_awe.errors.InputError` line naming the option; a reconnection after the ground
station closed the link is one such attempt too (an unreachable station costs the flight at most
that long per attempt, at most one attempt per :data:`RECONNECT_INTERVAL_S` of wall-clock time,
never an endless retry; between attempts the link reads nothing and sends nothing).

``fdm-awe fly`` opens the link before any work (after the option checks), so a ground station
that is not there is said at once, and hands it to the
:class:`~fdm_awe.mavlink.endpoint.MavlinkEndpoint` of the flight.
"""

from __future__ import annotations

import math
import socket
import time
from typing import Any

from pymavlink import mavutil

from fdm_awe.errors import InputError

#: how long a TCP client waits for the ground station to accept the connection [s] (one attempt)
TCP_CONNECT_TIMEOUT_S = 3.0
#: wall-clock time between two reconnection attempts of a TCP client [s]
RECONNECT_INTERVAL_S = 1.0


class BoundedTcp(mavutil.mavtcp):
    """pymavlink's TCP client with one connection attempt of at most ``connect_timeout_s`` [s]
    (also when it reconnects), instead of retries with sleeps and the system's timeout."""

    def __init__(self, device: str, connect_timeout_s: float = TCP_CONNECT_TIMEOUT_S, **kw: Any) -> None:
        self.connect_timeout_s = float(connect_timeout_s)
        self._next_attempt = -math.inf
        super().__init__(device, **kw)

    def reconnect(self) -> None:
        """One attempt to connect again (with ``autoreconnect``), at most one per
        :data:`RECONNECT_INTERVAL_S`; a failure leaves the link closed until the next."""
        if not self.autoreconnect:
            return
        now = time.monotonic()
        if now < self._next_attempt:
            return
        self._next_attempt = now + RECONNECT_INTERVAL_S
        self.close()
        try:
            self.do_connect()
        except OSError:
            self.port = None

    def recv(self, n: int | None = None) -> Any:
        if self.port is None:
            self.reconnect()
            if self.port is None:
                return b""
        return super().recv(n)

    def do_connect(self) -> None:
        self.port = None
        sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)  # pymavlink's links are IPv4
        try:
            sock.settimeout(self.connect_timeout_s)
            sock.connect(self.destination_addr)
            sock.setblocking(False)
            mavutil.set_close_on_exec(sock.fileno())
            sock.setsockopt(socket.SOL_TCP, socket.TCP_NODELAY, 1)
        except BaseException:
            sock.close()
            raise
        self.port = sock

    def close(self) -> None:
        if self.port is not None:
            self.port.close()
            self.port = None


def open_link(url: str, source_system: int = 1, source_component: int = 1, option: str = "--mavlink",
              connect_timeout_s: float = TCP_CONNECT_TIMEOUT_S) -> Any:
    """The pymavlink connection of ``url`` (``KIND:HOST:PORT``; a ``tcp`` client connected once
    within ``connect_timeout_s`` [s]); :class:`~fdm_awe.errors.InputError` naming ``option``
    when it cannot be opened (an address this machine cannot bind, a refused or unanswered
    connection)."""
    try:
        if url.startswith("tcp:"):
            return BoundedTcp(url[len("tcp:"):], connect_timeout_s, autoreconnect=True, source_system=source_system,
                              source_component=source_component)
        return mavutil.mavlink_connection(url, source_system=source_system, source_component=source_component,
                                          autoreconnect=True)
    except socket.timeout:
        raise InputError(f"{option} {url!r}: no answer from {url.partition(':')[2]} within {connect_timeout_s:g} s "
                         f"(one attempt); is a ground station listening there?") from None
    except OSError as e:
        reason = e.strerror or str(e)
        if url.startswith("tcp:"):
            raise InputError(f"{option} {url!r}: cannot connect to {url.partition(':')[2]} ({reason}; one attempt); "
                             f"is a ground station listening there?") from None
        raise InputError(f"{option} {url!r}: cannot open ({reason})") from None
    except Exception as e:  # noqa: BLE001 - pymavlink raises many types for bad URLs
        raise InputError(f"{option} {url!r}: cannot open ({type(e).__name__}: {e})") from None


def close_link(conn: Any) -> None:
    """Close a connection of :func:`open_link`, whatever state it is in."""
    try:
        conn.close()
    except Exception:  # noqa: BLE001 - closing is best effort
        pass


__all__ = ["BoundedTcp", "RECONNECT_INTERVAL_S", "TCP_CONNECT_TIMEOUT_S", "close_link", "open_link"]
