"""The overlapping Allan deviation of a stream: fed block by block as the samples
arrive, read at any time (a live view, a long recording watched as it grows).

Each update adds, for every octave averaging factor m, the new overlapping terms
(c_t − 2c_{t−m} + c_{t−2m})² of the cumulative phase c, so the work is O(taus)
per sample and the memory 2·m_max + 1 phase points per channel, whatever the
record's length. The result equals :func:`imunoise.adev` with ``taus="octave"``
on the samples so far (to rounding: the phase is referred to the first block's
mean, which cancels in every term, so an offset such as gravity keeps its digits).

The confidence intervals use the overlapping ADEV's EDF (the statistic's own
model, as :func:`imunoise.adev`) for the power-law noise type read off the curve's
local slope (σ² ∝ τ^μ, α = −μ − 1 rounded into the α ≤ 0 of rate noise), not the
lag-1 identification :func:`imunoise.adev` runs on the whole record, which a
stream does not keep.
"""

from __future__ import annotations

import math

import numpy as np

from imunoise._core import allan as _core_allan
from imunoise._summary import lines, plural
from imunoise._timefreq import tau_result
from imunoise._validate import integer, positive_finite, sample_rate
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
        self._first = 0
        self._offset: np.ndarray | None = None
        self._sums = np.zeros((self._m.size, self.channels))
        self._errors = np.zeros_like(self._sums)  # Kahan compensation of _sums
        self._terms = np.zeros(self._m.size, dtype=np.int64)
        self.n_samples = 0

    def update(self, samples) -> None:
        """Add a block of samples: shape (n,) for one channel, else (n, channels)."""
        y = np.asarray(samples)
        if not np.issubdtype(y.dtype, np.number) or np.iscomplexobj(y):
            raise ImunoiseTypeError(f"samples must hold real numbers; got dtype {y.dtype}")
        y = y.astype(float, copy=False).reshape(y.shape[0] if y.ndim else 1, -1)
        if y.shape[1] != self.channels:
            raise ImunoiseValueError(f"samples must have {self.channels} column(s); got shape "
                                     f"{np.shape(samples)}")
        if y.shape[0] == 0:
            return
        if not np.all(np.isfinite(y)):
            raise ImunoiseValueError("samples must be finite: a stream has no gaps to skip "
                                     "(analyse a record with missing samples with imunoise.adev)")
        if self._offset is None:
            self._offset = y.mean(axis=0)
        phase = self._history[-1] + np.cumsum(y - self._offset, axis=0)
        full = np.concatenate([self._history, phase])
        n_old, n_new = self.n_samples, self.n_samples + y.shape[0]
        for k, m in enumerate(self._m):
            # new terms end at phase points t = max(2m, n_old + 1) … n_new
            first = max(2 * int(m), n_old + 1)
            if first > n_new:
                continue
            t = np.arange(first, n_new + 1) - self._first
            d = full[t] - 2 * full[t - m] + full[t - 2 * m]
            self._add(k, np.sum(d * d, axis=0))
            self._terms[k] += t.size
        self.n_samples = n_new
        cut = max(0, full.shape[0] - self._keep)
        self._history = full[cut:].copy()
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
        keep = self._terms >= 2
        if not keep.any():
            raise ImunoiseValueError(f"the stream holds {self.n_samples} samples; the "
                                     "Allan deviation needs at least 3")
        m, terms = self._m[keep], self._terms[keep]
        var = self._sums[keep] / (2.0 * (m * m * terms)[:, None])
        alpha = _slope_alpha(m, var)
        edf = np.column_stack([
            _core_allan.estimator_edf("oadev", self.n_samples + 1,
                                      np.ascontiguousarray(alpha[:, j], dtype=np.int32),
                                      m.astype(np.uint64))
            for j in range(self.channels)])
        return tau_result(
            "adev", m, var, np.sqrt(var), np.repeat(terms[:, None], self.channels, axis=1),
            edf, alpha, np.zeros(alpha.shape, dtype=bool), fs=self.fs,
            confidence=self.confidence, one_d=self.channels == 1,
            missing=np.zeros(self.channels, np.int64), gaps="skip",
            n_points=self.n_samples + 1, data_type="freq")

    def __repr__(self) -> str:
        seconds = self.n_samples / self.fs
        return lines(f"AllanStream({plural(self.channels, 'channel')} at {self.fs:g} Hz",
                     [f"{self.n_samples:,} samples ({seconds:.6g} s)",
                      f"octave taus up to {self._m[-1] / self.fs:g} s"])


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
