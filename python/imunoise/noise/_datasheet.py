"""The datasheet values N, B, K that a fitted model implies, with their propagated
uncertainty: the numbers :class:`~imunoise.noise.NoiseModel` shows as ``N``, ``B``, ``K``.

A datasheet quotes what the curve shows, not which components made it:

- ``N``, the white-noise density: the fitted N together with every Gauss–Markov
  term whose hump (τ ≈ 1.89 τc) lies before τ = 1 s (falling toward its white tail at
  the read-off: σ²(1+φ)/((1−φ)·fs)) and a
  resonance damped faster than 1 s (its spectrum at zero frequency, quadrature
  included: a sensor's second-order filter passes its input's white noise). What a
  filter's white-noise input should be.
- ``K``, the rate random walk: a walk that keeps rising to the end of the record.
  The fitted K, together with the short-τ random-walk rate √(2σ²/τc) of a
  Gauss–Markov term whose hump (its Allan variance's peak, τ ≈ 1.89 τc) lies
  beyond the record (its duration, not only its longest fitted tau): over the record
  it rises like a walk, and an estimator's walk over that span is its rate. A
  Gauss–Markov term whose hump lies within the record is a bump, a bias state of
  its own: it shapes B and is never added to K (taken as K it would inflate an
  EKF's bias process noise by the bump's height over the walk's).
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

With ``method="slopes"`` every value is the read-off coefficient. The values of a
``"wls"`` fit and their uncertainties, propagated from the fit's covariance through
a numerical gradient, come from the core (``rust/fit/datasheet.rs``; each term's
share of N and K is its own, ``rust/fit/term.rs``); :func:`upper_bounds` and the
notes are here.
"""

from __future__ import annotations

import math

import numpy as np

from imunoise._core import fit as _core_fit
from imunoise.noise._terms import (
    GM_PEAK,
    TERMS,
    term_variances,
)
from imunoise.noise._typed import GaussMarkov


def datasheet_values(components, core, taus, method: str, record: float,
                     filters=None) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """``{term: (values, stds)}``, each of shape (channels,), for Q, N, B, K, R.
    ``core``: per channel, the core fit's (kind, parameters) terms and the
    covariance of their coordinates (``"wls"``), from which N, B, K and their
    uncertainties come (Rust: ``rust/fit/datasheet.rs``); ``record`` the record's
    duration (s); ``filters`` each channel's output filter or None (B is read off
    the curve the model draws, through it)."""
    out = {term: (components.value(term).astype(float), components.std(term).astype(float))
           for term in TERMS}
    if method != "wls":
        return out
    taus = np.ascontiguousarray(taus, dtype=float)
    values = {t: np.full(components.channels, np.nan) for t in ("N", "B", "K")}
    stds = {t: np.full(components.channels, np.nan) for t in ("N", "B", "K")}
    for c, (terms, cov) in enumerate(core):
        found = None if filters is None else filters[c]
        gain = None if found is None else found.gain
        for name, (v, e) in _core_fit.datasheet(terms, cov, taus, float(components.fs),
                                                record=float(record), filter=gain):
            values[name][c], stds[name][c] = v, e
    out.update({t: (values[t], stds[t]) for t in values})
    return out


#: Confidence of the bound on a value the data do not resolve.
UPPER_CONFIDENCE = 0.95


def upper_bounds(taus, var, edf, filters=None) -> dict[str, np.ndarray]:
    """``{term: (channels,)}``: the largest value of each of Q, N, B, K, R that the
    measured Allan variance allows at 95 % confidence.

    The rule: the term alone may not exceed the measured variance's one-sided upper
    confidence limit σ̂²·edf/χ²_α(edf) at any fitted tau, so its bound is
    min_τ √(limit(τ)/f(τ)) with f its Allan variance per unit coefficient² (3/τ²,
    1/τ, 2 ln2/π, τ/3, τ²/2). Every other term only adds to the curve, so the bound
    holds whatever they are. α is 5 % shared over the octaves the taus span
    (Bonferroni: estimates an octave apart are nearly independent, neighbours
    within one are not), so the bound holds at 95 % over the whole curve.
    ``var``, ``edf``: (taus, channels); ``filters``: each channel's output filter or
    None. Through a filter the white term's variance is c(τ)/τ per N², below 1/τ at
    the short taus the filter lowers, so N's bound is read off that.
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
    per_unit = np.repeat(per_unit[:, :, None], var.shape[1], axis=2)
    white = TERMS.index("N")
    for c, found in enumerate(filters or ()):
        if found is not None:
            per_unit[:, white, c] *= found.factor(taus)
    out = {}
    for k, term in enumerate(TERMS):
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            bound = np.sqrt(np.min(limit / per_unit[:, k, :], axis=0))
        out[term] = np.where(np.isfinite(bound), bound, np.nan)
    return out


def datasheet_notes(terms, fs: float, record: float, method: str) -> tuple[str, ...]:
    """What a reader of one channel's K needs to know (``terms``: its typed terms):
    which slow Gauss–Markov terms stand in for it (hump beyond the record) and which
    are bumps within the record, bias states of their own left out of it. Which term
    counts where is the core's rule (``Term::white_share``, ``walk_share``)."""
    if method != "wls":
        return ()
    markov = [t for t in terms if isinstance(t, GaussMarkov)]
    if not markov:
        return ()
    shares = _core_fit.datasheet_shares([t.core() for t in markov], float(fs), float(record))
    notes = []
    for term, (white, walk) in zip(markov, shares, strict=True):
        tau_c = term.tau_c
        if white > 0:  # in N: its hump lies before the 1 s read-off
            continue
        if walk > 0:
            notes.append(f"K includes a Gauss–Markov term of τc {tau_c:.3g} s whose hump "
                         f"(τ ≈ {GM_PEAK * tau_c:.3g} s) lies beyond the record "
                         f"({record:.3g} s): over the record it rises like a random walk")
        else:
            notes.append(f"a Gauss–Markov bump of τc {tau_c:.3g} s lies within the record: "
                         "a bias state of its own (the EKF export keeps it), not part of K")
    return tuple(notes)
