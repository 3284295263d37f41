"""Several logs of one mount on one time grid: the span they share, each log's
samples placed on it, and what each log lost.

The method (docs/mount.md)
--------------------------
1. Every log is on its own uniform grid (:mod:`imunoise.readers.grid`): row r of
   log i is at time t0_i + r/f_i. The **reference** is the first log; the common
   grid is its own grid, so the reference is never resampled, only cut.
2. The rates must agree: f_i differs from f_0 by at most ``tolerance`` (default
   0.1 %, crystals of one nominal rate). A larger difference is refused, not
   resampled: interpolation filters white noise (linear interpolation half-way
   between two samples halves its variance), so it would change the very noise the
   logs are read for.
3. Where each log starts on the reference's clock, t0_i:

   * ``clock="timestamps"``: the logs' timestamps are on one clock (a host clock,
     GPS time, a shared sync line); t0_i is the median of ``time − r/f_i`` over
     the log's timed rows;
   * ``clock="motion"``: each log's clock has its own zero (a VN-100's
     TimeStartup counts from its own power-on); t0_i is the lag that best lines up
     ``channel`` (the mount's motion, in every log) with the reference's: the peak
     of their cross-correlation, refined to a fraction of a sample by a parabola
     through the peak's three points. A peak correlation below
     :data:`MIN_CORRELATION` is refused: there is no shared motion to line up.

4. **Nearest sample**: row r of log i goes to the common row
   k = round((t0_i + r/f_i − t0_0)·f_0). No value is interpolated or invented:
   each log keeps its own samples, noise intact. Two rows of one log in one
   common row (a log a little faster than the reference) keep the nearer one and
   count the other as ``doubled``; a common row no sample of a log reaches (a
   slower log), and the log's own missing samples, are NaN (``missing``): a
   missing sample is left out of every statistic, never spliced over.
5. The common span runs from the latest first row to the earliest last row of
   all logs; rows of a log outside it are counted as ``before`` and ``after``.

The timing error of a sample is at most half a sample period, and ``phase``
says by how much each log's samples sit off the common grid on average. A
motion m(t) leaks into the difference of two logs by about m'(t)·Δt for a
timing difference Δt: sensors sampled on one sync line have none.
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np

from imunoise._support import summary as _summary
from imunoise._support.schema import ALLAN_SENSORS
from imunoise._support.validate import positive_finite
from imunoise.errors import ImunoiseTypeError, ImunoiseValueError
from imunoise.readers.log import ImuLog
from imunoise.readers.read import read

__all__ = ["CLOCKS", "MIN_CORRELATION", "RATE_TOLERANCE", "Aligned", "align"]

#: How the logs' times are related: one clock, or each its own (lined up on the motion).
CLOCKS = ("timestamps", "motion")
#: Largest relative rate difference to the reference log accepted by default.
RATE_TOLERANCE = 1e-3
#: Smallest peak correlation of a channel between two logs that ``clock="motion"``
#: takes as the same motion (below it the peak is as likely the noise's).
MIN_CORRELATION = 0.5


@dataclass(frozen=True, repr=False)
class Aligned:
    """Several logs of one mount on one time grid (:func:`align`).

    Iterates over (and indexes) its logs, all of one length and rate.

    Attributes
    ----------
    logs : tuple of ImuLog
        Each input log on the common grid: every channel it had, NaN in the rows
        it has no sample for; ``time`` the common grid's times (the reference's
        clock: its timestamps, or with ``clock="motion"`` seconds from its grid's
        row 0).
    fs : float
        Rate of the common grid (the reference's), Hz.
    clock : str
        ``"timestamps"`` or ``"motion"`` (see :func:`align`).
    offsets : ndarray of float
        Where each log's row 0 sits on the reference's clock, s from the
        reference's row 0 (0 for the reference).
    phase : ndarray of float
        Mean timing error of each log's samples against the common grid, s
        (at most half a period either way; 0 for the reference).
    correlation : ndarray of float
        With ``clock="motion"``, each log's peak correlation with the reference
        (1 for the reference); NaN with ``clock="timestamps"``.
    before, after : ndarray of int
        Rows of each input log before and after the common span (cut).
    doubled : ndarray of int
        Rows of each log dropped because a nearer row of the same log took their
        common row (a log faster than the reference).
    missing : ndarray of int
        Common rows without a sample of each log: its own missing samples in the
        span and the rows a slower log does not reach.
    """

    logs: tuple[ImuLog, ...]
    fs: float
    clock: str
    offsets: np.ndarray
    phase: np.ndarray
    correlation: np.ndarray
    before: np.ndarray
    after: np.ndarray
    doubled: np.ndarray
    missing: np.ndarray

    def __post_init__(self) -> None:
        for name in ("offsets", "phase", "correlation", "before", "after", "doubled", "missing"):
            getattr(self, name).flags.writeable = False

    def __iter__(self) -> Iterator[ImuLog]:
        return iter(self.logs)

    def __len__(self) -> int:
        return len(self.logs)

    def __getitem__(self, i: int) -> ImuLog:
        return self.logs[i]

    @property
    def n_samples(self) -> int:
        """Rows of the common grid."""
        return len(self.logs[0])

    @property
    def duration(self) -> float:
        """Length of the common span, s."""
        return self.n_samples / self.fs

    @property
    def dropped(self) -> np.ndarray:
        """Rows of each input log not on the common grid (before + after + doubled)."""
        return self.before + self.after + self.doubled

    def rows(self) -> list[list[str]]:
        """One row of text per log: source, offset, phase, correlation and the counts."""
        return [[_summary.source_name(log.source), _summary.number(self.offsets[i]),
                 _summary.number(self.phase[i]), _summary.number(self.correlation[i]),
                 str(self.before[i]), str(self.after[i]), str(self.doubled[i]),
                 str(self.missing[i])]
                for i, log in enumerate(self.logs)]

    #: Header of :meth:`rows`.
    HEADER = ("log", "offset [s]", "phase [s]", "correlation", "before", "after", "doubled",
              "missing")

    def _facts(self) -> list[str]:
        def counts(values) -> str:
            return "/".join(str(int(v)) for v in values)

        return [f"{_summary.plural(len(self), 'log')} at {_summary.number(self.fs)} Hz",
                f"{self.n_samples:,} common samples = {_summary.duration(self.duration)}",
                f"clock {self.clock}",
                f"cut before {counts(self.before)}, after {counts(self.after)}",
                f"doubled {counts(self.doubled)}", f"missing {counts(self.missing)}"]

    def __repr__(self) -> str:
        return _summary.lines("Aligned(", self._facts(), sep=", ")

    def _repr_html_(self) -> str:
        return _summary.html_table(self.HEADER, self.rows(),
                                   caption="Aligned: " + ", ".join(self._facts()))


def align(logs: Sequence[ImuLog | str | os.PathLike], *, clock: str = "timestamps",
          channel: str = "gyro", tolerance: float = RATE_TOLERANCE,
          fs: float | None = None) -> Aligned:
    """Put several logs of one mount on one time grid: the span they share, each
    log's own samples on it (nearest sample, none interpolated), what each lost.

    The first log is the reference: the common grid is its own, cut to the span
    every log covers. Each other log's rows go to the nearest common row; see
    :mod:`imunoise._analysis.align` (docs: "Sensors on one mount") for the method and its
    limits.

    Parameters
    ----------
    logs : sequence of ImuLog or path
        Two or more logs (paths are read with :func:`imunoise.read`), the first
        the reference.
    clock : {"timestamps", "motion"}
        ``"timestamps"`` (default): the logs' timestamps are on one clock (host
        time, GPS time, a shared sync) and place them. ``"motion"``: each log's
        clock has its own zero; the logs are lined up on the motion of the mount
        that ``channel`` sees in all of them (cross-correlation).
    channel : str
        The channel lined up with ``clock="motion"`` (default ``"gyro"``, all its
        axes).
    tolerance : float
        Largest relative difference of a log's rate to the reference's (default
        :data:`RATE_TOLERANCE`, 0.1 %). Larger ones are refused.
    fs : float, optional
        Sample rate for logs read from files without timestamps (as for
        :func:`imunoise.read`).

    Returns
    -------
    Aligned
        The logs on the common grid and, per log, its offset, timing phase and
        the rows it lost (``before``, ``after``, ``doubled``, ``missing``).

    Raises
    ------
    ImunoiseValueError
        Fewer than two logs; rates further apart than ``tolerance``; a log
        without timestamps with ``clock="timestamps"``; no shared motion with
        ``clock="motion"``; logs that do not overlap.
    """
    if isinstance(logs, ImuLog | str | os.PathLike | Aligned):
        raise ImunoiseTypeError(f"logs must be a sequence of logs or paths; got one "
                                f"{type(logs).__name__}")
    logs = [log if isinstance(log, ImuLog) else _read(log, i, fs) for i, log in
            enumerate(logs)]
    if len(logs) < 2:
        raise ImunoiseValueError(f"logs must hold at least 2 logs; got {len(logs)}")
    if clock not in CLOCKS:
        raise ImunoiseValueError(f"clock must be one of {', '.join(CLOCKS)}; got {clock!r}")
    tolerance = positive_finite(tolerance, "tolerance")
    ref = logs[0]
    for i, log in enumerate(logs[1:], start=1):
        rel = abs(log.fs / ref.fs - 1.0)
        if rel > tolerance:
            raise ImunoiseValueError(
                f"logs[{i}]'s rate {log.fs:.9g} Hz differs from logs[0]'s {ref.fs:.9g} Hz by "
                f"{rel:.3g} (relative), more than tolerance={tolerance:g}: nearest-sample "
                f"placement would lose one sample in {1 / rel:.3g}, and interpolation would "
                "filter the noise the logs are read for; record at one rate, or pass a larger "
                "tolerance")
    if clock == "timestamps":
        starts = np.array([_start(log, i) for i, log in enumerate(logs)])
        correlation = np.full(len(logs), np.nan)
    else:
        starts, correlation = _motion_starts(logs, channel)
    offsets = starts - starts[0]
    # each log's rows on the reference's grid, as (fractional) common rows
    positions = [(offsets[i] + np.arange(len(log)) / log.fs) * ref.fs
                 for i, log in enumerate(logs)]
    first = max(int(np.rint(p[0])) for p in positions)
    last = min(int(np.rint(p[-1])) for p in positions)
    if last < first:
        spans = ", ".join(f"logs[{i}] {p[0] / ref.fs:.6g}–{p[-1] / ref.fs:.6g} s"
                          for i, p in enumerate(positions))
        raise ImunoiseValueError(f"logs must overlap in time; on logs[0]'s clock they span "
                                 f"{spans}")
    n = last - first + 1
    placed, stats = [], []
    for log, pos in zip(logs, positions, strict=True):
        aligned_log, counts = _place(log, pos, first, n, ref)
        placed.append(aligned_log)
        stats.append(counts)
    before, after, doubled, missing, phase = (np.array(v) for v in zip(*stats, strict=True))
    return Aligned(logs=tuple(placed), fs=ref.fs, clock=clock,
                   offsets=offsets.astype(float), phase=phase.astype(float) / ref.fs,
                   correlation=correlation, before=before.astype(np.int64),
                   after=after.astype(np.int64), doubled=doubled.astype(np.int64),
                   missing=missing.astype(np.int64))


def _read(source, i: int, fs: float | None) -> ImuLog:
    if not isinstance(source, str | os.PathLike):
        raise ImunoiseTypeError(f"logs[{i}] must be an ImuLog or a path; got "
                                f"{type(source).__name__}")
    return read(source, fs=fs)


def _start(log: ImuLog, i: int) -> float:
    """Time of the log's grid row 0 on its timestamps' clock: the median of
    ``time − row/fs`` over the timed rows (robust to jitter and outliers)."""
    t = log.time
    if t is None or not np.isfinite(t).any():
        raise ImunoiseValueError(f"logs[{i}] ({_summary.source_name(log.source)}) has no "
                                 "timestamps: clock='timestamps' needs them (pass "
                                 "clock='motion' to line the logs up on the mount's motion)")
    rows = np.flatnonzero(np.isfinite(t))
    return float(np.median(t[rows] - rows / log.fs))


def _channel(log: ImuLog, i: int, channel: str) -> np.ndarray:
    """The log's ``channel`` as (n, k), its mean removed, missing samples 0."""
    y = getattr(log, channel, None) if channel in ImuLog.__dataclass_fields__ else None
    if y is None:
        raise ImunoiseValueError(f"logs[{i}] has no {channel!r} channel to line up with "
                                 f"clock='motion'; it has {', '.join(log.channels) or 'none'}")
    y = np.asarray(y, dtype=np.float64).reshape(len(log), -1)
    y = y - np.nanmean(y, axis=0)
    return np.nan_to_num(y, nan=0.0)


def _motion_starts(logs: Sequence[ImuLog], channel: str) -> tuple[np.ndarray, np.ndarray]:
    """Each log's row 0 on the reference's clock (s from its row 0) from the peak of
    the cross-correlation of ``channel``, and that peak's correlation coefficient."""
    from scipy import signal

    if channel not in ImuLog.__dataclass_fields__ or channel == "time":
        raise ImunoiseValueError(f"channel must be a channel of the logs (e.g. "
                                 f"{', '.join(ALLAN_SENSORS)}); got {channel!r}")
    ref = _channel(logs[0], 0, channel)
    fs = logs[0].fs
    starts, peaks = [0.0], [1.0]
    for i, log in enumerate(logs[1:], start=1):
        y = _channel(log, i, channel)
        if y.shape[1] != ref.shape[1]:
            raise ImunoiseValueError(f"logs[{i}]'s {channel} must have the {ref.shape[1]} "
                                     f"column(s) of logs[0]'s; got {y.shape[1]}")
        # c[L] = sum_r ref[r] · y[r − L]: the log's row r is the reference's row r + L
        c = sum(signal.correlate(ref[:, j], y[:, j], mode="full", method="fft")
                for j in range(ref.shape[1]))
        lags = signal.correlation_lags(len(ref), len(y), mode="full")
        k = int(np.argmax(c))
        peak = _overlap_correlation(ref, y, int(lags[k]))
        if peak < MIN_CORRELATION:
            raise ImunoiseValueError(
                f"logs[{i}]'s {channel} does not follow logs[0]'s (peak correlation "
                f"{peak:.3g}, below {MIN_CORRELATION}): clock='motion' needs a motion of the "
                "mount far above the sensors' noise; with timestamps on one clock pass "
                "clock='timestamps'")
        shift = 0.0
        if 0 < k < len(c) - 1:  # a parabola through the peak and its neighbours
            lo, mid, hi = c[k - 1], c[k], c[k + 1]
            curvature = lo - 2.0 * mid + hi
            if curvature < 0:
                shift = float(np.clip(0.5 * (lo - hi) / curvature, -0.5, 0.5))
        starts.append((lags[k] + shift) / fs)
        peaks.append(peak)
    return np.array(starts), np.array(peaks)


def _overlap_correlation(ref: np.ndarray, y: np.ndarray, lag: int) -> float:
    """Correlation coefficient of ``ref`` and ``y`` over the rows they share when
    ``y``'s row r is ``ref``'s row r + ``lag`` (0 without shared rows or signal)."""
    lo, hi = max(0, lag), min(len(ref), len(y) + lag)
    if hi <= lo:
        return 0.0
    a, b = ref[lo:hi], y[lo - lag:hi - lag]
    norm = float(np.sqrt(np.sum(a * a) * np.sum(b * b)))
    return float(np.sum(a * b) / norm) if norm > 0 else 0.0


def _place(log: ImuLog, pos: np.ndarray, first: int, n: int, ref: ImuLog):
    """The log on the common rows ``first … first + n − 1``, each of its rows at the
    nearest one (``pos``: its rows as fractional common rows); the counts it lost
    and its mean phase in rows."""
    slot = np.rint(pos).astype(np.int64)
    before = int(np.count_nonzero(slot < first))
    after = int(np.count_nonzero(slot > first + n - 1))
    inside = np.flatnonzero((slot >= first) & (slot <= first + n - 1))
    error = pos[inside] - slot[inside]
    # nearest first, so that of two rows in one slot the nearer is the one kept
    order = inside[np.argsort(np.abs(error), kind="stable")]
    _, keep = np.unique(slot[order] - first, return_index=True)
    chosen = order[keep]
    doubled = inside.size - chosen.size
    rows = slot[chosen] - first
    phase = float(np.mean(pos[chosen] - slot[chosen])) if chosen.size else 0.0
    channels = {}
    for name in log.channels:
        values = np.asarray(getattr(log, name), dtype=np.float64)
        out = np.full((n, *values.shape[1:]), np.nan)
        out[rows] = values[chosen]
        channels[name] = out
    present = np.zeros(n, dtype=bool)
    present[rows] = log.valid[chosen]
    time = _grid_time(ref, first, n)
    aligned = ImuLog(fs=ref.fs, source=log.source, format=log.format, issues=log.issues,
                     time=time, messages=log.messages, **channels)
    return aligned, (before, after, doubled, int(n - np.count_nonzero(present)), phase)


def _grid_time(ref: ImuLog, first: int, n: int) -> np.ndarray:
    """Times of the common rows on the reference's clock: its timestamps' line
    where it has them, else seconds from its row 0."""
    t0 = 0.0
    if ref.time is not None and np.isfinite(ref.time).any():
        rows = np.flatnonzero(np.isfinite(ref.time))
        t0 = float(np.median(ref.time[rows] - rows / ref.fs))
    return t0 + (first + np.arange(n)) / ref.fs
