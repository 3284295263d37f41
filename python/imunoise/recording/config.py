"""What the recorder sets on the sensor, reads back, and restores.

The output settings are the asynchronous ASCII type and rate (registers 6, 7), the
three binary outputs (75–77) and the communication protocol control (30, whose
SerialChecksum field chooses XOR-8 or CRC-16). Every write's echo is checked and
every written register read back (:func:`apply`); :func:`restore` writes the
settings read before (:func:`read_outputs`) back the same way, each register on
its own: one that fails does not keep the others from being restored.

The binary outputs (75–77) are optional: firmware without them answers
``$VNERR`` (invalid register) and is recorded with its ASCII output alone.
"""

from __future__ import annotations

import math

from imunoise.errors import ImunoiseValueError
from imunoise.recording.protocol import (
    ADOF_RATES,
    ADOR_MESSAGES,
    IMU_RATE,
    DeviceError,
    error_name,
)
from imunoise.recording.session import Session

__all__ = ["IDENTITY", "OPTIONAL_REGISTERS", "OUTPUT_REGISTERS", "ascii_type", "apply",
           "binary_output", "read_identity", "read_outputs", "restore", "wanted_outputs"]

#: Identity registers read into the metadata: number -> name.
IDENTITY = {1: "model", 2: "hardware_revision", 3: "serial_number", 4: "firmware"}
#: Registers that hold the output settings, in the order they are written.
OUTPUT_REGISTERS = (30, 75, 76, 77, 7, 6)
#: Output registers a sensor may lack (binary outputs: not on old firmware).
OPTIONAL_REGISTERS = (75, 76, 77)
#: Largest RateDivisor register 75 holds (a 16-bit field): the slowest binary output
#: runs at IMU_RATE / MAX_DIVISOR Hz.
MAX_DIVISOR = 0xFFFF
#: Largest field mask of a binary group (one 16-bit word per group).
MAX_MASK = 0xFFFF
#: ASCII types by name (``"VNYMR"``) -> register 6 value.
_ADOR_OF = {name: ador for ador, name in ADOR_MESSAGES.items()}


def _normal(fields: tuple[str, ...]) -> tuple[str, ...]:
    """Fields compared as numbers where they are (``"08"`` equals ``"8"``)."""
    out = []
    for f in fields:
        try:
            out.append(str(int(f, 16 if any(c in "ABCDEFabcdef" for c in f) else 10)))
        except ValueError:
            out.append(f.upper())
    return tuple(out)


def read_register(session: Session, reg: int) -> tuple[str, ...]:
    """The fields of register ``reg``."""
    reply, _ = session.command(f"VNRRG,{reg:02d}")
    return reply.fields[1:]


def read_identity(session: Session) -> dict[str, str]:
    """Model, hardware revision, serial number and firmware (registers 1–4)."""
    return {name: ",".join(read_register(session, reg)) for reg, name in IDENTITY.items()}


def read_outputs(session: Session, notes: list[str] | None = None,
                 ) -> dict[int, tuple[str, ...]]:
    """The output settings now on the sensor: register -> fields.

    An optional register (:data:`OPTIONAL_REGISTERS`) the sensor refuses with
    ``$VNERR`` is left out and said in ``notes`` (when given): old firmware has no
    binary outputs, and its ASCII output can still be recorded. A missing reply
    still raises: a sensor that stops answering is no firmware's choice."""
    values: dict[int, tuple[str, ...]] = {}
    refused: dict[int, str] = {}
    for reg in OUTPUT_REGISTERS:
        try:
            values[reg] = read_register(session, reg)
        except DeviceError as exc:
            if reg not in OPTIONAL_REGISTERS or exc.code is None:
                raise
            refused[reg] = error_name(exc.code)
    if refused and notes is not None:
        regs = ", ".join(map(str, refused))
        why = "; ".join(sorted(set(refused.values())))
        notes.append(f"registers {regs} (binary outputs) not read: the sensor answered "
                     f"$VNERR {why} (firmware without binary outputs?); left alone, the "
                     f"ASCII output alone is recorded")
    return values


def write_register(session: Session, reg: int, fields: tuple[str, ...]) -> None:
    """Write, check the echo, read back and check again; :class:`DeviceError` naming
    the register, what was written and what came back otherwise."""
    body = f"VNWRG,{reg:02d}," + ",".join(fields)
    reply, _ = session.command(body)
    echo = reply.fields[1:]
    try:
        back = read_register(session, reg)
    except DeviceError as exc:  # the write went through: not a refused write (no code)
        raise DeviceError(f"register {reg}: written, but reading it back failed: {exc}"
                          ) from None
    for what, got in (("echoed", echo), ("read back", back)):
        if _normal(got) != _normal(fields):
            raise DeviceError(f"register {reg}: wrote {','.join(fields)} but the sensor "
                              f"{what} {','.join(got)}")


def apply(session: Session, wanted: dict[int, tuple[str, ...]],
          touched: set[int] | None = None) -> None:
    """Write every register of ``wanted`` (in :data:`OUTPUT_REGISTERS` order);
    ``touched`` receives each register that may have changed (written, or a write
    lost or echoed wrong; not one the sensor refused with ``$VNERR``), so a restore
    writes back those and no others."""
    for reg in OUTPUT_REGISTERS:
        if reg in wanted:
            if touched is not None:
                touched.add(reg)
            try:
                write_register(session, reg, wanted[reg])
            except DeviceError as exc:
                if exc.code is not None and touched is not None:
                    touched.discard(reg)  # refused: the sensor kept its value
                raise
            if reg == 30:
                session.crc = wanted[30][4] == "3"


def restore(session: Session, previous: dict[int, tuple[str, ...]], changed) -> list[str]:
    """Write back the ``previous`` value of every register in ``changed``; returns
    what failed, one line per register (empty: all restored).

    Each register is tried whatever happened to the one before: a refused or lost
    write must not leave the others changed."""
    import serial

    failed = []
    for reg in OUTPUT_REGISTERS:
        if reg in changed and reg in previous:
            try:
                write_register(session, reg, previous[reg])
            except (DeviceError, OSError, serial.SerialException) as exc:
                failed.append(f"restoring register {reg} to {','.join(previous[reg])} "
                              f"failed: {exc}")
                continue
            if reg == 30:
                session.crc = previous[30][4] == "3"
    return failed


def ascii_type(name: str) -> int:
    """Register 6 value of an ASCII type name (``"VNYMR"`` or ``"YMR"``)."""
    key = name.upper() if name.upper().startswith("VN") else "VN" + name.upper()
    if key not in _ADOR_OF:
        raise ImunoiseValueError(f"ascii type must be one of {sorted(_ADOR_OF)}; got {name!r}")
    return _ADOR_OF[key]


def binary_output(rate: float, fields: str) -> tuple[str, ...]:
    """Register 75 fields for a binary output at ``rate`` Hz of ``fields``
    (``"common=0x0029"`` or ``"common=TimeStartup+AngularRate+Accel,imu=Temp"``)."""
    from imunoise._core import vn as _core_vn

    # Checked before anything is written: a rate the sensor cannot run (1e-300 Hz
    # gave a divisor of 8e302 that was sent as is) must not reach it.
    slowest = IMU_RATE / MAX_DIVISOR
    bound = (f"{IMU_RATE} Hz divided by a whole number from 1 to {MAX_DIVISOR} "
             f"({slowest:.4g} ... {IMU_RATE} Hz)")
    if not (isinstance(rate, int | float) and math.isfinite(rate) and rate > 0):
        raise ImunoiseValueError(
            f"binary rate must be a finite number of Hz, {bound}; got {rate!r}")
    divisor = IMU_RATE / rate
    if not (1 <= round(divisor) <= MAX_DIVISOR and abs(divisor - round(divisor)) < 1e-9):
        raise ImunoiseValueError(f"binary rate must be {bound}; got {rate!r}")
    divisor = round(divisor)
    table = _core_vn.vn_binary_fields()
    words: dict[int, int] = {}
    for part in fields.split(","):
        group, sep, names = part.partition("=")
        group = group.strip().lower()
        if not sep or group not in table:
            raise ImunoiseValueError(f"binary fields must be GROUP=FIELDS with GROUP one of "
                             f"{sorted(table)}; got {part!r}")
        index, known = table[group]
        mask = 0
        for name in names.split("+"):
            name = name.strip()
            if name.lower().startswith("0x"):
                try:
                    value = int(name, 16)
                except ValueError:
                    raise ImunoiseValueError(
                        f"binary field mask {name!r} is not a hex number") from None
                # one 16-bit word per group on the wire: a wider mask would be cut
                if not 0 < value <= MAX_MASK:
                    raise ImunoiseValueError(f"binary field mask of group {group} must be within "
                                     f"0x0001 ... 0x{MAX_MASK:04X} (16 bits); got {name}")
                mask |= value
            elif name in known:
                mask |= 1 << known[name]
            else:
                raise ImunoiseValueError(f"binary field {name!r} is not in group {group}; known: "
                                 f"{', '.join(sorted(known))}")
        words[index] = words.get(index, 0) | mask
    group_byte = sum(1 << i for i in words)
    return ("1", str(divisor), f"{group_byte:02X}",
            *(f"{words[i]:04X}" for i in sorted(words)))


def wanted_outputs(previous: dict[int, tuple[str, ...]], *, ascii: str | None = None,
                   rate: float | None = None, binary=(), crc: bool | None = None,
                   ) -> dict[int, tuple[str, ...]]:
    """The registers to write for the options given (unchanged ones left out).

    ``binary`` is a sequence of register-75 field tuples (:func:`binary_output`),
    one per binary output; the others are switched off when any is given.
    """
    wanted: dict[int, tuple[str, ...]] = {}
    if ascii is not None:
        wanted[6] = ("0",) if ascii.lower() == "off" else (str(ascii_type(ascii)),)
    if rate is not None:
        if rate not in ADOF_RATES:
            raise ImunoiseValueError(f"rate must be one of {ADOF_RATES} Hz; got {rate:g}")
        wanted[7] = (str(int(rate)),)
    if len(binary) > 3:
        raise ImunoiseValueError(f"at most 3 binary outputs; got {len(binary)}")
    if binary:
        for k, reg in enumerate((75, 76, 77)):
            wanted[reg] = tuple(binary[k]) if k < len(binary) else ("0", "0", "00")
    if crc is not None:
        fields = list(previous.get(30, ("0", "0", "0", "0", "1", "0", "1")))
        fields[4] = "3" if crc else "1"
        wanted[30] = tuple(fields)
    return {reg: f for reg, f in wanted.items() if _normal(previous.get(reg, ())) != _normal(f)}
