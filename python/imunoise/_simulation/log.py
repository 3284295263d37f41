"""Logs of a simulated still IMU, written in the sensor's own format.

The noise of each inertial channel comes from :func:`imunoise.simulate` with the
coefficients of a datasheet (the N and B it specifies; K, which datasheets of MEMS
parts rarely give, from ``DEFAULT_K``), on top of what a still sensor reads:
gravity on −Z, a constant attitude and a constant Earth field.

A datasheet's bias instability is the floor of the Allan curve, σ_min/0.6643, and
the white noise and rate random walk lift that floor above the flicker term alone.
The simulated flicker coefficient is therefore the one whose model floor, with the
datasheet's other terms, equals the datasheet value: a sensor simulated "at its
datasheet" then reads its datasheet value back (:func:`imunoise.compare` measures
the same floor), instead of 6 % above it.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from imunoise._simulation.simulate import simulate
from imunoise._support import schema as _schema
from imunoise._support import warn as _warn
from imunoise._support.deprecation import old_call_forms
from imunoise._support.validate import positive_finite, sample_rate
from imunoise.datasheet import load_spec
from imunoise.errors import AssumptionWarning, ImunoiseValueError
from imunoise.noise import FLICKER, model_variance
from imunoise.readers.log import ImuLog
from imunoise.units import convert_back
from imunoise.writers.vn import write_vn_ascii, write_vn_binary

__all__ = [
    "DEFAULT_K", "MAX_SAMPLES", "flicker_for_floor", "noise_of_spec", "simulate_log", "still_log",
]

#: Rate random walk used where the datasheet gives none (typical MEMS values):
#: gyro rad/s/√s, accelerometer m/s²/√s.
DEFAULT_K = {"gyro": 2e-6, "accel": 3e-5}

#: What a still, level VN-100 reads besides noise (Earth rate ignored).
_STILL_MEAN = {"gyro": (0.0, 0.0, 0.0), "accel": (0.0, 0.0, -_schema.G)}
STILL_YPR = (-77.7, -1.3, 0.15)  # deg
STILL_MAG = (0.045, 0.247, -0.338)  # Gauss
_FORMATS = ("vn-ascii", "vn-binary")
#: Most samples a simulated log may have (hours x 3600 x fs): 69 h at 40 Hz, 2.8 h at
#: 1 kHz. The log is built in memory, about 400 bytes per sample (4 GB at the bound).
MAX_SAMPLES = 10_000_000


def noise_of_spec(spec="vn100") -> dict[str, dict[str, float]]:
    """Noise coefficients in SI units (rad/s and m/s² rates) from a datasheet.

    Parameters
    ----------
    spec : str, path or mapping
        A built-in datasheet name (``"vn100"``), a TOML file in the format of
        ``imunoise/specs/vn100.toml``, or a mapping ``{"gyro": {"N": …, "B": …,
        "K": …}, "accel": {…}}`` already in SI units (returned as given).
    """
    if isinstance(spec, dict):
        return {sensor: dict(terms) for sensor, terms in spec.items()}
    loaded = load_spec(spec)
    noise: dict[str, dict[str, float]] = {s: {"K": DEFAULT_K[s]} for s in DEFAULT_K}
    for item in loaded.items:
        if item.sensor in noise and item.term in ("Q", "N", "B", "K", "R"):
            noise[item.sensor][item.term] = float(
                convert_back(item.value, item.term, item.unit, sensor=item.sensor)
            )
    for sensor, terms in noise.items():
        if "B" in terms:
            others = {t: v for t, v in terms.items() if t != "B"}
            terms["B"] = flicker_for_floor(terms["B"], sensor=sensor, **others)
    return noise


def flicker_for_floor(floor: float, *, sensor: str = "", **terms: float) -> float:
    r"""The flicker coefficient B whose Allan floor, with the other ``terms``, is ``floor``.

    The floor is the datasheet's bias instability, :math:`\min_\tau \sigma(\tau)/0.6643`.
    B adds the constant :math:`0.6643^2 B^2` to the Allan variance, so the minimum
    stays where the other terms put it and
    :math:`B^2 = \text{floor}^2 - \min_\tau \sigma^2_\text{others}(\tau)/0.6643^2`.
    Where the other terms alone already lift the floor above ``floor`` no B can
    reach it: B is 0 and a warning says so.

    Parameters
    ----------
    floor : float
        Bias instability, rate units (rad/s or m/s²).
    sensor : str, optional
        Named in the warning.
    **terms : float
        The other coefficients (Q, N, K, R) in SI units.
    """
    floor = float(floor)
    taus = np.logspace(-4, 8, 2401)  # 200 per decade: the minimum to ~1e-5 relative
    others = float(np.min(model_variance(taus, **terms))) / FLICKER**2
    if others >= floor**2:
        _warn.warn(
            f"{sensor or 'sensor'}: the datasheet's other terms alone put the Allan floor at "
            f"{np.sqrt(others):.3g}, above its bias instability {floor:.3g}; simulating B = 0",
            AssumptionWarning,
        )
        return 0.0
    return float(np.sqrt(floor**2 - others))


def still_log(hours: float, fs: float = 40.0, *, spec="vn100", seed=None) -> ImuLog:
    """An :class:`ImuLog` of a still sensor with the noise of ``spec``: gyro and
    accelerometer simulated, attitude and magnetic field constant."""
    hours = positive_finite(hours, "hours")
    fs = sample_rate(fs)
    samples = hours * 3600.0 * fs
    if samples > MAX_SAMPLES:
        raise ImunoiseValueError(
            f"hours={hours:g} at fs={fs:g} Hz gives {samples:.4g} samples; at most "
            f"{MAX_SAMPLES:,} are simulated (about 400 bytes of memory each; "
            f"{MAX_SAMPLES / fs / 3600:.4g} h at this rate)"
        )
    n = int(round(samples))
    if n < 2:
        raise ImunoiseValueError(
            f"hours={hours:g} at fs={fs:g} Hz gives {n} samples; at least 2 needed")
    noise = noise_of_spec(spec)
    rng = np.random.default_rng(seed)
    channels = {}
    for sensor in ("gyro", "accel"):
        coefficients = noise.get(sensor, {})
        channels[sensor] = simulate(n, fs, channels=3, seed=rng, **coefficients) + np.asarray(
            _STILL_MEAN[sensor]
        )
    channels["ypr"] = np.broadcast_to(np.array(STILL_YPR), (n, 3))
    channels["mag"] = np.broadcast_to(np.array(STILL_MAG), (n, 3))
    label = "IMU" if isinstance(spec, dict) else load_spec(spec).name
    return ImuLog.from_arrays(fs, source=f"<simulated {label}, {hours:g} h>", **channels)


@old_call_forms(keyword_only=("format", "spec", "seed"))
def simulate_log(path: str | os.PathLike, hours: float, fs: float = 40.0, *,
                 format: str = "vn-ascii", spec="vn100", seed=None) -> Path:
    """Write the log of a still VN-100 with datasheet-level noise.

    Parameters
    ----------
    path : str or path-like
        File to write (parent directories are created).
    hours : float
        Length of the recording.
    fs : float, optional
        Output rate in Hz (the VN-100 default is 40 Hz).
    format : {"vn-ascii", "vn-binary"}, optional
        ``$VNYMR`` sentences with 8-bit checksums, or binary packets with
        TimeStartup, YawPitchRoll, angular rate, acceleration and magnetic field.
    spec : str, path or mapping, optional
        Noise source, see :func:`noise_of_spec`.
    seed : int or None, optional
        Seed of the noise generator.

    Returns
    -------
    pathlib.Path
        The file written; ``imunoise.read`` reads it back.
    """
    if format not in _FORMATS:
        raise ImunoiseValueError(f"format must be one of {', '.join(_FORMATS)}; got {format!r}")
    log = still_log(hours, fs, spec=spec, seed=seed)
    path = Path(os.fspath(path))
    path.parent.mkdir(parents=True, exist_ok=True)
    if format == "vn-ascii":
        write_vn_ascii(log, "VNYMR", path=path)
    else:
        write_vn_binary(log, path=path)
    return path
