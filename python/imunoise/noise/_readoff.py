"""What the measured curve itself says: the IEEE 952 / MATLAB slope read-off, the
datasheet read-offs of the data (N at 1 s, K at 3 s, B = σ_min/0.6643) and how
well a model follows the curve (its coverage)."""

from __future__ import annotations

import math

import numpy as np

from imunoise._support import warn as _warn
from imunoise.errors import CoverageWarning
from imunoise.noise._terms import CLOSE, FLAT_SLOPE, FLICKER, READ_TAU, SLOPE, TERMS


def measured(result, taus):
    """Measured deviation and uncapped EDF at ``taus``, shape (T, C)."""
    all_taus = np.asarray(result.taus, dtype=float)
    idx = np.searchsorted(all_taus, taus)
    var = np.asarray(result.var if hasattr(result, "var") else np.square(result.dev), float)
    edf = np.asarray(result.edf, dtype=float)
    var = var.reshape(len(all_taus), -1)[idx]
    edf = edf.reshape(len(all_taus), -1)[idx]
    return np.sqrt(var), edf


def interval95(dev, edf):
    """95 % χ² interval of a deviation with ``edf`` degrees of freedom."""
    from scipy.stats import chi2

    e = np.where(np.isfinite(edf) & (edf > 0), edf, np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        lo = dev * np.sqrt(e / chi2.ppf(0.975, e))
        hi = dev * np.sqrt(e / chi2.ppf(0.025, e))
    return lo, hi


def coverage(model, taus, dev, edf):
    """Share of taus where the model is inside the 95 % interval or within 5 %."""
    pred = np.reshape(model.predict(taus).dev, dev.shape)
    lo, hi = interval95(dev, edf)
    inside = (pred >= lo) & (pred <= hi)
    close = np.abs(pred / dev - 1.0) <= CLOSE
    ok = np.isfinite(dev) & (dev > 0)
    hits = np.where(ok, inside | close, False).sum(axis=0)
    return hits / np.maximum(ok.sum(axis=0), 1)


def readoffs(taus, dev, edf, shaped):
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
        coef, std, sup, rng = fit_slopes(t, d**2, e, np.array([False, True, False, True, False]))
        for i, k in ((1, "N"), (3, "K")):
            if sup[i]:
                out[k]["value"][c], out[k]["std"][c], out[k]["tau"][c] = coef[i], std[i], rng[i, 0]
        # The minimum among the estimates with at least 10 degrees of freedom: a
        # scattered long-tau estimate that happens to lie low is no flat part.
        steady = np.flatnonzero(e >= 10)
        if steady.size < 3:
            continue
        j = int(steady[np.argmin(d[steady])])
        if j == steady[0] or (j == steady[-1] and not _flat_before(t, d, steady)):
            continue  # a minimum at the start, or at the end of a still falling curve
        lo, hi = interval95(d[j], e[j])
        out["B"]["value"][c] = d[j] / FLICKER
        out["B"]["std"][c] = d[j] / FLICKER / math.sqrt(2.0 * e[j])
        out["B"]["tau"][c] = t[j]
        out["B"]["low"][c], out["B"]["high"][c] = lo / FLICKER, hi / FLICKER
    return {k: {f: shaped(a) for f, a in parts.items()} for k, parts in out.items()}


def _flat_before(t, d, steady) -> bool:
    """Whether the curve has flattened at its last steady estimate: its log-log
    slope over the octave before it is above FLAT_SLOPE (a record that ends inside
    the flat part still has a bias-instability floor; one whose curve still falls
    has none)."""
    j = steady[-1]
    k = steady[np.argmin(np.abs(np.log(t[steady] / (t[j] / 2))))]
    if k == j:
        return False
    return math.log(d[j] / d[k]) / math.log(t[j] / t[k]) > FLAT_SLOPE



def fit_slopes(t, v, e, mask, tolerance=0.25):
    """IEEE 952 / MATLAB read-off; uncertainty from the EDF at the tangent point."""
    coef = np.zeros(5)
    std = np.full(5, np.nan)
    sup = np.zeros(5, dtype=bool)
    rng = np.full((5, 2), np.nan)
    if t.size < 2:
        _warn.warn("slope read-off needs at least two taus; no term resolved", CoverageWarning)
        return coef, std, sup, rng
    dev = np.sqrt(v)
    logt, logd = np.log10(t), np.log10(dev)
    slope = np.diff(logd) / np.diff(logt)  # slope[i] between points i and i+1
    # The rising terms (K, R) only from the curve's minimum on: a rise before the
    # curve falls is a filter's or a fast correlated term's hump (a sensor low-pass
    # filtered at 100 Hz read K 3,000× the truth at 2 ms there).
    bottom = int(np.argmin(dev))
    for i, term in enumerate(TERMS):
        if not mask[i]:
            continue
        target = SLOPE[term]
        miss = np.abs(slope - target)
        if target > 0:
            miss[:bottom] = np.inf
        j = int(np.argmin(miss))
        if not miss[j] <= tolerance:
            continue  # no part of the curve has this slope: not resolved
        # MATLAB: the line of exact slope through point j (the segment's left end).
        sigma, tau = dev[j], t[j]
        rel = 1.0 / math.sqrt(2.0 * e[j])  # u(σ̂)/σ̂ from var(σ̂²) = 2σ⁴/edf
        if term == "B":
            value = sigma / FLICKER
        else:
            # σ of the line at the reading τ equals the coefficient there:
            # N/√1, K·√(3/3), √3·Q/√3, R·√2/√2.
            value = sigma * (READ_TAU[term] / tau) ** target
        coef[i] = value
        std[i] = value * rel
        sup[i] = True
        rng[i] = t[j], t[j + 1]
    return coef, std, sup, rng
