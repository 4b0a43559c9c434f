"""The vehicle's side of the connection: opening it and reading it fairly.

:func:`open_connection` opens a pymavlink connection URL, except ``tcpin:HOST:PORT``, which is
this module's :class:`TcpServer`: pymavlink's TCP server serves one client, the first to
connect, so an idle connection made first locks every ground station out. The server here
serves up to :data:`MAX_TCP_CLIENTS` at once (MAVProxy and QGroundControl side by side, as
``udpin:`` serves every address), each byte stream parsed on its own; telemetry goes to all.
When it is full a new connection replaces the client that has gone longest without a valid
MAVLink message (one that never sent one counts from its connection): an idle or garbage
connection can never keep a ground station out, and a ground station, which sends a heartbeat
every second, is never the one dropped while another is silent. A client that does not read
what it is sent (its unsent data above :data:`MAX_TCP_BACKLOG_BYTES`) is dropped; data is never
cut inside a frame.

:class:`Receiver` reads a connection for the endpoint, one poll at a time, fairly: each peer
(a UDP source address, a TCP client) has its share of a poll's reads
(:data:`PEER_SHARE` of ``max_reads``). On UDP, where all peers share one socket buffer, what a
peer sends beyond its share in one poll is read and dropped unparsed (counted in ``dropped``),
which costs little, so a flood from one peer neither fills the buffer (where the kernel would
drop the ground station's commands with it) nor takes the poll's time. A TCP client beyond its
share is not read until the next poll: its data wait in its own socket, and TCP slows it down.
A UDP server (``udpin:``) answers an address only once it has sent a valid MAVLink message, and
keeps at most :data:`MAX_UDP_CLIENTS` of them (the one silent longest makes room), so junk from
ever new source ports cannot grow its list of destinations.

``open_link(url)`` opens ``udpout``/``udpin``/``udp`` as pymavlink does, ``tcpin`` as :class:`TcpServer`, and ``tcp``
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

import errno
import math
import socket
import time
import weakref
from typing import Any, Callable, Iterator

from pymavlink import mavutil

from fdm_awe.errors import InputError
from fdm_awe.mavlink.framing import StreamParser, parse_datagram

#: ground stations a ``tcpin:`` server serves at once
MAX_TCP_CLIENTS = 8
#: unsent bytes to one TCP client above which it counts as not reading and is dropped
MAX_TCP_BACKLOG_BYTES = 1 << 20
#: addresses a ``udpin:`` connection sends to at most
MAX_UDP_CLIENTS = 16
#: one peer's share of a poll's reads (the rest of what it sends in that poll is dropped unparsed)
PEER_SHARE = 0.25
#: reads per poll, as a multiple of ``max_reads``, spent on dropping a flooding peer's data
DROP_READS_FACTOR = 8
#: receive buffer asked for a UDP socket, bytes (the system may grant less): room for a burst
#: between two polls
UDP_RCVBUF_BYTES = 1 << 21
_AGAIN = (errno.EAGAIN, errno.EWOULDBLOCK)


class TcpClient:
    """One connection to a :class:`TcpServer`."""

    def __init__(self, sock: socket.socket, addr: Any, now: float) -> None:
        self.sock = sock
        self.addr = addr
        self.last_valid = now  #: wall time of its last valid message (its connection time before)
        self.outbox = bytearray()


class TcpServer:
    """``tcpin:HOST:PORT`` for several ground stations at once (see module doc).

    Args:
        host, port: the address to listen on.
        max_clients: connections served at once.
        clock: monotonic wall clock, s.
        log: called with one line when a client comes or goes.
    """

    def __init__(self, host: str, port: int, max_clients: int = MAX_TCP_CLIENTS,
                 clock: Callable[[], float] = time.monotonic,
                 log: Callable[[str], Any] | None = None) -> None:
        self.max_clients = max_clients
        self.clock = clock
        self.log = log or (lambda s: None)
        self.clients: list[TcpClient] = []
        self.listen = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        try:
            self.listen.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            self.listen.bind((host, port))
            self.listen.listen(max_clients)
            self.listen.setblocking(False)
        except OSError:
            self.listen.close()
            raise

    def _accept(self) -> None:
        while True:
            try:
                sock, addr = self.listen.accept()
            except OSError:
                return
            sock.setblocking(False)
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            if len(self.clients) >= self.max_clients:
                self.drop(min(self.clients, key=lambda c: c.last_valid),
                          f"replaced by {addr[0]}:{addr[1]} ({self.max_clients} clients at most)")
            self.clients.append(TcpClient(sock, addr, self.clock()))
            self.log(f"MAVLink: TCP client {addr[0]}:{addr[1]} connected")

    def drop(self, c: TcpClient, why: str) -> None:
        """Close a client's connection."""
        if c in self.clients:
            self.clients.remove(c)
            self.log(f"MAVLink: TCP client {c.addr[0]}:{c.addr[1]} dropped: {why}")
        try:
            c.sock.close()
        except OSError:
            pass

    def accept_new(self) -> None:
        """Take in the clients waiting to connect (what :meth:`recv_round` does first), for a
        sender that does not read (the boot heartbeat, :mod:`fdm_awe.mavlink.boot`)."""
        self._accept()

    def recv_round(self, n: int, skip: set[TcpClient] | frozenset = frozenset()) -> list[tuple[TcpClient, bytes]]:
        """Accept new clients, then one read of up to ``n`` bytes from each client that has data,
        except those in ``skip`` (whose data wait in their socket: TCP slows their sender)."""
        self._accept()
        out = []
        for c in list(self.clients):
            if c.outbox:
                self._flush(c)
            if c in skip or c not in self.clients:
                continue
            try:
                data = c.sock.recv(n)
            except OSError as e:
                if e.errno not in _AGAIN:
                    self.drop(c, f"{e.strerror or e}")
                continue
            if not data:
                self.drop(c, "closed by the client")
                continue
            out.append((c, data))
        return out

    def _flush(self, c: TcpClient) -> None:
        try:
            sent = c.sock.send(c.outbox)
        except OSError as e:
            if e.errno not in _AGAIN:
                self.drop(c, f"{e.strerror or e}")
            sent = 0
        del c.outbox[:sent]
        if len(c.outbox) > MAX_TCP_BACKLOG_BYTES:
            self.drop(c, f"not reading ({len(c.outbox)} bytes unsent)")

    def write(self, buf: bytes) -> None:
        """Send ``buf`` to every client (what a client cannot take now waits in its outbox)."""
        for c in list(self.clients):
            c.outbox += buf
            self._flush(c)

    def close(self) -> None:
        for c in list(self.clients):
            self.drop(c, "vehicle closed")
        self.listen.close()


def open_connection(url: str, sysid: int, compid: int,
                    log: Callable[[str], Any] | None = None) -> Any:
    """The connection of ``url``: a :class:`TcpServer` for ``tcpin:HOST:PORT``, else pymavlink's
    (exceptions as they come: the endpoint turns them into one line)."""
    if url.startswith("tcpin:"):
        host, _, port = url[len("tcpin:"):].rpartition(":")
        if not host or not port.isdigit():
            raise ValueError("TCP ports must be specified as host:port")
        return TcpServer(host, int(port), log=log)
    return mavutil.mavlink_connection(url, source_system=sysid, source_component=compid, autoreconnect=True)


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
              connect_timeout_s: float = TCP_CONNECT_TIMEOUT_S, log: Callable[[str], Any] | None = None) -> Any:
    """The pymavlink connection of ``url`` (``KIND:HOST:PORT``; a ``tcp`` client connected once
    within ``connect_timeout_s`` [s]); :class:`~fdm_awe.errors.InputError` naming ``option``
    when it cannot be opened (an address this machine cannot bind, a refused or unanswered
    connection); ``tcpin`` is a :class:`TcpServer` (``log`` gets its notes)."""
    try:
        if url.startswith("tcp:"):
            return BoundedTcp(url[len("tcp:"):], connect_timeout_s, autoreconnect=True, source_system=source_system,
                              source_component=source_component)
        return open_connection(url, source_system, source_component, log=log)
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


class Receiver:
    """Incoming data of ``conn`` as messages, poll by poll, each peer within its share (see
    module doc).

    Args:
        conn: the connection (:func:`open_connection`).
        codec: the pymavlink codec that decodes and checks signatures.
        max_reads: reads (datagrams, stream reads) parsed per poll at most.

    Attributes:
        stats: ``reads`` (parsed), ``dropped`` (UDP datagrams beyond a peer's share, not parsed),
            ``read_errors``.
    """

    def __init__(self, conn: Any, codec: Any, max_reads: int) -> None:
        self.conn = conn
        self.codec = codec
        self.max_reads = max_reads
        self.share = max(1, int(max_reads * PEER_SHARE))
        self.stats = {"reads": 0, "dropped": 0, "read_errors": 0}
        self._udp = isinstance(conn, mavutil.mavudp)
        if self._udp:
            try:
                conn.port.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, UDP_RCVBUF_BYTES)
            except OSError:
                pass
        self._mcast = isinstance(conn, mavutil.mavmcast)
        self._parsers: "weakref.WeakKeyDictionary[TcpClient, StreamParser]" = weakref.WeakKeyDictionary()
        self._stream = StreamParser(codec)

    def poll(self) -> Iterator[tuple[list[Any], int]]:
        """``(messages, bad)`` of each read of this poll (see module doc)."""
        if isinstance(self.conn, TcpServer):
            yield from self._poll_tcp_server()
        elif self._udp:
            yield from self._poll_udp()
        else:
            yield from self._poll_plain()

    def _poll_plain(self) -> Iterator[tuple[list[Any], int]]:
        """One peer: a stream (TCP client, serial) or UDP multicast."""
        for _ in range(self.max_reads):
            try:
                data = self.conn.recv(4096)
            except Exception:  # noqa: BLE001 - a transport error is not fatal; try next poll
                self.stats["read_errors"] += 1
                return
            if not data:
                return
            self.stats["reads"] += 1
            yield parse_datagram(self.codec, data) if self._mcast else self._stream.feed(data)

    def _poll_udp(self) -> Iterator[tuple[list[Any], int]]:
        conn = self.conn
        port = conn.port
        counts: dict[Any, int] = {}
        parsed = 0
        for _ in range(self.max_reads * DROP_READS_FACTOR):
            try:
                data, addr = port.recvfrom(65535)
            except OSError as e:
                if e.errno in _AGAIN:
                    return
                if e.errno != errno.ECONNREFUSED:   # (an earlier send refused: no read error)
                    self.stats["read_errors"] += 1
                continue   # the error is consumed; the next read works
            k = counts.get(addr, 0) + 1
            counts[addr] = k
            if k > self.share:
                self.stats["dropped"] += 1
                continue
            self.stats["reads"] += 1
            msgs, bad = parse_datagram(self.codec, data)
            if msgs and conn.udp_server:
                self._udp_client(addr)
            elif msgs and conn.broadcast:
                conn.last_address = addr   # udpbcast: answer the first that answers (pymavlink's rule)
            yield msgs, bad
            parsed += 1
            if parsed >= self.max_reads:
                return

    def _udp_client(self, addr: Any) -> None:
        """Answer ``addr`` from now on (pymavlink's list of ``udpin:`` destinations), at most
        :data:`MAX_UDP_CLIENTS` of them."""
        conn = self.conn
        now = time.time()
        if addr not in conn.clients and len(conn.clients) >= MAX_UDP_CLIENTS:
            old = min(conn.clients, key=lambda a: conn.clients_last_alive.get(a, 0.0))
            conn.clients.discard(old)
            conn.clients_last_alive.pop(old, None)
        conn.clients.add(addr)
        conn.clients_last_alive[addr] = now

    def _poll_tcp_server(self) -> Iterator[tuple[list[Any], int]]:
        server: TcpServer = self.conn
        counts: dict[TcpClient, int] = {}
        full: set[TcpClient] = set()
        parsed = 0
        while parsed < self.max_reads:
            got = server.recv_round(4096, full)
            if not got:
                return
            for c, data in got:
                parser = self._parsers.get(c)
                if parser is None:
                    parser = self._parsers[c] = StreamParser(self.codec)
                self.stats["reads"] += 1
                msgs, bad = parser.feed(data)
                if any(m.get_type() != "BAD_DATA" for m in msgs):
                    c.last_valid = server.clock()
                yield msgs, bad
                parsed += 1
                counts[c] = counts.get(c, 0) + 1
                if counts[c] >= self.share:
                    full.add(c)   # its share of this poll is used: the rest waits for the next
