"""The datasheet values N, B, K that a fitted model implies, with their propagated
uncertainty: the numbers :class:`~imunoise.noise.NoiseModel` shows as ``N``, ``B``, ``K``.

A datasheet quotes what the curve shows, not which components made it:

- ``N``, the white-noise density: the fitted N together with every Gauss–Markov
  term faster than 1 s (white at the τ = 1 s read-off: σ²(1+φ)/((1−φ)·fs)) and a
  resonance damped faster than 1 s (its spectrum at zero frequency, quadrature
  included: a sensor's second-order filter passes its input's white noise). What a
  filter's white-noise input should be.
- ``K``, the rate random walk: a walk that keeps rising to the end of the record.
  The fitted K, together with the short-τ random-walk rate √(2σ²/τc) of a
  Gauss–Markov term whose hump (its Allan variance's peak, τ ≈ 1.89 τc) lies
  beyond the longest fitted tau: over the record it rises like a walk, and an
  estimator's walk over that span is its rate. A Gauss–Markov term whose hump lies
  within the fitted taus is a bump, a bias state of its own: it shapes B and is
  never added to K (taken as K it would inflate an EKF's bias process noise by
  the bump's height over the walk's).
- ``B``, the bias instability: the floor of the model's deviation over the
  fitted taus divided by √(2 ln2/π) ≈ 0.6643 (:func:`model_floor`: the minimum,
  or, where the curve falls again past a slow bump, the valley before it); not
  resolved where the curve never flattens (no part with a log-log slope above −¼).
- ``Q`` and ``R`` are the fitted coefficients.

What the data cannot show is not resolved: NaN, never 0, with
:func:`upper_bounds` the largest value the measured curve allows.

A bounded motion of the mount (the platform's, not the sensor's) is part of the
curve B is read from, but neither N nor K: under it a sensor's own white noise may
not show at all, and N is then not resolved rather than the platform's rocking.

With ``method="slopes"`` every value is the read-off coefficient. Uncertainties
are propagated from the fit's covariance through a numerical gradient.
"""

from __future__ import annotations

import math

import numpy as np

from imunoise._core import fit as _core_fit
from imunoise.noise._terms import (
    FLAT_SLOPE,
    FLICKER,
    GM_MAX,
    GM_PEAK,
    MOTION_SLOT,
    PARAMS,
    RES_SLOT,
    SINE_SLOT,
    SKEW_SLOT,
    TERMS,
    core_terms,
    gm_white_density,
    is_log_time,
    resonance_white_density,
    term_variances,
)

#: Points of the log-spaced grid over the fitted taus on which B's minimum is sought.
_B_GRID = 200


def datasheet_values(components, taus, method: str) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """``{term: (values, stds)}``, each of shape (channels,), for Q, N, B, K, R."""
    out = {}
    for term in TERMS:
        if method != "wls" or term not in ("N", "B", "K"):
            out[term] = (components.value(term).astype(float),
                         components.std(term).astype(float))
        else:
            out[term] = _propagated(components, np.asarray(taus, float), term)
    return out


def _propagated(components, taus, term: str) -> tuple[np.ndarray, np.ndarray]:
    channels = components.channels
    values = np.zeros(channels)
    stds = np.full(channels, np.nan)
    cov = np.reshape(components.cov, (channels, PARAMS, PARAMS))
    fs = float(components.fs)
    for c in range(channels):
        p = parameters(components, c)
        f0 = value_of(term, p, taus, fs)
        values[c] = f0
        if not f0 > 0:
            continue
        active = np.flatnonzero(np.diag(cov[c]) > 0)
        grad = np.zeros(PARAMS)
        for j in active:
            up, down = p.copy(), p.copy()
            if j == SKEW_SLOT:  # either sign, within [−1, 1]
                h = 1e-4
                up[j], down[j] = min(p[j] + h, 1.0), max(p[j] - h, -1.0)
            else:
                h = 1e-4 if is_log_time(j) else 1e-4 * p[j]
                up[j] += h
                down[j] = max(down[j] - h, 0.0) if not is_log_time(j) else down[j] - h
            grad[j] = (value_of(term, up, taus, fs) - value_of(term, down, taus, fs)) / (
                up[j] - down[j])
        # Over the free parameters only: one not free (a frequency at fs/2, a skew at
        # ±1) has a NaN variance and no covariance.
        g = grad[active]
        stds[c] = math.sqrt(max(float(g @ cov[c][np.ix_(active, active)] @ g), 0.0))
    return values, stds


def parameters(components, channel: int) -> np.ndarray:
    """(Q², N², B², K², R², then σ², ln τc per Gauss–Markov slot, then A²/2,
    ln f0 per tone slot, then σ², ln f_r, ln τr, skew of the resonance, then σθ², ln τc
    of the bounded motion) of a channel."""
    p = np.zeros(PARAMS)
    p[:5] = [float(components.value(t)[channel]) ** 2 for t in TERMS]
    for k, (sigma, tau_c) in enumerate(components.gauss_markov(channel)):
        p[5 + 2 * k], p[6 + 2 * k] = sigma**2, math.log(tau_c)
    for k, (amplitude, f0) in enumerate(components.sine(channel)):
        p[SINE_SLOT + 2 * k], p[SINE_SLOT + 2 * k + 1] = amplitude**2 / 2, math.log(f0)
    for sigma, f_r, tau_r, skew in components.resonance(channel):
        p[RES_SLOT:SKEW_SLOT + 1] = sigma**2, math.log(f_r), math.log(tau_r), skew
    for sigma, tau_c in components.motion(channel):
        p[MOTION_SLOT], p[MOTION_SLOT + 1] = sigma**2, math.log(tau_c)
    return p


def model_floor(p: np.ndarray, taus: np.ndarray, fs: float) -> tuple[float, float] | None:
    """(τ, σ) of the floor of the model's deviation over the fitted taus, where B is
    read; None where the curve has none.

    The floor is the curve's minimum. Where that minimum is the last tau and the
    curve still falls there (slope below −¼), it is the lowest valley of the curve
    (where its slope turns from falling to rising), else the lowest point of its
    flat parts (log-log slope ≥ −¼): a slow Gauss–Markov bump beyond a flat bottom
    falls again past its peak, and the bottom before it is the bias floor a reader
    sees. A curve that never flattens after falling has none (a filter's rising
    head at the shortest taus is no floor). The tone, the resonance and a
    bounded motion are part of the curve whose floor B is read from; the tone and
    the resonance are neither white nor a walk, so N and K leave them out.
    """
    gm = _gauss_markov(p)
    tone = [(p[s], math.exp(p[s + 1])) for s in range(SINE_SLOT, RES_SLOT, 2) if p[s] > 0]
    osc = [_resonance(p)] if p[RES_SLOT] > 0 else []
    moving = [(p[MOTION_SLOT], math.exp(p[MOTION_SLOT + 1]))] if p[MOTION_SLOT] > 0 else []
    grid = np.geomspace(taus[0], taus[-1], _B_GRID)
    dev = np.sqrt(_core_fit.allan_terms(grid, fs, core_terms(p[:5], gm, tone, osc, moving))
                  .sum(axis=1))
    i = int(np.argmin(dev))
    slope = np.log(dev[-1] / dev[-2]) / np.log(grid[-1] / grid[-2])
    if i == grid.size - 1 and slope < FLAT_SLOPE:
        # the curve without its oscillators: a tone's comb has a zero at every period
        smooth = np.sqrt(_core_fit.allan_terms(grid, fs, core_terms(p[:5], gm, motion=moving))
                         .sum(axis=1))
        with np.errstate(divide="ignore", invalid="ignore"):  # 0 without other terms: no floor
            slope = np.gradient(np.log(smooth), np.log(grid))
        # only where the curve has fallen into it: a head that rises or stays flat
        # and then falls is a filter's or a fast Gauss–Markov term's hump, no bias
        # floor (a sensor low-pass filtered at 100 Hz read B 40× the truth there)
        flat = (slope >= FLAT_SLOPE) & (np.cumsum(slope < FLAT_SLOPE) > 0)
        if not flat.any():
            return None
        # a valley (the slope turns from falling to rising) where the curve has
        # one; else the lowest point of a shoulder
        valley = np.zeros_like(flat)
        valley[1:] = (slope[:-1] < 0) & (slope[1:] >= 0)
        i = int(np.argmin(np.where(valley if valley.any() else flat, smooth, np.inf)))
    return float(grid[i]), float(dev[i])


def _resonance(p: np.ndarray) -> tuple[float, float, float, float]:
    """(σ², f_r, τr, skew) of the resonance of ``p``."""
    return p[RES_SLOT], math.exp(p[RES_SLOT + 1]), math.exp(p[RES_SLOT + 2]), p[SKEW_SLOT]


def _gauss_markov(p: np.ndarray) -> list[tuple[float, float]]:
    """(σ², τc) of each Gauss–Markov slot of ``p`` in use."""
    return [(p[5 + 2 * k], math.exp(p[6 + 2 * k])) for k in range(GM_MAX) if p[5 + 2 * k] > 0]


def walks_beyond(tau_c: float, taus: np.ndarray) -> bool:
    """Whether a Gauss–Markov term of correlation time ``tau_c`` still rises at the
    longest fitted tau (its hump lies beyond the record), and so may stand in for K."""
    return GM_PEAK * tau_c > float(taus[-1])


def value_of(term: str, p: np.ndarray, taus: np.ndarray, fs: float) -> float:
    """The datasheet value of ``term`` for the parameter vector ``p``; NaN where
    not resolved."""
    if term == "B":
        floor = model_floor(p, taus, fs)
        return math.nan if floor is None else floor[1] / FLICKER
    total = p[1] if term == "N" else p[3]
    if term == "N" and p[RES_SLOT] > 0 and p[RES_SLOT + 2] <= 0.0:  # τr ≤ 1 s
        r2, f_r, tau_r, skew = _resonance(p)
        total += resonance_white_density(1.0, f_r, tau_r, fs, skew) * r2
    for q2, tau_c in _gauss_markov(p):
        if term == "N" and tau_c <= 1.0:
            total += q2 * gm_white_density(1.0, tau_c, fs)
        elif term == "K" and tau_c > 1.0 and walks_beyond(tau_c, taus):
            total += 2.0 * q2 / tau_c
    return math.sqrt(total) if total > 0 else math.nan


#: Confidence of the bound on a value the data do not resolve.
UPPER_CONFIDENCE = 0.95


def upper_bounds(taus, var, edf) -> dict[str, np.ndarray]:
    """``{term: (channels,)}``: the largest value of each of Q, N, B, K, R that the
    measured Allan variance allows at 95 % confidence.

    The rule: the term alone may not exceed the measured variance's one-sided upper
    confidence limit σ̂²·edf/χ²_α(edf) at any fitted tau, so its bound is
    min_τ √(limit(τ)/f(τ)) with f its Allan variance per unit coefficient² (3/τ²,
    1/τ, 2 ln2/π, τ/3, τ²/2). Every other term only adds to the curve, so the bound
    holds whatever they are. α is 5 % shared over the octaves the taus span
    (Bonferroni: estimates an octave apart are nearly independent, neighbours
    within one are not), so the bound holds at 95 % over the whole curve.
    ``var``, ``edf``: (taus, channels).
    """
    from scipy import stats

    taus = np.asarray(taus, float)
    var, edf = np.asarray(var, float), np.asarray(edf, float)
    octaves = max(1.0, math.log2(taus[-1] / taus[0])) if taus.size > 1 else 1.0
    alpha = (1.0 - UPPER_CONFIDENCE) / octaves
    ok = np.isfinite(var) & (var > 0) & np.isfinite(edf) & (edf > 0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        limit = np.where(ok, var * edf / stats.chi2.ppf(alpha, np.where(ok, edf, 1.0)), np.inf)
    # each IEEE term's own column at unit coefficient: its variance per coefficient²
    per_unit = term_variances(taus, 1.0, np.ones(len(TERMS)))
    out = {}
    for k, term in enumerate(TERMS):
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            bound = np.sqrt(np.min(limit / per_unit[:, k, None], axis=0))
        out[term] = np.where(np.isfinite(bound), bound, np.nan)
    return out


def datasheet_notes(components, taus, channel: int, method: str) -> tuple[str, ...]:
    """What a reader of channel ``channel``'s K needs to know: which slow
    Gauss–Markov terms stand in for it (hump beyond the record) and which are bumps
    within the record, bias states of their own left out of it."""
    if method != "wls":
        return ()
    taus = np.asarray(taus, float)
    notes = []
    for _, tau_c in components.gauss_markov(channel):
        if tau_c <= 1.0:
            continue
        if walks_beyond(tau_c, taus):
            notes.append(f"K includes a Gauss–Markov term of τc {tau_c:.3g} s whose hump "
                         f"(τ ≈ {GM_PEAK * tau_c:.3g} s) lies beyond the longest tau "
                         f"({taus[-1]:.3g} s): over the record it rises like a random walk")
        else:
            notes.append(f"a Gauss–Markov bump of τc {tau_c:.3g} s lies within the record: "
                         "a bias state of its own (the EKF export keeps it), not part of K")
    return tuple(notes)
