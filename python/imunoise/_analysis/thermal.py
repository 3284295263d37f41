r"""Bias against temperature: the thermal sensitivity of each axis, and its removal.

:func:`thermal` fits, per channel,

.. math:: b(T) = c_0 + c_1 (T - T_0) + c_2 (T - T_0)^2

(``degree=1`` or ``2``) to block means of the rate and the temperature, and
gives the coefficients with their uncertainties in the channel's unit and in
datasheet units (°/h/°C for gyros, mg/°C for accelerometers), the temperature
range the fit covers, and the compensated series
:math:`x_i - c_1 (T_i - T_0) - c_2 (T_i - T_0)^2` (the bias at :math:`T_0` kept).

Uncertainties
-------------
Ordinary least squares on the block means; the residuals of a real sensor are
correlated (bias wander), so the covariance is multiplied by
:math:`(1+\rho_1)/(1-\rho_1)`, the variance inflation of an AR(1) residual with
lag-1 autocorrelation :math:`\rho_1` (Bartlett 1946). Without that factor the
uncertainty of a slope fitted across a slow warm-up is several times too small.

Caveat: on a log that only warms up, temperature and time change together, so
the fit cannot tell a thermal bias from a warm-up transient or a slow drift;
``time_correlation`` (|r| of temperature with time) says how confounded they
are. A log with temperature cycles (or several logs at different
temperatures) separates them.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from imunoise._analysis.channels import rate_channels
from imunoise._support import schema as _schema
from imunoise._support import summary as _summary
from imunoise.display import format_value
from imunoise.errors import ImunoiseValueError
from imunoise.readers.log import ImuLog

__all__ = ["Thermal", "thermal", "DATASHEET_UNITS"]

#: Sensor -> (datasheet unit of a thermal coefficient, factor from the log's unit per °C).
DATASHEET_UNITS = {
    "gyro": ("°/h/°C", 180.0 / np.pi * 3600.0),
    "accel": ("mg/°C", 1000.0 / _schema.G),
}
#: Fewest blocks a fit needs.
MIN_BLOCKS = 10


@dataclass(frozen=True, repr=False)
class Thermal:
    r"""Bias-vs-temperature fit per channel (see :func:`thermal`).

    Attributes
    ----------
    names : tuple of str
        Channels fitted.
    sensors : tuple of str
        ``"gyro"``, ``"accel"`` or ``""`` (unknown: no datasheet units) per channel.
    degree : int
        1 (linear) or 2 (quadratic).
    reference : float
        :math:`T_0`, °C (the mean block temperature unless given).
    coef, coef_std : ndarray, (degree + 1, k)
        :math:`c_0, c_1[, c_2]` per channel and their standard uncertainties
        (channel unit, per °C, per °C²).
    temperature_range : (float, float)
        Lowest and highest block-mean temperature, °C.
    block_temperature : ndarray, (m,)
        Block-mean temperature, °C.
    block_bias : ndarray, (m, k)
        Block-mean rate.
    residual_std : ndarray
        Scatter of the block means about the fit, per channel.
    r_squared : ndarray
        Share of the block means' variance the fit explains.
    time_correlation : float
        Absolute Pearson correlation of block temperature and time (1: fully
        confounded).
    compensated : ndarray, (n, k)
        The samples with the fitted temperature dependence removed.
    """

    names: tuple[str, ...]
    sensors: tuple[str, ...]
    degree: int
    reference: float
    coef: np.ndarray
    coef_std: np.ndarray
    temperature_range: tuple[float, float]
    block_temperature: np.ndarray
    block_bias: np.ndarray
    residual_std: np.ndarray
    r_squared: np.ndarray
    time_correlation: float
    compensated: np.ndarray
    fs: float

    def __post_init__(self) -> None:
        for name in ("coef", "coef_std", "block_temperature", "block_bias", "compensated"):
            getattr(self, name).flags.writeable = False

    @property
    def slope(self) -> np.ndarray:
        """:math:`c_1` per channel, channel unit per °C (the slope at :math:`T_0`)."""
        return self.coef[1]

    def datasheet(self, term: int = 1) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
        """Coefficient ``term`` (1: linear, 2: quadratic) and its uncertainty per channel
        in datasheet units (°/h/°C, mg/°C; ``/°C²`` for the quadratic), with the unit
        names; NaN for channels of unknown sensor."""
        if term not in range(1, self.degree + 1):
            raise ImunoiseValueError(f"term must be 1..{self.degree}; got {term!r}")
        scale = np.array([DATASHEET_UNITS[s][1] if s in DATASHEET_UNITS else np.nan
                          for s in self.sensors])
        units = tuple(
            (DATASHEET_UNITS[s][0] + ("" if term == 1 else "²")) if s in DATASHEET_UNITS else "?"
            for s in self.sensors
        )
        return self.coef[term] * scale, self.coef_std[term] * scale, units

    def predict(self, temperature) -> np.ndarray:
        """The fitted bias at ``temperature`` (°C), (len, k)."""
        d = np.asarray(temperature, dtype=float).reshape(-1, 1) - self.reference
        return sum(self.coef[p] * d**p for p in range(self.degree + 1))

    def rows(self) -> list[dict]:
        """Per channel: name, slope and its std in datasheet units, unit, (quadratic),
        r_squared."""
        value, std, units = self.datasheet(1)
        out = []
        for j, name in enumerate(self.names):
            row = {"name": name, "slope": float(value[j]), "slope_std": float(std[j]),
                   "unit": units[j], "r_squared": float(self.r_squared[j])}
            if self.degree == 2:
                q, qs, qu = self.datasheet(2)
                row.update(quadratic=float(q[j]), quadratic_std=float(qs[j]), quadratic_unit=qu[j])
            out.append(row)
        return out

    def _facts(self) -> list[str]:
        lo, hi = self.temperature_range
        parts = [f"{'linear' if self.degree == 1 else 'quadratic'} over {lo:.1f}–{hi:.1f} °C"]
        parts += [f"{r['name']} {format_value(r['slope'], r['slope_std'], unit=r['unit'])}"
                  for r in self.rows()]
        return parts

    def __repr__(self) -> str:
        return _summary.lines("Thermal(", self._facts(), sep=", ")

    def _repr_html_(self) -> str:
        rows = [[r["name"], format_value(r["slope"], r["slope_std"]), r["unit"],
                 _summary.number(r["r_squared"])] for r in self.rows()]
        return _summary.html_table(["channel", "slope", "unit", "R²"], rows,
                                   caption="Thermal: " + self._facts()[0])


def thermal(
    data,
    temperature=None,
    fs: float | None = None,
    *,
    channels=None,
    sensor: str | None = None,
    degree: int = 1,
    block: float | None = None,
    reference: float | None = None,
) -> Thermal:
    r"""Fit bias against temperature per channel.

    Parameters
    ----------
    data : ImuLog or array_like, shape (n,) or (n, k)
        A log with a temperature channel (gyro and accel are fitted), or rate samples.
    temperature : array_like, shape (n,), optional
        °C, one per sample (default: the log's).
    fs : float, optional
        Sample rate, Hz (required for arrays).
    channels : str or sequence of str, optional
        Log channels to fit (default gyro and accel).
    sensor : {"gyro", "accel"}, optional
        For arrays: what the columns are (in rad/s or m/s²), for datasheet units.
    degree : {1, 2}
        Linear or quadratic in temperature.
    block : float, optional
        Block length of the means, s (default: the log's length / 500, ≥ 1 s).
    reference : float, optional
        :math:`T_0`, °C (default: mean block temperature).

    Returns
    -------
    Thermal
    """
    x, fs, names = rate_channels(data, fs, channels)
    n, k = x.shape
    if degree not in (1, 2) or isinstance(degree, bool):
        raise ImunoiseValueError(f"degree must be 1 or 2; got {degree!r}")
    temp = _temperature(data, temperature, n)
    if isinstance(data, ImuLog):
        sensors = tuple(name.split()[0] for name in names)
    elif sensor is None:
        sensors = ("",) * k
    elif sensor in DATASHEET_UNITS:
        sensors = (sensor,) * k
    else:
        raise ImunoiseValueError(f"sensor must be one of {sorted(DATASHEET_UNITS)} or None; "
                         f"got {sensor!r}")
    if block is None:
        block = max(1.0, n / fs / 500)
    elif isinstance(block, bool) or not (np.isfinite(block) and block > 0):
        raise ImunoiseValueError(f"block must be positive and finite (s); got {block!r}")
    size = max(1, int(round(block * fs)))
    m = n // size
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN blocks stay NaN
        tb = np.nanmean(temp[: m * size].reshape(m, size), axis=1)
        xb = np.nanmean(x[: m * size].reshape(m, size, k), axis=1)
    ok = np.isfinite(tb) & np.all(np.isfinite(xb), axis=1)
    if ok.sum() < MIN_BLOCKS + degree:
        raise ImunoiseValueError(f"data must hold at least {MIN_BLOCKS + degree} blocks of "
                         f"{size / fs:g} s with temperature and rate; got {int(ok.sum())}")
    tb_ok, xb_ok = tb[ok], xb[ok]
    if np.ptp(tb_ok) == 0:
        raise ImunoiseValueError("temperature is constant: no bias-vs-temperature fit possible")
    t0 = float(np.mean(tb_ok)) if reference is None else float(reference)
    design = np.vander(tb_ok - t0, degree + 1, increasing=True)
    coef, *_ = np.linalg.lstsq(design, xb_ok, rcond=None)
    resid = xb_ok - design @ coef
    dof = len(tb_ok) - degree - 1
    s2 = np.sum(resid**2, axis=0) / dof
    rho = np.array([_lag1(resid[:, j]) for j in range(k)])
    inflation = (1 + rho) / (1 - rho)
    xtx_inv = np.linalg.inv(design.T @ design)
    coef_std = np.sqrt(np.outer(np.diag(xtx_inv), s2 * inflation))
    total = np.sum((xb_ok - xb_ok.mean(axis=0)) ** 2, axis=0)
    r2 = 1 - np.sum(resid**2, axis=0) / np.where(total > 0, total, np.nan)
    t_blocks = np.arange(m)[ok]
    time_corr = abs(float(np.corrcoef(t_blocks, tb_ok)[0, 1]))
    d = _fill(temp) - t0
    correction = sum(coef[p] * d[:, None] ** p for p in range(1, degree + 1))
    return Thermal(
        names=names, sensors=sensors, degree=degree, reference=t0, coef=coef,
        coef_std=coef_std,
        temperature_range=(float(tb_ok.min()), float(tb_ok.max())),
        block_temperature=tb, block_bias=xb, residual_std=np.sqrt(s2), r_squared=r2,
        time_correlation=time_corr, compensated=x - correction, fs=fs,
    )


def _temperature(data, temperature, n) -> np.ndarray:
    if temperature is None:
        if isinstance(data, ImuLog):
            if data.temperature is None:
                raise ImunoiseValueError(
                    f"data has no temperature channel; it has {list(data.channels)}")
            return np.asarray(data.temperature, dtype=float)
        raise ImunoiseValueError("temperature is required when data is an array")
    temp = np.asarray(temperature, dtype=float).reshape(-1)
    if temp.shape[0] != n:
        raise ImunoiseValueError(
            f"temperature must have {n} samples (one per row); got {temp.shape[0]}")
    return temp


def _lag1(r: np.ndarray) -> float:
    """Lag-1 autocorrelation, clipped to [0, 0.99] (negative: no inflation)."""
    r = r - r.mean()
    den = float(np.dot(r, r))
    rho = float(np.dot(r[:-1], r[1:])) / den if den > 0 else 0.0
    return min(max(rho, 0.0), 0.99)


def _fill(temp: np.ndarray) -> np.ndarray:
    """Missing temperature samples interpolated from their neighbours (a gap in the
    temperature must not make a rate sample missing)."""
    ok = np.isfinite(temp)
    if ok.all() or not ok.any():
        return temp
    i = np.arange(len(temp))
    return np.interp(i, i[ok], temp[ok])
