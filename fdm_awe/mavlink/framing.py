"""MAVLink framing: how incoming bytes become messages.

On UDP every datagram is parsed on its own (:func:`parse_datagram`): the parser starts empty
for each one, so a cut frame or junk in one datagram cannot swallow the messages of the next.
On byte streams (TCP, serial) a :class:`StreamParser` keeps a frame that has not fully arrived
across reads, as a message may arrive in pieces (:class:`fdm_awe.mavlink.transport.Receiver`
picks one or the other by the transport).

Both find frames the same way (:func:`parse_frames`): from a start byte (0xFD MAVLink 2, 0xFE
MAVLink 1) the header gives the frame's length; a frame that fails to decode (bad CRC, unknown
flags, an unknown message id, whose CRC cannot be checked) is one bad piece, and the search
resumes at the byte after its start byte, as a MAVLink 2 parser resynchronises, so a valid
frame behind a stray start byte is still found. On a stream a start byte whose frame has not
all arrived is waited for, unless a complete frame with a valid CRC already follows it: then
that start byte was a stray one (its header takes the next frames' bytes as its own; waiting
for its length would cost those frames their answers) and parsing resumes at that frame.
"""

from __future__ import annotations

from typing import Any

from pymavlink.dialects.v20 import common as mav

#: resynchronisations tried within one datagram or stream read after a bad or cut frame (bounds a
#: read's cost; beyond it a bad frame is skipped whole and the rest of a datagram dropped)
MAX_RESYNC_PER_DATAGRAM = 32
#: the longest frame, bytes: MAVLink 2 header 10, payload 255, CRC 2, signature 13
MAX_FRAME_BYTES = 280
_STX2 = mav.PROTOCOL_MARKER_V2
_STX1 = mav.PROTOCOL_MARKER_V1


def reset_parser(parser: mav.MAVLink) -> None:
    """Forget whatever a pymavlink parser holds of a partial frame."""
    parser.buf = bytearray()
    parser.buf_index = 0
    parser.expected_length = mav.HEADER_LEN_V1 + 2
    parser.have_prefix_error = False


def next_start(data: bytes, pos: int) -> int:
    """Index of the first start byte (0xFD or 0xFE) at or after ``pos``; -1 if none."""
    a = data.find(_STX2, pos)
    b = data.find(_STX1, pos, a if a >= 0 else len(data))
    return b if b >= 0 else a


def frame_length(data: bytes, i: int) -> int | None:
    """Length in bytes of the frame whose start byte is ``data[i]``, from its header; None while
    the header's length bytes have not arrived."""
    n = len(data) - i
    if data[i] == _STX2:
        if n < 3:
            return None
        return mav.HEADER_LEN_V2 + 2 + data[i + 1] + (
            mav.MAVLINK_SIGNATURE_BLOCK_LEN if data[i + 2] & mav.MAVLINK_IFLAG_SIGNED else 0)
    if n < 2:
        return None
    return mav.HEADER_LEN_V1 + 2 + data[i + 1]


def crc_ok(data: bytes, i: int, length: int) -> bool:
    """Is ``data[i:i+length]`` a whole frame of a known message with a valid CRC? (The signature
    is not checked here: that is the decoder's, once.)"""
    if i + length > len(data):
        return False
    if data[i] == _STX2:
        if length < mav.HEADER_LEN_V2 + 2:
            return False
        msgid = data[i + 7] | data[i + 8] << 8 | data[i + 9] << 16
        end = i + length - (mav.MAVLINK_SIGNATURE_BLOCK_LEN if data[i + 2] & mav.MAVLINK_IFLAG_SIGNED else 0)
    else:
        msgid = data[i + 5]
        end = i + length
    kind = mav.mavlink_map.get(msgid)
    if kind is None or end - 2 <= i:
        return False
    crc = mav.x25crc(bytes(data[i + 1:end - 2]))
    crc.accumulate(bytes([kind.crc_extra]))
    return crc.crc == data[end - 2] | data[end - 1] << 8


def _complete_frame_after(data: bytes, pos: int) -> int:
    """Start of the first whole frame with a valid CRC at or after ``pos``; -1 if none."""
    k = next_start(data, pos)
    while k >= 0:
        length = frame_length(data, k)
        if length is not None and crc_ok(data, k, length):
            return k
        k = next_start(data, k + 1)
    return -1


def parse_frames(parser: mav.MAVLink, data: bytes, stream: bool = False) -> tuple[list[Any], int, int]:
    """The MAVLink messages in ``data``: ``(messages, bad, used)`` (see module doc).

    ``bad`` counts the undecodable pieces (junk before a start byte, failed frames, a cut frame
    at the end of a datagram). A whole frame refused by the signature check is returned (a
    BAD_DATA "Invalid signature": it is counted there). ``used``: the bytes consumed; on a
    ``stream`` the rest (``data[used:]``, the start of a frame that has not all arrived) is to
    be parsed again with the next bytes; on a datagram ``used == len(data)``. The parser ends
    empty.
    """
    msgs: list[Any] = []
    bad = 0
    n = len(data)
    pos = 0
    resyncs = 0
    try:
        while pos < n:
            j = next_start(data, pos)
            if j < 0:
                bad += 1   # junk to the end
                break
            if j > pos:
                bad += 1   # junk before a start byte
            length = frame_length(data, j)
            if length is None or j + length > n:   # a frame that has not all arrived
                if stream:
                    k = _complete_frame_after(data, j + 1) if resyncs < MAX_RESYNC_PER_DATAGRAM else -1
                    if k < 0:
                        reset_parser(parser)
                        return msgs, bad, j   # wait for its rest
                else:
                    k = j + 1 if resyncs < MAX_RESYNC_PER_DATAGRAM else n
                bad += 1
                resyncs += 1
                pos = k
                continue
            reset_parser(parser)
            m = parser.parse_char(data[j:j + length])
            kind = "BAD_DATA" if m is None else m.get_type()
            if kind == "BAD_DATA" and m is not None and m.reason == "Invalid signature":
                msgs.append(m)   # a whole frame refused by the signature check: counted there
                pos = j + length
            elif kind == "BAD_DATA" or kind.startswith("UNKNOWN"):
                bad += 1         # bad CRC or flags; an unknown id cannot be checked
                if resyncs < MAX_RESYNC_PER_DATAGRAM:
                    resyncs += 1
                    pos = j + 1   # look again from the byte after its start
                else:
                    pos = j + length
            else:
                msgs.append(m)
                pos = j + length
    except Exception:  # noqa: BLE001 - robust parsing should not raise; count it and move on
        bad += 1
    reset_parser(parser)
    return msgs, bad, n


def parse_datagram(parser: mav.MAVLink, data: bytes) -> tuple[list[Any], int]:
    """The MAVLink messages in one datagram, parsed on their own: ``(messages, bad)``.

    The parser starts empty and ends empty, so nothing of this datagram (a cut frame, a
    header announcing more bytes than came) can affect the next one. Within the datagram,
    after a frame that fails to decode or is cut off, parsing resumes one byte after that
    frame's start byte, so a valid frame behind it is still found (at most
    :data:`MAX_RESYNC_PER_DATAGRAM` times)."""
    msgs, bad, _ = parse_frames(parser, data, stream=False)
    return msgs, bad


class StreamParser:
    """The frames of one byte stream (a TCP connection, a serial line), read by read.

    Args:
        parser: the pymavlink codec that decodes (and checks signatures); it holds no state of
            this stream between reads, so one codec may serve several streams.
    """

    def __init__(self, parser: mav.MAVLink) -> None:
        self._parser = parser
        self._pending = b""

    @property
    def pending(self) -> int:
        """Bytes held of a frame that has not all arrived (at most :data:`MAX_FRAME_BYTES`)."""
        return len(self._pending)

    def feed(self, data: bytes) -> tuple[list[Any], int]:
        """The messages completed by ``data``: ``(messages, bad)``."""
        buf = self._pending + bytes(data) if self._pending else bytes(data)
        msgs, bad, used = parse_frames(self._parser, buf, stream=True)
        self._pending = buf[used:]
        return msgs, bad
