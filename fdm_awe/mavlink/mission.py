"""The mission protocol: the vehicle's path as a MAVLink mission, both ways.

MAV_MISSION_TYPE_MISSION only; fence and rally lists are empty (a download counts 0 items, an
upload of 0 items and MISSION_CLEAR_ALL are accepted). Download sends the vehicle's path as
MISSION_ITEM_INT (MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, MAV_CMD_NAV_WAYPOINT, altitude relative
to home = the winch), or MISSION_ITEM to a MISSION_REQUEST; the list is fixed at
MISSION_REQUEST_LIST until the ground station's MISSION_ACK; the item flown to (MISSION_CURRENT's
``seq``) carries ``current`` = 1, so the list uploads back as it came (MAVSDK's ``mission_raw``
checks it). Upload accepts MISSION_ITEM_INT
and MISSION_ITEM in the GLOBAL(_RELATIVE_ALT)(_INT) frames, re-requests an item after
``mission_timeout_s`` (wall clock) up to ``mission_retries`` times, and rejects with
MAV_MISSION_NO_SPACE (over ``max_mission_items``), UNSUPPORTED_FRAME, UNSUPPORTED (not a
waypoint), INVALID_PARAM5_X/6_Y/7 (bad latitude/longitude/altitude or farther than
``max_range_m`` from home), OPERATION_CANCELLED (timeout) or INVALID (the vehicle's
``set_mission`` refused; the reason goes out as STATUSTEXT). An upload of zero items and
MISSION_CLEAR_ALL clear the mission. The limits are the endpoint's attributes.

A mission item carries a position only, not the cycle's phases, timing, tension, reel speed,
fold or motor: the vehicle's own path uploaded back (a download, then MAVProxy's ``wp save``
and ``wp load``) is recognised by the vehicle (``set_mission`` answers ``"own path"``) and
keeps its cycle, told by a STATUSTEXT; any other path replaces the reference.
"""

from __future__ import annotations

import functools
import math
from typing import Any, Callable

from pymavlink.dialects.v20 import common as mav

from .link import Link
from .messages import current_item
from ..autopilot.vehicle import Waypoint


_MISSION = mav.MAV_MISSION_TYPE_MISSION
_EMPTY_TYPES = (mav.MAV_MISSION_TYPE_FENCE, mav.MAV_MISSION_TYPE_RALLY)
_GLOBAL_FRAMES_REL = (mav.MAV_FRAME_GLOBAL_RELATIVE_ALT, mav.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT)
_GLOBAL_FRAMES_AMSL = (mav.MAV_FRAME_GLOBAL, mav.MAV_FRAME_GLOBAL_INT)


#: why an uploaded item is refused (its STATUSTEXT), by MAV_MISSION_RESULT
_ITEM_REASONS: dict[int, str] = {
    mav.MAV_MISSION_UNSUPPORTED_FRAME: "frame unsupported: GLOBAL or GLOBAL_RELATIVE_ALT only",
    mav.MAV_MISSION_INVALID_PARAM5_X: "latitude invalid or too far from home",
    mav.MAV_MISSION_INVALID_PARAM6_Y: "longitude invalid or too far from home",
    mav.MAV_MISSION_INVALID_PARAM7: "altitude outside -1000..20000 m",
}


def _addressed(fn: Callable[[Any, Any, int, tuple[int, int]], None]) -> Callable[[Any, Any], None]:
    """A handler of messages addressed to this vehicle: called as ``fn(self, m, mission_type,
    source)``; a message for another system or component is ignored."""

    @functools.wraps(fn)
    def handler(self: Any, m: Any) -> None:
        if self._ep.for_me(m):
            fn(self, m, getattr(m, "mission_type", 0), _source(m))

    return handler


class _Upload:
    """State of a mission upload from a ground station (times: wall clock, s)."""

    __slots__ = ("gcs", "count", "items", "expected", "last_req", "retries")

    def __init__(self, gcs: tuple[int, int], count: int, now: float) -> None:
        self.gcs = gcs
        self.count = count
        self.items: list[Waypoint] = []
        self.expected = 0
        self.last_req = now
        self.retries = 0


def _source(m: Any) -> tuple[int, int]:
    return m.get_srcSystem(), m.get_srcComponent()


class MissionProtocol:
    """Mission download and upload for ``ep``'s vehicle (see module doc).

    Attributes:
        upload: the upload under way, or None.
    """

    def __init__(self, ep: Link) -> None:
        self._ep = ep
        self.upload: _Upload | None = None
        self._download: list[tuple[int, int, float]] | None = None

    def _ack(self, dest: tuple[int, int], result: int, mission_type: int) -> None:
        self._ep.send("MISSION_ACK", self._ep.mav.mission_ack_send, dest[0], dest[1], result, mission_type)

    def _request_item(self, dest: tuple[int, int], seq: int) -> None:
        self._ep.send("MISSION_REQUEST_INT", self._ep.mav.mission_request_int_send, dest[0], dest[1],
                       seq, _MISSION)

    # ------------------------------------------------------------------ download
    def _snapshot(self) -> list[tuple[int, int, float]]:
        """The vehicle's path as (lat 1e-7 deg, lon 1e-7 deg, altitude above home m) items."""
        ep = self._ep
        if ep.vehicle is None:
            return []
        out = []
        for wp in ep.vehicle.mission():
            lat, lon, _alt = ep.geo.to_geodetic(wp.north, wp.east, wp.down)
            out.append((int(round(lat * 1e7)), int(round(lon * 1e7)), float(-wp.down)))
        return out

    @_addressed
    def on_request_list(self, m: Any, mt: int, src: tuple[int, int]) -> None:
        """MISSION_REQUEST_LIST: the number of items (fixes the list being downloaded)."""
        ep = self._ep
        if mt == _MISSION:
            self._download = self._snapshot()
            n = len(self._download)
        elif mt in _EMPTY_TYPES:
            n = 0
        else:
            self._ack(src, mav.MAV_MISSION_UNSUPPORTED, mt)
            return
        ep.send("MISSION_COUNT", ep.mav.mission_count_send, src[0], src[1], n, mt)

    @_addressed
    def on_request(self, m: Any, mt: int, src: tuple[int, int]) -> None:
        """MISSION_REQUEST_INT / MISSION_REQUEST: one item, in the form asked for."""
        ep = self._ep
        if mt != _MISSION:
            self._ack(src, mav.MAV_MISSION_INVALID_SEQUENCE, mt)
            return
        if self._download is None:
            self._download = self._snapshot()
        items = self._download
        if not 0 <= m.seq < len(items):
            self._ack(src, mav.MAV_MISSION_INVALID_SEQUENCE, mt)
            return
        x, y, z = items[m.seq]
        current = 1 if m.seq == current_item(ep.telemetry(), len(items)) else 0
        if m.get_type() == "MISSION_REQUEST_INT":
            ep.send("MISSION_ITEM_INT", ep.mav.mission_item_int_send, src[0], src[1], m.seq,
                     mav.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, mav.MAV_CMD_NAV_WAYPOINT, current, 1,
                     0.0, 0.0, 0.0, 0.0, x, y, z, mt)
        else:
            ep.send("MISSION_ITEM", ep.mav.mission_item_send, src[0], src[1], m.seq,
                     mav.MAV_FRAME_GLOBAL_RELATIVE_ALT, mav.MAV_CMD_NAV_WAYPOINT, current, 1,
                     0.0, 0.0, 0.0, 0.0, x * 1e-7, y * 1e-7, z, mt)

    @_addressed
    def on_ack(self, m: Any, mt: int, src: tuple[int, int]) -> None:
        """MISSION_ACK: a download ends; an upload from the same station is cancelled."""
        if mt != _MISSION:
            return
        self._download = None   # download finished (or cancelled by the ground station)
        up = self.upload
        if up is not None and up.gcs == src:
            self.upload = None
            self._ep.warn("MAVLink: mission upload cancelled by the ground station")

    @_addressed
    def on_clear_all(self, m: Any, mt: int, src: tuple[int, int]) -> None:
        """MISSION_CLEAR_ALL: clear the vehicle's mission (fence and rally: nothing to clear)."""
        ep = self._ep
        if mt in (_MISSION, mav.MAV_MISSION_TYPE_ALL):
            if ep.vehicle is None:
                self._ack(src, mav.MAV_MISSION_ERROR, mt)
                return
            ep.vehicle.clear_mission()
            self._download = None
            ep.info("MAVLink: mission cleared")
        elif mt not in _EMPTY_TYPES:
            self._ack(src, mav.MAV_MISSION_UNSUPPORTED, mt)
            return
        self._ack(src, mav.MAV_MISSION_ACCEPTED, mt)

    # ------------------------------------------------------------------ upload
    @_addressed
    def on_count(self, m: Any, mt: int, src: tuple[int, int]) -> None:
        """MISSION_COUNT: start an upload (or clear the mission for 0 items)."""
        ep = self._ep
        if mt != _MISSION:
            ok = m.count == 0 and mt in _EMPTY_TYPES
            self._ack(src, mav.MAV_MISSION_ACCEPTED if ok else mav.MAV_MISSION_UNSUPPORTED, mt)
            return
        if ep.vehicle is None:
            self._ack(src, mav.MAV_MISSION_ERROR, mt)
            return
        if m.count > ep.max_mission_items:
            self.upload = None
            ep.warn(f"MAVLink: mission of {m.count} items refused (max {ep.max_mission_items})")
            self._ack(src, mav.MAV_MISSION_NO_SPACE, mt)
            return
        if m.count == 0:
            self.upload = None
            ep.vehicle.clear_mission()
            ep.info("MAVLink: empty mission uploaded; mission cleared")
            self._ack(src, mav.MAV_MISSION_ACCEPTED, mt)
            return
        self.upload = _Upload(src, m.count, ep.clock())
        self._request_item(src, 0)

    def check_timeout(self, now: float) -> None:
        """Re-request the awaited item after ``mission_timeout_s`` (``now``: wall clock, s);
        cancel the upload after ``mission_retries`` re-requests."""
        ep = self._ep
        up = self.upload
        if up is None or now - up.last_req < ep.mission_timeout_s:
            return
        if up.retries >= ep.mission_retries:
            self.upload = None
            ep.warn(f"MAVLink: mission upload timed out waiting for item {up.expected}")
            self._ack(up.gcs, mav.MAV_MISSION_OPERATION_CANCELLED, _MISSION)
            return
        up.retries += 1
        up.last_req = now
        self._request_item(up.gcs, up.expected)

    def _item_to_waypoint(self, m: Any) -> tuple[int, Waypoint | None]:
        """Validate one uploaded item -> (MAV_MISSION_RESULT, waypoint or None)."""
        if m.command != mav.MAV_CMD_NAV_WAYPOINT:
            return mav.MAV_MISSION_UNSUPPORTED, None
        if m.frame in _GLOBAL_FRAMES_REL:
            relative = True
        elif m.frame in _GLOBAL_FRAMES_AMSL:
            relative = False
        else:
            return mav.MAV_MISSION_UNSUPPORTED_FRAME, None
        scale = 1e-7 if m.get_type() == "MISSION_ITEM_INT" else 1.0
        lat, lon, z = float(m.x) * scale, float(m.y) * scale, float(m.z)
        if not (math.isfinite(lat) and -90.0 <= lat <= 90.0):
            return mav.MAV_MISSION_INVALID_PARAM5_X, None
        if not (math.isfinite(lon) and -180.0 <= lon <= 180.0):
            return mav.MAV_MISSION_INVALID_PARAM6_Y, None
        if not (math.isfinite(z) and -1000.0 <= z <= 20000.0):
            return mav.MAV_MISSION_INVALID_PARAM7, None
        geo = self._ep.geo
        alt = geo.home.alt_m + z if relative else z
        n, e, d = geo.to_ned(lat, lon, alt)
        if abs(n) > self._ep.max_range_m:
            return mav.MAV_MISSION_INVALID_PARAM5_X, None
        if abs(e) > self._ep.max_range_m:
            return mav.MAV_MISSION_INVALID_PARAM6_Y, None
        return mav.MAV_MISSION_ACCEPTED, Waypoint(n, e, d)

    @_addressed
    def on_item(self, m: Any, mt: int, src: tuple[int, int]) -> None:
        """MISSION_ITEM_INT / MISSION_ITEM of the upload under way: validate and store it,
        ask for the next one; after the last, hand the path to the vehicle."""
        ep = self._ep
        up = self.upload
        if up is None or src != up.gcs or mt != _MISSION:
            return  # not part of an upload we run: ignore
        if m.seq != up.expected:
            if m.seq > up.expected:  # we missed one: ask again for the one we need
                up.last_req = ep.clock()
                self._request_item(src, up.expected)
            return
        result, wp = self._item_to_waypoint(m)
        if wp is None:
            self.upload = None
            why = _ITEM_REASONS.get(result, "invalid")
            if result == mav.MAV_MISSION_UNSUPPORTED:
                why = f"command {m.command} unsupported: waypoints only (the cycle is a path)"
            ep.warn(f"MAVLink: mission item {m.seq} rejected (MAV_MISSION_RESULT {result}: {why})")
            ep.statustext(f"mission item {m.seq} refused: {why}", mav.MAV_SEVERITY_WARNING)
            self._ack(src, result, _MISSION)
            return
        up.items.append(wp)
        up.expected += 1
        up.retries = 0
        up.last_req = ep.clock()
        if up.expected < up.count:
            self._request_item(src, up.expected)
            return
        self.upload = None
        ok, why = ep.vehicle.set_mission(list(up.items))
        if ok:
            self._download = None
            if why == "own path":  # the vehicle's own path back: the cycle is kept, and said so
                ep.info(f"MAVLink: mission of {len(up.items)} waypoints is the vehicle's own path; cycle kept")
                ep.statustext("mission is the vehicle's own path: cycle kept", mav.MAV_SEVERITY_INFO)
            else:
                ep.info(f"MAVLink: mission of {len(up.items)} waypoints accepted")
            self._ack(src, mav.MAV_MISSION_ACCEPTED, _MISSION)
        else:
            ep.warn(f"MAVLink: mission refused by the vehicle: {why}")
            ep.statustext(f"mission refused: {why}", mav.MAV_SEVERITY_WARNING)
            self._ack(src, mav.MAV_MISSION_INVALID, _MISSION)
