r"""Dynamic Allan deviation: the overlapping ADEV of a sliding window.

Galleani & Tavella's dynamic Allan variance evaluates the Allan variance on a window
of the record that slides along it, so that a stretch where the noise changes (a
warm-up, vibration, a temperature swing) shows as a change over time that one
whole-record curve averages away.

Computation
-----------
With the mean-removed samples' cumulative sum :math:`c_k` (per channel, kept to a few
ulps by summing in blocks), the overlapping Allan variance of a window of W samples
starting at s is

.. math:: \sigma^2_y(\tau; s) = \frac{1}{2m^2 n_s}\sum_{k=s}^{s+W-2m} d_k,
          \qquad d_k = (c_{k+2m} - 2c_{k+m} + c_k)^2,

the second difference being blind to the window's own mean. For each m the squared
differences d_k over the whole record and their prefix sum give every window's sum
in O(1): the cost is one pass per tau over the record, whatever the number of
windows, instead of one ADEV per window. A term touching a missing sample (NaN) is
left out, as :func:`imunoise.adev` does with ``gaps="skip"``, and :math:`n_s` counts
the terms kept (a prefix sum of the valid ones).

Confidence intervals
--------------------
The EDF of a gap-free window depends only on the noise type α, the window length
and m (Greenhall's algorithm, the same code as :func:`imunoise.adev`). α is
identified once per tau on the whole record (``whole.alpha``), not per window: a
window is short, and identification from it would jump where the curve bends. A
window with gaps gets that EDF times the share of terms it kept (an approximation;
:func:`imunoise.adev` pools the gap-free runs instead).

Stationarity
------------
:attr:`DynamicAllan.stationarity` summarises how far the windows depart:

- for each window and tau, :math:`z` is the standard-normal score of the window's
  variance against the whole-record one under the window's χ² law
  (ν·σ²_w/σ²_whole ~ χ²_ν if the noise is stationary; Wilson–Hilferty's cube root);
- ``outside``: the share of windows × taus where the whole-record ADEV lies outside the
  window's interval (about 1 − confidence for stationary noise, a little less as the
  windows overlap the whole record);
- ``intervals``: where. The record is cut into blocks of one ``step``; at each tau
  with at least 5 terms' worth of samples per block (m ≤ step/10), a block's
  variance is compared with the median block's (robust to the departure itself)
  by the same χ² law, Bonferroni-corrected over blocks, taus and channels at 1 %;
  runs of departing blocks are the intervals, accurate to one step.

References
----------
L. Galleani and P. Tavella, "The dynamic Allan variance", IEEE Trans. UFFC 56(3),
2009, pp. 450–464.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt
from scipy import stats as _stats

from imunoise import display as _display
from imunoise._core import allan as _core_allan
from imunoise._support import schema as _schema
from imunoise._support import stream as _stream
from imunoise._support import summary as _summary
from imunoise._support import warn as _warn
from imunoise._support.runs import true_runs
from imunoise._support.validate import no_infinity, positive_finite, sample_rate, samples
from imunoise.allan import ONE_SIGMA, AllanResult, adev, adev_by_column, chi2_interval
from imunoise.errors import CoverageWarning, ImunoiseTypeError, ImunoiseValueError
from imunoise.taus import averaging_factors

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["Departure", "DynamicAllan", "Stationarity", "dynamic_adev"]

# Samples summed per block of the cumulative sum (see _phase).
_BLOCK = 4096
# Family-wise false-alarm rate of the interval search.
_ALARM = 0.01
#: Most windows :func:`dynamic_adev` computes (the record length over the step):
#: eight arrays of windows x taus x channels are kept, 64 bytes per cell (0.4 GB at
#: the bound with 20 taus and 3 channels).
MAX_WINDOWS = 100_000

# A block takes part in the interval search at taus with m <= step / _BLOCK_TERMS_PER_M.
_BLOCK_TERMS_PER_M = 10


@dataclass(frozen=True)
class Departure:
    """A stretch of the record where the noise departs from its typical level.

    Attributes
    ----------
    start, end : float
        Seconds from the first sample (block edges, one ``step`` apart).
    channel : int
        The channel.
    ratio : float
        Block ADEV / median block ADEV where the departure is clearest (largest |z|
        over the stretch's blocks and the taus searched); > 1 noisier, < 1 quieter.
    ratio_std : float
        Its standard uncertainty, ``ratio / sqrt(2 edf)`` from the block's degrees
        of freedom (what the report rounds the ratio to).
    """

    start: float
    end: float
    channel: int
    ratio: float
    ratio_std: float = float("nan")


@dataclass(frozen=True, repr=False)
class Stationarity:
    """How far the windows depart from the whole-record ADEV (see the module notes).

    Attributes
    ----------
    z : ndarray, (W, T) or (W, T, channels)
        Standard-normal score of each window's variance against the whole record's.
    outside : ndarray, () or (channels,)
        Share of windows × taus whose interval excludes the whole-record ADEV.
    expected_outside : float
        1 − confidence: what ``outside`` is near for stationary noise.
    worst_z, worst_time, worst_tau : ndarray, () or (channels,)
        The largest |z| and the window centre (s) and tau (s) where it is.
    intervals : tuple of Departure
        Stretches where the noise departs, to within one step.
    """

    z: np.ndarray
    outside: np.ndarray
    expected_outside: float
    worst_z: np.ndarray
    worst_time: np.ndarray
    worst_tau: np.ndarray
    intervals: tuple[Departure, ...]

    @property
    def stationary(self) -> bool:
        """True when no interval departs."""
        return not self.intervals

    def __repr__(self) -> str:
        found = ", ".join(
            f"{_summary.number(d.start)}–{_summary.number(d.end)} s ch{d.channel} "
            f"×{_display.rounded(d.ratio, d.ratio_std)}" for d in self.intervals[:3]
        ) or "none"
        more = f" (+{len(self.intervals) - 3})" if len(self.intervals) > 3 else ""
        return _summary.lines("Stationarity(", [
            f"outside {_summary.number(np.max(self.outside))} "
            f"(expected {_summary.number(self.expected_outside)})",
            f"max |z| {_summary.number(np.max(self.worst_z))}",
            f"departures {found}{more}",
        ], sep=", ")

    def _repr_html_(self) -> str:
        """The departures (the first :data:`~imunoise._support.summary.HTML_ROWS`), ratio
        rounded to its uncertainty as in the repr."""
        rows = [[_summary.number(d.start), _summary.number(d.end), d.channel,
                 _display.rounded(d.ratio, d.ratio_std)]
                for d in self.intervals[:_summary.HTML_ROWS]]
        caption = (f"Stationarity: outside {_summary.number(np.max(self.outside))} (expected "
                   f"{_summary.number(self.expected_outside)}), max |z| "
                   f"{_summary.number(np.max(self.worst_z))}, "
                   f"{_summary.plural(len(self.intervals), 'departure')}")
        return _summary.html_table(["start [s]", "end [s]", "channel", "ratio"],
                                   rows or [["—", "—", "—", "none"]], caption=caption)


@dataclass(frozen=True, repr=False)
class DynamicAllan:
    """The overlapping Allan deviation of every window of a sliding window.

    Arrays over windows and taus have shape ``(W, T)`` for 1-D input and
    ``(W, T, channels)`` otherwise; read-only.

    Attributes
    ----------
    times : ndarray, (W,)
        Window centres, seconds from the first sample.
    starts : ndarray of int, (W,)
        First sample of each window.
    taus, m : ndarray, (T,)
        Averaging times (s) and factors.
    dev, var : ndarray
        Deviation and variance of each window, input units.
    n : ndarray of int
        Terms each estimate averages (fewer where gaps leave some out).
    edf, ci_low, ci_high : ndarray
        Equivalent degrees of freedom and the ``confidence`` interval (module notes).
    whole : AllanResult
        :func:`imunoise.adev` of the whole record at the same taus (its ``alpha`` gave
        the EDF).
    window, step : float
        Window length and step, seconds.
    fs : float
        Sample rate, Hz.
    confidence : float
        Two-sided level of the intervals.
    n_samples : int
        Samples of the record.
    """

    times: np.ndarray
    starts: np.ndarray
    taus: np.ndarray
    m: np.ndarray
    dev: np.ndarray
    var: np.ndarray
    n: np.ndarray
    edf: np.ndarray
    ci_low: np.ndarray
    ci_high: np.ndarray
    whole: AllanResult
    window: float
    step: float
    fs: float
    confidence: float
    n_samples: int
    _blocks: tuple = ()

    def __post_init__(self) -> None:
        for name in ("times", "starts", "taus", "m", "dev", "var", "n", "edf", "ci_low",
                     "ci_high"):
            getattr(self, name).flags.writeable = False

    @property
    def channels(self) -> int:
        """Number of channels (1 for 1-D input)."""
        return 1 if self.dev.ndim == 2 else self.dev.shape[2]

    @property
    def ratio(self) -> np.ndarray:
        """Each window's ADEV over the whole-record ADEV at the same tau."""
        whole = self.whole.dev
        return self.dev / (whole[None, :] if self.dev.ndim == 2 else whole[None, :, :])

    @cached_property
    def stationarity(self) -> Stationarity:
        """The stationarity summary (module notes), computed on first use."""
        return _stationarity(self)

    def __len__(self) -> int:
        return len(self.times)

    def _facts(self) -> list[str]:
        return [
            _summary.plural(self.channels, "channel"),
            f"{len(self.times)} windows of {_summary.duration(self.window)} "
            f"every {_summary.duration(self.step)}",
            _summary.tau_span(self.taus),
            f"fs {_summary.number(self.fs)} Hz",
            f"{self.n_samples} samples = {_summary.duration(self.n_samples / self.fs)}",
            f"{100 * self.confidence:.3g} % CI",
        ]

    def __repr__(self) -> str:
        return _summary.lines("DynamicAllan(", self._facts(), sep=", ")

    def _repr_html_(self) -> str:
        """Per channel: the range of the deviation ratio and the largest |z|."""
        ratio = self.ratio.reshape(len(self.times), len(self.taus), -1)
        summary = self.stationarity
        worst = np.atleast_1d(summary.worst_z)
        rows = [
            [name, _summary.number(np.nanmin(ratio[..., j])),
             _summary.number(np.nanmax(ratio[..., j])), _summary.number(worst[j]),
             sum(d.channel == j for d in summary.intervals)]
            for j, name in enumerate(_schema.axis_names(self.channels))
        ]
        return _summary.html_table(
            ["axis", "min ratio", "max ratio", "max |z|", "departures"], rows,
            caption="DynamicAllan: " + ", ".join(self._facts()),
        )

    def plot(self, **kwargs) -> Figure:
        """Heat map of the deviation ratio over time and tau:
        :func:`imunoise.plot.dynamic`."""
        from imunoise import plot

        return plot.dynamic(self, **kwargs)


def dynamic_adev(
    x: npt.ArrayLike,
    fs: float,
    *,
    window: float | None = None,
    step: float | None = None,
    taus="octave",
    confidence: float = ONE_SIGMA,
) -> DynamicAllan:
    """Overlapping Allan deviation of a window sliding along the record.

    Parameters
    ----------
    x : array_like, shape (n,) or (n, channels)
        Rate samples; NaN marks a missing sample (terms touching it are left out).
    fs : float
        Sample rate, Hz.
    window : float, optional
        Window length, seconds (rounded to whole samples). Default a tenth of the
        record.
    step : float, optional
        Seconds between window starts (rounded to whole samples, at least one).
        Default a sixth of the window.
    taus : {"octave", "decade", "all"}, int or array_like, optional
        Tau grid over the window (see :func:`imunoise.taus.averaging_factors`); taus
        with fewer than two terms in a window are dropped.
    confidence : float, optional
        Two-sided level of the intervals, default one sigma.

    Returns
    -------
    DynamicAllan

    Examples
    --------
    >>> import imunoise
    >>> y = imunoise.simulate(72_000, 40.0, N=1e-3, channels=3, seed=2)
    >>> d = imunoise.dynamic_adev(y, 40.0, window=300.0, step=60.0)
    >>> d.dev.shape[0], d.dev.shape[2]
    (26, 3)
    """
    data, one_d = samples(x)
    no_infinity(data)
    _stream.release(data)  # a memory map's pages: read again a column at a time
    fs = sample_rate(fs)
    n = data.shape[0]
    width = n // 10 if window is None else _samples_of("window", window, fs)
    if width < 3 or width > n:
        raise ImunoiseValueError(
            f"window must hold between 3 and {n} samples (the record); got {width} "
            f"({width / fs:g} s at {fs:g} Hz)"
        )
    stride = max(width // 6, 1) if step is None else _samples_of("step", step, fs)
    windows = (n - width) // stride + 1
    if windows > MAX_WINDOWS:
        shortest = -(-(n - width) // (MAX_WINDOWS - 1))
        raise ImunoiseValueError(
            f"step={stride / fs:g} s gives {windows:,} windows; at most {MAX_WINDOWS:,} are "
            f"computed (every window keeps an ADEV per tau and channel): use a step of at "
            f"least {shortest / fs:g} s ({shortest} samples) for this record"
        )
    m = _window_factors(taus, fs, width)
    if _stream.is_mapped(data) and not one_d:  # a column at a time, not the map and its phase
        whole = adev_by_column(lambda j: _stream.column(data, j), data.shape[1], fs,
                               taus=m / fs, confidence=confidence)
    else:
        whole = adev(data[:, 0] if one_d else data, fs, taus=m / fs, confidence=confidence)
    if not np.array_equal(whole.m, m):
        m = np.intersect1d(m, whole.m)
    starts = np.arange(0, n - width + 1, stride, dtype=np.int64)
    sums, counts, blocks = _window_sums(data, m, starts, width, stride)
    with np.errstate(invalid="ignore", divide="ignore"):
        var = sums / (2.0 * (m.astype(float) ** 2)[None, :, None] * counts)
    var = np.where(counts >= 2, var, np.nan)
    alpha = np.broadcast_to(whole.alpha.reshape(len(m), -1), (len(m), data.shape[1]))
    full = (width + 1 - 2 * m).astype(float)
    edf_full = _edf(width + 1, alpha, m)
    edf = np.where(counts >= 2, edf_full[None] * counts / full[None, :, None], np.nan)
    dev = np.sqrt(var)
    low, high = chi2_interval(dev, edf, whole.confidence)
    squeeze = (lambda a: a[..., 0]) if one_d else (lambda a: a)
    return DynamicAllan(
        times=(starts + width / 2) / fs, starts=starts, taus=m / fs, m=m,
        dev=squeeze(dev), var=squeeze(var), n=squeeze(counts.astype(np.int64)),
        edf=squeeze(edf), ci_low=squeeze(low), ci_high=squeeze(high), whole=whole,
        window=width / fs, step=stride / fs, fs=fs, confidence=whole.confidence,
        n_samples=n, _blocks=blocks,
    )


# -- the computation ---------------------------------------------------------------


def _phase(y: np.ndarray, mean: np.ndarray, any_missing: bool
           ) -> tuple[np.ndarray, np.ndarray | None]:
    """Cumulative sum c (channels, n + 1) of the samples ``y`` less ``mean`` (NaN as 0),
    and the running count of missing samples (None when the record has none:
    ``any_missing``). Summed in blocks of :data:`_BLOCK` whose totals are added
    pairwise, so the error grows with the block, not the record."""
    n, ch = y.shape
    pad = (-n) % _BLOCK
    # one array: c = [0, running sums], the sums in place over its blocks
    out = np.zeros((ch, 1 + n + pad))
    blocks = out[:, 1:].reshape(ch, -1, _BLOCK)  # a view: one row per channel
    np.subtract(y.T, mean[:, None], out=out[:, 1:n + 1])
    missing = np.isnan(y) if any_missing else None
    if missing is not None:
        out[:, 1:n + 1][missing.T] = 0.0
    totals = blocks.sum(axis=2)
    np.cumsum(blocks, axis=2, out=blocks)
    blocks += np.concatenate([np.zeros((ch, 1)), np.cumsum(totals, axis=1)[:, :-1]],
                             axis=1)[:, :, None]
    c = out[:, :n + 1]
    if missing is None:
        return c, None
    bad = np.zeros((ch, n + 1), dtype=np.int64)
    np.cumsum(missing.T, axis=1, out=bad[:, 1:])
    return c, bad


def _second_sums_at(c: np.ndarray, bad: np.ndarray | None, mm: int, points: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Prefix sums at ``points`` (0 ≤ p ≤ k) of the squared second differences
    (c[i + 2m] − 2 c[i + m] + c[i])², i < k = len(c) − 2m, of the phase ``c`` (1-D),
    and of their count; with ``bad`` (the running count of missing samples) a
    difference that touches a missing sample is 0 and not counted.

    Segment by segment between the points: the differences of one segment in memory
    (they stay in the cache; those of the whole channel for every τ were read and
    written five times from memory). Each segment's total is its first term plus
    the pairwise sum of the rest, the operations ``np.add.reduceat`` does, so the
    numbers are those of the whole-array computation."""
    k = len(c) - 2 * mm
    cuts = np.unique(np.r_[0, points[points < k]])
    bounds = np.r_[cuts, k]
    seg_sums = np.empty(cuts.size)
    seg_terms = np.empty(cuts.size, dtype=np.int64)
    longest = int(np.max(np.diff(bounds))) if cuts.size else 0
    second, twice = np.empty(longest), np.empty(longest)
    for i, (a, b) in enumerate(zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True)):
        d = np.add(c[a + 2 * mm:b + 2 * mm], c[a:b], out=second[:b - a])
        d -= np.multiply(c[a + mm:b + mm], 2.0, out=twice[:b - a])
        d *= d
        if bad is None:
            seg_terms[i] = b - a
        else:
            ok = (bad[a + 2 * mm:b + 2 * mm] - bad[a:b]) == 0
            d[~ok] = 0.0
            seg_terms[i] = np.count_nonzero(ok)
        seg_sums[i] = d[0] + d[1:].sum()
    sums = np.zeros(cuts.size + 1)
    np.cumsum(seg_sums, out=sums[1:])
    terms = np.zeros(cuts.size + 1, dtype=np.int64)
    np.cumsum(seg_terms, out=terms[1:])
    at = np.searchsorted(bounds, points)
    return sums[at], (points if bad is None else terms[at])


def _window_sums(data, m, starts, width, stride):
    """Sums of the squared second differences and their counts, (W, T, channels), of
    every window; and per tau searched for intervals, the same per block of ``stride``.
    A channel at a time (the phase and the differences of a segment of one channel in
    memory), each centred on its mean over the whole record."""
    n, ch = data.shape
    any_missing = bool(np.isnan(data).any())
    mean = np.nanmean(data, axis=0) if any_missing else data.mean(axis=0)
    _stream.release(data)
    sums = np.empty((len(starts), len(m), ch))
    counts = np.empty((len(starts), len(m), ch))
    block_edges = np.arange(0, n + 1, stride, dtype=np.int64)
    per_tau: dict[int, list[tuple[np.ndarray, np.ndarray]]] = {}
    mapped = _stream.is_mapped(data)
    for j in range(ch):
        # a memory map's column read a block at a time (its pages given back)
        column = _stream.column(data, j)[:, None] if mapped else data[:, j:j + 1]
        c, bad = _phase(column, mean[j:j + 1], any_missing)
        del column
        c, bad = c[0], None if bad is None else bad[0]
        for t, mm in enumerate(int(v) for v in m):
            k = n + 1 - 2 * mm
            last = starts + width + 1 - 2 * mm
            edges = np.minimum(block_edges, k)
            points = np.r_[starts, last, edges]
            prefix, terms = _second_sums_at(c, bad, mm, points)
            w, e = len(starts), len(edges)
            sums[:, t, j] = prefix[w:2 * w] - prefix[:w]
            counts[:, t, j] = terms[w:2 * w] - terms[:w]
            if mm * _BLOCK_TERMS_PER_M <= stride:
                block_p, block_n = prefix[2 * w:2 * w + e], terms[2 * w:2 * w + e]
                per_tau.setdefault(t, []).append((np.diff(block_p)[:, None],
                                                  np.diff(block_n)[:, None]))
        del c, bad
    blocks = tuple((t, np.hstack([p for p, _n in parts]), np.hstack([q for _p, q in parts]))
                   for t, parts in per_tau.items())
    return sums, counts, blocks


def _edf(n_phase: int, alpha: np.ndarray, m: np.ndarray) -> np.ndarray:
    """(T, channels) EDF of a gap-free stretch of ``n_phase`` phase points."""
    a = np.ascontiguousarray(alpha, dtype=np.int32)
    out = np.empty(a.shape)
    for j in range(a.shape[1]):
        out[:, j] = _core_allan.estimator_edf("oadev", n_phase, a[:, j],
                                              m.astype(np.uint64))
    return out


def _stationarity(d: DynamicAllan) -> Stationarity:
    var = d.var.reshape(len(d.times), len(d.taus), -1)
    edf = d.edf.reshape(var.shape)
    whole = np.asarray(d.whole.var).reshape(1, len(d.taus), -1)
    with np.errstate(invalid="ignore", divide="ignore"):
        z = _chi2_score(var / whole, edf)
        low = d.ci_low.reshape(var.shape) ** 2
        high = d.ci_high.reshape(var.shape) ** 2
    valid = np.isfinite(z)
    outside = np.where(valid, (whole < low) | (whole > high), False).sum(axis=(0, 1)) / \
        np.maximum(valid.sum(axis=(0, 1)), 1)
    absz = np.where(valid, np.abs(z), -1.0)
    flat = absz.reshape(-1, absz.shape[2]).argmax(axis=0)
    w_idx, t_idx = np.unravel_index(flat, absz.shape[:2])
    channels = np.arange(absz.shape[2])
    worst = absz[w_idx, t_idx, channels]
    one = (lambda a: np.asarray(a[0])) if d.dev.ndim == 2 else np.asarray
    return Stationarity(
        z=z[..., 0] if d.dev.ndim == 2 else z,
        outside=one(outside), expected_outside=1.0 - d.confidence,
        worst_z=one(worst), worst_time=one(d.times[w_idx]), worst_tau=one(d.taus[t_idx]),
        intervals=_departures(d),
    )


def _departures(d: DynamicAllan) -> tuple[Departure, ...]:
    """Runs of step blocks whose variance departs from the median block's."""
    if not d._blocks:
        return ()
    stride = int(round(d.step * d.fs))
    alpha = np.asarray(d.whole.alpha).reshape(len(d.taus), -1)
    tests = sum(b[1].shape[0] * b[1].shape[1] for b in d._blocks)
    limit = _stats.norm.isf(_ALARM / (2 * max(tests, 1)))
    flagged = None
    ratio = score = dof = None
    for t, sums, counts in d._blocks:
        mm = int(d.m[t])
        with np.errstate(invalid="ignore", divide="ignore"):
            var = np.where(counts >= 2, sums / (2.0 * mm * mm * counts), np.nan)
            typical = np.nanmedian(var, axis=0)
            full = stride + 1 - 2 * mm
            edf = _edf(stride + 1, alpha[t:t + 1], d.m[t:t + 1])[0] * counts / full
            z = np.abs(np.nan_to_num(_chi2_score(var / typical, edf)))
            r = np.sqrt(var / typical)
        if ratio is None:
            flagged, ratio, score, dof = z > limit, r, z, edf
        flagged |= z > limit
        clearer = z > score
        ratio = np.where(clearer, r, ratio)  # the ratio where the departure is clearest
        dof = np.where(clearer, edf, dof)
        score = np.maximum(z, score)
    out = []
    for j in range(flagged.shape[1]):
        for a, b in zip(*true_runs(flagged[:, j]), strict=True):
            k = a + int(np.argmax(score[a:b, j]))
            out.append(Departure(start=a * stride / d.fs, end=min(b * stride, d.n_samples) / d.fs,
                                 channel=j, ratio=float(ratio[k, j]),
                                 ratio_std=float(ratio[k, j] / np.sqrt(2.0 * dof[k, j]))))
    return tuple(sorted(out, key=lambda dep: (dep.start, dep.channel)))


def _chi2_score(ratio, edf):
    """Standard-normal score of ``ratio`` = χ²_ν/ν (positive: above the reference), by
    the Wilson–Hilferty cube-root transform (accurate to ~0.01 for ν ≥ 3, and unlike
    the exact tail it does not saturate at |z| ≈ 38 where the tail underflows)."""
    spread = 2.0 / (9.0 * edf)
    return (np.cbrt(ratio) - (1.0 - spread)) / np.sqrt(spread)


# -- arguments ------------------------------------------------------------------------


def _samples_of(name: str, seconds, fs: float) -> int:
    value = positive_finite(seconds, name, unit="s")
    count = int(round(value * fs))
    if count < 1:
        raise ImunoiseValueError(
            f"{name} must be at least one sample (1/fs = {1 / fs:g} s); got {seconds!r}"
        )
    return count


def _window_factors(taus, fs: float, width: int) -> np.ndarray:
    if isinstance(taus, numbers.Real) and not isinstance(taus, (bool, numbers.Integral)):
        raise ImunoiseTypeError(
            f"taus must be a grid name, points per decade or an array; got {taus!r}")
    m, user_given = averaging_factors(taus, fs, width)
    fits = (m >= 1) & (width + 1 - 2 * m >= 2)
    if user_given and not fits.all():
        _warn.warn(
            f"{int(np.count_nonzero(~fits))} of {m.size} taus dropped: a window of {width} "
            f"samples holds taus from {1 / fs:g} s to {math.floor((width - 1) / 2) / fs:g} s",
            CoverageWarning,
        )
    m = np.unique(m[fits])
    if m.size == 0:
        raise ImunoiseValueError(
            f"no tau fits a window of {width} samples: the largest is "
            f"{math.floor((width - 1) / 2) / fs:g} s"
        )
    return m.astype(np.int64)
