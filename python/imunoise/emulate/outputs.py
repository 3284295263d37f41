"""What an emulated still VN-100 sends: simulated samples encoded as its outputs.

The IMU samples are those of :func:`imunoise._simulation.log.still_log` (the
datasheet's noise on gyro and accelerometer, gravity on −Z) at the IMU rate,
generated in blocks of :data:`BLOCK` samples with seeds of their own (the flicker
term therefore restarts every block: fine for a stream, not for an Allan analysis
of hours). A block is the same whenever it is made, so an output that looks back
into the block before reads what the other outputs read.

Attitude and magnetic field move as a still sensor's do: the magnetometer reads
the constant Earth field plus its own noise (:data:`MAG_N`, :data:`MAG_B`), and
yaw, pitch and roll are those of a complementary filter around the constant
attitude: pitch and roll follow the tilt the accelerometer's noise shows and yaw
the heading the magnetometer's shows, both with time constant
:data:`ATTITUDE_TAU` and the gyro's rate integrated in between, so they carry
small noise and slow wander consistent with the gyro, accelerometer and
magnetometer (the filter restarts every block, like the flicker); the
quaternion is that of the same yaw, pitch and roll. Temperature and pressure are
constant.

Each output averages the IMU samples of its period (the ASCII type at register
7's rate, a binary output at 800 Hz / RateDivisor): taking every k-th sample
instead kept the 800 Hz white noise and made its density √k too high at the
output (√20 at 40 Hz); averaged, the density is the datasheet's at every rate.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import lfilter

from imunoise._simulation.log import STILL_MAG, STILL_YPR, still_log
from imunoise._simulation.simulate import simulate
from imunoise.emulate.registers import ADOR_MESSAGES, IMU_RATE, Registers
from imunoise.writers.vn import write_vn_ascii, write_vn_binary

__all__ = ["ATTITUDE_TAU", "BLOCK", "MAG_B", "MAG_N", "SampleSource", "encode"]

#: IMU samples simulated at once (82 s at 800 Hz).
BLOCK = 1 << 16
#: Magnetometer white noise density (Gauss/√Hz) and bias instability (Gauss): the
#: order of a VN-100's (its datasheet gives a noise density of 140 µGauss/√Hz).
MAG_N = 140e-6
MAG_B = 30e-6
#: Time constant (s) of the emulated attitude filter: below it the gyro's
#: integrated rate, above it the accelerometer's tilt and the magnetometer's heading.
ATTITUDE_TAU = 2.0
_CHANNELS = ("gyro", "accel", "mag", "ypr")
_TEMPERATURE = 25.0  # degC
_PRESSURE = 101.3  # kPa
_CACHED = 2  # blocks kept: the current one and the one an average may reach back into


def _complementary(rate: np.ndarray, angle: np.ndarray, dt: float) -> np.ndarray:
    """θ[n] = α (θ[n−1] + ω[n] dt) + (1 − α) a[n]: the angle of rate ``rate``
    (rad/s) and reference ``angle`` (rad), α = τ / (τ + dt); it starts at the
    reference's mean over the first τ (one noisy sample would be a jump that takes
    τ to fade: 0.9° of yaw from the magnetometer's noise at 800 Hz)."""
    alpha = ATTITUDE_TAU / (ATTITUDE_TAU + dt)
    drive = alpha * rate * dt + (1 - alpha) * angle
    start = float(np.mean(angle[:max(1, round(ATTITUDE_TAU / dt))]))
    out, _ = lfilter([1.0], [1.0, -alpha], drive, zi=[alpha * start])
    return out


def _still_block(seed, spec) -> dict[str, np.ndarray]:
    """One block of a still sensor at the IMU rate: gyro (rad/s), accel (m/s²), mag
    (Gauss) and yaw, pitch, roll (deg)."""
    rng = np.random.default_rng(seed)
    log = still_log(BLOCK / IMU_RATE / 3600.0, IMU_RATE, spec=spec, seed=rng)
    gyro, accel = np.asarray(log.gyro), np.asarray(log.accel)
    mag = np.asarray(STILL_MAG) + simulate(BLOCK, IMU_RATE, N=MAG_N, B=MAG_B, channels=3,
                                            seed=rng)
    dt = 1.0 / IMU_RATE
    # the tilt and heading the noisy accelerometer and magnetometer show (body x
    # forward, y right, z down: a still sensor reads (g sinθ, −g sinφ cosθ, ...))
    g = np.linalg.norm(accel, axis=1)
    pitch = np.arcsin(np.clip(accel[:, 0] / g, -1, 1))
    roll = np.arctan2(-accel[:, 1], -accel[:, 2])
    heading = np.arctan2(mag[:, 1], mag[:, 0]) - np.arctan2(STILL_MAG[1], STILL_MAG[0])
    ypr = np.column_stack([
        _complementary(gyro[:, 2], heading, dt),
        _complementary(gyro[:, 1], pitch, dt),
        _complementary(gyro[:, 0], roll, dt),
    ])
    ypr = np.asarray(STILL_YPR) + np.degrees(ypr)
    return {"gyro": gyro, "accel": accel, "mag": mag, "ypr": ypr}


class SampleSource:
    """Still-sensor samples by IMU tick, simulated block by block."""

    def __init__(self, seed=None, spec="vn100") -> None:
        self._base = int(np.random.default_rng(seed).integers(1 << 62))
        self._spec = spec
        self._blocks: dict[int, dict[str, np.ndarray]] = {}

    def _block(self, block: int) -> dict[str, np.ndarray]:
        if block not in self._blocks:
            if len(self._blocks) >= _CACHED:  # the one farthest from where outputs are
                del self._blocks[max(self._blocks, key=lambda b: abs(b - block))]
            self._blocks[block] = _still_block([block, self._base], self._spec)
        return self._blocks[block]

    def take(self, ticks: np.ndarray, window: int = 1) -> dict[str, np.ndarray]:
        """Channels at the IMU ticks ``ticks`` (increasing), each the mean of the
        ``window`` IMU samples up to and including its tick (the output's period;
        ticks before the first are not there)."""
        ticks = np.asarray(ticks, dtype=np.int64)
        n = len(ticks)
        rows = ticks[:, None] + np.arange(1 - window, 1, dtype=np.int64)[None, :]
        flat = np.maximum(rows, 0).ravel()
        parts = {k: np.empty((len(flat), 3)) for k in _CHANNELS}
        for block in np.unique(flat // BLOCK):
            inside = flat // BLOCK == block
            data = self._block(int(block))
            for k in _CHANNELS:
                parts[k][inside] = data[k][flat[inside] % BLOCK]
        out = {k: v.reshape(n, window, 3).mean(axis=1) for k, v in parts.items()}
        out["temperature"] = np.full(n, _TEMPERATURE)
        out["pressure"] = np.full(n, _PRESSURE)
        out["quaternion"] = _quaternion(out["ypr"])
        return out


def _quaternion(ypr: np.ndarray) -> np.ndarray:
    """(qx, qy, qz, qw), scalar last as the VN-100 sends it, of the 3-2-1 rotation
    of yaw, pitch, roll (deg): the same attitude as the Euler angles beside it."""
    half = np.radians(ypr) / 2
    cy, cp, cr = np.cos(half).T
    sy, sp, sr = np.sin(half).T
    return np.column_stack([sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
                            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy])


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
        step = IMU_RATE // registers.values[7][0]
        ticks = _due(start, stop, step)
        if len(ticks):
            text = write_vn_ascii(source.take(ticks, step), ADOR_MESSAGES[ador],
                                  crc=registers.crc)
            records.extend(line + b"\n" for line in text.split(b"\n")[:-1])
    for divisor, selection in registers.binary_outputs():
        ticks = _due(start, stop, divisor)
        if len(ticks):
            data = source.take(ticks, divisor)
            data["time"] = (ticks - clock_zero) / IMU_RATE
            packets = write_vn_binary(data, selection)
            size = len(packets) // len(ticks)
            records.extend(packets[i:i + size] for i in range(0, len(packets), size))
    return records


def check_selection(registers: Registers, source: SampleSource) -> None:
    """Raise ``ValueError`` when an output asks for a field the emulator cannot fill."""
    encode(registers, source, 0, IMU_RATE, 0)
