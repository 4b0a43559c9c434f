"""The vehicle's heartbeat while the rest loads: a ground station sees it about a second after launch.

Between opening the ``--mavlink`` link and the flight's first step the command reads the
reference, optimises one when it has none, sets JSBSim up and compiles the step's kernels: 17.5 s
from launch to the first HEARTBEAT of a stored reference's flight, before this beacon. An
autopilot boots the same way and says so: :class:`BootBeacon` sends a HEARTBEAT each second from
a thread on the opened link (fixed wing, the ArduPilot identity of
:mod:`fdm_awe.mavlink.messages`, the start mode's ``custom_mode``, ``MAV_STATE_BOOT``, signed
with the link's key when there is one) until :meth:`BootBeacon.stop`, which the flight calls
before its endpoint's first update, so only one thread ever writes to the link at a time. It
answers nothing: parameters, missions and commands wait for the endpoint (a ground station
asks again). On ``tcpin:`` it takes in the ground stations that connect meanwhile, so they see
it too.
"""

from __future__ import annotations

import threading
from typing import Any

from pymavlink.dialects.v20 import common as mav

from . import signing as _signing
from ..mode_table import MODE_NUMBERS

#: seconds between two boot heartbeats
PERIOD_S = 1.0


class BootBeacon:
    """HEARTBEAT with MAV_STATE_BOOT on ``conn`` every :data:`PERIOD_S` until :meth:`stop`.

    Args:
        conn: the opened pymavlink connection (:func:`fdm_awe.mavlink.transport.open_link`).
        mode: the start mode's name (a key of MODE_NUMBERS).
        sysid, compid: the vehicle's MAVLink ids.
        signing_key: the link's 32-byte key (None: unsigned).
    """

    def __init__(self, conn: Any, mode: str = "AUTO", sysid: int = 1, compid: int = mav.MAV_COMP_ID_AUTOPILOT1,
                 signing_key: bytes | None = None) -> None:
        self._conn = conn
        self._codec = _signing.Codec(conn, srcSystem=sysid, srcComponent=compid)
        self._signer = _signing.Signer([self._codec], signing_key)
        self._custom = MODE_NUMBERS.get(mode, 0)
        self._stop = threading.Event()
        self.sent = 0  #: heartbeats sent
        self._thread = threading.Thread(target=self._run, name="mavlink-boot-heartbeat", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                accept = getattr(self._conn, "accept_new", None)  # tcpin: ground stations connecting now
                if accept is not None:
                    accept()
                self._signer.tick()
                self._codec.heartbeat_send(mav.MAV_TYPE_FIXED_WING, mav.MAV_AUTOPILOT_ARDUPILOTMEGA,
                                           mav.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, self._custom, mav.MAV_STATE_BOOT)
                self.sent += 1
            except Exception:  # noqa: BLE001 - a link that cannot send yet is tried again next second
                pass
            self._stop.wait(PERIOD_S)

    def stop(self) -> None:
        """Stop sending and wait for the thread (idempotent); the link is the caller's again."""
        self._stop.set()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(timeout=5.0)
