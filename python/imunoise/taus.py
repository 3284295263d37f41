"""Tau grids: which averaging factors m (τ = m/fs) a statistic is evaluated at."""

from __future__ import annotations

import numbers

import numpy as np

from imunoise._support import warn as _warn
from imunoise.errors import CoverageWarning, ImunoiseTypeError, ImunoiseValueError

#: Named grids. Their largest m follows allantools: every m below the number of
#: phase points, then any tau whose estimator has fewer than two terms is dropped.
GRID_NAMES = ("octave", "decade", "all")


def averaging_factors(taus, fs: float, n_samples: int) -> tuple[np.ndarray, bool]:
    """Candidate averaging factors for a tau specification.

    Parameters
    ----------
    taus : {"octave", "decade", "all"}, int or array_like
        ``"octave"``: m = 1, 2, 4, …; ``"decade"``: m = 1, 2, 4, 10, 20, 40, …;
        ``"all"``: every m; an int p: p log-spaced points per decade, rounded to
        unique whole m; an array: taus in seconds, rounded to whole samples.
    fs : float
        Sample rate in Hz.
    n_samples : int
        Number of rate samples (the phase has one point more).

    Returns
    -------
    m : ndarray of int64; sorted and unique for named grids, one per requested
        tau (not yet merged) for an array
    user_given : bool
        True when the taus came from the caller (dropping some deserves a warning).
    """
    n_phase = n_samples + 1
    if isinstance(taus, str):
        if taus == "octave":
            m = 2 ** np.arange(int(np.floor(np.log2(n_phase))) + 1)
        elif taus == "decade":
            decades = 10 ** np.arange(int(np.floor(np.log10(n_phase))) + 1)
            m = (decades[:, None] * np.array([1, 2, 4])).ravel()
        elif taus == "all":
            m = np.arange(1, n_phase)
        else:
            raise ImunoiseValueError(
                f"taus must be one of {', '.join(map(repr, GRID_NAMES))}, an integer number "
                f"of points per decade, or an array of seconds; got {taus!r}"
            )
        return _unique_in_range(m, n_phase), False
    if isinstance(taus, numbers.Integral) and not isinstance(taus, bool):
        if taus < 1:
            raise ImunoiseValueError(f"taus as points per decade must be >= 1; got {taus}")
        most = max_points_per_decade(n_samples)
        if taus > most:
            raise ImunoiseValueError(
                f"taus as points per decade must be at most {most} for {n_samples} samples "
                f"(3 per sample: denser grids give no new averaging factor; taus='all' "
                f"takes every one); got {taus}"
            )
        decades = np.log10(n_phase - 1) if n_phase > 2 else 0.0
        exponents = np.arange(int(np.floor(decades * taus)) + 1) / taus
        m = np.round(10.0**exponents)
        return _unique_in_range(m, n_phase), False
    if isinstance(taus, (bool, numbers.Real)):
        raise ImunoiseTypeError(
            f"taus must be a grid name, an integer number of points per decade, or an "
            f"array of seconds; got {type(taus).__name__} {taus!r}"
        )
    arr = np.asarray(taus)
    if arr.dtype.kind not in "iuf" or arr.ndim != 1:
        raise ImunoiseTypeError(
            f"taus must be a 1-D array of seconds; got {arr.dtype} array of shape {arr.shape}"
        )
    if arr.size == 0:
        raise ImunoiseValueError("taus must not be empty")
    if not np.all(np.isfinite(arr)):
        raise ImunoiseValueError("taus must be finite")
    if np.any(arr <= 0):
        i = int(np.flatnonzero(arr <= 0)[0])
        raise ImunoiseValueError(f"taus must be > 0 s; got taus[{i}] = {arr[i]:g}")
    # float m first: a huge tau must not wrap around when cast to int
    m = np.round(arr.astype(np.float64) * fs)
    outside = (m < 1) | (m >= n_phase)
    if outside.all():
        shown = ", ".join(f"taus[{i}] = {arr[i]:g} s" for i in np.flatnonzero(outside)[:3])
        raise ImunoiseValueError(
            f"no tau is within the record: {shown}{' ...' if arr.size > 3 else ''}; "
            f"{n_samples} samples at {fs:g} Hz give taus from 1/fs = {1 / fs:g} s to "
            f"{max(n_samples, 1) / fs:g} s at most"
        )
    return np.clip(m, 0, n_phase).astype(np.int64), True


def max_points_per_decade(n_samples: int) -> int:
    """Largest ``taus`` as points per decade for ``n_samples`` samples: at 3 per
    sample consecutive grid points near the longest tau are less than one sample
    apart (ratio 10**(1/p), p = 3 n), so every whole averaging factor is reached and
    more points only repeat them."""
    return 3 * max(int(n_samples), 1)


def _unique_in_range(m, n_phase: int) -> np.ndarray:
    m = np.unique(np.asarray(m, dtype=np.int64))
    return m[(m >= 1) & (m < n_phase)]


def keep_estimable(
    m: np.ndarray, terms: np.ndarray, fs: float, user_given: bool, kind: str
) -> np.ndarray:
    """Drops taus whose estimator has fewer than two terms (or m < 1), warning once
    when the caller asked for them explicitly, and merges duplicates."""
    keep = (m >= 1) & (terms > 1)
    dropped = int(np.count_nonzero(~keep))
    if dropped and user_given:
        _warn.warn(
            f"{dropped} of {len(m)} taus dropped: {kind} needs tau >= 1/fs = {1 / fs:g} s "
            f"and at least 2 terms in its sum (largest usable tau {m[keep].max() / fs:g} s)"
            if keep.any()
            else f"{dropped} of {len(m)} taus dropped: none is in range for {kind}", CoverageWarning
        )
    return np.unique(m[keep])
