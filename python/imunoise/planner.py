r"""How long to record: the record length that resolves N, B and K to a target.

Each coefficient is read off the Allan deviation at the tau that determines it:

- **N** at τ_N = 1 s (the datasheet read-off), or shorter where the white term is
  not yet 3× the others there; noise type white rate (α = 0);
- **B** at τ_B, the minimum of the model's deviation (σ_min/0.6643); flicker
  rate (α = −1);
- **K** at τ_K, where the rate random walk is 3× the other terms (its +½ slope);
  random-walk rate (α = −2).

The relative error of a read-off is that of σ̂(τ): σ̂²/σ² ~ χ²_ν/ν with ν the
equivalent degrees of freedom of the overlapping Allan variance of a record of
n samples at m = τ·fs (Greenhall's algorithm, as :func:`imunoise.adev` reports
them). The uncertainty promised at ``confidence`` is the half-width x with
P(|σ̂/σ − 1| ≤ x) = confidence, and the record length the least n whose x is
at most the target. This is the statistical uncertainty alone: a model that
does not follow the sensor (a Gauss–Markov bump, temperature drift) adds its own.
Checked by simulation in ``tests/record/test_planner.py``. ``imunoise.plan`` is :func:`plan`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from imunoise._core import allan as _core_allan
from imunoise._support.validate import sample_rate
from imunoise.errors import ImunoiseValueError
from imunoise.noise._terms import FLICKER, model_variance

__all__ = ["PLAN_TERMS", "Plan", "TermPlan", "fit_line", "plan", "relative_uncertainty"]

#: Terms the planner answers for, with the power-law noise type (α) of each.
PLAN_TERMS = {"N": 0, "B": -1, "K": -2}
#: A term is read where it is this many times the other terms' variance.
_DOMINANT = 3.0
#: Record lengths beyond this (s) are printed as "> 1000 h".
_LONGEST = 3.6e6
#: Longest record the planner considers (samples).
_MAX_SAMPLES = 1e13


def relative_uncertainty(edf, confidence: float = 0.95):
    """Half-width x (relative) with P(|σ̂/σ − 1| ≤ x) = ``confidence`` for a
    deviation estimated with ``edf`` degrees of freedom (σ̂²/σ² ~ χ²_edf/edf)."""
    from scipy.optimize import brentq
    from scipy.stats import chi2

    def one(nu: float) -> float:
        if not (np.isfinite(nu) and nu > 0):
            return math.inf

        def excess(x: float) -> float:
            low = chi2.cdf(nu * max(1 - x, 0.0) ** 2, nu)
            return chi2.cdf(nu * (1 + x) ** 2, nu) - low - confidence

        hi = 1.0
        while excess(hi) < 0:
            hi *= 2
            if hi > 1e6:
                return math.inf
        return float(brentq(excess, 0.0, hi, xtol=1e-6))

    return np.vectorize(one, otypes=[float])(np.asarray(edf, dtype=float))


@dataclass(frozen=True)
class TermPlan:
    """One coefficient's plan: ``value`` (input units), read at ``tau`` (s), needs
    ``seconds`` of record for the target (``inf``: not within reach)."""

    term: str
    value: float
    tau: float
    seconds: float


@dataclass(frozen=True)
class Plan:
    """Record lengths for N, B and K (:func:`plan`)."""

    fs: float
    target: float
    confidence: float
    terms: Mapping[str, TermPlan]
    coefficients: Mapping[str, float]
    label: str = ""
    #: Terms whose value the source does not give and the planner assumed (a
    #: datasheet without K: the simulator's typical K); :meth:`line` says so.
    assumed: tuple[str, ...] = ()

    @property
    def seconds(self) -> float:
        """The record length that resolves every term to the target."""
        return max((t.seconds for t in self.terms.values()), default=0.0)

    def uncertainty(self, seconds: float) -> dict[str, float]:
        """Relative uncertainty (at ``confidence``) of each term after ``seconds``
        of record (``inf`` where the record is shorter than 2τ)."""
        n = int(seconds * self.fs)
        return {k: float(relative_uncertainty(_edf(n, self.fs, t.tau, PLAN_TERMS[k]),
                                              self.confidence))
                for k, t in self.terms.items()}

    def line(self, seconds: float | None = None) -> str:
        """One line: what each term needs, and (given a record length) what it has."""
        from imunoise.display import duration, format_value

        if not self.terms:
            return f"plan{' ' + self.label if self.label else ''}: no N, B or K to plan for"
        need = ", ".join(f"{k} {_length(t.seconds)}" for k, t in self.terms.items())
        text = (f"plan{' ' + self.label if self.label else ''}: ±{100 * self.target:g} % "
                f"({100 * self.confidence:g} % confidence) needs {need}")
        if self.assumed:
            text += (f" ({', '.join(self.assumed)}: not on the datasheet, a typical value is "
                     "assumed; its record length is a guide only)")
        if seconds is not None:
            # two digits in plain decimals: "±100 %" (":.2g" wrote "±1e+02 %")
            have = ", ".join(f"{k} ±{format_value(100 * u, digits=2)} %"
                             if math.isfinite(u) and u < 10
                             else f"{k} not yet (its τ is beyond the record)"
                             for k, u in self.uncertainty(seconds).items())
            text += f"; this record ({duration(seconds)}) resolves {have}"
        return text

    def __str__(self) -> str:
        return self.line()

    def __repr__(self) -> str:
        return f"Plan({self.line()})"

    def _repr_html_(self) -> str:
        """Per term: its value, the τ it is read at and the record it needs."""
        from imunoise._support import summary as _summary

        rows = [(k, _summary.number(t.value), _summary.number(t.tau), _length(t.seconds))
                for k, t in self.terms.items()]
        return _summary.html_table(["term", "value", "τ [s]", "record needed"], rows,
                                   caption=f"Plan — {self.line()}")


def _length(seconds: float) -> str:
    from imunoise.display import duration

    return duration(seconds) if seconds <= _LONGEST else f"> {duration(_LONGEST)}"


def _edf(n: int, fs: float, tau: float, alpha: int) -> float:
    m = max(1, round(tau * fs))
    if n < 2 * m + 1:
        return math.nan
    e = _core_allan.estimator_edf("adev", n + 1, np.array([alpha], np.int32),
                                  np.array([m], np.uint64))
    return float(e[0])


def _taus(N: float, B: float, K: float, fs: float) -> dict[str, float]:
    grid = np.logspace(math.log10(1 / fs), 9, 3000)
    parts = {"N": N**2 / grid, "B": np.full_like(grid, (FLICKER * B) ** 2), "K": K**2 * grid / 3}
    total = parts["N"] + parts["B"] + parts["K"]
    taus = {}
    if N > 0:
        ok = parts["N"] >= _DOMINANT * (total - parts["N"])
        taus["N"] = min(1.0, float(grid[ok][-1])) if ok.any() else float(grid[0])
    if B > 0 and K > 0:
        taus["B"] = float(grid[np.argmin(model_variance(grid, N=N, B=B, K=K))])
    elif B > 0:  # no walk: the curve only flattens; B is read where the floor dominates
        ok = parts["B"] >= _DOMINANT * (total - parts["B"])
        taus["B"] = float(grid[ok][0]) if ok.any() else float(grid[-1])
    if K > 0:
        ok = parts["K"] >= _DOMINANT * (total - parts["K"])
        taus["K"] = float(grid[ok][0]) if ok.any() else float(grid[-1])
    return {k: max(t, 1 / fs) for k, t in taus.items()}


def _seconds(fs: float, tau: float, alpha: int, target: float, confidence: float) -> float:
    m = max(1, round(tau * fs))
    lo, hi = 2 * m + 1, 4 * m + 16

    def ok(n: int) -> bool:
        return float(relative_uncertainty(_edf(n, fs, tau, alpha), confidence)) <= target

    while not ok(hi):
        lo, hi = hi, hi * 2
        if hi > _MAX_SAMPLES:
            return math.inf
    while hi - lo > max(1, lo // 1000):
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if ok(mid) else (mid, hi)
    return hi / fs


def _coefficients(source, sensor: str) -> tuple[dict[str, float], str, tuple[str, ...]]:
    """The coefficients to plan with, the plan's label and the terms assumed."""
    if isinstance(source, Mapping):
        return {k: float(source.get(k, 0.0)) for k in PLAN_TERMS}, "", ()
    if hasattr(source, "terms") and hasattr(source, "N"):  # a NoiseModel
        # The median over the axes that resolve the term; a term no axis resolves
        # (NaN) is planned as absent, as a datasheet that omits it.
        out = {}
        for k in PLAN_TERMS:
            values = np.atleast_1d(getattr(source, k)).astype(float)
            values = values[np.isfinite(values)]
            out[k] = float(np.median(values)) if values.size else 0.0
        return out, "", ()
    from imunoise._simulation.log import noise_of_spec
    from imunoise.datasheet import load_spec

    noise = noise_of_spec(source)
    if sensor not in noise:
        raise ImunoiseValueError(
            f"sensor must be one of {sorted(noise)} for this spec; got {sensor!r}")
    spec = load_spec(source)
    given = {item.term for item in spec.items if item.sensor == sensor}
    assumed = tuple(k for k in PLAN_TERMS if k not in given and noise[sensor].get(k, 0.0) > 0)
    return ({k: float(noise[sensor].get(k, 0.0)) for k in PLAN_TERMS},
            f"{spec.name} {sensor}", assumed)


def plan(source="vn100", *, fs: float = 40.0, target: float = 0.2, confidence: float = 0.95,
         sensor: str = "gyro") -> Plan:
    """The record length that resolves N, B and K to ``target`` (relative).

    Parameters
    ----------
    source : str, path, NoiseModel or mapping
        A datasheet (``"vn100"`` or a TOML file; K from the simulator's typical
        value where the sheet gives none), a fitted :class:`~imunoise.NoiseModel`
        of a short recording (median over its axes), or ``{"N": .., "B": .., "K": ..}``.
    fs : float
        Sample rate of the recording to plan, Hz.
    target : float
        Relative half-width wanted, 0 < target < 1 (0.2: ±20 %).
    confidence : float
        Probability that a record of the planned length is within the target.
    sensor : str
        ``"gyro"`` or ``"accel"`` (with a datasheet).

    Returns
    -------
    Plan
        ``plan.terms[k].seconds`` per term, ``plan.seconds`` for all,
        ``plan.uncertainty(seconds)`` for a given record, ``plan.line()``.
    """
    fs = sample_rate(fs)
    if not (isinstance(target, int | float) and 0 < target < 1):
        raise ImunoiseValueError(f"target must be a relative uncertainty in (0, 1); got {target!r}")
    if not (isinstance(confidence, int | float) and 0 < confidence < 1):
        raise ImunoiseValueError(f"confidence must be in (0, 1); got {confidence!r}")
    coefficients, label, assumed = _coefficients(source, sensor)
    bad = {k: v for k, v in coefficients.items() if not (math.isfinite(v) and v >= 0)}
    if bad:
        raise ImunoiseValueError(f"coefficients must be finite and >= 0; got {bad}")
    taus = _taus(coefficients["N"], coefficients["B"], coefficients["K"], fs)
    terms = {k: TermPlan(k, coefficients[k], tau,
                         _seconds(fs, tau, PLAN_TERMS[k], float(target), float(confidence)))
             for k, tau in taus.items()}
    return Plan(fs=fs, target=float(target), confidence=float(confidence), terms=terms,
                coefficients=coefficients, label=label, assumed=assumed)


def fit_line(model, fs: float, seconds: float, *, target: float = 0.2,
             confidence: float = 0.95) -> str:
    """One line for a fitted model: what ``seconds`` of record at ``fs`` resolve and
    what ``target`` needs (``imunoise fit`` prints it; the report may)."""
    try:
        return plan(model, fs=fs, target=target, confidence=confidence).line(seconds)
    except ValueError as exc:
        return f"plan: not available ({exc})"
