"""The time grid of a log: nominal rate, where every sample sits, and every dropout.

Every reader goes through this module, so that all formats agree on what a gap is.

From timestamps (:meth:`TimeGrid.from_timestamps`)
    1. ``dt0`` = median of the positive timestamp steps (robust to jitter and to a
       minority of dropouts). When every step rounds to one ``dt0`` nothing is
       missing or out of order: one row per sample, ``dt`` the mean step (the
       median when both agree to :data:`SAME_STEP`), and the steps below are
       skipped. Otherwise ``dt0`` becomes the mean of the steps that round to one
       ``dt0`` (within a run of such steps the jitter cancels but at its ends),
       then the step within ±4 % of it at which all stamps line up best (phase
       coherence, :func:`_coherent_step`): a 1 % error would round a long gap wrong.
    2. Provisional slots: the cumulative sum of ``round(step / dt0)``, which follows
       bursts (a late sample followed by early ones) without drifting.
    3. The nominal step ``dt`` and origin are the least-squares line through
       (slot, time), refitted :data:`REFITS` times through the slots of the line
       before: this absorbs a rate error of ``dt0`` (coarse clock resolution), a
       linear drift between the stamping clock and the sensor's, and the slips of
       step 2 under heavy jitter.
    4. When a sample sits more than :data:`PHASE_TRIGGER` steps off that line, the
       phase of the samples against it is tracked in blocks of :data:`PHASE_BLOCK`
       samples (:func:`_phase`) and the line refitted: a host clock that wanders
       against the sensor's by more than the jitter allows does not slip a slot.
    5. Every sample goes to slot ``round((t - t0) / dt - phase)``. A step longer
       than 1.5 nominal steps is a gap (one missing sample per further nominal
       step); jitter of the single samples up to about ±0.4 steps around the
       tracked phase is not (the tests: uniform ±0.2 steps, 1 ms clock ticks,
       ±200 ppm rate errors, random dropouts; real bags with ±30 %).
    6. Two samples with different timestamps in one slot (heavy jitter: a late
       sample and an early one) are separated when the slot beside the one further
       from its centre, on its side, is free. A sample whose slot is still taken
       (an exact duplicate timestamp, or a third sample) is dropped and counted as
       ``duplicate_time``; a timestamp smaller than its predecessor's is counted
       as ``time_reversed`` and the sample placed at its slot. Nothing is sorted
       silently: both counts are in :class:`~imunoise.readers.log.ParseIssues`.

From damaged-record positions (:meth:`TimeGrid.from_missing`)
    A log without timestamps (plain ``$VNYMR`` at a set rate) has one record per
    sample; every damaged record of the main message stream stands for one missing
    sample at its place in the sequence. Damaged records before the first or after
    the last good record are not gaps (a capture that starts or ends mid-sentence).

The grid spans the first to the last sample: missing samples at either end cannot
be seen and are not reported.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from imunoise._support import summary as _summary
from imunoise._support.runs import true_runs
from imunoise.errors import ImunoiseValueError

__all__ = ["MAX_GRID_RATIO", "Gaps", "TimeGrid", "outlier_stamps"]

#: Timestamps that would make a grid this many times longer than the samples
#: (over 99 % missing) are not taken as a sample clock; damaged records that would
#: fill a grid this many times longer than the good ones are an error
#: (:meth:`TimeGrid.from_missing`): a reader never allocates more missing rows.
MAX_GRID_RATIO = 100
#: A timestamp this many nominal steps away from the line of its neighbours (that
#: they do not follow) is an outlier: counted as ``time_outlier``, its sample kept
#: at the place its neighbours give it (bunched host stamps stay well inside).
OUTLIER_STEPS = 10
#: Samples on each side of a sample whose median residual places it.
OUTLIER_WINDOW = 5
#: A step back by more than this many nominal steps (after outliers) is a reset of
#: the clock (a device restart): the log is split there into segments kept in
#: file order, each on its own grid, counted as ``time_reset``.
RESET_STEPS = 10
#: Locations kept per kind of timestamp problem in ``TimeGrid.first`` (the parse
#: issues' ``first``).
FIRST_KEPT = 5
#: Refits of the clock line through its own slots.
REFITS = 2
#: Samples per block of the phase tracker (:func:`_phase`).
PHASE_BLOCK = 64
#: Largest distance (steps) of a sample from its slot on the fitted line that
#: needs no phase tracking (a sensor's own clock stays far below it).
PHASE_TRIGGER = 0.25
#: Relative difference below which the fitted step is taken to be the median step.
SAME_STEP = 1e-6


def _repeats(slot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Samples whose slot an earlier one (in file order) took, and that one."""
    order = np.argsort(slot, kind="stable")
    s_sorted = slot[order]
    repeat = np.zeros(len(slot), dtype=bool)
    same = s_sorted[1:] == s_sorted[:-1]
    repeat[order[1:]] = same
    rep = np.flatnonzero(repeat)
    occupant = order[np.searchsorted(s_sorted, slot[rep])]
    return rep, occupant


def _settle(slot: np.ndarray, pos: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Resolve two samples in one slot (in place) by moving the one further from
    the slot's centre to the free neighbour on its side, when their timestamps
    differ (heavy jitter: one sample late, the next on time). Returns the mask of
    the samples left without a slot (duplicates)."""
    rep, occ = _repeats(slot)
    if len(rep):
        first = np.abs(pos[rep] - slot[rep]) >= np.abs(pos[occ] - slot[occ])
        mover = np.where(first, rep, occ)
        alt = np.where(pos[mover] < slot[mover], slot[mover] - 1, slot[mover] + 1)
        free = (t[rep] != t[occ]) & ~np.isin(alt, slot)
        alt, mover = alt[free], mover[free]
        _, once = np.unique(alt, return_index=True)
        slot[mover[once]] = alt[once]
        rep, occ = _repeats(slot)
    repeat = np.zeros(len(slot), dtype=bool)
    repeat[rep] = True
    return repeat


def _phase(pos: np.ndarray) -> np.ndarray:
    """The slow drift of the samples' phase against the grid, in steps, per sample.

    The circular mean of ``pos - round(pos)`` over blocks of :data:`PHASE_BLOCK`
    samples, unwrapped from block to block and interpolated: gaps (whole steps)
    leave it alone, jitter averages out, and a stamping clock that drifts against
    the sensor's (non-linearly, as a host clock under NTP does) is followed."""
    n = len(pos)
    angle = 2 * np.pi * (pos - np.rint(pos))
    starts = np.arange(0, n, PHASE_BLOCK)
    c = np.add.reduceat(np.cos(angle), starts)
    s = np.add.reduceat(np.sin(angle), starts)
    phase = np.unwrap(np.arctan2(s, c)) / (2 * np.pi)
    ends = np.append(starts[1:], n)
    return np.interp(np.arange(n), (starts + ends - 1) / 2, phase)


def _coherent_step(t: np.ndarray, dt0: float) -> float:
    """The step within ±4 % of ``dt0`` at which the timestamps line up best.

    Maximises the phase coherence |Σ exp(2πi·t/dt)| (at most 4096 stamps, spread
    over the record). Under heavy jitter the mean of the single steps can be off
    by a percent or two, enough for a 30-step gap to round to 29; the coherence
    of all stamps fixes the step to a fraction of a step over the whole span."""
    tc = t - t[0]
    if len(tc) > 4096:
        tc = tc[np.linspace(0, len(tc) - 1, 4096).astype(np.int64)]
    cands = dt0 * (1.0 + np.linspace(-0.04, 0.04, 801))
    power = np.abs(np.exp(2j * np.pi * np.outer(1.0 / cands, tc)).sum(axis=1))
    return float(cands[int(np.argmax(power))])


def _line(slot: np.ndarray, t: np.ndarray, dt0: float) -> tuple[float, float]:
    """Least-squares ``t = a + dt * slot`` (centred); ``dt0`` (the median step)
    when the fit is off by more than a factor 2 or agrees with it to
    :data:`SAME_STEP`."""
    sc, tc = slot - slot.mean(), t - t.mean()
    denom = float(sc @ sc)
    dt = float(sc @ tc) / denom if denom > 0 else dt0
    if not (0.5 * dt0 < dt < 2.0 * dt0) or abs(dt - dt0) <= SAME_STEP * dt0:
        dt = dt0
    return float(t.mean() - dt * slot.mean()), dt


@dataclass(frozen=True, repr=False)
class Gaps:
    """The dropouts of a log, one row per run of consecutive missing samples.

    Attributes
    ----------
    index : numpy.ndarray of int64
        Grid row of the first missing sample of each gap.
    samples : numpy.ndarray of int64
        Missing samples in each gap.
    fs : float
        Sample rate in Hz.
    t0 : float
        Time of grid row 0 in seconds (0 when the log has no timestamps).

    Notes
    -----
    ``start`` is the nominal time of the first missing sample, ``duration`` the
    time the missing samples would have covered (``samples / fs``) and ``end`` =
    ``start + duration`` the nominal time of the next sample that is there.
    """

    index: np.ndarray
    samples: np.ndarray
    fs: float
    t0: float = 0.0

    def __post_init__(self) -> None:
        for name in ("index", "samples"):
            arr = np.asarray(getattr(self, name), dtype=np.int64).reshape(-1)
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)
        if len(self.index) != len(self.samples):
            raise ImunoiseValueError(
                f"index and samples must have equal lengths; got {len(self.index)} "
                f"and {len(self.samples)}"
            )

    @classmethod
    def none(cls, fs: float, t0: float = 0.0) -> Gaps:
        return cls(np.zeros(0, np.int64), np.zeros(0, np.int64), fs, t0)

    @classmethod
    def from_valid(cls, valid: np.ndarray, fs: float, t0: float = 0.0) -> Gaps:
        """Runs of ``False`` in the boolean row mask ``valid``."""
        missing = ~np.asarray(valid, dtype=bool)
        if not missing.any():
            return cls.none(fs, t0)
        starts, ends = true_runs(missing)
        return cls(starts, ends - starts, fs, t0)

    @property
    def start(self) -> np.ndarray:
        """Nominal time (s) of the first missing sample of each gap."""
        return self.t0 + self.index / self.fs

    @property
    def duration(self) -> np.ndarray:
        """Seconds each gap covers (``samples / fs``)."""
        return self.samples / self.fs

    @property
    def end(self) -> np.ndarray:
        """Nominal time (s) of the first sample after each gap."""
        return self.start + self.duration

    @property
    def total(self) -> int:
        """Missing samples over all gaps."""
        return int(self.samples.sum())

    def largest(self, k: int = 5) -> Gaps:
        """The ``k`` longest gaps, longest first."""
        order = np.argsort(-self.samples, kind="stable")[:k]
        return Gaps(self.index[order], self.samples[order], self.fs, self.t0)

    def valid(self, n: int) -> np.ndarray:
        """Boolean mask of the ``n`` grid rows: ``True`` where the sample is there."""
        mask = np.ones(n, dtype=bool)
        for i, s in zip(self.index, self.samples, strict=True):
            mask[i : i + s] = False
        return mask

    def __len__(self) -> int:
        return len(self.index)

    def rows(self) -> list[tuple[float, float, int]]:
        """``(start_s, duration_s, samples)`` per gap, for tables and JSON."""
        return [
            (float(a), float(d), int(s))
            for a, d, s in zip(self.start, self.duration, self.samples, strict=True)
        ]

    def __str__(self) -> str:
        if not len(self):
            return "no gaps"
        rows = [f"{a:.3f} s +{d:.3f} s ({s} samples)" for a, d, s in self.rows()]
        return f"{len(self)} gap(s): " + "; ".join(rows)

    def _facts(self) -> str:
        """``"2 gaps, 43 samples = 1.08 s missing at 40 Hz; longest 40 samples at 12.3 s"``."""
        if not len(self):
            return f"no gaps at {_summary.number(self.fs)} Hz"
        (start, _length, k), = self.largest(1).rows()
        at = start - self.t0
        return (f"{_summary.plural(len(self), 'gap')}, {self.total} samples = "
                f"{_summary.duration(self.total / self.fs)} missing at "
                f"{_summary.number(self.fs)} Hz; longest {k} samples at "
                f"{'' if self.t0 == 0 else 't0 + '}{_summary.number(at)} s")

    def __repr__(self) -> str:
        return f"Gaps({self._facts()})"

    def _repr_html_(self) -> str:
        shown = self.largest(_summary.HTML_ROWS)
        caption = f"Gaps: {self._facts()}"
        if len(shown) < len(self):
            caption += f" (the {len(shown)} longest shown)"
        return _summary.html_table(
            ["start [s from row 0]", "duration [s]", "samples"],
            [[_summary.number(a - self.t0), _summary.number(d), k] for a, d, k in shown.rows()],
            caption=caption,
        )


def outlier_stamps(t: np.ndarray, steps: np.ndarray, dt0: float) -> tuple[np.ndarray, np.ndarray]:
    """Timestamps one bad value made: indices and the times their neighbours give them.

    The residual ``r = t - i * dt0`` of a clock with gaps only grows (a step per
    gap), so in a window centred on a sample its median is the sample's own
    residual; a sample :data:`OUTLIER_STEPS` steps away from that median, with
    neighbours that do not follow it, is an outlier (a corrupt value, one bad
    stamp). Only samples beside a step that is not one nominal step are looked
    at. The first and last sample (no window around them) are outliers only when
    their step to the neighbour is absurd (more than :data:`MAX_GRID_RATIO` times
    the samples in steps, or backwards by more than :data:`OUTLIER_STEPS`).
    """
    n = len(t)
    with np.errstate(over="ignore", invalid="ignore"):  # an absurd stamp overflows
        odd = np.flatnonzero(np.rint(steps / dt0) != 1)
    cand = np.unique(np.concatenate([odd, odd + 1]))
    if not len(cand):
        return np.zeros(0, np.int64), np.zeros(0)
    r = t - np.arange(n) * dt0
    k = np.minimum(np.minimum(cand, n - 1 - cand), OUTLIER_WINDOW)
    offsets = np.arange(-OUTLIER_WINDOW, OUTLIER_WINDOW + 1)
    idx = np.clip(cand[:, None] + offsets, 0, n - 1)
    window = np.where(np.abs(offsets) <= k[:, None], r[idx], np.nan)
    with np.errstate(invalid="ignore"):
        med = np.nanmedian(window, axis=1)
    bad = (k > 0) & (np.abs(r[cand] - med) > OUTLIER_STEPS * dt0)
    for end, nb in ((0, 1), (n - 1, n - 2)):  # the ends: only absurd steps
        if n > 2 and end in cand:
            step = (t[nb] - t[end]) * (1 if end == 0 else -1)
            if step > MAX_GRID_RATIO * n * dt0 or step < -OUTLIER_STEPS * dt0:
                j = int(np.searchsorted(cand, end))
                bad[j] = True
                med[j] = r[nb]  # on its neighbour's line, one step away
    out = cand[bad]
    return out, med[bad] + out * dt0


@dataclass(frozen=True)
class TimeGrid:
    """Where each sample of a log sits on a uniform grid.

    Attributes
    ----------
    slot : numpy.ndarray of int64
        Grid row of every input sample, ``-1`` for samples dropped as duplicates.
    n : int
        Grid rows (first to last sample, missing ones included).
    fs : float or None
        Nominal rate in Hz from the timestamps; ``None`` when the grid was built
        without them (the reader then uses its ``fs``).
    t0 : float
        Time of row 0 on the timestamps' clock (0 without timestamps).
    duplicate_time, time_reversed : int
        Samples dropped because their slot was taken; timestamps smaller than
        the one before.
    time_outlier : int
        Timestamps that did not fit their neighbours (:data:`OUTLIER_STEPS`):
        their samples are kept, placed (and timed) by their neighbours.
    time_reset : int
        Places where the clock restarted (:data:`RESET_STEPS`): the log is the
        segments between them, in file order, each on its own grid.
    first : Mapping[str, tuple[int, ...]]
        For each of those kinds, the 1-based numbers (in input order) of the
        first samples concerned (for ``time_reset``: the first sample of each new
        segment).
    fixed : tuple of (indices, times) or None
        The outliers and the times their neighbours give them.
    """

    slot: np.ndarray
    n: int
    fs: float | None = None
    t0: float = 0.0
    duplicate_time: int = 0
    time_reversed: int = 0
    time_outlier: int = 0
    time_reset: int = 0
    first: Mapping[str, tuple[int, ...]] = field(default_factory=dict)
    fixed: tuple[np.ndarray, np.ndarray] | None = None

    @classmethod
    def identity(cls, n: int) -> TimeGrid:
        return cls(np.arange(n, dtype=np.int64), n)

    @classmethod
    def from_timestamps(cls, time) -> TimeGrid:
        """The grid of timestamps ``time`` (seconds, or any unit: ``fs`` is per unit).

        Timestamps with no finite step give the identity grid without a rate;
        timestamps that only go back, the identity grid at the rate of their steps
        with every step counted as ``time_reversed``; one positive step, or only
        two samples, the identity grid at that rate. Outlier timestamps are put
        back on their neighbours' line and resets split the log into segments
        (see the attributes) before the steps below.

        Raises
        ------
        ValueError
            When the grid would be more than :data:`MAX_GRID_RATIO` times longer
            than the samples.
        """
        t = np.asarray(time, dtype=np.float64).reshape(-1)
        n = len(t)
        steps = np.diff(t)
        pos = steps[steps > 0]
        if not np.isfinite(t).all():
            return cls.identity(n)
        if not len(pos):
            back = np.flatnonzero(steps < 0)
            if not len(back):
                return cls.identity(n)
            return cls(np.arange(n, dtype=np.int64), n, fs=1.0 / float(np.median(-steps[back])),
                       t0=float(t[0]), time_reversed=len(back),
                       first={"time_reversed": tuple(int(i) + 2 for i in back[:FIRST_KEPT])})
        if n < 3 or len(pos) < 2:  # too short to find gaps; the rate of what is there
            return cls(np.arange(n, dtype=np.int64), n, fs=1.0 / float(np.median(pos)))
        dt0 = float(np.median(pos))
        out, out_t = outlier_stamps(t, steps, dt0)
        if len(out):
            t = t.copy()
            t[out] = out_t
            steps = np.diff(t)
        resets = np.flatnonzero(steps < -RESET_STEPS * dt0)
        if len(resets) and len(resets) <= n // 20:
            grid = cls._segments(t, resets + 1)
        else:
            grid = cls._one_clock(t, steps, dt0)
        if not len(out):
            return grid
        first = {**grid.first, "time_outlier": tuple(int(i) + 1 for i in out[:FIRST_KEPT])}
        return replace(grid, time_outlier=len(out), first=first, fixed=(out, out_t))

    @classmethod
    def _segments(cls, t: np.ndarray, starts: np.ndarray) -> TimeGrid:
        """The grid of a clock that restarted before each sample of ``starts``: one
        grid per segment, one after the other in file order (no rows between them:
        the time between segments is not known); the rate of the longest."""
        bounds = [0, *starts.tolist(), len(t)]
        grids = [cls.from_timestamps(t[a:b]) for a, b in zip(bounds[:-1], bounds[1:], strict=True)]
        slots, offset = [], 0
        first: dict[str, list[int]] = {"time_reset": [int(i) + 1 for i in starts[:FIRST_KEPT]]}
        for a, g in zip(bounds, grids, strict=False):
            slots.append(np.where(g.slot >= 0, g.slot + offset, -1))
            offset += g.n
            for kind, where in g.first.items():
                first.setdefault(kind, []).extend(int(w) + a for w in where)
        longest = max(range(len(grids)), key=lambda k: bounds[k + 1] - bounds[k])
        return cls(
            slot=np.concatenate(slots), n=offset, fs=grids[longest].fs, t0=grids[0].t0,
            duplicate_time=sum(g.duplicate_time for g in grids),
            time_reversed=sum(g.time_reversed for g in grids),
            time_outlier=sum(g.time_outlier for g in grids),
            time_reset=len(starts) + sum(g.time_reset for g in grids),
            first={k: tuple(sorted(v)[:FIRST_KEPT]) for k, v in first.items()},
        )

    @classmethod
    def _one_clock(cls, t: np.ndarray, steps: np.ndarray, dt0: float) -> TimeGrid:
        """The grid of timestamps of one clock (no reset), ``dt0`` their median step."""
        n = len(t)
        median = dt0
        single = np.rint(steps / dt0) == 1
        if single.all():  # the common case: nothing missing, nothing out of order
            span = float(t[-1] - t[0]) / (n - 1)
            dt = median if abs(span - median) <= SAME_STEP * median else span
            return cls(np.arange(n, dtype=np.int64), n, fs=1.0 / dt, t0=float(t[0]))
        if single.sum() >= 2:  # the mean single step: jitter only at the ends of runs
            dt0 = float(steps[single].mean())
        dt0 = _coherent_step(t, dt0)
        prov = np.concatenate(([0.0], np.cumsum(np.rint(steps / dt0))))
        a, dt = _line(prov, t, median)
        for _ in range(REFITS):  # the slots of the line, and the line through them
            a, dt = _line(np.rint((t - a) / dt), t, median)
        pos_slot = (t - a) / dt
        if np.abs(pos_slot - np.rint(pos_slot)).max() > PHASE_TRIGGER:
            # a wandering (host) clock or heavy jitter: follow the phase, refit
            a, dt = _line(np.rint(pos_slot - _phase(pos_slot)), t, median)
            pos_slot = (t - a) / dt
            pos_slot -= _phase(pos_slot)
        span = float(pos_slot.max() - pos_slot.min())
        if span > MAX_GRID_RATIO * n:
            raise ImunoiseValueError(
                f"time: the timestamps span {span:.4g} nominal steps of {dt:.4g} for {n} "
                f"samples (more than {MAX_GRID_RATIO}x); they are not a sample clock"
            )
        slot = np.rint(pos_slot).astype(np.int64)
        repeat = _settle(slot, pos_slot, t)
        duplicates = int(repeat.sum())
        lo = int(slot[~repeat].min())
        slot -= lo
        t0 = a + lo * dt
        slot[repeat] = -1
        back = np.flatnonzero(steps < 0)
        return cls(
            slot=slot,
            n=int(slot.max()) + 1,
            fs=1.0 / dt,
            t0=t0,
            duplicate_time=duplicates,
            time_reversed=len(back),
            first={"duplicate_time": tuple(int(i) + 1 for i in np.flatnonzero(repeat)[:FIRST_KEPT]),
                   "time_reversed": tuple(int(i) + 2 for i in back[:FIRST_KEPT])},
        )

    @classmethod
    def from_missing(cls, n_records: int, positions) -> TimeGrid:
        """The grid of ``n_records`` good records with one missing sample before
        record ``p`` for every ``p`` in ``positions`` (repeats allowed; positions
        0 and ``n_records``, before the first and after the last record, ignored).

        Raises ``ValueError`` when the grid would be more than
        :data:`MAX_GRID_RATIO` times longer than the good records."""
        p = np.asarray(positions, dtype=np.int64).reshape(-1)
        p = p[(p > 0) & (p < n_records)]
        if n_records + len(p) > MAX_GRID_RATIO * n_records:
            raise ImunoiseValueError(
                f"{len(p)} damaged records among {n_records} good ones would be "
                f"{len(p)} missing rows, more than {MAX_GRID_RATIO}x the samples: the log "
                f"is not a sample sequence (a damaged or crafted file)"
            )
        slot = np.arange(n_records, dtype=np.int64)
        if len(p):
            # Skipped when nothing is missing: a serial pass over every record.
            slot += np.searchsorted(np.sort(p), slot, side="right")
        return cls(slot=slot, n=n_records + len(p))

    @property
    def kept(self) -> np.ndarray:
        """Indices of the input samples that are on the grid."""
        return np.flatnonzero(self.slot >= 0)

    @property
    def valid(self) -> np.ndarray:
        """Boolean mask of the grid rows that hold a sample."""
        if self.is_identity:
            return np.ones(self.n, dtype=bool)
        mask = np.zeros(self.n, dtype=bool)
        mask[self.slot[self.slot >= 0]] = True
        return mask

    @cached_property
    def is_identity(self) -> bool:
        """Every input sample in its own row, in order, nothing missing (asked once
        per channel: computed once, a pass over every sample)."""
        s = self.slot
        if self.n != len(s) or not len(s):
            return self.n == len(s)
        # n increasing integers from 0 to n - 1 are 0, 1, ..., n - 1: no index
        # array to allocate and compare against.
        return bool(s[0] == 0 and s[-1] == self.n - 1 and np.all(s[1:] > s[:-1]))

    def gaps(self, fs: float) -> Gaps:
        """The missing rows as a :class:`Gaps` table (``fs`` from the reader)."""
        return Gaps.from_valid(self.valid, fs, self.t0)

    def place(self, values: np.ndarray | None) -> np.ndarray | None:
        """Per-sample ``values`` (n, ...) on the grid, NaN in missing rows.

        The input itself is returned when the grid is the identity (no copy)."""
        if values is None or self.is_identity:
            return values
        values = np.asarray(values, dtype=np.float64)
        out = np.full((self.n, *values.shape[1:]), np.nan)
        keep = self.slot >= 0
        out[self.slot[keep]] = values[keep]
        return out

    def place_time(self, time: np.ndarray | None, before: float | None = None) -> np.ndarray | None:
        """Timestamps on the grid: measured where a sample is; in a missing row,
        interpolated between the samples on either side (a gap never ends the grid).

        ``before`` is the time of the row just before row 0 (a piece of a stream);
        without it, row 0 holds a sample."""
        if time is not None and self.fixed is not None:
            time = np.array(time, dtype=np.float64)
            time[self.fixed[0]] = self.fixed[1]
        if time is None or self.is_identity:
            return time
        keep = self.slot >= 0
        rows = np.arange(self.n)
        have = np.zeros(self.n, dtype=bool)
        have[self.slot[keep]] = True
        out = np.full(self.n, np.nan)
        out[self.slot[keep]] = np.asarray(time, dtype=np.float64)[keep]
        gap = np.flatnonzero(~have)
        prev = np.maximum.accumulate(np.where(have, rows, -1))[gap]
        nxt = np.flatnonzero(have)[np.searchsorted(np.flatnonzero(have), gap)]
        t_prev = np.where(prev >= 0, out[np.maximum(prev, 0)], np.nan if before is None else before)
        out[gap] = t_prev + (out[nxt] - t_prev) * (gap - prev) / (nxt - prev)
        return out
