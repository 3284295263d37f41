"""The VN-100 register protocol as text: build commands, check and split replies.

Formats are those of ``shared/vn100-protocol.md`` §2 and §4: a sentence is
``$<body>*<check>\\r\\n`` where the check is the XOR-8 checksum (2 hex digits) or
the CRC-16/XMODEM (4 hex digits) of the body; ``$VNERR,<hex code>`` reports a
rejected command. Pure functions, no I/O: the serial session and the emulator
both use them.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = [
    "ADOF_RATES", "ADOR_MESSAGES", "BAUD_RATES", "ERROR_NAMES", "IMU_RATE", "DeviceError",
    "Reply", "checksum8", "crc16", "error_name", "parse_reply", "sentence",
]

#: ``$VNERR`` codes (§4) by number.
ERROR_NAMES = {
    0x01: "hard fault",
    0x02: "serial buffer overflow",
    0x03: "invalid checksum",
    0x04: "invalid command",
    0x05: "not enough parameters",
    0x06: "too many parameters",
    0x07: "invalid parameter",
    0x08: "invalid register",
    0x09: "unauthorized access",
    0x0A: "watchdog reset",
    0x0B: "output buffer overflow",
    0x0C: "insufficient baud rate",
    0xFF: "error buffer overflow",
}

#: Asynchronous ASCII types (register 6) the recorder sets and the emulator streams:
#: ADOR -> message.
ADOR_MESSAGES = {1: "VNYPR", 2: "VNQTN", 8: "VNQMR", 10: "VNMAG", 11: "VNACC", 12: "VNGYR",
                 13: "VNMAR", 14: "VNYMR", 19: "VNIMU"}
#: Rates (Hz) register 7 accepts.
ADOF_RATES = (1, 2, 4, 5, 10, 20, 25, 40, 50, 100, 200)
#: The VN-100's IMU rate (Hz): binary outputs run at IMU_RATE / RateDivisor.
IMU_RATE = 800
#: Baud rates a VN-100 accepts (register 5), the factory one first.
BAUD_RATES = (115200, 921600, 460800, 230400, 128000, 57600, 38400, 19200, 9600)


def checksum8(body: bytes) -> int:
    """XOR of every byte of ``body`` (the bytes between ``$`` and ``*``)."""
    c = 0
    for b in body:
        c ^= b
    return c


def crc16(data: bytes) -> int:
    """CRC-16/XMODEM (poly 0x1021, init 0), the VectorNav CRC."""
    crc = 0
    for b in data:
        crc = ((crc >> 8) | (crc << 8)) & 0xFFFF
        crc ^= b
        crc ^= (crc & 0xFF) >> 4
        crc ^= (crc << 12) & 0xFFFF
        crc ^= ((crc & 0xFF) << 5) & 0xFFFF
    return crc


def sentence(body: str, *, crc: bool = False) -> bytes:
    """``$body*CS\\r\\n`` with the XOR-8 checksum (or, with ``crc``, the CRC-16)."""
    raw = body.encode("ascii")
    check = f"{crc16(raw):04X}" if crc else f"{checksum8(raw):02X}"
    return b"$" + raw + b"*" + check.encode() + b"\r\n"


def error_name(code: int) -> str:
    """``"invalid register (0x08)"``."""
    return f"{ERROR_NAMES.get(code, 'unknown error')} (0x{code:02X})"


class DeviceError(RuntimeError):
    """The sensor answered ``$VNERR``, or not at all, or not as asked.

    ``code`` is the ``$VNERR`` code (``None`` for a missing or wrong reply)."""

    def __init__(self, message: str, code: int | None = None) -> None:
        super().__init__(message)
        self.code = code


@dataclass(frozen=True)
class Reply:
    """One checked sentence: ``header`` (``"VNRRG"``) and its comma fields."""

    header: str
    fields: tuple[str, ...]

    @property
    def error(self) -> int | None:
        """The ``$VNERR`` code, or ``None`` for any other sentence."""
        if self.header != "VNERR" or not self.fields:
            return None
        try:
            return int(self.fields[0], 16)
        except ValueError:
            return None


def parse_reply(line: bytes) -> Reply | None:
    """The :class:`Reply` of one sentence ``$...*CS`` (with or without ``\\r\\n``);
    ``None`` when it is not a sentence or its check fails. ``XX``/``XXXX`` (no
    check, host to sensor only) is accepted so the emulator can parse commands."""
    line = line.strip(b"\r\n")
    if not line.startswith(b"$") or b"*" not in line:
        return None
    body, _, check = line[1:].rpartition(b"*")
    check = check.upper()
    if check not in (b"XX", b"XXXX"):
        try:
            value = int(check, 16)
        except ValueError:
            return None
        expected = checksum8(body) if len(check) == 2 else crc16(body) if len(check) == 4 else -1
        if value != expected:
            return None
    try:
        text = body.decode("ascii")
    except UnicodeDecodeError:
        return None
    header, *fields = text.split(",")
    return Reply(header, tuple(fields))
