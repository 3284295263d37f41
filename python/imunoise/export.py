"""Parameter files for estimators: Kalibr, OpenVINS, and JSON of a full model.

Kalibr's IMU model (``imu.yaml``) and OpenVINS' ``kalibr_imu_chain.yaml`` take
continuous-time densities in SI units:

===============================  =======================  ====================
key                              noise-model coefficient  unit
===============================  =======================  ====================
``gyroscope_noise_density``      N of the gyro            rad/s/√Hz
``gyroscope_random_walk``        K of the gyro            rad/s²/√Hz
``accelerometer_noise_density``  N of the accelerometer   m/s²/√Hz
``accelerometer_random_walk``    K of the accelerometer   m/s³/√Hz
===============================  =======================  ====================

(N in rad/√s is numerically rad/s/√Hz, K in rad/s/√s is rad/s²/√Hz.) Kalibr's
model has no Gauss–Markov state, so the values written are the model's
datasheet values (``model.N``, ``model.K``: the numbers every view prints): Gauss–Markov terms
whose hump lies before 1 s are folded into the white noise, a slow one whose hump lies beyond
the record into the random walk (over the record it rises like one); a bump within
the record is no walk and stays out. The :func:`ekf_dict` export keeps the
Gauss–Markov terms as bias states instead. A value the data do not resolve is
written as its 95 % upper bound (``model.upper``), with a warning: 0 would tell
an estimator "no such noise". The
files hold one number per sensor, so the axes are combined: ``combine="max"``
(default, the worst axis: conservative, what Kalibr's authors recommend when in
doubt) or ``"rms"`` (√ of the mean square over axes). Kalibr's documentation
also suggests inflating the values of a still-bench characterisation for a
moving platform; do that with ``inflate`` (default 1: the measured values).

All files are written atomically (:mod:`imunoise._support.atomic`): a unique temporary
beside the target is written, fsync-ed and renamed onto it.

References
----------
Kalibr wiki, "IMU Noise Model" (ethz-asl/kalibr).
OpenVINS documentation, "Sensor Calibration" / ``kalibr_imu_chain.yaml``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from imunoise import units as _units
from imunoise._support import atomic as _atomic
from imunoise._support import warn as _warn
from imunoise.errors import CoverageWarning, ImunoiseDeprecationWarning, ImunoiseValueError
from imunoise.noise import _typed

__all__ = [
    "ekf_dict",
    "ekf_yaml",
    "write_ekf",
    "kalibr_dict",
    "kalibr_yaml",
    "openvins_yaml",
    "model_json",
    "write_atomic",
    "write_kalibr",
    "write_openvins",
    "write_json",
]


def write_atomic(path, text: str) -> Path:
    """Deprecated (0.2): every writer of imunoise writes atomically; to write text of
    your own atomically use :func:`write_json` / :func:`write_kalibr` or your own code.
    Writes ``text`` to ``path`` through the one atomic-write helper."""
    _warn.warn("imunoise.export.write_atomic is deprecated and will be removed in 0.3; "
               "the export.write_* functions write atomically", ImunoiseDeprecationWarning)
    return _atomic.write_text(path, text)


def _value_or_bound(model, term: str, sensor: str) -> np.ndarray:
    """The datasheet value of ``term`` per axis, its 95 % upper bound where the data
    do not resolve it (an estimator needs a number, and 0 would mean "none"), with a
    warning naming the axes; NaN only where there is neither."""
    values = np.atleast_1d(model.value(term)).astype(float)
    missing = ~np.atleast_1d(model.resolved(term))
    if missing.any():
        bounds = np.atleast_1d(model.upper[term])
        values = np.where(missing, bounds, values)
        axes = ", ".join(str(i) for i in np.flatnonzero(missing))
        _warn.warn(
            f"the {sensor} model does not resolve {term} on axis {axes}; writing its 95 % "
            "upper bound (model.upper), the largest value the measured curve allows",
            CoverageWarning,
        )
    return values


def _combine(model, term: str, combine: str, sensor: str, input_unit) -> float:
    # The model's datasheet value: Kalibr's white + random-walk model has no
    # Gauss–Markov state, so fast ones count as white noise and slow ones as walk.
    values = _value_or_bound(model, term, sensor)
    sup = np.isfinite(values)
    scale = _units.input_scale(sensor, input_unit)
    if not sup.any():
        _warn.warn(
            f"the {sensor} model has no {term} and no bound on it on any axis; writing 0 "
            f"(an estimator may need a small positive value)",
            CoverageWarning,
        )
        return 0.0
    v = values[sup] * scale
    if combine == "max":
        return float(np.max(v))
    return float(math.sqrt(np.mean(v**2)))


def kalibr_dict(gyro=None, accel=None, *, rostopic: str = "/imu0", update_rate=None,
                combine: str = "max", inflate: float = 1.0, gyro_unit: str | None = None,
                accel_unit: str | None = None) -> dict:
    """The values of a Kalibr ``imu.yaml`` (SI, continuous time).

    Parameters
    ----------
    gyro, accel : NoiseModel, optional
        Models fitted to gyroscope and accelerometer rates (at least one).
    rostopic : str
    update_rate : float, optional
        IMU rate in Hz; default the models' ``fs``.
    combine : {"max", "rms"}
        How the axes are combined (worst axis or root mean square).
    inflate : float
        Multiplier on every density (≥ 1 for a moving platform).
    gyro_unit, accel_unit : str, optional
        Units of the rate data the models were fitted to (default rad/s, m/s²).
    """
    if gyro is None and accel is None:
        raise ImunoiseValueError("gyro and accel are both None; pass at least one NoiseModel")
    if combine not in ("max", "rms"):
        raise ImunoiseValueError(f"combine must be 'max' or 'rms'; got {combine!r}")
    if not (math.isfinite(inflate) and inflate > 0):
        raise ImunoiseValueError(f"inflate must be finite and > 0; got {inflate!r}")
    if update_rate is None:
        update_rate = (gyro if gyro is not None else accel).fs
    update_rate = float(update_rate)
    if not (math.isfinite(update_rate) and update_rate > 0):
        raise ImunoiseValueError(f"update_rate must be finite and > 0; got {update_rate!r}")
    out: dict = {}
    if accel is not None:
        out["accelerometer_noise_density"] = inflate * _combine(
            accel, "N", combine, "accel", accel_unit)
        out["accelerometer_random_walk"] = inflate * _combine(
            accel, "K", combine, "accel", accel_unit)
    if gyro is not None:
        out["gyroscope_noise_density"] = inflate * _combine(gyro, "N", combine, "gyro", gyro_unit)
        out["gyroscope_random_walk"] = inflate * _combine(gyro, "K", combine, "gyro", gyro_unit)
    out["rostopic"] = str(rostopic)
    out["update_rate"] = update_rate
    return out


_COMMENTS = {
    "accelerometer_noise_density": "m/s^2/sqrt(Hz), continuous time (N)",
    "accelerometer_random_walk": "m/s^3/sqrt(Hz), continuous time (K)",
    "gyroscope_noise_density": "rad/s/sqrt(Hz), continuous time (N)",
    "gyroscope_random_walk": "rad/s^2/sqrt(Hz), continuous time (K)",
    "rostopic": "the IMU ROS topic",
    "update_rate": "Hz (for discretization of the values above)",
}


def _scalar(v) -> str:
    if isinstance(v, str):
        return v
    return f"{v:.6e}" if v else "0.0"


def kalibr_yaml(gyro=None, accel=None, **kwargs) -> str:
    """Kalibr ``imu.yaml`` text (see :func:`kalibr_dict` for the options)."""
    d = kalibr_dict(gyro, accel, **kwargs)
    combine = kwargs.get("combine", "max")
    lines = [
        "# IMU noise model for Kalibr, written by imunoise",
        f"# axes combined by: {combine}",
    ]
    for k, v in d.items():
        val = f"{v:.1f}" if k == "update_rate" else _scalar(v)
        lines.append(f"{k}: {val}  # {_COMMENTS[k]}")
    return "\n".join(lines) + "\n"


def openvins_yaml(gyro=None, accel=None, *, imu_name: str = "imu0", **kwargs) -> str:
    """OpenVINS-style ``kalibr_imu_chain.yaml`` text (identity T_i_b, calibrated model)."""
    d = kalibr_dict(gyro, accel, **kwargs)
    lines = [
        "%YAML:1.0",
        "",
        f"{imu_name}:",
        "  T_i_b:",
        "    - [1.0, 0.0, 0.0, 0.0]",
        "    - [0.0, 1.0, 0.0, 0.0]",
        "    - [0.0, 0.0, 1.0, 0.0]",
        "    - [0.0, 0.0, 0.0, 1.0]",
    ]
    for k in (
        "accelerometer_noise_density",
        "accelerometer_random_walk",
        "gyroscope_noise_density",
        "gyroscope_random_walk",
    ):
        if k in d:
            lines.append(f"  {k}: {_scalar(d[k])}")
    lines += [
        "  model: calibrated",
        f"  rostopic: {d['rostopic']}",
        "  time_offset: 0.0",
        f"  update_rate: {d['update_rate']:.1f}",
    ]
    return "\n".join(lines) + "\n"


def model_json(model=None, **models) -> str:
    """JSON text of one model (``model_json(m)``) or several (``model_json(gyro=g, accel=a)``)."""
    if model is not None and models:
        raise ImunoiseValueError("pass either one model or keyword models, not both")
    if model is not None:
        payload = model.to_dict()
    elif models:
        payload = {name: m.to_dict() for name, m in models.items()}
    else:
        raise ImunoiseValueError("model_json needs a NoiseModel")
    return json.dumps(payload, indent=2, allow_nan=False) + "\n"


def _ekf_axes(model, sensor: str, input_unit, min_samples: float) -> dict:
    scale = _units.input_scale(sensor, input_unit)
    axes = {}
    names = ["x", "y", "z"] if model.channels == 3 else [f"ch{i}" for i in range(model.channels)]
    # The state-space model is built from the fitted components (a slow
    # Gauss–Markov term is a state of its own, not part of K); the datasheet
    # values the other views print go beside it.
    sheet = {t: _value_or_bound(model, t, sensor) for t in ("N", "B", "K")}
    for c, name in enumerate(names):
        terms = model.terms[c]
        # Each kind says what it gives the filter (Term.ekf: white noise for the
        # measurement, bias states), so a new kind needs no branch here.
        white2 = 0.0
        states = []
        for share in (term.ekf(model.fs, min_samples) for term in terms):
            white2 += share.white_density
            states += [{
                "sigma": state.sigma * scale,
                "correlation_time": state.correlation_time,
                "driving_noise_density": state.driving_noise_density * scale,
            } for state in share.states]
        # The walk's driving noise: the fitted K; where the data do not resolve K,
        # its bound (a slow Gauss–Markov term standing in for K is a state above).
        walk = _typed.coefficient(terms, "K")
        if not model.resolved("K")[c]:
            walk = float(sheet["K"][c])
        axes[name] = {
            "white_noise_density": math.sqrt(white2) * scale,
            "random_walk": walk * scale,
            "bias_instability": float(sheet["B"][c]) * scale,
            "gauss_markov": states,
            "datasheet": {t: float(sheet[t][c]) * scale for t in ("N", "B", "K")},
            "upper_bounds": [t for t in ("N", "B", "K") if not model.resolved(t)[c]],
        }
    return axes


def ekf_dict(gyro=None, accel=None, *, gyro_unit: str | None = None,
             accel_unit: str | None = None, min_samples: float = 10.0) -> dict:
    """A Gauss–Markov bias model per axis for an extended Kalman filter (SI units).

    Per sensor and axis: ``white_noise_density`` (rad/s/√Hz or m/s²/√Hz: the
    continuous-time density of the measurement noise), ``random_walk`` (K,
    rad/s²/√Hz or m/s³/√Hz: driving noise of a random-walk bias state),
    ``bias_instability`` (B, the flicker term, rad/s or m/s²; no finite state
    models it exactly) and ``gauss_markov``: one bias state per Gauss–Markov
    term, ḃ = −b/τc + w with ``sigma`` (steady-state standard deviation),
    ``correlation_time`` τc (s) and ``driving_noise_density`` √(2σ²/τc) (the
    density of w). Discretised at step Δt: b[k+1] = e^(−Δt/τc)·b[k] + w[k],
    var w[k] = σ²(1 − e^(−2Δt/τc)). A Gauss–Markov term faster than
    ``min_samples`` samples cannot be a state at the IMU rate and is folded
    into the white noise. These state-space values come from the fitted
    terms (``model.terms``); ``datasheet`` holds the model's datasheet
    values N, B, K (``model.N``…, the numbers the report and the other exports
    print) in the same SI units, for reference. Where the data do not resolve N,
    B or K, the value written is its 95 % upper bound (``model.upper``), with a
    warning, and ``upper_bounds`` names those terms.
    """
    if gyro is None and accel is None:
        raise ImunoiseValueError("gyro and accel are both None; pass at least one NoiseModel")
    if not (math.isfinite(min_samples) and min_samples >= 0):
        raise ImunoiseValueError(f"min_samples must be finite and >= 0; got {min_samples!r}")
    out: dict = {}
    for key, model, sensor, unit, rate, walk in (
            ("gyroscope", gyro, "gyro", gyro_unit, "rad/s", "rad/s^2"),
            ("accelerometer", accel, "accel", accel_unit, "m/s^2", "m/s^3")):
        if model is None:
            continue
        out[key] = {
            "units": {"white_noise_density": f"{rate}/sqrt(Hz)",
                      "random_walk": f"{walk}/sqrt(Hz)", "bias_instability": rate,
                      "sigma": rate, "correlation_time": "s",
                      "driving_noise_density": f"{rate}/sqrt(s)"},
            "axes": _ekf_axes(model, sensor, unit, min_samples),
        }
    out["update_rate"] = float((gyro if gyro is not None else accel).fs)
    return out


def ekf_yaml(gyro=None, accel=None, **kwargs) -> str:
    """YAML text of :func:`ekf_dict`."""
    d = ekf_dict(gyro, accel, **kwargs)
    lines = ["# IMU bias model for an EKF (continuous time, SI units), written by imunoise"]
    for sensor in ("gyroscope", "accelerometer"):
        if sensor not in d:
            continue
        lines.append(f"{sensor}:")
        lines.append("  units: {" + ", ".join(f"{k}: {v}" for k, v in d[sensor]["units"].items())
                     + "}")
        lines.append("  axes:")
        for axis, a in d[sensor]["axes"].items():
            lines.append(f"    {axis}:")
            for key in ("white_noise_density", "random_walk", "bias_instability"):
                lines.append(f"      {key}: {_scalar(a[key])}")
            lines.append("      datasheet: {" + ", ".join(
                f"{k}: {_scalar(v)}" for k, v in a["datasheet"].items()) + "}")
            lines.append("      upper_bounds: [" + ", ".join(a["upper_bounds"]) + "]")
            if not a["gauss_markov"]:
                lines.append("      gauss_markov: []")
                continue
            lines.append("      gauss_markov:")
            for g in a["gauss_markov"]:
                lines.append(f"        - {{sigma: {_scalar(g['sigma'])}, correlation_time: "
                             f"{_scalar(g['correlation_time'])}, driving_noise_density: "
                             f"{_scalar(g['driving_noise_density'])}}}")
    lines.append(f"update_rate: {d['update_rate']:.1f}")
    return "\n".join(lines) + "\n"


def write_ekf(path, gyro=None, accel=None, **kwargs) -> Path:
    """Write :func:`ekf_yaml` atomically; returns the path."""
    return _atomic.write_text(path, ekf_yaml(gyro, accel, **kwargs))


def write_kalibr(path, gyro=None, accel=None, **kwargs) -> Path:
    """Write a Kalibr ``imu.yaml`` atomically; returns the path."""
    return _atomic.write_text(path, kalibr_yaml(gyro, accel, **kwargs))


def write_openvins(path, gyro=None, accel=None, **kwargs) -> Path:
    """Write an OpenVINS ``kalibr_imu_chain.yaml`` atomically; returns the path."""
    return _atomic.write_text(path, openvins_yaml(gyro, accel, **kwargs))


def write_json(path, model=None, **models) -> Path:
    """Write the full model(s) as JSON atomically; returns the path."""
    return _atomic.write_text(path, model_json(model, **models))
