"""The registers an emulated VN-100 holds and how it answers ``$VNRRG``/``$VNWRG``.

Only what a recorder touches is emulated: the identity registers 1–4 (read-only),
baud rate 5, asynchronous ASCII type 6 and rate 7, communication protocol control
30 and the binary outputs 75–77 (``shared/vn100-protocol.md`` §3, §4, §5.4). A
write is checked as the sensor checks it and answered with the echo of the new
values or a ``$VNERR`` code.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from imunoise.recording.protocol import ADOF_RATES, ADOR_MESSAGES, BAUD_RATES, IMU_RATE

__all__ = ["ADOF_RATES", "ADOR_MESSAGES", "IMU_RATE", "RegisterError", "Registers"]

#: Group bits a VN-100 has (Common, Time, IMU, Attitude).
_GROUP_BITS = (0, 1, 2, 4)

_IDENTITY = {1: ("VN-100T-CR",), 2: ("2",), 3: ("0100012345",), 4: ("2.1.0.0",)}
_FACTORY = {5: (115200,), 6: (14,), 7: (40,), 30: (0, 0, 0, 0, 1, 0, 1),
            75: (0, 0, 0), 76: (0, 0, 0), 77: (0, 0, 0)}


class RegisterError(ValueError):
    """A write or read the sensor refuses; ``code`` is its ``$VNERR`` code."""

    def __init__(self, code: int) -> None:
        super().__init__(f"VNERR {code:02X}")
        self.code = code


def _ints(fields, count: int) -> list[int]:
    if len(fields) < count:
        raise RegisterError(0x05)
    if len(fields) > count:
        raise RegisterError(0x06)
    try:
        return [int(f) for f in fields]
    except ValueError:
        raise RegisterError(0x07) from None


@dataclass
class Registers:
    """The register file; ``values[reg]`` is a tuple of the register's fields
    (binary outputs: AsyncMode, RateDivisor, group byte, field words)."""

    values: dict[int, tuple] = field(default_factory=lambda: {**_IDENTITY, **_FACTORY})

    def read(self, reg: int) -> str:
        """The fields of ``$VNRRG,reg,...`` as text."""
        if reg not in self.values:
            raise RegisterError(0x08)
        value = self.values[reg]
        if reg in (75, 76, 77):
            mode, divisor, group, *words = value
            return ",".join([str(mode), str(divisor), f"{group:02X}", *(f"{w:04X}" for w in words)])
        return ",".join(str(v) for v in value)

    def write(self, reg: int, fields) -> str:
        """Check and store a write; returns the echo's fields (as :meth:`read`)."""
        if reg in _IDENTITY:
            raise RegisterError(0x09)
        if reg not in self.values:
            raise RegisterError(0x08)
        if reg == 5:
            (baud,) = _ints(fields, 1)
            if baud not in BAUD_RATES:
                raise RegisterError(0x07)
            self.values[5] = (baud,)
        elif reg == 6:
            (ador,) = _ints(fields[:1], 1)  # an optional serial port may follow
            if ador != 0 and ador not in ADOR_MESSAGES:
                raise RegisterError(0x07)
            self.values[6] = (ador,)
        elif reg == 7:
            (adof,) = _ints(fields[:1], 1)
            if adof not in ADOF_RATES:
                raise RegisterError(0x07)
            self.values[7] = (adof,)
        elif reg == 30:
            value = _ints(fields, 7)
            if value[4] not in (1, 3) or value[6] not in (0, 1, 2) or any(v < 0 for v in value):
                raise RegisterError(0x07)
            self.values[30] = tuple(value)
        else:
            self.values[reg] = self._binary_output(fields)
        return self.read(reg)

    @staticmethod
    def _binary_output(fields) -> tuple:
        if len(fields) < 3:
            raise RegisterError(0x05)
        try:
            mode, divisor = int(fields[0]), int(fields[1])
            group = int(fields[2], 16)
            words = [int(w, 16) for w in fields[3:]]
        except ValueError:
            raise RegisterError(0x07) from None
        bits = [b for b in range(8) if group >> b & 1]
        if (mode not in (0, 1, 2, 3) or not 0 <= divisor <= 0xFFFF
                or any(b not in _GROUP_BITS for b in bits)
                or any(not 0 < w < 0x8000 for w in words)):
            raise RegisterError(0x07)
        if len(words) < len(bits):
            raise RegisterError(0x05)
        if len(words) > len(bits):
            raise RegisterError(0x06)
        return (mode, divisor, group, *words)

    def binary_outputs(self) -> list[tuple[int, list[tuple[int, int]]]]:
        """``[(rate divisor, [(group index, field mask), ...])]`` of every binary
        output that streams on the port."""
        out = []
        for reg in (75, 76, 77):
            mode, divisor, group, *words = self.values[reg]
            if mode and divisor and group:
                bits = [b for b in range(8) if group >> b & 1]
                out.append((divisor, list(zip(bits, words, strict=True))))
        return out

    @property
    def crc(self) -> bool:
        """Sentences carry the CRC-16 (register 30 SerialChecksum 3)."""
        return self.values[30][4] == 3

    @property
    def send_errors(self) -> bool:
        """``$VNERR`` replies are sent (register 30 ErrorMode != 0)."""
        return self.values[30][6] != 0
