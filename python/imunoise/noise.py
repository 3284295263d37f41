"""Noise model of an inertial sensor, fitted to an Allan deviation.

The IEEE Std 952-1997 / 1293-1998 model of the Allan variance of rate data is

.. math::

    \\sigma^2(\\tau) = \\frac{3Q^2}{\\tau^2} + \\frac{N^2}{\\tau}
        + \\frac{2\\ln 2}{\\pi} B^2 + \\frac{K^2\\tau}{3} + \\frac{R^2\\tau^2}{2}

with Q the quantization noise (rate·s), N the angle/velocity random walk
(rate·√s = rate/√Hz, slope −½), B the bias instability (rate, flat part:
σ_flat = √(2 ln2/π)·B ≈ 0.6643·B), K the rate random walk (rate/√s, slope +½)
and R the rate ramp (rate/s, slope +1).

:func:`fit` offers two estimators:

``"wls"`` (default)
    Weighted non-negative least squares on σ²(τ) with weights from the
    equivalent degrees of freedom: var(σ̂²) ≈ 2σ⁴/edf. Solved in Rust with faer
    (Lawson–Hanson active set, QR, column scaling, reweighting from the model
    curve). Every term gets a standard uncertainty; a term that never reaches
    ``min_share`` (25 %) of the model at any fitted τ, or whose square is less
    than ``min_z`` (2) standard uncertainties above 0, is set to 0 and flagged.
``"slopes"``
    The IEEE 952 Annex C / MATLAB example read-off: find the τ where the
    log-log slope of the curve is closest to the term's slope, draw the line
    with the exact slope through that point and read it at the term's τ:
    N at τ = 1 s (slope −½), K at τ = 3 s (slope +½), Q at τ = √3 s (slope −1),
    R at τ = √2 s (slope +1), and B = σ_flat/√(2 ln2/π) at the point of slope 0.

Two classic mistakes the code cannot make: B is σ_flat/0.6643 (not 0.664·σ²),
and the +½ slope is rate random walk K (white noise is the −½ slope).

References
----------
IEEE Std 952-1997, "IEEE Standard Specification Format Guide and Test
Procedure for Single-Axis Interferometric Fiber Optic Gyros", Annex C.
N. El-Sheimy, H. Hou, X. Niu, "Analysis and Modeling of Inertial Sensors Using
Allan Variance", IEEE Trans. Instrum. Meas. 57(1), 2008.
MathWorks, "Inertial Sensor Noise Analysis Using Allan Variance" (example).
"""

from __future__ import annotations

import math
import numbers
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from imunoise import units as _units

__all__ = ["TERMS", "FLICKER", "NoiseModel", "Prediction", "fit", "model_variance"]

TERMS = ("Q", "N", "B", "K", "R")
"""The five coefficients, in the order used everywhere."""

FLICKER = math.sqrt(2 * math.log(2) / math.pi)
"""σ_flat / B = √(2 ln2/π) ≈ 0.6643."""

_NAMES = {
    "Q": "quantization noise",
    "N": "random walk (white noise)",
    "B": "bias instability",
    "K": "rate random walk",
    "R": "rate ramp",
}
_SENSOR_NAMES = {
    "gyro": {"N": "angle random walk", "Q": "angle quantization"},
    "accel": {"N": "velocity random walk", "Q": "velocity quantization"},
}
# Log-log slope of each term on the deviation curve and the tau where its
# straight line is read (IEEE 952 Annex C).
_SLOPE = {"Q": -1.0, "N": -0.5, "B": 0.0, "K": 0.5, "R": 1.0}
_READ_TAU = {"Q": math.sqrt(3.0), "N": 1.0, "K": 3.0, "R": math.sqrt(2.0)}
MIN_SHARE = 0.25
MIN_Z = 2.0


def _basis(taus: np.ndarray) -> np.ndarray:
    """Model variance per unit squared coefficient, shape (len(taus), 5)."""
    t = np.asarray(taus, dtype=float)
    return np.stack(
        [3.0 / t**2, 1.0 / t, np.full_like(t, FLICKER**2), t / 3.0, t**2 / 2.0], axis=-1
    )


def model_variance(taus, Q=0.0, N=0.0, B=0.0, K=0.0, R=0.0) -> np.ndarray:
    """Allan variance of the five-term model at ``taus`` (scalar coefficients)."""
    return _basis(taus) @ np.array([Q * Q, N * N, B * B, K * K, R * R], dtype=float)


@dataclass(frozen=True)
class Prediction:
    """Model Allan deviation: the total curve and each term's curve.

    ``dev`` and every ``terms[name]`` have shape (len(taus),) for a one-channel
    model and (len(taus), channels) otherwise.
    """

    taus: np.ndarray
    dev: np.ndarray
    terms: dict[str, np.ndarray]


@dataclass(frozen=True)
class NoiseModel:
    """Fitted noise coefficients, per channel, in the input's units.

    All arrays are read-only.

    Attributes
    ----------
    Q, N, B, K, R : ndarray
        Coefficients: rate·s, rate·√s, rate, rate/√s, rate/s. Shape () for a
        one-channel result, (channels,) otherwise. An unsupported term is 0.
    Q_std, N_std, B_std, K_std, R_std : ndarray
        Standard uncertainties (NaN where the term is unsupported).
    supported : dict[str, ndarray of bool]
        Whether the data support each term (``False``: the value is 0 and
        means "not resolved", not "absent").
    tau_range : dict[str, ndarray]
        For each term, (..., 2) array of the smallest and largest fitted τ
        where the term is at least 25 % of the model (``"wls"``) or the
        tangent τ (``"slopes"``); NaN when unsupported.
    method : str
        ``"wls"`` or ``"slopes"``.
    kind, fs, overlapping
        Copied from the Allan result.
    taus : ndarray
        The averaging times used by the fit.
    chi2, dof : ndarray
        Weighted residual sum of squares and its degrees of freedom (``"wls"``).
    """

    Q: np.ndarray
    N: np.ndarray
    B: np.ndarray
    K: np.ndarray
    R: np.ndarray
    Q_std: np.ndarray
    N_std: np.ndarray
    B_std: np.ndarray
    K_std: np.ndarray
    R_std: np.ndarray
    supported: dict[str, np.ndarray]
    tau_range: dict[str, np.ndarray]
    method: str
    kind: str
    fs: float
    overlapping: bool
    taus: np.ndarray
    chi2: np.ndarray = field(repr=False)
    dof: np.ndarray = field(repr=False)

    # -- shape --------------------------------------------------------------
    @property
    def channels(self) -> int:
        """Number of channels (1 for a one-channel model)."""
        return 1 if np.ndim(self.N) == 0 else int(np.shape(self.N)[0])

    @property
    def one_channel(self) -> bool:
        """True when fitted to a 1-D result (coefficients are 0-d arrays)."""
        return np.ndim(self.N) == 0

    def value(self, term: str) -> np.ndarray:
        """Coefficient ``term`` as an array of shape (channels,)."""
        _check_term(term)
        return np.atleast_1d(getattr(self, term))

    def std(self, term: str) -> np.ndarray:
        """Standard uncertainty of ``term`` as an array of shape (channels,)."""
        _check_term(term)
        return np.atleast_1d(getattr(self, term + "_std"))

    # -- curves -------------------------------------------------------------
    def predict(self, taus=None) -> Prediction:
        """Model Allan deviation at ``taus`` (default: the fitted taus).

        Returns the total curve σ(τ) and each term's own curve, e.g.
        ``terms["N"] = N/√τ``.
        """
        t = self.taus if taus is None else np.asarray(taus, dtype=float)
        if t.ndim != 1 or t.size == 0 or not np.all(np.isfinite(t)) or np.any(t <= 0):
            raise ValueError(f"taus must be a non-empty 1-D array of finite values > 0; got {t!r}")
        basis = _basis(t)  # (T, 5)
        coef = np.stack([self.value(k) ** 2 for k in TERMS], axis=0)  # (5, C)
        parts = basis[:, :, None] * coef[None, :, :]  # (T, 5, C)
        total = np.sqrt(parts.sum(axis=1))
        terms = {k: np.sqrt(parts[:, i, :]) for i, k in enumerate(TERMS)}
        if self.one_channel:
            total = total[:, 0]
            terms = {k: v[:, 0] for k, v in terms.items()}
        return Prediction(taus=t, dev=total, terms=terms)

    # -- units and tables ---------------------------------------------------
    def in_units(self, sensor: str = "gyro", units: dict[str, str] | None = None,
                 input_unit: str | None = None) -> dict[str, dict]:
        """Coefficients in datasheet units.

        Parameters
        ----------
        sensor : {"gyro", "accel"}
        units : dict, optional
            Target unit per term, e.g. ``{"N": "deg/s/sqrt(Hz)"}``; missing terms
            use :data:`imunoise.units.DEFAULT_UNITS`.
        input_unit : str, optional
            Unit of the rate data the model was fitted to (``"rad/s"`` default
            for gyros, ``"m/s^2"`` for accelerometers; also ``"deg/s"``, ``"g"``).

        Returns
        -------
        dict
            ``{term: {"value", "std", "unit", "label", "supported"}}`` with arrays
            shaped like the model's coefficients.
        """
        units = dict(units or {})
        unknown = set(units) - set(TERMS)
        if unknown:
            raise ValueError(f"units keys must be among {TERMS}; got {sorted(unknown)}")
        out = {}
        for term in TERMS:
            info = _units.unit_info(term, units.get(term), sensor)
            conv = _units.convert
            out[term] = {
                "value": conv(getattr(self, term), term, info.name, sensor=sensor,
                              input_unit=input_unit),
                "std": conv(getattr(self, term + "_std"), term, info.name, sensor=sensor,
                            input_unit=input_unit),
                "unit": info.name,
                "label": info.label,
                "supported": self.supported[term],
            }
        return out

    def table(self, sensor: str = "gyro", units: dict[str, str] | None = None,
              input_unit: str | None = None, axes: Sequence[str] | None = None,
              terms: Sequence[str] = ("N", "B", "K", "Q", "R")) -> list[dict]:
        """Per-axis table in datasheet units: one row per coefficient.

        Each row is a dict with ``term``, ``quantity``, ``unit``, ``label`` and,
        per axis name (default X, Y, Z…), the value, ``<axis>_std`` and
        ``<axis>_supported``. Render it with :func:`format_table`.
        """
        axes = _axis_names(self.channels, axes)
        conv = self.in_units(sensor, units, input_unit)
        rows = []
        for term in terms:
            _check_term(term)
            c = conv[term]
            row = {
                "term": term,
                "quantity": _SENSOR_NAMES[sensor].get(term, _NAMES[term]),
                "unit": c["unit"],
                "label": c["label"],
            }
            vals = np.atleast_1d(c["value"])
            stds = np.atleast_1d(c["std"])
            sup = np.atleast_1d(c["supported"])
            for i, ax in enumerate(axes):
                row[ax] = float(vals[i])
                row[ax + "_std"] = float(stds[i])
                row[ax + "_supported"] = bool(sup[i])
            rows.append(row)
        return rows

    def table_text(self, sensor: str = "gyro", **kwargs) -> str:
        """Text rendering of :meth:`table`."""
        rows = self.table(sensor, **kwargs)
        return format_table(rows, _axis_names(self.channels, kwargs.get("axes")))

    # -- exports ------------------------------------------------------------
    def to_kalibr(self, accel: NoiseModel | None = None, path=None, **kwargs) -> str:
        """Kalibr ``imu.yaml`` text with this model as the gyroscope.

        See :func:`imunoise.export.kalibr_yaml` for the options; with ``path``
        the file is also written atomically.
        """
        from imunoise import export

        text = export.kalibr_yaml(gyro=self, accel=accel, **kwargs)
        if path is not None:
            export.write_atomic(path, text)
        return text

    def to_dict(self) -> dict:
        """Plain-Python view of the model (lists and floats), e.g. for JSON."""
        d = {
            "method": self.method,
            "kind": self.kind,
            "fs": self.fs,
            "overlapping": self.overlapping,
            "channels": self.channels,
            "taus": self.taus.tolist(),
            "units": {
                "Q": "rate*s",
                "N": "rate*sqrt(s)",
                "B": "rate",
                "K": "rate/sqrt(s)",
                "R": "rate/s",
            },
        }
        for term in TERMS:
            d[term] = {
                "value": self.value(term).tolist(),
                "std": [None if not np.isfinite(v) else float(v) for v in self.std(term)],
                "supported": np.atleast_1d(self.supported[term]).tolist(),
                "tau_range": [
                    [None if not np.isfinite(v) else float(v) for v in pair]
                    for pair in np.reshape(self.tau_range[term], (-1, 2))
                ],
            }
        return d


def _axis_names(channels: int, axes: Sequence[str] | None) -> list[str]:
    if axes is None:
        axes = ["X", "Y", "Z"] if channels == 3 else [f"ch{i}" for i in range(channels)]
        if channels == 1:
            axes = ["value"]
    axes = list(axes)
    if len(axes) != channels:
        raise ValueError(f"axes must name {channels} channels; got {axes!r}")
    return axes


def format_table(rows: list[dict], axes: Sequence[str]) -> str:
    """Render :meth:`NoiseModel.table` rows as fixed-width text.

    Unsupported terms print as ``—``; values carry ``± std``.
    """
    def cell(row, ax):
        if not row[ax + "_supported"]:
            return "— (unresolved)"
        v, s = row[ax], row[ax + "_std"]
        return f"{v:.4g} ± {s:.2g}" if np.isfinite(s) else f"{v:.4g}"

    header = ["coefficient", "unit", *axes]
    body = [[f"{r['term']} {r['quantity']}", r["label"], *(cell(r, a) for a in axes)]
            for r in rows]
    widths = [max(len(str(x[i])) for x in [header, *body]) for i in range(len(header))]
    lines = ["  ".join(str(x).ljust(w) for x, w in zip(line, widths, strict=True)).rstrip()
             for line in [header, *body]]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def _check_term(term: str) -> None:
    if term not in TERMS:
        raise ValueError(f"term must be one of {TERMS}; got {term!r}")


# --------------------------------------------------------------------------
# fitting


def _extract(result, tau_range):
    """Validate an Allan result; return taus (T,), var (T, C), edf (T, C), 1-D flag."""
    missing = [a for a in ("taus", "kind", "edf", "fs") if not hasattr(result, a)]
    if missing or not (hasattr(result, "var") or hasattr(result, "dev")):
        raise TypeError(
            f"result must be an AllanResult (from imunoise.adev); got {type(result).__name__} "
            f"without {missing or ['var']}"
        )
    if result.kind != "adev":
        raise ValueError(
            f"result.kind must be 'adev' (the noise model is that of the Allan variance); "
            f"got {result.kind!r}"
        )
    taus = np.asarray(result.taus, dtype=float)
    var = np.asarray(result.var if hasattr(result, "var") else np.square(result.dev),
                     dtype=float)
    edf = np.asarray(result.edf, dtype=float)
    if taus.ndim != 1 or taus.size == 0:
        raise ValueError(f"result.taus must be a non-empty 1-D array; got shape {taus.shape}")
    one = var.ndim == 1
    if one:
        var, edf = var[:, None], edf[:, None]
    if var.ndim != 2 or var.shape[0] != taus.size or edf.shape != var.shape:
        raise ValueError(
            f"result.var and result.edf must have shape ({taus.size},) or ({taus.size}, k); "
            f"got {var.shape} and {edf.shape}"
        )
    if var.shape[1] == 0:
        raise ValueError("result has no channels (var has 0 columns)")
    if not np.all(np.isfinite(taus)) or np.any(taus <= 0):
        raise ValueError(f"result.taus must be finite and > 0; got {taus!r}")
    keep = np.ones(taus.size, dtype=bool)
    if tau_range is not None:
        try:
            lo, hi = (float(v) for v in tau_range)
        except (TypeError, ValueError):
            msg = f"tau_range must be (min, max) in seconds; got {tau_range!r}"
            raise ValueError(msg) from None
        if not (lo <= hi):
            raise ValueError(f"tau_range must satisfy min <= max; got {tau_range!r}")
        keep = (taus >= lo) & (taus <= hi)
        if not keep.any():
            raise ValueError(
                f"tau_range {tau_range!r} contains none of result.taus "
                f"({taus.min():.3g} s .. {taus.max():.3g} s)"
            )
    cap = _edf_cap(result, taus)
    if cap is not None:
        edf = np.minimum(edf, cap[:, None])
    return taus[keep], var[keep], edf[keep], one


def _edf_cap(result, taus):
    """Largest EDF an IMU rate-noise type can give at each tau (white rate noise).

    For the noise types the model describes at mid and long τ (white, flicker
    and random-walk rate noise, α ≤ 0) the EDF of the Allan variance is largest
    for white rate noise (α = 0). Capping the result's EDF there keeps a noise
    type misidentified as phase noise (α = 2, whose EDF is ≈ N/2 at every τ) from
    dominating the weights. Overlapping: Riley, NIST SP 1065, Table 11 (white
    FM): edf = (3(N−1)/(2m) − 2(N−2)/N)·4m²/(4m² + 5), N phase points;
    non-overlapping: the number of terms.
    """
    n_terms = getattr(result, "n", None)
    if n_terms is None:
        return None
    n_terms = np.asarray(n_terms, dtype=float)
    if n_terms.shape != taus.shape:
        return None
    m = np.maximum(np.rint(taus * float(result.fs)), 1.0)
    if not getattr(result, "overlapping", True):
        return np.maximum(n_terms, 1.0)
    n_phase = n_terms + 2 * m  # overlapping ADEV has N - 2m terms over N phase points
    with np.errstate(divide="ignore", invalid="ignore"):
        cap = (3 * (n_phase - 1) / (2 * m) - 2 * (n_phase - 2) / n_phase) * 4 * m**2 / (
            4 * m**2 + 5)
    return np.where(np.isfinite(cap) & (cap > 1.0), cap, 1.0)


def _terms_mask(terms) -> np.ndarray:
    if isinstance(terms, str):
        terms = tuple(terms)
    terms = tuple(terms)
    bad = [t for t in terms if t not in TERMS]
    if bad or not terms:
        raise ValueError(f"terms must be a non-empty subset of {TERMS}; got {terms!r}")
    return np.array([t in terms for t in TERMS])


def fit(result, method: str = "wls", terms: Sequence[str] = TERMS, tau_range=None,
        min_share: float = MIN_SHARE, min_z: float = MIN_Z, *,
        uncertainty: str = "independent", replicates: int = 30, seed=None) -> NoiseModel:
    """Fit the IEEE 952 noise model to an Allan deviation.

    Parameters
    ----------
    result : AllanResult
        From :func:`imunoise.adev` (overlapping or not); ``kind`` must be
        ``"adev"``. Taus with a non-finite or non-positive variance or EDF are
        ignored.
    method : {"wls", "slopes"}
        Weighted non-negative least squares (default) or the IEEE 952 / MATLAB
        slope read-off (see the module docstring).
    terms : sequence of {"Q", "N", "B", "K", "R"}
        Terms allowed in the model; the others are 0 and unsupported.
    tau_range : (float, float), optional
        Only use taus in [min, max] seconds.
    min_share : float
        ``"wls"``: a term must reach this fraction of the model variance at
        some fitted τ to be kept (default 0.25).
    min_z : float
        ``"wls"``: a squared coefficient must be at least this many standard
        uncertainties above zero to be kept (default 2, i.e. N ≥ 4·u(N)).
    uncertainty : {"independent", "bootstrap"}
        How the ``*_std`` are obtained. ``"independent"`` (default, instant):
        from the fit's covariance, treating the taus as independent (somewhat
        optimistic, see Notes). ``"bootstrap"``: parametric bootstrap —
        ``replicates`` records of the same length and rate are simulated from the
        fitted model (:func:`imunoise.simulate`), analysed with the same taus and
        fitted with the same options; each ``*_std`` is the standard deviation of
        that coefficient over the replicates. It accounts for the correlation
        between taus; it costs ``replicates`` simulations and Allan deviations
        per channel (≈ 0.6 s each for a 5 h, 40 Hz record with flicker noise).
    replicates : int
        ``"bootstrap"`` only: number of simulated records (≥ 5; default 30).
    seed : int, numpy.random.Generator or None
        ``"bootstrap"`` only: seed of the simulations, for reproducible results.

    Returns
    -------
    NoiseModel

    Notes
    -----
    The EDF of the result is capped at its white-rate-noise value (the largest
    for the α ≤ 0 noise types of an IMU) before weighting, see ``_edf_cap``.
    The weights w = edf/(2σ⁴) treat the Allan variances at different taus as
    independent; overlapping estimates at neighbouring octaves are mildly
    correlated, so the uncertainties are approximate (they are inflated by
    √(χ²/dof) when the model fits worse than the EDF predict). Standard
    uncertainties of the coefficients follow from those of their squares:
    u(N) = u(N²)/(2N).
    """
    if method not in ("wls", "slopes"):
        raise ValueError(f"method must be 'wls' or 'slopes'; got {method!r}")
    if uncertainty not in ("independent", "bootstrap"):
        raise ValueError(
            f"uncertainty must be 'independent' or 'bootstrap'; got {uncertainty!r}"
        )
    if uncertainty == "bootstrap":
        if isinstance(replicates, bool) or not isinstance(replicates, numbers.Integral):
            raise TypeError(f"replicates must be an integer; got {replicates!r}")
        if replicates < 5:
            raise ValueError(f"replicates must be >= 5; got {replicates}")
    mask = _terms_mask(terms)
    if not (0.0 <= min_share < 1.0):
        raise ValueError(f"min_share must be in [0, 1); got {min_share!r}")
    if not (math.isfinite(min_z) and min_z >= 0):
        raise ValueError(f"min_z must be finite and >= 0; got {min_z!r}")
    taus, var, edf, one = _extract(result, tau_range)
    channels = var.shape[1]
    coef = np.zeros((channels, 5))
    std = np.full((channels, 5), np.nan)
    sup = np.zeros((channels, 5), dtype=bool)
    rng = np.full((channels, 5, 2), np.nan)
    chi2 = np.full(channels, np.nan)
    dof = np.zeros(channels, dtype=int)
    for c in range(channels):
        ok = np.isfinite(var[:, c]) & (var[:, c] > 0) & np.isfinite(edf[:, c]) & (edf[:, c] > 0)
        if not ok.any():
            raise ValueError(
                f"result has no usable tau for channel {c}: var and edf must be finite and > 0"
            )
        if ok.sum() < 2:
            raise ValueError(
                f"result has {ok.sum()} usable tau for channel {c}; the fit needs at least 2 "
                "(var and edf finite and > 0)"
            )
        t, v, e = taus[ok], var[ok, c], edf[ok, c]
        if method == "wls":
            coef[c], std[c], sup[c], chi2[c], dof[c] = _fit_wls(t, v, e, mask, min_share, min_z)
            rng[c] = _support_range(t, coef[c], sup[c], min_share)
        else:
            coef[c], std[c], sup[c], rng[c] = _fit_slopes(t, v, e, mask)
    if uncertainty == "bootstrap":
        generator = np.random.default_rng(seed)
        for c in range(channels):
            # Replicates refit the kept terms without the keep/drop thresholds: a
            # term dropped in some replicates would mix zeros into its spread.
            kept = [t for t, keep in zip(TERMS, sup[c], strict=True) if keep]
            if not kept:
                continue
            options = dict(method=method, terms=kept, tau_range=tau_range, min_share=0.0,
                           min_z=0.0)
            std[c] = _bootstrap_std(result, coef[c], int(replicates), generator, options)
    std[~sup] = np.nan

    def shaped(a):
        out = np.array(a[0] if one else a)
        out.setflags(write=False)
        return out

    values = {k: shaped(coef[:, i]) for i, k in enumerate(TERMS)}
    stds = {k + "_std": shaped(std[:, i]) for i, k in enumerate(TERMS)}
    return NoiseModel(
        **values,
        **stds,
        supported={k: shaped(sup[:, i]) for i, k in enumerate(TERMS)},
        tau_range={k: shaped(rng[:, i, :]) for i, k in enumerate(TERMS)},
        method=method,
        kind=result.kind,
        fs=float(result.fs),
        overlapping=bool(getattr(result, "overlapping", True)),
        taus=_readonly(taus),
        chi2=shaped(chi2),
        dof=shaped(dof),
    )


def _record_length(result) -> int:
    """Samples behind an Allan result, from its terms at the shortest tau. With
    gaps, the gap-free length with as many terms (the most of any channel)."""
    try:
        m0, n0 = int(np.asarray(result.m)[0]), int(np.max(np.asarray(result.n)[0]))
        overlapping = bool(result.overlapping)
    except (AttributeError, IndexError, TypeError):
        raise TypeError(
            "uncertainty='bootstrap' needs an AllanResult from imunoise.adev (with m, n and "
            "overlapping)"
        ) from None
    # Overlapping ADEV has N − 2m terms over N = n + 1 phase points; the
    # non-overlapping one ⌊n/m⌋ − 1 (exact at m = 1, the first tau of every grid).
    return n0 + 2 * m0 - 1 if overlapping else (n0 + 1) * m0


def _bootstrap_std(result, coef, replicates, rng, options) -> np.ndarray:
    """Standard deviation of each coefficient over fits to records simulated from
    ``coef`` (Q, N, B, K, R) with the length, rate and taus of ``result``."""
    from imunoise.allan import adev
    from imunoise.simulate import simulate

    n = _record_length(result)
    sims = simulate(n, result.fs, *coef, channels=replicates, seed=rng)
    again = adev(sims, result.fs, taus=np.asarray(result.taus), overlapping=result.overlapping,
                 confidence=result.confidence)
    refit = fit(again, **options)
    values = np.stack([np.atleast_1d(refit.value(t)) for t in TERMS], axis=1)
    return values.std(axis=0, ddof=1)


def _readonly(a):
    out = np.array(a)
    out.setflags(write=False)
    return out


def _fit_wls(t, v, e, mask, min_share, min_z):
    from imunoise import _core

    try:
        sq, cov, supported, chi2, dof = _core.fit_wls(
            np.ascontiguousarray(t), np.ascontiguousarray(v), np.ascontiguousarray(e),
            [bool(m) for m in mask], 3, float(min_share), float(min_z),
        )
    except ValueError as exc:
        raise ValueError(f"cannot fit the noise model to result: {exc}") from None
    coef = np.sqrt(np.maximum(sq, 0.0))
    var_sq = np.diag(cov)
    with np.errstate(divide="ignore", invalid="ignore"):
        std = np.where(supported, np.sqrt(np.maximum(var_sq, 0.0)) / (2.0 * coef), np.nan)
    coef = np.where(supported, coef, 0.0)
    return coef, std, supported, chi2, dof


def _support_range(t, coef, sup, min_share):
    basis = _basis(t) * coef**2
    total = basis.sum(axis=1)
    out = np.full((5, 2), np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        share = basis / total[:, None]
    for i in range(5):
        if sup[i]:
            hit = t[share[:, i] >= min_share]
            if hit.size:
                out[i] = hit.min(), hit.max()
    return out


def _fit_slopes(t, v, e, mask, tolerance=0.25):
    """IEEE 952 / MATLAB read-off; uncertainty from the EDF at the tangent point."""
    coef = np.zeros(5)
    std = np.full(5, np.nan)
    sup = np.zeros(5, dtype=bool)
    rng = np.full((5, 2), np.nan)
    if t.size < 2:
        warnings.warn("slope read-off needs at least two taus; no term resolved",
                      RuntimeWarning, stacklevel=3)
        return coef, std, sup, rng
    dev = np.sqrt(v)
    logt, logd = np.log10(t), np.log10(dev)
    slope = np.diff(logd) / np.diff(logt)  # slope[i] between points i and i+1
    for i, term in enumerate(TERMS):
        if not mask[i]:
            continue
        target = _SLOPE[term]
        j = int(np.argmin(np.abs(slope - target)))
        if abs(slope[j] - target) > tolerance:
            continue  # no part of the curve has this slope: not resolved
        # MATLAB: the line of exact slope through point j (the segment's left end).
        sigma, tau = dev[j], t[j]
        rel = 1.0 / math.sqrt(2.0 * e[j])  # u(σ̂)/σ̂ from var(σ̂²) = 2σ⁴/edf
        if term == "B":
            value = sigma / FLICKER
        else:
            # σ of the line at the reading τ equals the coefficient there:
            # N/√1, K·√(3/3), √3·Q/√3, R·√2/√2.
            value = sigma * (_READ_TAU[term] / tau) ** target
        coef[i] = value
        std[i] = value * rel
        sup[i] = True
        rng[i] = t[j], t[j + 1]
    return coef, std, sup, rng
