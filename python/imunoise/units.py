"""Datasheet units for the noise coefficients of gyroscopes and accelerometers.

A :class:`~imunoise.noise.NoiseModel` holds its coefficients in the units of the
rate data it was fitted to ("input units")::

    Q  rate·s       (angle / velocity quantization)
    N  rate·√s      (angle / velocity random walk; equals rate/√Hz)
    B  rate         (bias instability)
    K  rate/√s      (rate random walk; equals rate/s/√Hz)
    R  rate/s       (rate ramp)

This module converts them to the units datasheets use. The input unit of a gyro
is ``"rad/s"`` (default) or ``"deg/s"``; of an accelerometer ``"m/s^2"`` (default)
or ``"g"``. Conversions use g = 9.80665 m/s² (the standard gravity of the CGPM,
1901), 1 h = 3600 s, so 1/√s = 60/√h.

Examples
--------
>>> from imunoise import units
>>> round(units.convert(1e-4, "N", "deg/sqrt(h)", sensor="gyro"), 6)  # rad/√s
0.343775
>>> round(units.convert(1.0, "B", "mg", sensor="accel", input_unit="g"), 9)
1000.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from imunoise._support import schema as _schema
from imunoise.errors import ImunoiseTypeError, ImunoiseValueError

__all__ = [
    "G",
    "DEG",
    "Unit",
    "SENSORS",
    "INPUT_UNITS",
    "UNITS",
    "DEFAULT_UNITS",
    "DATASHEET_UNITS",
    "convert",
    "convert_back",
    "input_scale",
    "unit_info",
]

G = _schema.G
"""Standard gravity, m/s²."""

DEG = math.pi / 180.0
"""One degree in radians."""

SENSORS = _schema.ALLAN_SENSORS
"""Sensors whose noise coefficients have datasheet units."""

INPUT_UNITS: dict[str, dict[str, float]] = {
    # factor that turns one input unit into the SI rate unit (rad/s or m/s²)
    "gyro": {"rad/s": 1.0, "deg/s": DEG},
    "accel": {"m/s^2": 1.0, "g": G, "mg": G * 1e-3},
}


@dataclass(frozen=True)
class Unit:
    """A datasheet unit for one coefficient of one sensor kind.

    ``factor`` multiplies the coefficient in SI units (rad/s or m/s² based) to
    give the value in this unit.
    """

    name: str
    label: str
    term: str
    sensor: str
    factor: float


_H = 3600.0
_SQRT_H = 60.0  # √(3600 s) in √s


def _units() -> dict[tuple[str, str], Unit]:
    rows = [
        # gyro, SI rate unit rad/s
        ("gyro", "Q", "rad", "rad", 1.0),
        ("gyro", "Q", "deg", "°", 1 / DEG),
        ("gyro", "Q", "arcsec", "″", 3600 / DEG),
        ("gyro", "N", "rad/sqrt(s)", "rad/√s", 1.0),
        ("gyro", "N", "deg/sqrt(h)", "°/√h", _SQRT_H / DEG),
        ("gyro", "N", "deg/s/sqrt(Hz)", "°/s/√Hz", 1 / DEG),
        ("gyro", "N", "deg/h/sqrt(Hz)", "°/h/√Hz", _H / DEG),
        ("gyro", "B", "rad/s", "rad/s", 1.0),
        ("gyro", "B", "deg/h", "°/h", _H / DEG),
        ("gyro", "B", "deg/s", "°/s", 1 / DEG),
        ("gyro", "K", "rad/s/sqrt(s)", "rad/s/√s", 1.0),
        ("gyro", "K", "deg/h/sqrt(h)", "°/h/√h", _H * _SQRT_H / DEG),
        ("gyro", "K", "deg/s/sqrt(s)", "°/s/√s", 1 / DEG),
        ("gyro", "R", "rad/s^2", "rad/s²", 1.0),
        ("gyro", "R", "deg/h^2", "°/h²", _H * _H / DEG),
        # accelerometer, SI rate unit m/s²
        ("accel", "Q", "m/s", "m/s", 1.0),
        ("accel", "N", "m/s/sqrt(s)", "m/s/√s", 1.0),
        ("accel", "N", "mg/sqrt(Hz)", "mg/√Hz", 1e3 / G),
        ("accel", "N", "ug/sqrt(Hz)", "µg/√Hz", 1e6 / G),
        ("accel", "N", "m/s/sqrt(h)", "m/s/√h", _SQRT_H),
        ("accel", "B", "m/s^2", "m/s²", 1.0),
        ("accel", "B", "mg", "mg", 1e3 / G),
        ("accel", "B", "ug", "µg", 1e6 / G),
        ("accel", "K", "m/s^2/sqrt(s)", "m/s²/√s", 1.0),
        ("accel", "K", "m/s/h/sqrt(h)", "m/s/h/√h", _H * _SQRT_H),
        ("accel", "K", "mg/sqrt(s)", "mg/√s", 1e3 / G),
        ("accel", "K", "ug/sqrt(s)", "µg/√s", 1e6 / G),
        ("accel", "R", "m/s^3", "m/s³", 1.0),
        ("accel", "R", "mg/s", "mg/s", 1e3 / G),
        ("accel", "R", "ug/s", "µg/s", 1e6 / G),
    ]
    return {(s, n): Unit(n, lab, t, s, f) for s, t, n, lab, f in rows}


UNITS: dict[tuple[str, str], Unit] = _units()
"""Every known unit, keyed by (sensor, name)."""

DEFAULT_UNITS: dict[str, dict[str, str]] = {
    "gyro": {
        "Q": "deg",
        "N": "deg/sqrt(h)",
        "B": "deg/h",
        "K": "deg/h/sqrt(h)",
        "R": "deg/h^2",
    },
    "accel": {
        "Q": "m/s",
        "N": "mg/sqrt(Hz)",
        "B": "ug",
        "K": "m/s^2/sqrt(s)",
        "R": "m/s^3",
    },
}
"""The datasheet unit used for each coefficient when none is asked for."""

DATASHEET_UNITS: dict[str, dict[str, str]] = {
    "gyro": {
        "Q": "deg",
        "N": "deg/s/sqrt(Hz)",
        "B": "deg/h",
        "K": "deg/h/sqrt(h)",
        "R": "deg/h^2",
    },
    "accel": {
        "Q": "m/s",
        "N": "ug/sqrt(Hz)",
        "B": "ug",
        "K": "m/s^2/sqrt(s)",
        "R": "m/s^3",
    },
}
"""The units MEMS datasheets (the VN-100's among them) write: noise density per √Hz,
bias stability in °/h and µg; ``units="datasheet"`` in :meth:`NoiseModel.table`."""


def unit_choice(units, sensor: str) -> dict[str, str]:
    """A ``units`` option of the tables as a dict: ``None`` (the defaults),
    ``"datasheet"`` (:data:`DATASHEET_UNITS`) or ``{term: unit}``."""
    _check_sensor(sensor)
    if units is None:
        return {}
    if isinstance(units, str):
        if units != "datasheet":
            raise ImunoiseValueError(f"units must be 'datasheet', a dict of term -> unit or None; "
                             f"got {units!r}")
        return dict(DATASHEET_UNITS[sensor])
    if not isinstance(units, dict):
        raise ImunoiseTypeError(
            f"units must be 'datasheet', a dict or None; got {type(units).__name__}")
    return dict(units)

_ALIASES = {
    "°": "deg",
    "µ": "u",
    "μ": "u",
    "√": "sqrt",
    "²": "^2",
    "³": "^3",
}


def _normalise(name: str) -> str:
    out = name.strip()
    for a, b in _ALIASES.items():
        out = out.replace(a, b)
    # "sqrth" (from "√h") -> "sqrt(h)"
    for v in ("h", "s", "Hz"):
        out = out.replace(f"sqrt{v}", f"sqrt({v})")
    return out.replace(" ", "")


def _check_sensor(sensor: str) -> str:
    if sensor not in SENSORS:
        raise ImunoiseValueError(f"sensor must be one of {SENSORS}; got {sensor!r}")
    return sensor


def input_scale(sensor: str, input_unit: str | None = None) -> float:
    """Factor turning one input rate unit into the SI rate unit of ``sensor``."""
    _check_sensor(sensor)
    table = INPUT_UNITS[sensor]
    if input_unit is None:
        input_unit = next(iter(table))
    if input_unit not in table:
        raise ImunoiseValueError(
            f"input_unit for a {sensor} must be one of {tuple(table)}; got {input_unit!r}"
        )
    return table[input_unit]


def unit_info(term: str, unit: str | None, sensor: str) -> Unit:
    """Look up a datasheet unit (``None`` gives the default unit of ``term``)."""
    _check_sensor(sensor)
    if term not in ("Q", "N", "B", "K", "R"):
        raise ImunoiseValueError(f"term must be one of Q, N, B, K, R; got {term!r}")
    name = DEFAULT_UNITS[sensor][term] if unit is None else _normalise(unit)
    info = UNITS.get((sensor, name))
    if info is None or info.term != term:
        known = [u.name for (s, _), u in UNITS.items() if s == sensor and u.term == term]
        raise ImunoiseValueError(f"unit for {sensor} {term} must be one of {known}; got {unit!r}")
    return info


def convert(value, term: str, unit: str | None = None, *, sensor: str = "gyro",
            input_unit: str | None = None) -> float | np.ndarray:
    """Convert a coefficient from input units to a datasheet unit.

    Parameters
    ----------
    value : float or array_like
        Coefficient ``term`` in the input's units (see the module docstring).
    term : {"Q", "N", "B", "K", "R"}
    unit : str, optional
        Target unit, e.g. ``"deg/sqrt(h)"`` or ``"°/√h"``; default from
        :data:`DEFAULT_UNITS`.
    sensor : {"gyro", "accel"}
    input_unit : str, optional
        Unit of the rate data: ``"rad/s"``/``"deg/s"`` or ``"m/s^2"``/``"g"``/``"mg"``.
    """
    info = unit_info(term, unit, sensor)
    scale = input_scale(sensor, input_unit) * info.factor
    if np.ndim(value) == 0:
        return float(value) * scale
    return np.asarray(value, dtype=float) * scale


def convert_back(value, term: str, unit: str | None = None, *, sensor: str = "gyro",
                 input_unit: str | None = None) -> float | np.ndarray:
    """Inverse of :func:`convert`: a datasheet value back to input units."""
    info = unit_info(term, unit, sensor)
    scale = input_scale(sensor, input_unit) * info.factor
    if np.ndim(value) == 0:
        return float(value) / scale
    return np.asarray(value, dtype=float) / scale
