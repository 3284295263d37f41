"""The overlapping Allan deviation of a stream: fed block by block as the samples
arrive, read at any time (a live view, a long recording watched as it grows).

Each update adds, for every octave averaging factor m, the new overlapping terms
(c_t − 2c_{t−m} + c_{t−2m})² of the cumulative phase c, so the work is O(taus)
per sample and the memory 2·m_max + 1 phase points per channel, whatever the
record's length. The result equals :func:`imunoise.adev` with ``taus="octave"``
on the samples so far (to rounding: the phase is referred to the first block's
mean, which cancels in every term, so an offset such as gravity keeps its digits).

Missing samples (NaN) are gaps, as :func:`imunoise.adev` skips them
(``gaps="skip"``): a missing rate sample breaks the phase interval it spans and
every term whose span holds a broken interval is left out (``n`` counts the terms
used, per channel). The phase is held across the gap, so the terms after it are
exact. A stream whose samples carry timestamps puts a NaN row in each slot a
dropped sample would have filled; the live view of :func:`imunoise.record` does.

The confidence intervals use the overlapping ADEV's EDF (the statistic's own
model, as :func:`imunoise.adev`) for the power-law noise type read off the curve's
local slope (σ² ∝ τ^μ, α = −μ − 1 rounded into the α ≤ 0 of rate noise), not the
lag-1 identification :func:`imunoise.adev` runs on the whole record, which a
stream does not keep.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from imunoise._analysis.timefreq import tau_result
from imunoise._core import allan as _core_allan
from imunoise._support.summary import lines, plural
from imunoise._support.validate import integer, positive_finite, sample_rate
from imunoise.allan import ONE_SIGMA, AllanResult
from imunoise.errors import ImunoiseTypeError, ImunoiseValueError

__all__ = ["AllanStream"]

#: Largest averaging factor kept by default: 2¹⁶ samples (0.5 MiB of phase per channel).
DEFAULT_MAX_M = 1 << 16


class AllanStream:
    """Overlapping Allan deviation of a stream of rate samples, read at any time.

    Parameters
    ----------
    fs : float
        Sample rate, Hz.
    channels : int
        Channels per sample (columns of each block).
    max_tau : float, optional
        Longest averaging time wanted, s: the octave factors m = 1, 2, 4 … up to
        ``max_tau·fs`` are kept (default 2¹⁶ samples). Memory is 2·m_max + 1 phase
        points per channel.
    confidence : float
        Two-sided level of the intervals of :meth:`result`.

    Examples
    --------
    >>> import imunoise
    >>> live = imunoise.AllanStream(100.0, channels=3)
    >>> for block in blocks:                 # doctest: +SKIP
    ...     live.update(block)
    ...     curve = live.result()            # an AllanResult, as imunoise.adev gives
    """

    def __init__(self, fs: float, *, channels: int = 1, max_tau: float | None = None,
                 confidence: float = ONE_SIGMA) -> None:
        self.fs = sample_rate(fs)
        self.channels = integer(channels, "channels", 1)
        if max_tau is None:
            max_m = DEFAULT_MAX_M
        else:
            max_m = int(positive_finite(max_tau, "max_tau") * self.fs)
            if max_m < 1:
                raise ImunoiseValueError(f"max_tau must be at least one sample period "
                                         f"({1 / self.fs:g} s); got {max_tau!r}")
        self.confidence = float(confidence)
        if not 0 < self.confidence < 1:
            raise ImunoiseValueError(f"confidence must be in (0, 1); got {confidence!r}")
        self._m = 2 ** np.arange(int(math.floor(math.log2(max_m))) + 1, dtype=np.int64)
        self._keep = 2 * int(self._m[-1]) + 1
        self._history = np.zeros((1, self.channels))  # phase points from index _first on
        # broken intervals before each phase point of _history (cumulative, per channel)
        self._broken = np.zeros((1, self.channels), dtype=np.int64)
        self._first = 0
        self._offset: np.ndarray | None = None
        self._sums = np.zeros((self._m.size, self.channels))
        self._errors = np.zeros_like(self._sums)  # Kahan compensation of _sums
        self._terms = np.zeros((self._m.size, self.channels), dtype=np.int64)
        self.n_samples = 0
        #: Missing samples (NaN) so far, per channel.
        self.missing = np.zeros(self.channels, dtype=np.int64)

    def update(self, samples) -> None:
        """Add a block of samples: shape (n,) for one channel, else (n, channels);
        NaN marks a missing sample (a gap)."""
        y = np.asarray(samples)
        if not np.issubdtype(y.dtype, np.number) or np.iscomplexobj(y):
            raise ImunoiseTypeError(f"samples must hold real numbers; got dtype {y.dtype}")
        y = y.astype(float, copy=False).reshape(y.shape[0] if y.ndim else 1, -1)
        if y.shape[1] != self.channels:
            raise ImunoiseValueError(f"samples must have {self.channels} column(s); got shape "
                                     f"{np.shape(samples)}")
        if y.shape[0] == 0:
            return
        missing = np.isnan(y)
        if np.isinf(y).any():
            raise ImunoiseValueError("samples must be finite or NaN (a missing sample); got "
                                     f"{int(np.isinf(y).sum())} infinite value(s)")
        if self._offset is None or not np.all(np.isfinite(self._offset)):
            # the offset cancels in every term; it only keeps a large mean's digits
            with np.errstate(invalid="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # an all-NaN column
                first = np.nanmean(y, axis=0)
            self._offset = first if self._offset is None else np.where(
                np.isfinite(self._offset), self._offset, first)
        offset = np.nan_to_num(self._offset)
        phase = self._history[-1] + np.cumsum(np.where(missing, 0.0, y - offset), axis=0)
        full = np.concatenate([self._history, phase])
        broken = np.concatenate([self._broken,
                                 self._broken[-1] + np.cumsum(missing, axis=0, dtype=np.int64)])
        n_old, n_new = self.n_samples, self.n_samples + y.shape[0]
        for k, m in enumerate(self._m):
            # new terms end at phase points t = max(2m, n_old + 1) … n_new
            first = max(2 * int(m), n_old + 1)
            if first > n_new:
                continue
            t = np.arange(first, n_new + 1) - self._first
            d = full[t] - 2 * full[t - m] + full[t - 2 * m]
            whole = broken[t] == broken[t - 2 * m]  # no missing sample in the term's span
            self._add(k, np.sum(np.where(whole, d * d, 0.0), axis=0))
            self._terms[k] += whole.sum(axis=0)
        self.n_samples = n_new
        self.missing += missing.sum(axis=0)
        cut = max(0, full.shape[0] - self._keep)
        self._history = full[cut:].copy()
        self._broken = broken[cut:].copy()
        self._first += cut

    def _add(self, k: int, value: np.ndarray) -> None:
        """Kahan-compensated ``_sums[k] += value``: blocks add many small terms."""
        y = value - self._errors[k]
        t = self._sums[k] + y
        self._errors[k] = (t - self._sums[k]) - y
        self._sums[k] = t

    def result(self) -> AllanResult:
        """The overlapping Allan deviation of the samples so far at the octave taus
        with at least two terms (as :func:`imunoise.adev` keeps them)."""
        keep = self._terms.min(axis=1) >= 2
        if not keep.any():
            raise ImunoiseValueError(f"the stream holds {self.n_samples} samples "
                                     f"({_plural_missing(self.missing)}); the Allan deviation "
                                     "needs at least 3 in a row")
        m, terms = self._m[keep], self._terms[keep]
        var = self._sums[keep] / (2.0 * (m * m)[:, None] * terms)
        alpha = _slope_alpha(m, var)
        # the EDF of a record without gaps that gives each tau its terms (N = terms + 2m)
        edf = np.column_stack([
            [float(_core_allan.estimator_edf(
                "oadev", int(terms[i, j] + 2 * m[i]),
                np.array([alpha[i, j]], dtype=np.int32),
                np.array([m[i]], dtype=np.uint64))[0]) for i in range(m.size)]
            if self.missing[j] else
            _core_allan.estimator_edf("oadev", self.n_samples + 1,
                                      np.ascontiguousarray(alpha[:, j], dtype=np.int32),
                                      m.astype(np.uint64))
            for j in range(self.channels)])
        return tau_result(
            "adev", m, var, np.sqrt(var), terms,
            edf, alpha, np.zeros(alpha.shape, dtype=bool), fs=self.fs,
            confidence=self.confidence, one_d=self.channels == 1,
            missing=self.missing.copy(), gaps="skip",
            n_points=self.n_samples + 1, data_type="freq")

    def __repr__(self) -> str:
        seconds = self.n_samples / self.fs
        return lines(f"AllanStream({plural(self.channels, 'channel')} at {self.fs:g} Hz",
                     [f"{self.n_samples:,} samples ({seconds:.6g} s)",
                      f"octave taus up to {self._m[-1] / self.fs:g} s"])


def _plural_missing(missing: np.ndarray) -> str:
    """``"none missing"`` or ``"12 missing"`` (the most of any channel)."""
    most = int(np.max(missing)) if missing.size else 0
    return f"{most} missing" if most else "none missing"


def _slope_alpha(m: np.ndarray, var: np.ndarray) -> np.ndarray:
    """(T, channels) power-law noise type of rate noise from the curve's local slope:
    σ² ∝ τ^μ, α = −μ − 1 rounded into [−2, 0] (white to random-walk rate noise); white
    where the curve has a single tau."""
    if m.size < 2:
        return np.zeros(var.shape, dtype=np.int64)
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.gradient(np.log(var), np.log(m.astype(float)), axis=0)
    alpha = np.rint(-slope - 1.0)
    return np.clip(np.nan_to_num(alpha, nan=0.0), -2, 0).astype(np.int64)
