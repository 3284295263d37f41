"""A serial session with a VN-100: open the port, send commands, find their replies.

Replies arrive interleaved with the asynchronous stream (binary packets may hold
``$`` and ``\\r\\n``), so a reply is a checked sentence with the expected header
found anywhere in the received bytes; every byte read is kept, and what follows
the reply is handed on (:attr:`Session.rest`): the recorder starts the record
exactly after the echo of ``$VNASY,1``.
"""

from __future__ import annotations

import time

from imunoise.recording.protocol import (
    BAUD_RATES,
    DeviceError,
    Reply,
    error_name,
    parse_reply,
    sentence,
)

__all__ = ["Session", "find_baud", "open_port"]

#: Seconds to wait for a reply.
REPLY_TIMEOUT = 2.0
#: Seconds a read waits for the first byte (also how fast a vanished port is seen).
READ_TIMEOUT = 0.02
_CHUNK = 1 << 16


def open_port(port: str, baud: int):
    """A pyserial port, 8N1, no flow control, raw."""
    try:
        import serial
    except ImportError:  # pragma: no cover - pyserial is a dependency
        raise ImportError("imunoise record needs pyserial: pip install pyserial") from None
    return serial.Serial(port, baud, timeout=READ_TIMEOUT, write_timeout=REPLY_TIMEOUT)


class Session:
    """Commands and raw reads on an open port (``serial`` is a pyserial port)."""

    def __init__(self, serial, *, crc: bool = False) -> None:
        self.serial = serial
        self.crc = crc
        self.rest = b""  # bytes received after the last reply found

    def read(self) -> bytes:
        """Whatever arrives within :data:`READ_TIMEOUT` (bytes the last command left
        first). Raises ``OSError``/``SerialException`` when the port is gone."""
        if self.rest:
            data, self.rest = self.rest, b""
            return data
        return bytes(self.serial.read(_CHUNK))

    def command(self, body: str, *, timeout: float = REPLY_TIMEOUT) -> tuple[Reply, bytes]:
        """Send ``$body*CS`` and wait for its reply: ``(reply, bytes before it, reply
        included)``; what follows is left in :attr:`rest`. ``$VNERR`` raises
        :class:`DeviceError` naming the code."""
        header = body.split(",")[0]
        key = tuple(body.split(",")[:2]) if header in ("VNRRG", "VNWRG") else (header,)
        self.serial.write(sentence(body, crc=self.crc))
        buf = bytearray(self.rest)
        self.rest = b""
        started = time.monotonic()
        deadline = started + timeout
        resent = False
        searched = 0
        while True:
            found = _find_reply(buf, key, searched)
            if found is not None:
                reply, end = found
                self.rest = bytes(buf[end:])
                if reply.error is not None:
                    raise DeviceError(f"${body}: the sensor answered $VNERR "
                                      f"{error_name(reply.error)}", reply.error)
                return reply, bytes(buf[:end])
            searched = max(0, len(buf) - 400)  # a reply may straddle two reads
            if time.monotonic() > deadline:
                raise DeviceError(f"no reply to ${body} within {timeout:g} s")
            if not resent and time.monotonic() > started + timeout / 2:
                # a command can be lost (line noise, a sensor still starting): once more;
                # every command the recorder sends may be repeated without harm
                self.serial.write(sentence(body, crc=self.crc))
                resent = True
            buf += self.serial.read(_CHUNK)


def _find_reply(buf: bytearray, key: tuple[str, ...], start: int):
    """The first checked sentence from ``start`` whose fields begin with ``key``
    (or a ``$VNERR``), with the offset just after its ``\\n``."""
    i = buf.find(b"$VN", start)
    while i >= 0:
        end = buf.find(b"\n", i)
        if end < 0:
            return None
        reply = parse_reply(bytes(buf[i:end + 1]))
        if reply is not None:
            head = (reply.header, *(f.lstrip("0") or "0" for f in reply.fields[:1]))
            want = (key[0], *(k.lstrip("0") or "0" for k in key[1:2]))
            if reply.header == "VNERR" or head[:len(want)] == want:
                return reply, end + 1
        i = buf.find(b"$VN", i + 1)
    return None


def find_baud(port: str, rates=BAUD_RATES) -> int:
    """The baud rate at which the sensor on ``port`` answers ``$VNRRG,01``."""
    tried = []
    for baud in rates:
        try:
            serial = open_port(port, baud)
        except (OSError, ValueError):
            tried.append(baud)
            continue
        try:
            Session(serial).command("VNRRG,01", timeout=0.5)
            return baud
        except DeviceError:
            tried.append(baud)
        finally:
            serial.close()
    raise DeviceError(f"{port}: no VN-100 answered at any baud rate tried "
                      f"({', '.join(map(str, tried))})")
