"""A serial session with a VN-100: open the port, send commands, find their replies.

Replies arrive interleaved with the asynchronous stream (binary packets may hold
``$`` and ``\\r\\n``), so a reply is a checked sentence with the expected header
found anywhere in the received bytes; every byte read is kept, and what follows
the reply is handed on (:attr:`Session.rest`): the recorder starts the record
exactly after the echo of ``$VNASY,1``.
"""

from __future__ import annotations

import os
import stat
import time

from imunoise.recording.protocol import (
    BAUD_RATES,
    DeviceError,
    Reply,
    error_name,
    parse_reply,
    sentence,
)

__all__ = ["Session", "check_port", "find_baud", "open_port"]

#: Seconds to wait for a reply.
REPLY_TIMEOUT = 2.0
#: Seconds a read waits for the first byte (also how fast a vanished port is seen).
READ_TIMEOUT = 0.02
_CHUNK = 1 << 16


def check_port(port: str) -> None:
    """:class:`DeviceError` naming ``port`` when it is no serial port: a regular
    file, a folder or a FIFO (pyserial's own error for them, "(25, 'Inappropriate
    ioctl for device')", names no port), or, on POSIX, nothing at all."""
    try:
        mode = os.stat(port).st_mode
    except FileNotFoundError:
        if os.name == "posix":
            raise DeviceError(f"{port}: no such port") from None
        return  # COM3 and the like are no files
    except (OSError, ValueError):
        return  # let the open say what is wrong
    if not stat.S_ISCHR(mode):
        kind = ("a folder" if stat.S_ISDIR(mode) else "a regular file" if stat.S_ISREG(mode)
                else "not a character device")
        raise DeviceError(f"{port}: not a serial port ({kind})")


def open_port(port: str, baud: int):
    """A pyserial port, 8N1, no flow control, raw; :class:`DeviceError` naming the
    port when it is not a serial port or cannot be opened."""
    try:
        import serial
    except ImportError:  # pragma: no cover - pyserial is a dependency
        raise ImportError("imunoise record needs pyserial: pip install pyserial") from None
    check_port(port)
    try:
        return serial.Serial(port, baud, timeout=READ_TIMEOUT, write_timeout=REPLY_TIMEOUT)
    except OSError as exc:  # SerialException is an OSError
        reason = os.strerror(exc.errno) if isinstance(exc.errno, int) else str(exc)
        if "Inappropriate ioctl" in reason:
            reason = "not a serial port (a device that is not a terminal)"
        raise DeviceError(f"{port}: cannot open the port: {reason}") from None


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
                # what came instead says why: nothing (a silent or absent sensor), or
                # bytes none of which is a checked reply (a wrong baud rate, line noise)
                got = (f"{len(buf)} bytes came, none a valid reply (wrong baud rate? bad "
                       f"checksums?)" if buf else "nothing came")
                raise DeviceError(f"no reply to ${body} within {timeout:g} s: {got}")
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
        check_port(port)  # no such port, or not a serial one: no baud rate will do
        try:
            serial = open_port(port, baud)
        except (DeviceError, ValueError):  # a rate this port cannot take
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
