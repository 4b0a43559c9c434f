"""MAVLink 2 message signing, as ArduPilot does it.

A 32-byte secret key, shared by the vehicle and the ground stations allowed to command it,
authenticates every message: the sender appends a 6-byte signature (the first 6 bytes of
SHA-256 over key + frame + link id + timestamp), the receiver checks it. With a key set the
vehicle

- signs everything it sends (the autopilot and the winch component);
- accepts only messages signed with its key whose timestamp moves forward on their stream
  (link id, system, component; a new stream at most one minute behind the vehicle's own
  timestamp), so a recorded message cannot be replayed;
- ignores every other message, unsigned or badly signed (commands, parameter and mission
  requests alike), except RADIO_STATUS and RADIO from a telemetry radio (ArduPilot's accept
  list for a link that is not its USB port), and counts them
  (``MavlinkEndpoint.stats["signing"]``: ``accepted``, ``unsigned_rejected``,
  ``bad_signature_rejected``).

A ground station without the key still sees the telemetry (a signature does not hide a
message) but cannot arm, change the mode, set a parameter or upload a mission.

Unlike pymavlink's own check, the signature is checked before the timestamp is taken as the
stream's newest: a forged frame with a far-future timestamp cannot lock a ground station's
stream out.

The vehicle's timestamp (10 us units since 2015-01-01 00:00 UTC) starts from the wall clock
and follows it (:meth:`Signer.tick`), so a restarted vehicle never goes back in time.

Key files (:func:`load_key`): a file of exactly 32 bytes is the key itself (binary); any other
file holds one line of text, a passphrase, and the key is its SHA-256, as MAVProxy's
``signing setup PASSPHRASE`` makes it (MAVProxy and pymavlink ground stations then use the
same passphrase).
"""

from __future__ import annotations

import hashlib
import hmac
import os
import time
from pathlib import Path
from typing import Any

from pymavlink.dialects.v20 import common as mav

from fdm_awe.errors import InputError
from fdm_awe.fileio import atomic_write_bytes

from .link import Link

KEY_BYTES = 32
#: 2015-01-01 00:00 UTC, s since the Unix epoch: the MAVLink signing timestamp's origin
EPOCH_2015 = 1420070400
#: messages accepted unsigned (ArduPilot's list for a non-USB link)
ACCEPT_UNSIGNED = frozenset({mav.MAVLINK_MSG_ID_RADIO_STATUS,
                             getattr(mav, "MAVLINK_MSG_ID_RADIO", 166)})
#: a new stream may start this far behind the vehicle's timestamp (10 us units: one minute)
NEW_STREAM_WINDOW = 6_000_000
#: a passphrase file is at most this long
MAX_PASSPHRASE_BYTES = 4096


def passphrase_key(passphrase: str) -> bytes:
    """The 32-byte key of a passphrase: its SHA-256 (MAVProxy's ``signing setup``)."""
    return hashlib.sha256(passphrase.encode("utf-8")).digest()


def load_key(path: str | os.PathLike, option: str = "--mavlink-key") -> bytes:
    """The signing key in ``path`` (see module doc); InputError (one line naming ``option``)
    for a missing, unreadable, empty, all-zero or oversized file."""
    from fdm_awe.fileio import check_input_file

    p = check_input_file(path, option)  # an existing regular file: a 32-byte key or a one-line passphrase
    try:
        data = p.read_bytes()
    except OSError as e:
        raise InputError(f"{option} {p}: unreadable ({e.strerror or e})") from None
    if len(data) == KEY_BYTES:
        key = data
    else:
        if len(data) > MAX_PASSPHRASE_BYTES:
            raise InputError(f"{option} {p}: {len(data)} bytes; a key file holds exactly 32 bytes, "
                             f"a passphrase file one line of at most {MAX_PASSPHRASE_BYTES} bytes")
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            raise InputError(f"{option} {p}: {len(data)} bytes that are not text; a key file holds exactly "
                             f"32 bytes, a passphrase file one line of text") from None
        lines = text.splitlines()
        phrase = lines[0].strip() if len(lines) == 1 else ""
        if len(lines) != 1 or not phrase:
            raise InputError(f"{option} {p}: a passphrase file holds one non-empty line "
                             f"(found {len(lines)} lines); a key file holds exactly 32 bytes")
        key = passphrase_key(phrase)
    if not any(key):
        raise InputError(f"{option} {p}: the key is all zero (that means signing off); use another key")
    return key


def save_key(path: str | os.PathLike, key: bytes) -> None:
    """Write a 32-byte key file atomically, readable by its owner only."""
    atomic_write_bytes(Path(path), bytes(key))
    try:
        os.chmod(path, 0o600)
    except OSError:
        pass


def now_timestamp(clock: Any = time.time) -> int:
    """The signing timestamp of the wall clock: 10 us units since 2015-01-01 UTC."""
    return int((clock() - EPOCH_2015) * 100_000)


class Codec(mav.MAVLink):
    """pymavlink's MAVLink 2 codec with the signature checked before the timestamp."""

    def check_signature(self, msgbuf: bytearray, srcSystem: int, srcComponent: int) -> bool:
        sg = self.signing
        assert sg.secret_key is not None
        sig = hashlib.sha256(bytes(sg.secret_key) + bytes(msgbuf[:-6])).digest()[:6]
        if not hmac.compare_digest(sig, bytes(msgbuf[-6:])):
            return False
        tlow, thigh = self.mav_sign_unpacker.unpack(bytes(msgbuf[-12:-6]))
        timestamp = tlow + (thigh << 32)
        key = (msgbuf[-13], srcSystem, srcComponent)
        last = sg.stream_timestamps.get(key)
        if last is not None:
            if timestamp <= last:
                return False   # replayed or reordered
        elif timestamp + NEW_STREAM_WINDOW < sg.timestamp:
            return False       # a new stream far in the past
        sg.stream_timestamps[key] = timestamp
        sg.timestamp = max(sg.timestamp, timestamp)
        return True


def _accept_unsigned(codec: Any, msg_id: int) -> bool:
    return msg_id in ACCEPT_UNSIGNED


def rejection(m: Any) -> str | None:
    """``"unsigned"`` or ``"bad_signature"`` when a BAD_DATA message is a frame refused by the
    signature check, else None."""
    if m.get_type() != "BAD_DATA" or getattr(m, "reason", "") != "Invalid signature":
        return None
    buf = m.get_msgbuf()
    signed = len(buf) > 2 and buf[0] == mav.PROTOCOL_MARKER_V2 and buf[2] & mav.MAVLINK_IFLAG_SIGNED
    return "bad_signature" if signed else "unsigned"


class Signer:
    """The signing state of a vehicle's encoders (one key, one link id, shared timestamp).

    Args:
        codecs: the pymavlink encoders that send (the first also receives and checks).
        key: the 32-byte secret key, or None for no signing.
        link_id: the link id written into outgoing signatures (0..255).
        clock: wall clock, s since the Unix epoch.
    """

    def __init__(self, codecs: list[Any], key: bytes | None = None, link_id: int = 0,
                 clock: Any = time.time) -> None:
        if not isinstance(link_id, int) or not 0 <= link_id <= 255:
            raise InputError(f"MAVLink signing link_id: {link_id!r} outside [0, 255]")
        self.codecs = codecs
        self.link_id = link_id
        self._clock = clock
        self.key: bytes | None = None
        self.set_key(key)

    @property
    def on(self) -> bool:
        return self.key is not None

    def set_key(self, key: bytes | None, timestamp: int = 0) -> None:
        """Use ``key`` from now on (None or all zero: signing off); ``timestamp`` (10 us since
        2015) raises the vehicle's timestamp when it is ahead of the wall clock."""
        if key is not None:
            key = bytes(key)
            if len(key) != KEY_BYTES:
                raise InputError(f"MAVLink signing key: {len(key)} bytes; needs exactly {KEY_BYTES}")
            if not any(key):
                key = None
        self.key = key
        ts = max(now_timestamp(self._clock), int(timestamp))
        for c in self.codecs:
            sg = c.signing
            sg.secret_key = key
            sg.sign_outgoing = key is not None
            sg.link_id = self.link_id
            sg.allow_unsigned_callback = _accept_unsigned if key is not None else None
            sg.timestamp = max(sg.timestamp, ts)
            sg.stream_timestamps = {}

    def tick(self) -> None:
        """Keep the timestamps no slower than the wall clock."""
        if self.key is None:
            return
        ts = now_timestamp(self._clock)
        for c in self.codecs:
            if c.signing.timestamp < ts:
                c.signing.timestamp = ts


def on_setup_signing(ep: Link, m: Any) -> None:
    """SETUP_SIGNING to the vehicle ``ep`` (a MavlinkEndpoint): only with signing on, so the
    request itself carried a valid signature (this link is not a secure channel like
    ArduPilot's USB port, where a first key may be set). A new key replaces the old one at once
    and is saved to the endpoint's key file; an all-zero key switches signing off until the
    next start (the file keeps its key)."""
    if m.target_system != ep.sysid:
        return
    if not ep.signer.on:
        ep.statustext("SETUP_SIGNING refused: no key set (start with a key file)", mav.MAV_SEVERITY_WARNING)
        return
    key = bytes(bytearray(m.secret_key))
    if any(key) and ep.signing_key_file is not None:
        try:
            save_key(ep.signing_key_file, key)
        except OSError as e:
            ep.statustext(f"SETUP_SIGNING refused: key not saved ({e.strerror})", mav.MAV_SEVERITY_WARNING)
            return
    ep.signer.set_key(key, int(m.initial_timestamp))
    text = "signing key changed" if any(key) else "signing off until restart"
    ep.info(f"MAVLink: {text} (SETUP_SIGNING from {m.get_srcSystem()}:{m.get_srcComponent()})")
    ep.statustext(text, mav.MAV_SEVERITY_NOTICE)
