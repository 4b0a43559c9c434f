"""MAVLink framing: how incoming bytes become messages.

On UDP every datagram is parsed on its own (:func:`parse_datagram`): the parser starts empty
for each one, so a cut frame or junk in one datagram cannot swallow the messages of the next.
On byte streams (TCP, serial) the parser keeps its state across reads, as a message may
arrive in pieces (:class:`fdm_awe.mavlink.endpoint.MavlinkEndpoint` decides which by the
transport, :data:`DATAGRAM_TRANSPORTS`).
"""

from __future__ import annotations

from typing import Any

from pymavlink import mavutil
from pymavlink.dialects.v20 import common as mav

#: pymavlink transports that deliver whole datagrams (UDP, UDP multicast)
DATAGRAM_TRANSPORTS = (mavutil.mavudp, mavutil.mavmcast)
#: resynchronisations tried within one datagram after a bad or cut frame (bounds a poll's cost)
MAX_RESYNC_PER_DATAGRAM = 32


def reset_parser(parser: mav.MAVLink) -> None:
    """Forget whatever a pymavlink parser holds of a partial frame."""
    parser.buf = bytearray()
    parser.buf_index = 0
    parser.expected_length = mav.HEADER_LEN_V1 + 2
    parser.have_prefix_error = False


def parse_datagram(parser: mav.MAVLink, data: bytes) -> tuple[list[Any], int]:
    """The MAVLink messages in one datagram, parsed on their own: ``(messages, bad)``.

    The parser starts empty and ends empty, so nothing of this datagram (a cut frame, a
    header announcing more bytes than came) can affect the next one. Within the datagram,
    after a frame that fails to decode (bad CRC, unknown flags) or is cut off, parsing
    resumes one byte after that frame's start byte, so a valid frame behind it is still found
    (at most :data:`MAX_RESYNC_PER_DATAGRAM` times). A frame of an unknown message id counts
    as failed (its CRC cannot be checked). ``bad`` counts the undecodable pieces (junk before
    a start byte, failed frames, a cut frame at the end)."""
    msgs: list[Any] = []
    bad = 0
    n = len(data)
    pos = 0
    resyncs = 0
    try:
        while pos < n:
            reset_parser(parser)
            m = parser.parse_char(data[pos:])
            nxt = n  # where to continue: the end, unless a bad or cut frame asks for a resync
            while m is not None:
                kind = m.get_type()
                if kind == "BAD_DATA" and m.reason == "Bad prefix":
                    bad += 1  # junk before a start byte: skipped
                elif kind == "BAD_DATA" and m.reason == "Invalid signature":
                    msgs.append(m)  # a whole frame refused by the signature check: counted there
                elif kind == "BAD_DATA" or kind.startswith("UNKNOWN"):
                    # a frame that failed (bad CRC or flags; an unknown id cannot be checked):
                    # look again from the byte after its start
                    bad += 1
                    if resyncs < MAX_RESYNC_PER_DATAGRAM:
                        nxt = n - parser.buf_len() - len(m.get_msgbuf()) + 1
                        break
                else:
                    msgs.append(m)
                m = parser.parse_char(b"")
            else:
                left = parser.buf_len()
                if left:  # a cut frame (or a header announcing more than the datagram holds)
                    bad += 1
                    if resyncs < MAX_RESYNC_PER_DATAGRAM:
                        nxt = n - left + 1
            if nxt < n:
                resyncs += 1
            pos = nxt
    except Exception:  # noqa: BLE001 - robust parsing should not raise; count it and move on
        bad += 1
    reset_parser(parser)
    return msgs, bad
