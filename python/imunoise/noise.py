"""Noise model of an inertial sensor, fitted to an Allan deviation.

The IEEE Std 952-1997 / 1293-1998 model of the Allan variance of rate data is

.. math::

    \\sigma^2(\\tau) = \\frac{3Q^2}{\\tau^2} + \\frac{N^2}{\\tau}
        + \\frac{2\\ln 2}{\\pi} B^2 + \\frac{K^2\\tau}{3} + \\frac{R^2\\tau^2}{2}

with Q the quantization noise (rate·s), N the angle/velocity random walk
(rate·√s = rate/√Hz, slope −½), B the bias instability (rate, flat part:
σ_flat = √(2 ln2/π)·B ≈ 0.6643·B), K the rate random walk (rate/√s, slope +½)
and R the rate ramp (rate/s, slope +1).

Real sensors are not five terms: their own low-pass filter bends the short
taus and slowly wandering biases put bumps in the curve. The model therefore
also has up to three first-order Gauss–Markov (exponentially correlated) bias
terms, each with a standard deviation σ and a correlation time τc, whose Allan
variance is the discrete AR1 form of IEEE 952 Annex C (slope +½ for τ ≪ τc, a
peak near 1.9 τc, slope −½ for τ ≫ τc), and at most one tone A·sin(2πf₀t + ϕ)
(a line: dither, ripple, a sharp mode), IEEE 952 Annex C's sinusoidal term
A²·sin⁴(πf₀τ)/(πf₀τ)² in its sampled form 2·(A²/2)·sin⁴(πνm)/(m² sin²πν),
ν = f₀/fs, m = τ·fs, whose frequency is searched like the correlation times,
and at most one resonance: a damped oscillator (second-order Gauss–Markov
process) of standard deviation σ, centre frequency f_r and damping time τr,
autocovariance σ²ρ^|h|·cos(θh) with ρ = exp(−1/(fs·τr)), θ = 2πf_r/fs (a
sensor's filter top or a mechanical mode: a band, not a line), whose Allan
variance is the real part of the AR1 form continued to z = ρe^(iθ).

:func:`fit` offers two estimators:

``"wls"`` (default)
    Weighted least squares on ln σ̂²(τ) (Rust, faer). Each tau weighs
    ω/(var(ln σ̂²) + δ²): ω is the share of an octave of τ it stands for (so
    octave, 5, 10, 20 or 50 taus per decade carry the same evidence and give the
    same coefficients), var(ln σ̂²) = ψ′(edf/2) its sampling variance, and δ² a
    model-discrepancy variance fitted by maximum likelihood (so a tau with an
    EDF of 10⁶, where the model is only approximately right, cannot outweigh the
    rest). For fixed correlation times every term is linear in its variance:
    non-negative Gauss–Newton steps, a grid and golden-section search over the
    times, and, with ``terms="auto"``, the structure with the lowest BIC.
    Details and the reasons for each choice: ``docs/noise.md``.
``"slopes"``
    The IEEE 952 Annex C / MATLAB example read-off: find the τ where the
    log-log slope of the curve is closest to the term's slope, draw the line
    with the exact slope through that point and read it at the term's τ:
    N at τ = 1 s (slope −½), K at τ = 3 s (slope +½), Q at τ = √3 s (slope −1),
    R at τ = √2 s (slope +1), and B = σ_flat/√(2 ln2/π) at the point of slope 0.

Whatever the method, :attr:`NoiseModel.readoff` holds the datasheet read-offs
of the data (N at 1 s, K at 3 s, B = σ_min/0.6643) next to the model, and
:attr:`NoiseModel.coverage` says how well the model follows the curve.

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
import os
import warnings
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from imunoise import _schema, _summary
from imunoise import numbers as _numbers
from imunoise import units as _units
from imunoise._core import fit as _core_fit
from imunoise._deprecation import old_call_forms

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from imunoise.allan import AllanResult

__all__ = ["TERMS", "FLICKER", "NoiseModel", "Prediction", "fit", "model_variance"]

TERMS: tuple[str, ...] = tuple(_core_fit.IEEE_TERM_NAMES)
"""The five coefficients, in the order used everywhere (Q, N, B, K, R)."""

FLICKER = math.sqrt(_core_fit.FLICKER_FACTOR)
"""σ_flat / B = √(2 ln2/π) ≈ 0.6643."""

#: Most simulated samples (replicates x record length) of ``fit(uncertainty=
#: "bootstrap")``: they are held at once, 8 bytes each (1.6 GB at the bound).
MAX_BOOTSTRAP_SAMPLES = 200_000_000

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
GM_MAX: int = _core_fit.MAX_GAUSS_MARKOV
"""Most first-order Gauss–Markov terms a model may have."""

_PARAMS: int = _core_fit.PARAMETERS
"""Parameter slots of the covariance: five IEEE variances, (σ², ln τc) per GM term,
then (A²/2, ln f0) of the tone."""
_SINE: int = _core_fit.SINE_SLOT
"""Slot of the tone's variance A²/2 in the covariance (its ln f0 follows)."""
_RES: int = _core_fit.RESONANCE_SLOT
"""Slot of the resonance's variance σ² in the covariance (ln f_r, ln τr follow)."""


def gm_white_density(sigma: float, tau_c: float, fs: float) -> float:
    """N² (rate²·s) that a sampled Gauss–Markov term of standard deviation ``sigma``
    and correlation time ``tau_c`` contributes at τ ≫ τc: σ²(1+φ)/((1−φ)·fs),
    φ = exp(−1/(fs·τc)), the −½ asymptote of its Allan variance."""
    phi = math.exp(-1.0 / (fs * tau_c))
    return sigma**2 * (1 + phi) / ((1 - phi) * fs)


def resonance_white_density(sigma: float, f_r: float, tau_r: float, fs: float) -> float:
    """N² (rate²·s) that a sampled resonance of standard deviation ``sigma``,
    frequency ``f_r`` and damping time ``tau_r`` contributes at τ ≫ τr:
    σ²·Re[(1+z)/(1−z)]/fs, z = exp(−1/(fs·τr) + 2πi·f_r/fs), the −½ asymptote of
    its Allan variance (its spectrum at zero frequency)."""
    z = complex(math.exp(-1.0 / (fs * tau_r)), 0.0) * complex(
        math.cos(2 * math.pi * f_r / fs), math.sin(2 * math.pi * f_r / fs))
    return sigma**2 * ((1 + z) / (1 - z)).real / fs


def _is_log_time(slot: int) -> bool:
    """Whether covariance slot ``slot`` holds a logarithm (ln τc, ln f0, ln f_r, ln τr)."""
    return slot > _RES or (5 <= slot < _RES and (slot - 5) % 2 == 1)


_CLOSE = 0.05
"""A model within this relative distance of the measured deviation follows it."""


def _terms(taus, fs: float, coef, markov=(), tone=(), resonance=()) -> np.ndarray:
    """Allan variance of each model term at ``taus``: (len(taus), 5 + len(markov) +
    len(tone) + len(resonance)), from the one implementation of the model (Rust);
    ``coef`` holds Q…R, ``markov`` (sigma, tau_c) pairs, ``tone`` (amplitude, f0)
    pairs, ``resonance`` (sigma, f_r, tau_r) triples."""
    t = np.ascontiguousarray(np.atleast_1d(np.asarray(taus, dtype=float)))
    with np.errstate(over="ignore"):  # a coefficient near 1e154 squares to inf, not an error
        squares = np.square(np.asarray(coef, dtype=float)).tolist()
    return _core_fit.noise_terms(t, float(fs), squares,
                             [(s * s, tc) for s, tc in markov],
                             [(a * a / 2, f0) for a, f0 in tone],
                             [(s * s, f, tr) for s, f, tr in resonance])


def model_variance(taus, Q=0.0, N=0.0, B=0.0, K=0.0, R=0.0) -> np.ndarray:
    """Allan variance of the five-term IEEE model at ``taus`` (scalar coefficients)."""
    return _terms(taus, 1.0, (Q, N, B, K, R)).sum(axis=1)


@dataclass(frozen=True, repr=False)
class Prediction:
    """Model Allan deviation: the total curve and each term's curve.

    ``dev`` and every ``terms[name]`` have shape (len(taus),) for a one-channel
    model and (len(taus), channels) otherwise. ``terms`` has ``Q``…``R`` and,
    when a channel has Gauss–Markov terms, ``GM1`` and ``GM2`` (0 where absent).
    """

    taus: np.ndarray
    dev: np.ndarray
    terms: dict[str, np.ndarray]

    @property
    def channels(self) -> int:
        """Number of channels (1 for a one-channel model)."""
        return 1 if np.ndim(self.dev) == 1 else int(np.shape(self.dev)[1])

    def _facts(self) -> list[str]:
        drawn = [k for k, v in self.terms.items() if np.any(np.asarray(v) > 0)]
        return [_summary.plural(self.channels, "channel"), _summary.tau_span(self.taus),
                "terms " + (" ".join(drawn) or "none")]

    def __repr__(self) -> str:
        return _summary.lines("Prediction(", self._facts(), sep=", ")

    def _repr_html_(self) -> str:
        """Per channel: the model deviation at the first and last tau and its minimum."""
        header, rows = _summary.curve_rows(self.taus, self.dev,
                                           _schema.axis_names(self.channels))
        return _summary.html_table(header, rows,
                                   caption="Prediction: " + ", ".join(self._facts()))


@dataclass(frozen=True, repr=False)
class NoiseModel:
    """Fitted noise coefficients, per channel, in the input's units.

    All arrays are read-only.

    Attributes
    ----------
    Q, N, B, K, R : ndarray
        IEEE 952 coefficients: rate·s, rate·√s, rate, rate/√s, rate/s. Shape ()
        for a one-channel result, (channels,) otherwise. A term not in the
        model is 0.
    Q_std, N_std, B_std, K_std, R_std : ndarray
        Standard uncertainties (NaN where the term is not in the model).
    gm_sigma, gm_tau : ndarray
        First-order Gauss–Markov bias terms: standard deviation (rate) and
        correlation time (s), shape (2,) or (channels, 2), by increasing τc;
        NaN where a channel has fewer than two.
    gm_sigma_std, gm_tau_std : ndarray
        Their standard uncertainties.
    sine_amplitude, sine_freq : ndarray
        A tone A·sin(2πf0·t + ϕ) in the data (IEEE 952 Annex C's sinusoidal
        term, Allan variance A²·sin⁴(πf0τ)/(πf0τ)², sampled form in
        ``docs/noise.md``): peak amplitude (rate) and frequency (Hz), shape ()
        or (channels,); NaN where a channel has none.
    sine_amplitude_std, sine_freq_std : ndarray
        Their standard uncertainties.
    resonance_sigma, resonance_freq, resonance_tau : ndarray
        A damped oscillator (second-order Gauss–Markov process, autocovariance
        σ²·ρ^|h|·cos(2πf_r h/fs), ρ = exp(−1/(fs·τr))): standard deviation
        (rate), centre frequency f_r (Hz) and damping time τr (s; the quality
        factor is π·f_r·τr), shape () or (channels,); NaN where a channel has
        none.
    resonance_sigma_std, resonance_freq_std, resonance_tau_std : ndarray
        Their standard uncertainties (the frequency's is NaN when it sits on the
        fs/2 bound of the search).
    supported : dict[str, ndarray of bool]
        Whether each IEEE term is in the model (``False``: the value is 0 and
        means "not resolved", not "absent").
    tau_range : dict[str, ndarray]
        For each IEEE term, (..., 2) array of the smallest and largest fitted τ
        where the term is at least 25 % of the model (``"wls"``) or the
        tangent τ (``"slopes"``); NaN when unsupported.
    method : str
        ``"wls"`` or ``"slopes"``.
    kind, fs, overlapping
        Copied from the Allan result.
    taus : ndarray
        The averaging times used by the fit.
    coverage : ndarray
        Share of the fitted taus where the model lies inside the measured 95 %
        confidence interval or within 5 % of the measured deviation, whichever
        is wider: how well the model follows the curve (1 = everywhere).
    discrepancy : ndarray
        ``"wls"``: δ, the relative standard deviation of the Allan variance that
        the model leaves unexplained beyond the estimates' own scatter
        (0 when it describes the curve to within its noise).
    chi2, n_eff : ndarray
        ``"wls"``: Σ ω r²/var(ln σ̂²), the residual sum with the sampling
        variance alone and each tau weighted by its share ω of an octave, and
        n_eff = Σ ω, the octaves of evidence (χ²/n_eff ≈ 1 for a model that
        describes the curve).
    readoff : dict[str, dict[str, ndarray]]
        The datasheet read-offs of the measured curve, whatever the method:
        ``"N"`` (slope −½ line at τ = 1 s), ``"K"`` (slope +½ line at τ = 3 s)
        and ``"B"`` (σ_min/0.6643 at the curve's minimum), each with
        ``value``, ``std`` and ``tau`` (the tau read), NaN where the curve has
        no such part; ``"B"`` also has ``low``/``high`` (95 % interval).
    cov : ndarray
        ``"wls"``: covariance of (Q², N², B², K², R², then σ², ln τc of each
        Gauss–Markov slot, then A²/2, ln f0 of the tone, then σ², ln f_r, ln τr
        of the resonance), shape (16, 16) or (channels, 16, 16); NaN for
        ``"slopes"``.
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
    gm_sigma: np.ndarray
    gm_tau: np.ndarray
    gm_sigma_std: np.ndarray
    gm_tau_std: np.ndarray
    sine_amplitude: np.ndarray
    sine_freq: np.ndarray
    sine_amplitude_std: np.ndarray
    sine_freq_std: np.ndarray
    resonance_sigma: np.ndarray
    resonance_freq: np.ndarray
    resonance_tau: np.ndarray
    resonance_sigma_std: np.ndarray
    resonance_freq_std: np.ndarray
    resonance_tau_std: np.ndarray
    supported: dict[str, np.ndarray]
    tau_range: dict[str, np.ndarray]
    method: str
    kind: str
    fs: float
    overlapping: bool
    taus: np.ndarray
    coverage: np.ndarray
    discrepancy: np.ndarray = field(repr=False)
    chi2: np.ndarray = field(repr=False)
    n_eff: np.ndarray = field(repr=False)
    readoff: dict[str, dict[str, np.ndarray]] = field(repr=False)
    cov: np.ndarray = field(repr=False)

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

    def gauss_markov(self, channel: int = 0) -> list[tuple[float, float]]:
        """The (sigma, tau_c) of each Gauss–Markov term of ``channel``."""
        sig = np.reshape(self.gm_sigma, (-1, GM_MAX))[channel]
        tau = np.reshape(self.gm_tau, (-1, GM_MAX))[channel]
        return [(float(s), float(t)) for s, t in zip(sig, tau, strict=True) if np.isfinite(s)]

    def sine(self, channel: int = 0) -> list[tuple[float, float]]:
        """The (amplitude, f0) of the tone of ``channel``: one pair, or none."""
        amp = float(np.atleast_1d(self.sine_amplitude)[channel])
        f0 = float(np.atleast_1d(self.sine_freq)[channel])
        return [(amp, f0)] if np.isfinite(amp) else []

    def resonance(self, channel: int = 0) -> list[tuple[float, float, float]]:
        """The (sigma, f_r, tau_r) of the resonance of ``channel``: one triple, or none."""
        sigma, f_r, tau_r = (float(np.atleast_1d(a)[channel]) for a in
                             (self.resonance_sigma, self.resonance_freq, self.resonance_tau))
        return [(sigma, f_r, tau_r)] if np.isfinite(sigma) else []

    # -- curves -------------------------------------------------------------
    def predict(self, taus=None) -> Prediction:
        """Model Allan deviation at ``taus`` (default: the fitted taus).

        Returns the total curve σ(τ) and each term's own curve, e.g.
        ``terms["N"] = N/√τ``, ``terms["GM1"]`` for the first Gauss–Markov term,
        ``terms["sine"]`` for the tone and ``terms["resonance"]`` for the
        resonance (when a channel has one).
        """
        t = self.taus if taus is None else np.asarray(taus, dtype=float)
        if t.ndim != 1 or t.size == 0 or not np.all(np.isfinite(t)) or np.any(t <= 0):
            raise ValueError(f"taus must be a non-empty 1-D array of finite values > 0; got {t!r}")
        gm_names = [f"GM{k + 1}" for k in range(GM_MAX)]
        names = [*TERMS, *gm_names, "sine", "resonance"]
        parts = np.zeros((t.size, len(names), self.channels))
        for c in range(self.channels):
            markov, tone, osc = self.gauss_markov(c), self.sine(c), self.resonance(c)
            var = _terms(t, self.fs, [self.value(k)[c] for k in TERMS], markov, tone, osc)
            cols = [*range(len(TERMS) + len(markov)), *([names.index("sine")] if tone else []),
                    *([names.index("resonance")] if osc else [])]
            parts[:, cols, c] = var
        total = np.sqrt(parts.sum(axis=1))
        channels = range(self.channels)
        used = [*TERMS, *gm_names[: max(len(self.gauss_markov(c)) for c in channels)],
                *(["sine"] if any(self.sine(c) for c in channels) else []),
                *(["resonance"] if any(self.resonance(c) for c in channels) else [])]
        terms = {k: np.sqrt(parts[:, names.index(k), :]) for k in used}
        if self.one_channel:
            total = total[:, 0]
            terms = {k: v[:, 0] for k, v in terms.items()}
        return Prediction(taus=t, dev=total, terms=terms)

    def equivalent(self, term: str) -> np.ndarray:
        """The datasheet value of ``term`` that the whole model implies, per channel.

        ``"N"``: the white-noise density of the model, N together with every
        Gauss–Markov term faster than 1 s (white at the τ = 1 s read-off:
        σ²(1+φ)/((1−φ)·fs)) and a resonance damped faster than 1 s (its
        spectrum at zero frequency, :func:`resonance_white_density`); what a
        filter's white-noise input should be.
        ``"K"``: K together with every slower Gauss–Markov term's short-τ
        random-walk rate √(2σ²/τc) (its +½ slope; a random walk that bounds
        the bias over times shorter than τc). ``"B"``: the minimum of the model's
        deviation over the fitted taus divided by 0.6643, the bias instability
        a datasheet would quote from this curve (0 when the curve still falls
        at the longest tau with a slope below −¼: no flat part). Other terms,
        and ``method="slopes"``: the coefficient. Shape (channels,).
        """
        return self._equivalents(term, with_std=False)[0]

    def equivalent_std(self, term: str) -> np.ndarray:
        """Standard uncertainty of :meth:`equivalent`, propagated from the fit's
        covariance (linearised: a numerical gradient), shape (channels,)."""
        return self._equivalents(term)[1]

    def _equivalents(self, term: str, with_std: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Values and (``with_std``: the gradients are the costly part) their stds."""
        _check_term(term)
        if self.method != "wls" or term not in ("N", "B", "K"):
            return self.value(term).astype(float), self.std(term).astype(float)
        values = np.zeros(self.channels)
        stds = np.full(self.channels, np.nan)
        cov = np.reshape(self.cov, (self.channels, _PARAMS, _PARAMS))
        for c in range(self.channels):
            p = self._parameters(c)
            f0 = self._equivalent_of(term, p)
            values[c] = f0
            if not (with_std and f0 > 0):
                continue
            active = np.flatnonzero(np.diag(cov[c]) > 0)
            grad = np.zeros(_PARAMS)
            for j in active:
                h = 1e-4 if _is_log_time(j) else 1e-4 * p[j]
                up, down = p.copy(), p.copy()
                up[j] += h
                down[j] = max(down[j] - h, 0.0) if not _is_log_time(j) else down[j] - h
                grad[j] = (self._equivalent_of(term, up) - self._equivalent_of(term, down)) / (
                    up[j] - down[j])
            stds[c] = math.sqrt(max(float(grad @ cov[c] @ grad), 0.0))
        return values, stds

    def _parameters(self, channel: int) -> np.ndarray:
        """(Q², N², B², K², R², then σ², ln τc per Gauss–Markov slot, then A²/2,
        ln f0 of the tone, then σ², ln f_r, ln τr of the resonance) of a channel."""
        p = np.zeros(_PARAMS)
        p[:5] = [float(self.value(t)[channel]) ** 2 for t in TERMS]
        for k, (sigma, tau_c) in enumerate(self.gauss_markov(channel)):
            p[5 + 2 * k], p[6 + 2 * k] = sigma**2, math.log(tau_c)
        for amplitude, f0 in self.sine(channel):
            p[_SINE], p[_SINE + 1] = amplitude**2 / 2, math.log(f0)
        for sigma, f_r, tau_r in self.resonance(channel):
            p[_RES], p[_RES + 1], p[_RES + 2] = sigma**2, math.log(f_r), math.log(tau_r)
        return p

    def _equivalent_of(self, term: str, p: np.ndarray) -> float:
        gm = [(p[5 + 2 * k], math.exp(p[6 + 2 * k])) for k in range(GM_MAX) if p[5 + 2 * k] > 0]
        if term == "B":
            # The tone and the resonance are part of the curve whose floor B is
            # read from; they are neither white nor a walk, so N and K leave them out.
            tone = [(p[_SINE], math.exp(p[_SINE + 1]))] if p[_SINE] > 0 else []
            osc = ([(p[_RES], math.exp(p[_RES + 1]), math.exp(p[_RES + 2]))]
                   if p[_RES] > 0 else [])
            grid = np.geomspace(self.taus[0], self.taus[-1], 200)
            dev = np.sqrt(_core_fit.noise_terms(grid, self.fs, list(p[:5]), gm, tone, osc).sum(
                axis=1))
            i = int(np.argmin(dev))
            # A minimum at the longest tau is a floor only where the curve has
            # flattened (log-log slope above −¼ there); else it is still falling.
            slope = np.log(dev[-1] / dev[-2]) / np.log(grid[-1] / grid[-2])
            if i == grid.size - 1 and slope < -0.25:
                return 0.0
            return float(dev[i] / FLICKER)
        total = p[1] if term == "N" else p[3]
        if term == "N" and p[_RES] > 0 and p[_RES + 2] <= 0.0:  # τr ≤ 1 s
            total += resonance_white_density(1.0, math.exp(p[_RES + 1]),
                                             math.exp(p[_RES + 2]), self.fs) * p[_RES]
        for q2, tau_c in gm:
            if term == "N" and tau_c <= 1.0:
                total += q2 * gm_white_density(1.0, tau_c, self.fs)
            elif term == "K" and tau_c > 1.0:
                total += 2.0 * q2 / tau_c
        return math.sqrt(max(total, 0.0))

    def plot(self, result: AllanResult, **kwargs) -> Figure:
        """The model over ``result``, the Allan result it was fitted to, with its terms,
        read-off points and the data/model ratio: :func:`imunoise.plot.allan`."""
        from imunoise import plot

        return plot.allan(result, self, **kwargs)

    # -- summaries ----------------------------------------------------------
    def _axis_facts(self, channel: int) -> str:
        """``"N=(1.234 ± 0.012)e-4 B=(1.2 ± 0.3)e-5, 1 GM, covers 85 %"``: one channel,
        input units, each value rounded to its uncertainty."""
        terms = [f"{t}={_summary.estimate(*self._value_std(t, channel))}" for t in TERMS
                 if np.atleast_1d(self.supported[t])[channel]]
        gm = len(self.gauss_markov(channel))
        tone = "".join(f", tone {_summary.number(f0)} Hz" for _, f0 in self.sine(channel))
        tone += "".join(f", resonance {_summary.number(f)} Hz"
                        for _, f, _ in self.resonance(channel))
        return (" ".join(terms) or "no term resolved") + (f", {gm} GM" if gm else "") + tone + (
            f", covers {100 * float(np.atleast_1d(self.coverage)[channel]):.3g} %")

    def _value_std(self, term: str, channel: int) -> tuple[float, float]:
        return float(np.ravel(self.value(term))[channel]), float(np.ravel(self.std(term))[channel])

    def _title(self) -> str:
        return (f"{self.method} fit of {self.kind} at {_summary.number(self.fs)} Hz, "
                f"{_summary.plural(self.channels, 'channel')}")

    def __repr__(self) -> str:
        names = _schema.axis_names(self.channels)
        axes = [self._axis_facts(c) if self.one_channel else f"{names[c]}: {self._axis_facts(c)}"
                for c in range(self.channels)]
        return _summary.lines(f"NoiseModel({self._title()}", axes)

    def _repr_html_(self) -> str:
        """One row per axis: each term's value ± standard uncertainty in the input's
        units (``not resolved`` where the data do not resolve it), the Gauss–Markov
        terms and the coverage."""
        units = self.to_dict()["units"]
        rows = []
        for c, name in enumerate(_schema.axis_names(self.channels)):
            row: list[object] = [name]
            for t in TERMS:
                v, e = self.value(t)[c], self.std(t)[c]
                resolved = np.atleast_1d(self.supported[t])[c]
                row.append("not resolved" if not resolved else _summary.number(v) + (
                    f" ± {e:.2g}" if np.isfinite(e) else ""))
            row.append(", ".join(f"σ {_summary.number(sg)}, τc {_summary.number(tc)} s"
                                 for sg, tc in self.gauss_markov(c)) or "—")
            row.append(", ".join(f"A {_summary.number(a)}, f0 {_summary.number(f0)} Hz"
                                 for a, f0 in self.sine(c)) or "—")
            row.append(", ".join(f"σ {_summary.number(sg)}, f_r {_summary.number(f)} Hz, "
                                 f"τr {_summary.number(tr)} s"
                                 for sg, f, tr in self.resonance(c)) or "—")
            row.append(f"{100 * float(np.atleast_1d(self.coverage)[c]):.3g} %")
            rows.append(row)
        return _summary.html_table(
            ["axis", *(f"{t} [{units[t]}]" for t in TERMS), "Gauss–Markov", "tone",
             "resonance", "coverage"],
            rows, caption=f"NoiseModel: {self._title()}, {_summary.tau_span(self.taus)}")

    # -- units and tables ---------------------------------------------------
    @old_call_forms(keyword_only=("units", "input_unit"))
    def in_units(self, sensor: str = "gyro", *, units: dict[str, str] | None = None,
                 input_unit: str | None = None) -> dict[str, dict]:
        """Datasheet values in datasheet units: N, B, K are the model's
        :meth:`equivalent` values (what a datasheet quotes from this curve, with
        the Gauss–Markov terms included), Q and R the coefficients.

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
            value, std = self._equivalents(term)
            supported = (value > 0) & np.isfinite(value)
            shape = np.shape(self.N)
            out[term] = {
                "value": conv(np.reshape(value, shape), term, info.name, sensor=sensor,
                              input_unit=input_unit),
                "std": conv(np.reshape(np.where(supported, std, np.nan), shape), term,
                            info.name, sensor=sensor, input_unit=input_unit),
                "unit": info.name,
                "label": info.label,
                "supported": np.reshape(supported, shape),
            }
        return out

    @old_call_forms(keyword_only=("units", "input_unit", "axes", "terms"))
    def table(self, sensor: str = "gyro", *, units: dict[str, str] | None = None,
              input_unit: str | None = None, axes: Sequence[str] | None = None,
              terms: Sequence[str] = ("N", "B", "K", "Q", "R")) -> list[dict]:
        """Per-axis table in datasheet units: one row per coefficient, then the
        model's other terms where any axis has them (``σ1``, ``τc1``, … per
        Gauss–Markov term, ``A``, ``f0`` of the tone, ``σr``, ``f_r``, ``τr`` of
        the resonance; σ and A in the unit of B, times in s, frequencies in Hz).

        Each row is a dict with ``term``, ``quantity``, ``unit``, ``label``,
        ``missing`` (the text of an axis without the value: ``not resolved`` for
        a coefficient, ``—`` for a term the axis's model does not have) and,
        per axis name (default X, Y, Z…), the value, ``<axis>_std`` and
        ``<axis>_supported``. Render it with :func:`format_table`.
        """
        axes = _schema.axis_names(self.channels, axes)
        conv = self.in_units(sensor, units=units, input_unit=input_unit)
        rows = []
        for term in terms:
            _check_term(term)
            c = conv[term]
            row = {
                "term": term,
                "quantity": _SENSOR_NAMES[sensor].get(term, _NAMES[term]),
                "unit": c["unit"],
                "label": c["label"],
                "missing": _numbers.NOT_RESOLVED,
            }
            vals = np.atleast_1d(c["value"])
            stds = np.atleast_1d(c["std"])
            sup = np.atleast_1d(c["supported"])
            for i, ax in enumerate(axes):
                row[ax] = float(vals[i])
                row[ax + "_std"] = float(stds[i])
                row[ax + "_supported"] = bool(sup[i])
            rows.append(row)
        rate = _units.unit_info("B", (units or {}).get("B"), sensor)

        def to_rate(v):
            return _units.convert(v, "B", rate.name, sensor=sensor, input_unit=input_unit)

        for term, quantity, unit, values, stds in self._other_terms():
            rate_valued = unit is None
            row = {"term": term, "quantity": quantity, "missing": "—",
                   "unit": rate.name if rate_valued else unit,
                   "label": rate.label if rate_valued else unit}
            for i, ax in enumerate(axes):
                v, e = float(values[i]), float(stds[i])
                row[ax] = float(to_rate(v)) if rate_valued and np.isfinite(v) else v
                row[ax + "_std"] = float(to_rate(e)) if rate_valued and np.isfinite(e) else e
                row[ax + "_supported"] = bool(np.isfinite(v))
            rows.append(row)
        return rows

    def _other_terms(self) -> list[tuple[str, str, str | None, np.ndarray, np.ndarray]]:
        """(term, quantity, unit — None for a rate —, values, stds per channel) of
        each row of the model's non-IEEE terms that any axis has."""
        out = []
        sig = np.reshape(self.gm_sigma, (self.channels, GM_MAX))
        sig_std = np.reshape(self.gm_sigma_std, (self.channels, GM_MAX))
        tau = np.reshape(self.gm_tau, (self.channels, GM_MAX))
        tau_std = np.reshape(self.gm_tau_std, (self.channels, GM_MAX))
        for k in range(GM_MAX):
            if np.isfinite(sig[:, k]).any():
                out.append((f"σ{k + 1}", "Gauss–Markov bias", None, sig[:, k],
                            sig_std[:, k]))
                out.append((f"τc{k + 1}", "Gauss–Markov correlation time", "s", tau[:, k],
                            tau_std[:, k]))
        one = np.atleast_1d
        if np.isfinite(one(self.sine_amplitude)).any():
            out.append(("A", "tone amplitude", None, one(self.sine_amplitude),
                        one(self.sine_amplitude_std)))
            out.append(("f0", "tone frequency", "Hz", one(self.sine_freq),
                        one(self.sine_freq_std)))
        if np.isfinite(one(self.resonance_sigma)).any():
            out.append(("σr", "resonance standard deviation", None, one(self.resonance_sigma),
                        one(self.resonance_sigma_std)))
            out.append(("f_r", "resonance frequency", "Hz", one(self.resonance_freq),
                        one(self.resonance_freq_std)))
            out.append(("τr", "resonance damping time", "s", one(self.resonance_tau),
                        one(self.resonance_tau_std)))
        return out

    def table_text(self, sensor: str = "gyro", **kwargs) -> str:
        """Text rendering of :meth:`table`."""
        rows = self.table(sensor, **kwargs)
        return format_table(rows, _schema.axis_names(self.channels, kwargs.get("axes")))

    # -- exports ------------------------------------------------------------
    @old_call_forms(keyword_only=("accel", "path"))
    def to_kalibr(self, *, accel: NoiseModel | None = None, path=None, **kwargs) -> str:
        """Kalibr ``imu.yaml`` text with this model as the gyroscope.

        See :func:`imunoise.export.kalibr_yaml` for the options; with ``path``
        the file is also written atomically.
        """
        from imunoise import _atomic, export

        text = export.kalibr_yaml(gyro=self, accel=accel, **kwargs)
        if path is not None:
            _atomic.write_text(path, text)
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
        d["gauss_markov"] = [
            [{"sigma": sg, "tau_c": tc} for sg, tc in self.gauss_markov(c)]
            for c in range(self.channels)
        ]
        d["sine"] = [
            [{"amplitude": a, "frequency": f0} for a, f0 in self.sine(c)]
            for c in range(self.channels)
        ]
        d["resonance"] = [
            [{"sigma": sg, "frequency": f, "tau_r": tr} for sg, f, tr in self.resonance(c)]
            for c in range(self.channels)
        ]
        d["coverage"] = np.atleast_1d(self.coverage).tolist()
        d["discrepancy"] = np.atleast_1d(self.discrepancy).tolist()
        d["readoff"] = {
            term: {k: [None if not np.isfinite(v) else float(v) for v in np.atleast_1d(a)]
                   for k, a in parts.items()}
            for term, parts in self.readoff.items()
        }
        return d


def format_table(rows: list[dict], axes: Sequence[str]) -> str:
    """Render :meth:`NoiseModel.table` rows as fixed-width text.

    Terms the data do not resolve print as ``not resolved`` (the report's and
    ``imunoise fit``'s wording too), a term an axis's model does not have as
    ``—``; values carry ``± std``, rounded to it
    (:func:`imunoise.numbers.format_value`).
    """
    def cell(row, ax):
        if not row[ax + "_supported"]:
            return row.get("missing", _numbers.NOT_RESOLVED)
        return _numbers.format_value(row[ax], row[ax + "_std"])

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


def _parse_terms(terms) -> tuple[np.ndarray, int, tuple[bool, bool], bool]:
    """``terms`` → (IEEE mask, Gauss–Markov count, (tone, resonance), select by BIC)."""
    if isinstance(terms, str) and terms == "auto":
        return np.ones(len(TERMS), dtype=bool), GM_MAX, (True, True), True
    names = tuple(terms) if not isinstance(terms, str) else tuple(terms)
    allowed = (*TERMS, "GM", "sine", "resonance")
    bad = [t for t in names if t not in allowed]
    gm = names.count("GM")
    if (bad or not names or gm > GM_MAX or names.count("sine") > 1
            or names.count("resonance") > 1):
        raise ValueError(
            f"terms must be 'auto' or a non-empty sequence of {allowed} with 'GM' at most "
            f"{GM_MAX} times, 'sine' at most once and 'resonance' at most once; got {terms!r}"
        )
    mask = np.array([t in names for t in TERMS])
    return mask, gm, ("sine" in names, "resonance" in names), False


@old_call_forms(keyword_only=("method", "terms", "tau_range"))
def fit(result, *, method: str = "wls", terms: str | Sequence[str] = "auto",
        tau_range: tuple[float, float] | None = None, uncertainty: str = "independent",
        replicates: int = 30, seed=None, warn_coverage: bool = True) -> NoiseModel:
    """Fit the noise model to an Allan deviation.

    Parameters
    ----------
    result : AllanResult
        From :func:`imunoise.adev` (overlapping or not); ``kind`` must be
        ``"adev"``. Taus with a non-finite or non-positive variance or EDF are
        ignored.
    method : {"wls", "slopes"}
        Log-space weighted least squares (default) or the IEEE 952 / MATLAB
        slope read-off (see the module docstring).
    terms : "auto" or sequence of {"Q", "N", "B", "K", "R", "GM", "sine", "resonance"}
        ``"auto"`` (default): the IEEE terms, up to three Gauss–Markov terms,
        a tone and a resonance, the structure with the lowest BIC (the fewest
        terms that describe the curve). A sequence fits exactly those terms
        (``"GM"`` up to three times for Gauss–Markov terms, ``"sine"`` once for
        a tone, ``"resonance"`` once for a damped oscillator); a term the data
        push below zero is still 0.
    tau_range : (float, float), optional
        Only use taus in [min, max] seconds.
    uncertainty : {"independent", "bootstrap"}
        How the ``*_std`` are obtained. ``"independent"`` (default, instant):
        the inverse Fisher information of the fit, each octave of taus counted
        as one independent piece of evidence and the model discrepancy δ
        included. ``"bootstrap"``: parametric bootstrap — ``replicates`` records
        of the same length and rate are simulated from the fitted model
        (:func:`imunoise.simulate`), analysed with the same taus and refitted
        with the same structure; each ``*_std`` is the standard deviation over
        the replicates (≈ 0.6 s per replicate and channel for 5 h at 40 Hz).
    replicates : int
        ``"bootstrap"`` only: number of simulated records (≥ 5; default 30).
    seed : int, numpy.random.Generator or None
        ``"bootstrap"`` only: seed of the simulations, for reproducible results.
    warn_coverage : bool
        Warn when the model follows the curve poorly (below); False for callers
        that say it in their own words (the report, ``imunoise fit``).

    Returns
    -------
    NoiseModel

    Warns
    -----
    RuntimeWarning
        When the model follows the measured curve at fewer than 80 % of the
        taus (:attr:`NoiseModel.coverage`): its coefficients then summarise a
        curve they do not describe; look at the residual panel of
        :func:`imunoise.plot.allan`.

    Notes
    -----
    The EDF of the result is capped at its white-rate-noise value (the largest
    for the α ≤ 0 noise types of an IMU) before weighting, see ``_edf_cap``.
    Standard uncertainties of the coefficients follow from those of their
    squares: u(N) = u(N²)/(2N); of a correlation time from that of ln τc.
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
        n = _record_length(result)
        if replicates * n > MAX_BOOTSTRAP_SAMPLES:
            most = MAX_BOOTSTRAP_SAMPLES // n
            raise ValueError(
                (f"replicates must be at most {most:,} for a record of {n:,} samples"
                 if most >= 5 else
                 f"a record of {n:,} samples is too long for a bootstrap (use "
                 f"uncertainty='independent')")
                + f" (the simulated records, replicates x samples, are held at once: at most "
                f"{MAX_BOOTSTRAP_SAMPLES:,}); got replicates={replicates:,}"
            )
    mask, gm_count, oscillators, select = _parse_terms(terms)
    taus, var, edf, one = _extract(result, tau_range)
    dev_all, edf_raw = _measured(result, taus)
    channels = var.shape[1]
    coef = np.zeros((channels, 5))
    std = np.full((channels, 5), np.nan)
    sup = np.zeros((channels, 5), dtype=bool)
    rng = np.full((channels, 5, 2), np.nan)
    gm = np.full((channels, GM_MAX, 2), np.nan)
    gm_std = np.full((channels, GM_MAX, 2), np.nan)
    sine = np.full((channels, 2), np.nan)  # amplitude, f0
    sine_std = np.full((channels, 2), np.nan)
    osc = np.full((channels, 3), np.nan)  # sigma, f_r, tau_r
    osc_std = np.full((channels, 3), np.nan)
    stats = np.full((channels, 3), np.nan)  # discrepancy, chi2, n_eff
    cov = np.full((channels, _PARAMS, _PARAMS), np.nan)
    usable = []
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
        usable.append(ok)
    if method == "wls":
        # The Rust fit releases the GIL: channels run in parallel threads.
        def fit_channel(c):
            ok = usable[c]
            return _fit_wls(taus[ok], var[ok, c], edf[ok, c], float(result.fs), mask,
                            gm_count, oscillators, select)

        with ThreadPoolExecutor(max_workers=min(channels, os.cpu_count() or 1)) as pool:
            fits = list(pool.map(fit_channel, range(channels)))
        for c, out in enumerate(fits):
            coef[c], std[c], sup[c], gm[c], gm_std[c], sine[c], sine_std[c], osc[c], \
                osc_std[c], stats[c], cov[c] = out
            markov = [(a, b) for a, b in gm[c] if np.isfinite(a)]
            tones = [tuple(sine[c])] if np.isfinite(sine[c, 0]) else []
            oscs = [tuple(osc[c])] if np.isfinite(osc[c, 0]) else []
            parts = _terms(taus[usable[c]], result.fs, coef[c], markov, tones, oscs)
            rng[c] = _support_range(parts, taus[usable[c]], sup[c])
    else:
        for c in range(channels):
            ok = usable[c]
            coef[c], std[c], sup[c], rng[c] = _fit_slopes(taus[ok], var[ok, c], edf[ok, c], mask)
    if uncertainty == "bootstrap":
        generator = np.random.default_rng(seed)
        for c in range(channels):
            kept = [t for t, keep in zip(TERMS, sup[c], strict=True) if keep]
            markov = [(float(a), float(b)) for a, b in gm[c] if np.isfinite(a)]
            tones = [(float(sine[c, 0]), float(sine[c, 1]))] if np.isfinite(sine[c, 0]) else []
            oscs = [tuple(map(float, osc[c]))] if np.isfinite(osc[c, 0]) else []
            if not kept and not markov and not tones and not oscs:
                continue
            options = dict(method=method, terms=[*kept, *["GM"] * len(markov),
                                                 *["sine"] * len(tones),
                                                 *["resonance"] * len(oscs)],
                           tau_range=tau_range)
            std[c], gm_std[c], sine_std[c], osc_std[c] = _bootstrap_std(
                result, coef[c], markov, (tones, oscs), int(replicates), generator, options)
    std[~sup] = np.nan

    def shaped(a):
        out = np.array(a[0] if one else a)
        out.setflags(write=False)
        return out

    values = {k: shaped(coef[:, i]) for i, k in enumerate(TERMS)}
    stds = {k + "_std": shaped(std[:, i]) for i, k in enumerate(TERMS)}
    model = NoiseModel(
        **values,
        **stds,
        gm_sigma=shaped(gm[:, :, 0]),
        gm_tau=shaped(gm[:, :, 1]),
        gm_sigma_std=shaped(gm_std[:, :, 0]),
        gm_tau_std=shaped(gm_std[:, :, 1]),
        sine_amplitude=shaped(sine[:, 0]),
        sine_freq=shaped(sine[:, 1]),
        sine_amplitude_std=shaped(sine_std[:, 0]),
        sine_freq_std=shaped(sine_std[:, 1]),
        resonance_sigma=shaped(osc[:, 0]),
        resonance_freq=shaped(osc[:, 1]),
        resonance_tau=shaped(osc[:, 2]),
        resonance_sigma_std=shaped(osc_std[:, 0]),
        resonance_freq_std=shaped(osc_std[:, 1]),
        resonance_tau_std=shaped(osc_std[:, 2]),
        supported={k: shaped(sup[:, i]) for i, k in enumerate(TERMS)},
        tau_range={k: shaped(rng[:, i, :]) for i, k in enumerate(TERMS)},
        method=method,
        kind=result.kind,
        fs=float(result.fs),
        overlapping=bool(getattr(result, "overlapping", True)),
        taus=_readonly(taus),
        coverage=shaped(np.zeros(channels)),
        discrepancy=shaped(stats[:, 0]),
        chi2=shaped(stats[:, 1]),
        n_eff=shaped(stats[:, 2]),
        readoff=_readoffs(taus, dev_all, edf_raw, shaped),
        cov=shaped(cov),
    )
    cover = _coverage(model, taus, dev_all, edf_raw)
    object.__setattr__(model, "coverage", shaped(cover))
    for c in np.flatnonzero(cover < 0.8) if method == "wls" and warn_coverage else ():
        warnings.warn(
            f"the noise model follows the Allan deviation of channel {c} at only "
            f"{cover[c]:.0%} of the taus (inside the 95 % interval or within 5 %); its "
            "coefficients summarise a curve they do not describe: plot it with "
            "result.plot(model) or imunoise.plot.allan(result, model=model)",
            RuntimeWarning, stacklevel=3,  # past old_call_forms' wrapper
        )
    return model


def _measured(result, taus):
    """Measured deviation and uncapped EDF at ``taus``, shape (T, C)."""
    all_taus = np.asarray(result.taus, dtype=float)
    idx = np.searchsorted(all_taus, taus)
    var = np.asarray(result.var if hasattr(result, "var") else np.square(result.dev), float)
    edf = np.asarray(result.edf, dtype=float)
    var = var.reshape(len(all_taus), -1)[idx]
    edf = edf.reshape(len(all_taus), -1)[idx]
    return np.sqrt(var), edf


def _interval95(dev, edf):
    """95 % χ² interval of a deviation with ``edf`` degrees of freedom."""
    from scipy.stats import chi2

    e = np.where(np.isfinite(edf) & (edf > 0), edf, np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        lo = dev * np.sqrt(e / chi2.ppf(0.975, e))
        hi = dev * np.sqrt(e / chi2.ppf(0.025, e))
    return lo, hi


def _coverage(model, taus, dev, edf):
    """Share of taus where the model is inside the 95 % interval or within 5 %."""
    pred = np.reshape(model.predict(taus).dev, dev.shape)
    lo, hi = _interval95(dev, edf)
    inside = (pred >= lo) & (pred <= hi)
    close = np.abs(pred / dev - 1.0) <= _CLOSE
    ok = np.isfinite(dev) & (dev > 0)
    hits = np.where(ok, inside | close, False).sum(axis=0)
    return hits / np.maximum(ok.sum(axis=0), 1)


def _readoffs(taus, dev, edf, shaped):
    """Datasheet read-offs of the measured curve, per channel."""
    channels = dev.shape[1]
    out = {k: {f: np.full(channels, np.nan) for f in ("value", "std", "tau")}
           for k in ("N", "K", "B")}
    out["B"]["low"] = np.full(channels, np.nan)
    out["B"]["high"] = np.full(channels, np.nan)
    for c in range(channels):
        ok = np.isfinite(dev[:, c]) & (dev[:, c] > 0) & np.isfinite(edf[:, c]) & (edf[:, c] > 0)
        t, d, e = taus[ok], dev[ok, c], edf[ok, c]
        if t.size < 2:
            continue
        coef, std, sup, rng = _fit_slopes(t, d**2, e, np.array([False, True, False, True, False]))
        for i, k in ((1, "N"), (3, "K")):
            if sup[i]:
                out[k]["value"][c], out[k]["std"][c], out[k]["tau"][c] = coef[i], std[i], rng[i, 0]
        # The minimum among the estimates with at least 10 degrees of freedom: a
        # scattered long-tau estimate that happens to lie low is no flat part.
        steady = np.flatnonzero(e >= 10)
        if steady.size < 3:
            continue
        j = int(steady[np.argmin(d[steady])])
        if 0 < j < steady[-1]:  # a minimum at an end is no flat part
            lo, hi = _interval95(d[j], e[j])
            out["B"]["value"][c] = d[j] / FLICKER
            out["B"]["std"][c] = d[j] / FLICKER / math.sqrt(2.0 * e[j])
            out["B"]["tau"][c] = t[j]
            out["B"]["low"][c], out["B"]["high"][c] = lo / FLICKER, hi / FLICKER
    return {k: {f: shaped(a) for f, a in parts.items()} for k, parts in out.items()}


def _record_length(result) -> int:
    """Samples behind an Allan result: its ``n_samples`` when gap-free; with gaps,
    the gap-free length with as many terms at the shortest tau (the most of any
    channel), which is what a simulated replicate must match."""
    n_samples = getattr(result, "n_samples", None)
    if n_samples and not np.any(np.asarray(getattr(result, "missing", 0))):
        return int(n_samples)
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


def _bootstrap_std(result, coef, markov, oscillators, replicates, rng, options):
    """Standard deviation of each coefficient (and Gauss–Markov σ, τc, tone A, f0
    and resonance σ, f_r, τr) over fits to records simulated from the model with
    the length, rate and taus of ``result``; ``oscillators`` is (tones, resonances)."""
    from imunoise._simulate import simulate
    from imunoise.allan import adev

    tones, oscs = oscillators
    n = _record_length(result)
    sims = simulate(n, result.fs, *coef, channels=replicates, seed=rng, gm=markov,
                    sinusoid=tones[0] if tones else None,
                    resonance=oscs[0] if oscs else None)
    again = adev(sims, result.fs, taus=np.asarray(result.taus), overlapping=result.overlapping,
                 confidence=result.confidence)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        refit = fit(again, **options)
    values = np.stack([np.atleast_1d(refit.value(t)) for t in TERMS], axis=1)
    gm = np.stack([np.reshape(refit.gm_sigma, (-1, GM_MAX)),
                   np.reshape(refit.gm_tau, (-1, GM_MAX))], axis=-1)
    tone = np.stack([np.atleast_1d(refit.sine_amplitude), np.atleast_1d(refit.sine_freq)],
                    axis=-1)
    osc = np.stack([np.atleast_1d(a) for a in (refit.resonance_sigma, refit.resonance_freq,
                                               refit.resonance_tau)], axis=-1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN: no tone
        return (values.std(axis=0, ddof=1), np.nanstd(gm, axis=0, ddof=1),
                np.nanstd(tone, axis=0, ddof=1), np.nanstd(osc, axis=0, ddof=1))


def _readonly(a):
    out = np.array(a)
    out.setflags(write=False)
    return out


def _fit_wls(t, v, e, fs, mask, gm_count, oscillators, select):
    tone, resonance = oscillators
    try:
        r = _core_fit.fit_noise(
            np.ascontiguousarray(t), np.ascontiguousarray(v), np.ascontiguousarray(e), fs,
            [bool(m) for m in mask], gm_count, select, tone, resonance,
        )
    except ValueError as exc:
        raise ValueError(f"cannot fit the noise model to result: {exc}") from None
    sq, gm, cov = r.ieee, r.gm, r.cov
    delta, chi2, n_eff = r.discrepancy, r.chi2, r.n_eff
    supported = sq > 0
    coef = np.sqrt(np.maximum(sq, 0.0))
    var_sq = np.diag(cov)[:5]
    with np.errstate(divide="ignore", invalid="ignore"):
        std = np.where(supported, np.sqrt(np.maximum(var_sq, 0.0)) / (2.0 * coef), np.nan)
    markov = np.full((GM_MAX, 2), np.nan)
    markov_std = np.full((GM_MAX, 2), np.nan)
    for k, (q2, tau_c) in enumerate(gm):
        sigma = math.sqrt(q2)
        markov[k] = sigma, tau_c
        u_q2, u_log_tau = cov[5 + 2 * k, 5 + 2 * k], cov[6 + 2 * k, 6 + 2 * k]
        markov_std[k] = math.sqrt(max(u_q2, 0.0)) / (2 * sigma), tau_c * math.sqrt(
            max(u_log_tau, 0.0))
    sine = np.full(2, np.nan)
    sine_std = np.full(2, np.nan)
    for s2, f0 in r.sine:
        # s² = A²/2, so u(A) = u(s²)/A.
        amplitude = math.sqrt(2 * s2)
        sine[:] = amplitude, f0
        sine_std[:] = (math.sqrt(max(cov[_SINE, _SINE], 0.0)) / amplitude,
                       f0 * math.sqrt(max(cov[_SINE + 1, _SINE + 1], 0.0)))
    osc = np.full(3, np.nan)
    osc_std = np.full(3, np.nan)
    for r2, f_r, tau_r in r.resonance:
        # u(σ) = u(σ²)/(2σ); f_r, τr from their logarithms (NaN: f_r on the fs/2 bound).
        sigma = math.sqrt(r2)
        osc[:] = sigma, f_r, tau_r
        osc_std[:] = (math.sqrt(max(cov[_RES, _RES], 0.0)) / (2 * sigma),
                      f_r * math.sqrt(cov[_RES + 1, _RES + 1]) if np.isfinite(
                          cov[_RES + 1, _RES + 1]) else np.nan,
                      tau_r * math.sqrt(max(cov[_RES + 2, _RES + 2], 0.0)))
    return (np.where(supported, coef, 0.0), std, supported, markov, markov_std, sine, sine_std,
            osc, osc_std, (delta, chi2, n_eff), cov)


def _support_range(parts, t, sup, min_share=0.25):
    """Per IEEE term, the fitted taus where it is at least ``min_share`` of the
    whole model (Gauss–Markov terms included)."""
    total = parts.sum(axis=1)
    basis = parts[:, :5]
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
