"""MAVFTP (FILE_TRANSFER_PROTOCOL): every request is answered with a NAK (UnknownCommand).

The vehicle has no file system to offer; ground stations (MAVProxy, QGroundControl) first
ask for the parameters over MAVFTP and, on the NAK, fall back to the parameter protocol at
once instead of waiting for a timeout (mavlink.io/en/services/ftp.html).
"""

from __future__ import annotations

from typing import Any

from .link import Link


# MAVFTP opcodes/errors (mavlink.io/en/services/ftp.html)
_FTP_NAK = 129
_FTP_ERR_UNKNOWN_COMMAND = 7


def nak_payload(request: Any) -> list[int]:
    """The 251-byte FILE_TRANSFER_PROTOCOL payload NAKing the request whose payload is
    ``request``: sequence + 1, the same session, ``req_opcode`` the request's, error
    UnknownCommand."""
    req = bytes(bytearray(request[:12]).ljust(12, b"\x00"))
    seq = req[0] | (req[1] << 8)
    session, opcode = req[2], req[3]
    payload = [0] * 251
    rseq = (seq + 1) & 0xFFFF
    payload[0], payload[1] = rseq & 0xFF, rseq >> 8
    payload[2] = session
    payload[3] = _FTP_NAK
    payload[4] = 1           # size of data
    payload[5] = opcode      # req_opcode
    payload[12] = _FTP_ERR_UNKNOWN_COMMAND
    return payload


def on_ftp(ep: Link, m: Any) -> None:
    """FILE_TRANSFER_PROTOCOL addressed to ``ep``: answer with the NAK."""
    if not ep.for_me(m):
        return
    ep.send("FILE_TRANSFER_PROTOCOL", ep.mav.file_transfer_protocol_send, 0,
             m.get_srcSystem(), m.get_srcComponent(), nak_payload(m.payload))
