"""The terms of the noise model: names, constants and the one implementation of
their Allan variance (Rust, :func:`imunoise._core.fit.allan_terms`)."""

from __future__ import annotations

import math

import numpy as np

from imunoise._core import fit as _core_fit
from imunoise.errors import ImunoiseValueError

TERMS: tuple[str, ...] = tuple(_core_fit.IEEE_TERM_NAMES)
"""The five coefficients, in the order used everywhere (Q, N, B, K, R)."""

FLICKER = math.sqrt(_core_fit.FLICKER_FACTOR)
"""σ_flat / B = √(2 ln2/π) ≈ 0.6643."""

NAMES = {
    "Q": "quantization noise",
    "N": "random walk (white noise)",
    "B": "bias instability",
    "K": "rate random walk",
    "R": "rate ramp",
}
SENSOR_NAMES = {
    "gyro": {"N": "angle random walk", "Q": "angle quantization"},
    "accel": {"N": "velocity random walk", "Q": "velocity quantization"},
}
# Log-log slope of each term on the deviation curve and the tau where its
# straight line is read (IEEE 952 Annex C).
SLOPE = {"Q": -1.0, "N": -0.5, "B": 0.0, "K": 0.5, "R": 1.0}
READ_TAU = {"Q": math.sqrt(3.0), "N": 1.0, "K": 3.0, "R": math.sqrt(2.0)}
GM_PEAK: float = _core_fit.GM_PEAK
"""τ/τc where a first-order Gauss–Markov term's Allan variance peaks (IEEE 952
Annex C): its hump. Below it the term rises like a random walk, above it falls
like white noise."""

GM_MAX: int = _core_fit.MAX_GAUSS_MARKOV
"""Most first-order Gauss–Markov terms a model may have."""

TONES_MAX: int = _core_fit.MAX_TONES
"""Most tones a model may have."""

# The deprecated ``Components.cov`` layout (the typed terms carry their own
# uncertainties): five IEEE variances, (σ², ln τc) per Gauss–Markov slot, (A²/2,
# ln f0) per tone slot, the resonance's (σ², ln f_r, ln τr, skew), the motion's
# (σθ², ln τc).
SINE_SLOT: int = 5 + 2 * GM_MAX
"""Slot of the first tone's variance A²/2 (its ln f0 follows, then the next tone's)."""
RES_SLOT: int = SINE_SLOT + 2 * TONES_MAX
"""Slot of the resonance's variance σ² (ln f_r, ln τr, skew follow)."""
SKEW_SLOT: int = RES_SLOT + 3
"""Slot of the resonance's skew."""
MOTION_SLOT: int = RES_SLOT + 4
"""Slot of the bounded motion's variance σθ² (ln τc follows)."""
PARAMS: int = MOTION_SLOT + 2
"""Slots of the layout."""


def gm_white_density(sigma: float, tau_c: float, fs: float) -> float:
    """N² (rate²·s) that a sampled Gauss–Markov term of standard deviation ``sigma``
    and correlation time ``tau_c`` contributes at τ ≫ τc: σ²(1+φ)/((1−φ)·fs),
    φ = exp(−1/(fs·τc)), the −½ asymptote of its Allan variance."""
    phi = math.exp(-1.0 / (fs * tau_c))
    return sigma**2 * (1 + phi) / ((1 - phi) * fs)


def resonance_white_density(sigma: float, f_r: float, tau_r: float, fs: float,
                            skew: float = 0.0) -> float:
    """N² (rate²·s) that a sampled resonance of standard deviation ``sigma``,
    frequency ``f_r``, damping time ``tau_r`` and ``skew`` contributes at τ ≫ τr:
    σ²·Re[(1 − iβ)(1+z)/(1−z)]/fs, z = exp(−1/(fs·τr) + 2πi·f_r/fs),
    β = skew·:func:`quadrature_bound`, the −½ asymptote of its Allan variance (its
    spectrum at zero frequency: a low-pass filter's skew > 0 raises it, skew −1
    makes it 0)."""
    z = complex(math.exp(-1.0 / (fs * tau_r)), 0.0) * complex(
        math.cos(2 * math.pi * f_r / fs), math.sin(2 * math.pi * f_r / fs))
    bound = quadrature_bound(f_r, tau_r, fs)
    beta = skew * bound if math.isfinite(bound) else 0.0
    return sigma**2 * (complex(1.0, -beta) * (1 + z) / (1 - z)).real / fs


def resolution_noise(step: float, fs: float) -> tuple[float, float]:
    """(N, Q) that a record whose samples are whole multiples of ``step`` (rate
    units: its count, LSB or print resolution) owes to that resolution at rate ``fs``.

    - Rounding each rate sample to ``step`` adds white noise of variance step²/12
      per sample: N = step/√(12·fs) (rate·√s).
    - Counting an integrated angle (or velocity) — increments, as ring-laser and
      fibre-optic gyros output — adds the angle's rounding error, white in angle:
      Q = step/(fs·√12) (rate·s), IEEE 952's quantization noise.

    Both hold where the signal moves by at least a count between samples (noise or
    dither); slower, the rounding error is correlated and smaller at long τ. Which
    one a record has, its curve tells (slope −½ or −1 at the shortest taus)."""
    if not (math.isfinite(step) and step > 0):
        raise ImunoiseValueError(f"step must be finite and > 0; got {step!r}")
    if not (math.isfinite(fs) and fs > 0):
        raise ImunoiseValueError(f"fs must be finite and > 0; got {fs!r}")
    return step / math.sqrt(12.0 * fs), step / (fs * math.sqrt(12.0))


def quadrature_bound(f_r: float, tau_r: float, fs: float) -> float:
    """κ, the largest |β| of a resonance of frequency ``f_r`` and damping time
    ``tau_r`` sampled at ``fs`` whose spectrum is non-negative (autocovariance
    ρ^|h|(cos θh + β sin θ|h|), β = skew·κ): sinh(u)/sin θ, u = 1/(fs·τr),
    θ = 2π·f_r/fs (infinite at fs/2, where the quadrature part vanishes)."""
    s = abs(math.sin(2 * math.pi * f_r / fs))
    return math.inf if s < 1e-12 else math.sinh(1.0 / (fs * tau_r)) / s


FLAT_SLOPE: float = _core_fit.FLAT_SLOPE
"""A curve whose log-log slope is above this has flattened: a minimum at its end is
a bias-instability floor (slope −½ is white noise, 0 the floor)."""

CLOSE = 0.05
"""A model within this relative distance of the measured deviation follows it."""


def core_terms(squares, markov=(), tone=(), resonance=(), motion=()) -> list:
    """The core's (kind, parameters) of a model in variance form: ``squares`` Q²…R²
    (every one, 0 where absent), ``markov`` (σ², τc), ``tone`` (A²/2, f0),
    ``resonance`` (σ², f_r, τr, skew), ``motion`` (σθ², τc)."""
    names = [name for name, _, _ in _core_fit.TERM_KINDS]
    terms = [(names[j], [float(v)]) for j, v in enumerate(squares)]
    terms += [("gauss_markov", [float(v), float(t)]) for v, t in markov]
    terms += [("tone", [float(v), float(f)]) for v, f in tone]
    terms += [("resonance", [float(v), float(f), float(t), float(k)])
              for v, f, t, k in resonance]
    terms += [("motion", [float(v), float(t)]) for v, t in motion]
    return terms


def term_variances(taus, fs: float, coef, markov=(), tone=(), resonance=(),
                   motion=()) -> np.ndarray:
    """Allan variance of each model term at ``taus``: (len(taus), 5 + len(markov) +
    len(tone) + len(resonance) + len(motion)), from the one implementation of the
    model (Rust); ``coef`` holds Q…R, ``markov`` (sigma, tau_c) pairs, ``tone``
    (amplitude, f0) pairs, ``resonance`` (sigma, f_r, tau_r, skew) quadruples,
    ``motion`` (sigma, tau_c) pairs of a bounded motion (sigma of its angle, rate·s)."""
    t = np.ascontiguousarray(np.atleast_1d(np.asarray(taus, dtype=float)))
    with np.errstate(over="ignore"):  # a coefficient near 1e154 squares to inf, not an error
        squares = np.square(np.asarray(coef, dtype=float)).tolist()
    return _core_fit.allan_terms(t, float(fs), core_terms(
        squares, [(s * s, tc) for s, tc in markov], [(a * a / 2, f0) for a, f0 in tone],
        [(s * s, f, tr, skew) for s, f, tr, skew in resonance],
        [(s * s, tc) for s, tc in motion]))


def model_variance(taus, Q=0.0, N=0.0, B=0.0, K=0.0, R=0.0) -> np.ndarray:
    """Allan variance of the five-term IEEE model at ``taus`` (scalar coefficients)."""
    return term_variances(taus, 1.0, (Q, N, B, K, R)).sum(axis=1)


