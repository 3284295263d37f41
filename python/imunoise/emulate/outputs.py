"""What an emulated still VN-100 sends: simulated samples encoded as its outputs.

The samples are those of :func:`imunoise._simulate_log.still_log` (the datasheet's
noise on gyro and accelerometer, gravity on −Z, constant attitude and field) at the
IMU rate, generated in blocks of :data:`BLOCK` samples with their own seeds (the
flicker term therefore restarts every block: fine for a stream, not for an Allan
analysis of hours). Temperature, pressure and the quaternion are constant. Each
output takes every k-th IMU sample: the ASCII type at register 7's rate, a binary
output at 800 Hz / RateDivisor.
"""

from __future__ import annotations

import numpy as np

from imunoise._simulate_log import still_log
from imunoise.emulate.registers import ADOR_MESSAGES, IMU_RATE, Registers
from imunoise.writers.vn import write_vn_ascii, write_vn_binary

__all__ = ["BLOCK", "SampleSource", "encode"]

#: IMU samples simulated at once (82 s at 800 Hz).
BLOCK = 1 << 16
_TEMPERATURE = 25.0  # degC
_PRESSURE = 101.3  # kPa
_QUATERNION = (0.0, 0.0, 0.0, 1.0)


class SampleSource:
    """Still-sensor samples by IMU tick, simulated block by block."""

    def __init__(self, seed=None, spec="vn100") -> None:
        self._rng = np.random.default_rng(seed)
        self._spec = spec
        self._first = -1
        self._block: dict[str, np.ndarray] = {}

    def _load(self, block: int) -> None:
        log = still_log(BLOCK / IMU_RATE / 3600.0, IMU_RATE, spec=self._spec,
                        seed=np.random.default_rng([block, int(self._rng.integers(1 << 62))]))
        self._block = {"gyro": log.gyro, "accel": log.accel, "mag": log.mag, "ypr": log.ypr}
        self._first = block

    def take(self, ticks: np.ndarray) -> dict[str, np.ndarray]:
        """Channels at the IMU ticks ``ticks`` (increasing; at most one block apart)."""
        parts: dict[str, list[np.ndarray]] = {k: [] for k in ("gyro", "accel", "mag", "ypr")}
        for block in np.unique(ticks // BLOCK):
            if block != self._first:
                self._load(int(block))
            rows = ticks[ticks // BLOCK == block] % BLOCK
            for k in parts:
                parts[k].append(self._block[k][rows])
        out = {k: np.concatenate(v) for k, v in parts.items()}
        n = len(ticks)
        out["temperature"] = np.full(n, _TEMPERATURE)
        out["pressure"] = np.full(n, _PRESSURE)
        out["quaternion"] = np.tile(_QUATERNION, (n, 1))
        return out


def _due(start: int, stop: int, step: int) -> np.ndarray:
    """Ticks in [start, stop) that are multiples of ``step``."""
    first = -(-start // step) * step
    return np.arange(first, stop, step, dtype=np.int64)


def encode(registers: Registers, source: SampleSource, start: int, stop: int,
           clock_zero: int = 0) -> list[bytes]:
    """The records the sensor sends for IMU ticks [start, stop): the ASCII type of
    register 6 at register 7's rate, then every binary output; one bytes object per
    record. ``TimeStartup`` counts from tick ``clock_zero`` (the last reset)."""
    records: list[bytes] = []
    ador = registers.values[6][0]
    if ador:
        ticks = _due(start, stop, IMU_RATE // registers.values[7][0])
        if len(ticks):
            text = write_vn_ascii(source.take(ticks), ADOR_MESSAGES[ador], crc=registers.crc)
            records.extend(line + b"\n" for line in text.split(b"\n")[:-1])
    for divisor, selection in registers.binary_outputs():
        ticks = _due(start, stop, divisor)
        if len(ticks):
            data = source.take(ticks)
            data["time"] = (ticks - clock_zero) / IMU_RATE
            packets = write_vn_binary(data, selection)
            size = len(packets) // len(ticks)
            records.extend(packets[i:i + size] for i in range(0, len(packets), size))
    return records


def check_selection(registers: Registers, source: SampleSource) -> None:
    """Raise ``ValueError`` when an output asks for a field the emulator cannot fill."""
    encode(registers, source, 0, IMU_RATE, 0)
