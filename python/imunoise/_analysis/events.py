r"""Events in a still recording: spikes (single outliers) and bursts (vibration, shocks).

A still log is meant to hold sensor noise only; a door slam, a footstep or a
glitch adds samples that inflate the standard deviation, bend the histogram and
add power at short averaging times. :func:`events` finds them per channel and
merges them across channels.

Detector
--------
Per channel, after removing a robust baseline (medians of ``baseline``-second
blocks, interpolated linearly, so slow bias drift is not an event):

1. **Spikes** (Hampel test): :math:`|z_i| > k` with :math:`z_i = r_i/\hat\sigma`,
   :math:`\hat\sigma = 1.4826\,\mathrm{MAD}(r)` (consistent for Gaussian noise
   and unmoved by the events themselves), :math:`k = \Phi^{-1}(1 - p/4)`.
2. **Bursts** (windowed energy): :math:`S_j = \sum_{i\in W_j} z_i^2` over a
   sliding window of ``window`` seconds (:math:`w` samples), and of :math:`w/2` and
   :math:`w/4` (:data:`BURST_SCALES`; a short burst is diluted in a long window).
   Under white Gaussian noise :math:`S_j \sim \chi^2_w`; a window is flagged when
   :math:`S_j > \chi^{2}_{w}{}^{-1}(1 - p_w)`, with
   :math:`p_w = p\,w/(2\,c\,s)` for :math:`s` window sizes, :math:`c =`
   :data:`OVERLAP_FACTOR` (overlapping windows cross the threshold in clusters;
   the factor was measured, see below). Real noise is not white: the scale and
   the degrees of freedom of the window energy come from the record itself
   (Satterthwaite), from its quiet part (a second pass leaves out what the first
   found: a record with vibration of its own would otherwise set the thresholds
   of its quiet stretches).
   The start and end of a burst are then placed by maximum likelihood of a
   variance change inside the flagged stretch (the CUSUM change-point estimate,
   Page 1954), with a Student-t likelihood (ν from the quiet noise's kurtosis,
   at least :data:`CHANGE_POINT_DOF`) so that one heavy-tailed sample adds at most
   :math:`(\nu/2)\ln v`, and without the isolated outliers (spike samples whose
   neighbours are quiet), which stay spikes of their own: an outlier just before
   a burst neither becomes its start nor swallows it.
3. **Bursts inside bursts**: a burst at least :data:`INNER_MIN_WINDOWS` windows long
   (a vibration) is searched again on its own, with its own noise law and whitened
   by its own predictor; a shock during it is reported as an event of its own
   (:attr:`Events.within` names the longer one).

``false_alarm`` (:math:`p`, default :data:`FALSE_ALARM`) is the design rate of
false events per sample and channel, split evenly between the two tests.
Measured on white Gaussian noise (``benches/bench_events.py``, 2·10⁷ samples):
see ``docs/events.md`` for the numbers; the target is at most one false event
per 10⁶ samples at the default.

Events of one kind closer than ``merge`` seconds are joined, per channel and
then across channels; a spike joins a burst only where it overlaps it or lies
within half the shortest energy window of it. :meth:`Events.exclude` turns the
events into missing samples (NaN), which the Allan-family statistics skip
(``docs/gaps.md``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy import linalg as _linalg
from scipy import signal as _signal
from scipy import stats as _sstats

from imunoise._analysis.channels import rate_columns
from imunoise._support import blocks as _blocks
from imunoise._support import summary as _summary
from imunoise._support.runs import true_runs
from imunoise._support.validate import positive_finite
from imunoise.errors import ImunoiseValueError
from imunoise.readers.log import ImuLog

__all__ = ["Baselines", "Events", "events", "rms_ratio", "search", "FALSE_ALARM",
           "OVERLAP_FACTOR", "CHANGE_POINT_DOF", "BURST_SCALES"]

#: A burst this many energy windows long is searched for bursts inside it.
INNER_MIN_WINDOWS = 10

#: Default design rate of false events per sample and channel.
FALSE_ALARM = 1e-7
#: Threshold crossings of a sliding energy window per independent window under
#: white noise, relative to ``n/w·p_w``: an upper bound of that ratio over the windows
#: used, so the design false-alarm rate stays a bound (tests/events/test_events.py).
OVERLAP_FACTOR = 4.0
#: Fewest degrees of freedom of the Student-t likelihood that places a burst's
#: edges: heavy tails bound the influence of single samples on an edge (evidence in
#: docs/events.md). A record with lighter tails gets more (Gaussian in the limit).
CHANGE_POINT_DOF = 10.0
#: Energy windows per channel: ``window``, ``window``/2, … (``BURST_SCALES`` of them).
BURST_SCALES = 3
#: Smallest energy window, samples (fewer makes the χ² test a spike test).
MIN_WINDOW = 4
#: Significance at which a burst's raw (unwhitened) energy over its span must exceed
#: the quiet noise's: the whitened test also answers to a change of the noise's
#: spectral shape alone, which adds no power a person could see; a stricter level
#: also drops weak real bursts (the trade-off measured: docs/events.md).
CONFIRM_P = 1e-2
#: Most coefficients of the whitening predictor of the burst test (fewer when the
#: energy window is shorter): enough to whiten a line and a band of the sensor's own
#: (docs/events.md).
WHITENING_ORDER = 16


@dataclass(frozen=True, repr=False)
class Events:
    r"""Events found in a record (see :func:`events`).

    Attributes
    ----------
    fs : float
        Sample rate, Hz.
    n_samples : int
        Samples of the record.
    names : tuple of str
        The channels searched (``"gyro X"`` …, ``"x"``/``"ch0"`` for arrays).
    start_index, end_index : ndarray of int
        First sample of each event and one past its last (grid rows).
    channels : tuple of tuple of str
        The channels each event was found in.
    peak : ndarray
        Largest :math:`|x - \text{baseline}|/\hat\sigma` inside each event, over its channels.
    kind : tuple of str
        ``"spike"`` (one to a few samples above the Hampel threshold) or ``"burst"``.
        A burst inside a longer one (a shock during a vibration) is an event of its
        own, listed after the longer one (:attr:`within`).
    sigma : ndarray
        Robust noise level :math:`\hat\sigma = 1.4826\,\mathrm{MAD}` of each channel,
        in the channel's unit.
    spike_threshold : float
        :math:`k`, sigmas.
    energy_threshold : float
        Mean :math:`z^2` over a full window that flags a burst.
    window : int
        Energy window, samples.
    false_alarm : float
        Design rate of false events per sample and channel.
    """

    fs: float
    n_samples: int
    names: tuple[str, ...]
    start_index: np.ndarray
    end_index: np.ndarray
    channels: tuple[tuple[str, ...], ...]
    peak: np.ndarray
    kind: tuple[str, ...]
    sigma: np.ndarray
    spike_threshold: float
    energy_threshold: float
    window: int
    false_alarm: float

    def __post_init__(self) -> None:
        for name in ("start_index", "end_index", "peak", "sigma"):
            getattr(self, name).flags.writeable = False

    def __len__(self) -> int:
        return len(self.start_index)

    @property
    def start(self) -> np.ndarray:
        """Start of each event, s from the first sample."""
        return self.start_index / self.fs

    @property
    def end(self) -> np.ndarray:
        """End of each event (one sample past its last), s."""
        return self.end_index / self.fs

    @property
    def duration(self) -> np.ndarray:
        """Length of each event, s."""
        return (self.end_index - self.start_index) / self.fs

    @property
    def within(self) -> np.ndarray:
        """Index of the longer event each event lies inside, −1 for none."""
        out = np.full(len(self), -1, dtype=np.int64)
        widest = -1  # the event reaching furthest so far; events are sorted by start
        for i in range(len(self)):
            if widest >= 0 and self.end_index[i] <= self.end_index[widest]:
                out[i] = widest
            else:
                widest = i
        return out

    @property
    def mask(self) -> np.ndarray:
        """Boolean (n_samples,): ``True`` inside an event (any channel)."""
        return self.padded_mask(0.0)

    @property
    def share(self) -> float:
        """Fraction of the samples inside events."""
        return float(self.mask.mean()) if self.n_samples else 0.0

    def padded_mask(self, pad: float = 0.0) -> np.ndarray:
        """:attr:`mask` with every event widened by ``pad`` seconds on each side."""
        if pad < 0 or not np.isfinite(pad):
            raise ImunoiseValueError(f"pad must be >= 0 and finite (s); got {pad!r}")
        extra = int(np.ceil(pad * self.fs))
        out = np.zeros(self.n_samples, dtype=bool)  # a byte per sample, nothing wider
        lo = np.clip(self.start_index - extra, 0, self.n_samples)
        hi = np.clip(self.end_index + extra, 0, self.n_samples)
        for a, b in zip(lo.tolist(), hi.tolist(), strict=True):
            out[a:b] = True
        return out

    def exclude(self, data, *, pad: float = 0.0):
        """``data`` with the events' samples missing (NaN), every channel of the row.

        Parameters
        ----------
        data : ImuLog or array_like, shape (n_samples,) or (n_samples, k)
            The record the events were found in (or another one on the same grid).
        pad : float
            Seconds added on each side of every event.

        Returns
        -------
        ImuLog or ndarray
            A log whose event rows are NaN in every channel (its ``gaps`` now list
            them), or a float copy of the array with NaN rows. The gap-aware
            Allan statistics (``docs/gaps.md``) then leave out every term that
            touches an event.
        """
        mask = self.padded_mask(pad)
        if isinstance(data, ImuLog):
            if len(data) != self.n_samples:
                raise ImunoiseValueError(
                    f"data has {len(data)} samples; the events are for {self.n_samples}"
                )
            changed = {}
            for name in data.channels:
                arr = np.array(getattr(data, name), dtype=np.float64)
                arr[mask] = np.nan
                changed[name] = arr
            return replace(data, gaps=None, **changed)
        arr = np.array(data, dtype=np.float64)
        if arr.ndim not in (1, 2) or arr.shape[0] != self.n_samples:
            raise ImunoiseValueError(
                f"data must have shape ({self.n_samples},) or ({self.n_samples}, k); "
                f"got {arr.shape}"
            )
        arr[mask] = np.nan
        return arr

    def rms_ratio(self, data, *, baseline: float = 10.0) -> np.ndarray:
        """How much louder each event is than the quiet record: per event and channel,
        the RMS over the event over the RMS outside every event, both about the
        detector's median baseline (``baseline``-second blocks, as :func:`events`).

        Parameters
        ----------
        data : ImuLog or array_like
            The record the events were found in (the same channels).

        Returns
        -------
        ndarray, shape (events, channels)
            1 for an event no louder than the quiet noise; NaN where a channel has
            no valid sample in the event.
        """
        # a channel at a time (a memory-mapped log: one channel in memory)
        cols, _fs, names = rate_columns(data, None if isinstance(data, ImuLog) else self.fs,
                                        None)
        if cols.n != self.n_samples or names != self.names:
            raise ImunoiseValueError(f"data must be the record of the events ({self.n_samples} "
                             f"samples of {', '.join(self.names)}); got {cols.n} samples "
                             f"of {', '.join(names)}")
        baseline = positive_finite(baseline, "baseline", unit="s")
        return _rms_ratio(self, cols, max(2 * self.window, int(round(baseline * self.fs))))

    def rows(self) -> list[dict]:
        """One dict per event: start, end, duration (s), kind, channels, peak (sigmas),
        within (index of the longer event it lies inside, or None)."""
        within = self.within
        return [
            {
                "start": float(self.start[i]),
                "end": float(self.end[i]),
                "duration": float(self.duration[i]),
                "kind": self.kind[i],
                "channels": ", ".join(self.channels[i]),
                "peak": float(self.peak[i]),
                "within": int(within[i]) if within[i] >= 0 else None,
            }
            for i in range(len(self))
        ]

    def _facts(self) -> list[str]:
        bursts = sum(k == "burst" for k in self.kind)
        inside = int(np.count_nonzero(self.within >= 0))
        nested = f", {inside} inside longer ones" if inside else ""
        parts = [
            f"{_summary.plural(len(self), 'event')} ({bursts} bursts, {len(self) - bursts} "
            f"spikes{nested})",
            f"{100 * self.share:.3g} % of {self.n_samples} samples",
        ]
        parts += [
            f"{r['start']:.4g}–{r['end']:.4g} s {r['kind']} {r['peak']:.3g}σ" for r in self.rows()
        ]
        return parts

    def __repr__(self) -> str:
        return _summary.lines("Events(", self._facts(), sep=", ")

    def _repr_html_(self) -> str:
        rows = [
            [_summary.number(r["start"]), _summary.number(r["end"]), r["kind"], r["channels"],
             f"{r['peak']:.3g}"]  # as the repr and the report print it
            for r in self.rows()[: _summary.HTML_ROWS]
        ]
        caption = "Events: " + ", ".join(self._facts()[:2])
        if len(self) > _summary.HTML_ROWS:
            caption += f" (first {_summary.HTML_ROWS} shown)"
        return _summary.html_table(
            ["start [s]", "end [s]", "kind", "channels", "peak [σ]"], rows, caption=caption
        )


@dataclass(frozen=True)
class Baselines:
    """What :func:`search` standardised each channel by: per channel the knots of its
    median baseline and its σ̂ (:func:`_standardise`), for blocks of ``block`` rows.
    :func:`rms_ratio` of the same record reads its standardised samples from them
    instead of taking the blocks' medians and the MAD again."""

    block: int
    per_channel: tuple[tuple[tuple | None, float], ...]


def rms_ratio(found: Events, data, baselines: Baselines) -> np.ndarray:
    """``found.rms_ratio(data)`` of the record ``data`` that :func:`search` returned
    ``found`` and ``baselines`` for (the default baseline): the same numbers, each
    channel standardised from its baseline's knots (one pass, no medians)."""
    cols, _fs, names = rate_columns(data, None if isinstance(data, ImuLog) else found.fs,
                                    None)
    if cols.n != found.n_samples or names != found.names or len(
            baselines.per_channel) != len(cols):
        raise ImunoiseValueError("data must be the record the events and baselines were "
                                 "found in")
    return _rms_ratio(found, cols, baselines.block, baselines)


def _rms_ratio(found: Events, cols, block: int,
               baselines: Baselines | None = None) -> np.ndarray:
    """:meth:`Events.rms_ratio` of the columns ``cols``, standardised over blocks of
    ``block`` rows (from ``baselines`` when given: the numbers :func:`_standardise`
    gives)."""
    quiet = ~found.mask
    out = np.full((len(found), len(cols)), np.nan)
    any_quiet = bool(quiet.any())
    for j in range(len(cols)):
        if baselines is None:
            sq, _sigma, _knots = _standardise(cols.owned(j), block)
        else:
            knots, sigma = baselines.per_channel[j]
            sq = cols.owned(j)
            for a, b in _blocks.ranges(cols.n):
                sq[a:b] = _standardised_rows(sq[a:b], a, knots, sigma)
        sq *= sq  # NaN where missing
        with np.errstate(invalid="ignore", divide="ignore"):
            level = np.sqrt(_nanmean(sq, quiet)) if any_quiet else np.nan
            for i, (a, b) in enumerate(zip(found.start_index, found.end_index,
                                           strict=True)):
                inside = sq[a:b]
                if np.isfinite(inside).any():
                    out[i, j] = np.sqrt(np.nanmean(inside)) / level
    return out


def events(
    data,
    fs: float | None = None,
    *,
    channels=None,
    false_alarm: float = FALSE_ALARM,
    window: float = 1.0,
    baseline: float = 10.0,
    merge: float = 0.5,
) -> Events:
    r"""Find spikes and bursts in a still recording, per channel.

    Parameters
    ----------
    data : ImuLog or array_like, shape (n,) or (n, k)
        A log (its gyro and accel channels are searched) or samples (NaN = missing).
    fs : float, optional
        Sample rate, Hz; required for arrays, ``log.fs`` for a log.
    channels : str or sequence of str, optional
        Log channels to search (default: those of ``gyro``, ``accel`` the log has).
    false_alarm : float
        Design rate of false events per sample and channel (both tests together);
        sets the thresholds. Default :data:`FALSE_ALARM`.
    window : float
        Energy window of the burst test, s (at least :data:`MIN_WINDOW` samples).
    baseline : float
        Block length of the median baseline, s: slower changes are not events.
    merge : float
        Events closer than this (s) are joined.

    Returns
    -------
    Events

    Notes
    -----
    See the module documentation for the tests and ``docs/events.md`` for their
    measured false-alarm and detection rates. The noise level is the MAD of each
    whole channel: a log whose noise level changes (a sensor switched to a
    different filter) needs to be split first.
    """
    return search(data, fs, channels=channels, false_alarm=false_alarm, window=window,
                  baseline=baseline, merge=merge)[0]


def search(data, fs: float | None = None, *, channels=None, false_alarm: float = FALSE_ALARM,
           window: float = 1.0, baseline: float = 10.0,
           merge: float = 0.5) -> tuple[Events, Baselines]:
    """:func:`events`, and the baselines it standardised each channel by (for
    :func:`rms_ratio` of the same record)."""
    cols, fs, names = rate_columns(data, fs, channels)
    if isinstance(false_alarm, bool) or not (0 < float(false_alarm) < 0.01):
        raise ImunoiseValueError(
            f"false_alarm must be in (0, 0.01) per sample; got {false_alarm!r}")
    false_alarm = float(false_alarm)
    window = positive_finite(window, "window", unit="s")
    baseline = positive_finite(baseline, "baseline", unit="s")
    if isinstance(merge, bool) or not (np.isfinite(merge) and merge >= 0):
        raise ImunoiseValueError(f"merge must be >= 0 and finite (s); got {merge!r}")
    n = cols.n
    w = max(MIN_WINDOW, int(round(window * fs)))
    if n < 2 * w:
        raise ImunoiseValueError(f"data needs at least 2·window = {2 * w} samples; got {n}")
    block = max(2 * w, int(round(baseline * fs)))
    k_spike = float(_sstats.norm.isf(false_alarm / 4))
    # a short burst is diluted in a long window: the energy test runs at w, w/2, w/4
    # (false-alarm budget split between them)
    windows = sorted({max(MIN_WINDOW, w >> i) for i in range(BURST_SCALES)}, reverse=True)
    p_window = min(0.5, false_alarm * w / (2 * OVERLAP_FACTOR * len(windows)))
    p_v = [min(0.5, false_alarm * v / (2 * OVERLAP_FACTOR * len(windows))) for v in windows]
    touch = windows[-1] // 2
    gap = int(round(merge * fs))

    per_channel = []
    sigma = np.empty(len(cols))
    for j in range(len(cols)):
        # the one array of the channel's length kept: its standardised samples; what
        # is derived from them is read a block at a time (imunoise._support.blocks)
        r, mad_sigma, knots = _standardise(cols.owned(j), block)
        valid = np.isfinite(r)
        if valid.all():
            valid = None  # no missing sample
        # first pass with the noise law of the whole channel, then once more with
        # the law of its quiet part: a record with vibration of its own otherwise
        # sets thresholds for quiet noise from its loud stretches (docs/events.md).
        # The last pass's energy test sees the record whitened by the predictor of
        # that quiet part: the
        # sensor's own resonance or filter is then neither taken for energy nor
        # hides a burst's onset, while a vibration the quiet part does not have (a
        # machine's line for a few minutes) is not whitened away. (Whitening after
        # the first pass, whose quiet part still holds such a line, cut that
        # vibration into fragments.)
        quiet = None  # every sample
        law = None  # (quiet, scale, rho, z, spikes, isolated) of the pass before
        for step, whiten in enumerate((False, False, True)):
            if step == 1 and quiet is None:
                continue  # the first pass found nothing: its law is the quiet part's
            if law is not None and _same_mask(law[0], quiet):
                # the pass before had these quiet samples: its law, spikes and
                # outliers are this pass's (not computed again: a quarter of the passes
                # over the channel)
                _quiet, scale, rho, z, spikes, isolated = law
            else:
                scale, rho = _energy_law(_masked(_blocks.view(r), quiet), n, w)
                z = _scaled(r, np.sqrt(scale))
                spikes = tuple(_spikes(z, n, k_spike))
                quiet_level = _sstats.chi2.isf(p_v[-1], _dof(rho, windows[-1])) / _dof(
                    rho, windows[-1])
                isolated = _isolated(z, n, k_spike, touch, quiet_level)
                law = (quiet, scale, rho, z, spikes, isolated)
            spans = list(spikes)
            spans += _burst_test(z, n, valid, rho, quiet, windows, p_v, k_spike, isolated,
                                 whiten=whiten)
            if spans:
                quiet = ~_span_mask(spans, n, pad=w)
        sigma[j] = mad_sigma * np.sqrt(scale)
        spans = [sp for sp in spans if sp[2] != "burst" or _raised(z(sp[0], sp[1]), rho)]
        joined = _join([(a, b, kind, {j}) for a, b, kind in spans], gap, touch)
        # searched once the channel's spans are joined: a shock that the burst test
        # found by itself is then inside the vibration it was joined to
        inner = _inner_bursts(z, [(a, b, kind) for a, b, kind, _c in joined], windows, p_v,
                              k_spike, isolated)
        # z again over each event when the events' peaks are read (_merge_channels),
        # from the baseline's knots: one channel's samples in memory at a time
        per_channel.append((joined, (j, scale, knots, mad_sigma),
                            [(a, b, kind, {j}) for a, b, kind in inner]))
        del r, z, valid, quiet, isolated, law
    found = _merge_channels(
        per_channel, names, fs, n, gap, touch, sigma,
        lambda j, scale, knots, mad_sigma, a, b: _standardised_rows(
            cols.rows(j, a, b), a, knots, mad_sigma) / np.sqrt(scale),
        k_spike=k_spike,
        energy=float(_sstats.chi2.isf(p_window, w)) / w,
        window=w,
        false_alarm=false_alarm,
    )
    return found, Baselines(block, tuple((knots, mad_sigma) for _j, _scale, knots, mad_sigma in
                                         (key for _spans, key, _inner in per_channel)))


def _standardise(col: np.ndarray, block: int) -> tuple[np.ndarray, float, tuple | None]:
    """``(x - baseline)/σ̂`` (NaN where missing), σ̂ and the knots of the baseline
    (block centres and medians; None when no block has a valid sample) of one channel
    ``col`` (a float64 array of its own, overwritten: the result is ``col``)."""
    n = len(col)
    starts = np.arange(0, n, block)
    medians = np.empty(len(starts))
    # the blocks' medians a group of blocks at a time (each block's its own order
    # statistics: the same numbers however the blocks are grouped)
    for a, b in _blocks.ranges(n, block):
        x, i = col[a:b], a // block
        if np.isfinite(x).all():  # the usual case: one vectorised median over the blocks
            full = len(x) // block
            medians[i:i + full] = np.median(x[: full * block].reshape(full, block), axis=1)
            if len(x) > full * block:
                medians[i + full] = np.median(x[full * block:])
        else:
            with np.errstate(all="ignore"):
                medians[i:i + -(-len(x) // block)] = [
                    _nanmedian(x[s:s + block]) for s in range(0, len(x), block)]
    centres = np.minimum(starts + block / 2, n) - 0.5
    ok = np.isfinite(medians)
    if not ok.any():
        col[:] = np.nan
        return col, float("nan"), None
    knots = (centres[ok], medians[ok])
    for a, b in _blocks.ranges(n):
        col[a:b] -= np.interp(np.arange(a, b), *knots)
    r = col
    valid = np.isfinite(r)
    complete = bool(valid.all())
    rv = np.abs(r) if complete else np.abs(r[valid])  # its own copy
    sigma = 1.4826 * float(np.median(rv, overwrite_input=True))
    if sigma == 0:  # coarse quantization: most samples on one level
        rv = r if complete else r[valid]
        q75, q25 = np.percentile(rv, [75, 25])
        sigma = 0.7413 * float(q75 - q25) or float(np.std(rv))
    del rv
    if sigma == 0:
        r[valid] = 0.0
        return r, 0.0, knots
    r /= sigma
    return r, sigma, knots


def _standardised_rows(rows: np.ndarray, a: int, knots: tuple | None,
                       sigma: float) -> np.ndarray:
    """:func:`_standardise`'s values at rows ``a`` … ``a + len(rows) − 1`` of a channel
    (``rows``), from its baseline ``knots`` and σ̂: the same numbers, from those rows
    only."""
    if knots is None:
        return np.full(len(rows), np.nan)
    r = rows - np.interp(np.arange(a, a + len(rows)), *knots)
    if sigma == 0:
        return np.where(np.isfinite(r), 0.0, np.nan)
    return r / sigma


def _raised(seg: np.ndarray, rho: np.ndarray) -> bool:
    """Whether the mean z² of ``seg`` (the raw standardised record over a burst, NaN
    = missing) exceeds the quiet noise's at :data:`CONFIRM_P`: Satterthwaite's
    χ²(ν)/ν for its length, ν from ``rho`` (w lags; a longer span adds ν in proportion)."""
    v = seg[np.isfinite(seg)]
    if v.size < 2:
        return True  # nothing to judge by: the burst test's word stands
    w = len(rho)
    dof = _dof(rho, v.size) if v.size <= w else _dof(rho, w) * v.size / w
    return float(np.mean(v * v)) > float(_sstats.chi2.isf(CONFIRM_P, dof)) / dof


def _isolated(z: _blocks.Series, n: int, k_spike: float, half: int,
              level: float) -> np.ndarray:
    """Boolean (n,): samples above the spike threshold whose ``half`` neighbours on
    each side are quiet (mean clipped z² below ``level``, the shortest energy
    window's threshold): outliers, not the onset of a burst."""
    out = np.zeros(n, dtype=bool)
    big = _above(z, n, k_spike)  # |nan_to_num(z)| > k: NaN is not above k either
    if not big.size or half < 1:
        return out

    def clipped_square(a: int, b: int) -> np.ndarray:
        c = np.clip(np.nan_to_num(z(a, b)), -k_spike, k_spike)
        return c * c

    lo, hi = np.maximum(big - half, 0), np.minimum(big + 1 + half, n)
    at = np.unique(np.concatenate((big, lo, hi, big + 1)))
    sums = _blocks.running_sums_at(clipped_square, n, at)

    def csum(i: np.ndarray) -> np.ndarray:
        return sums[np.searchsorted(at, i)]

    left = (csum(big) - csum(lo)) / np.maximum(big - lo, 1)
    right = (csum(hi) - csum(big + 1)) / np.maximum(hi - big - 1, 1)
    out[big] = np.maximum(left, right) < level
    return out


def _above(z: _blocks.Series, n: int, k: float) -> np.ndarray:
    """Rows where |z| > k (NaN is not)."""
    found = []
    for a, b in _blocks.ranges(n):
        found.append(np.flatnonzero(np.abs(z(a, b)) > k) + a)
    return np.concatenate(found) if found else np.zeros(0, dtype=np.int64)


def _span_mask(spans: list[tuple[int, int, str]], n: int, *, pad: int) -> np.ndarray:
    """Boolean (n,): within ``pad`` samples of one of ``spans``."""
    out = np.zeros(n, dtype=bool)
    for a, b, _kind in spans:
        out[max(0, a - pad):min(n, b + pad)] = True
    return out


def _same_mask(a: np.ndarray | None, b: np.ndarray | None) -> bool:
    """Whether two quiet masks (None: every sample) keep the same samples."""
    if a is None or b is None:
        return a is b
    return a is b or bool(np.array_equal(a, b))


def _masked(series: _blocks.Series, keep: np.ndarray | None) -> _blocks.Series:
    """``series`` with NaN where ``keep`` is False (None: unchanged)."""
    if keep is None:
        return series
    return lambda a, b: np.where(keep[a:b], series(a, b), np.nan)


def _scaled(r: np.ndarray, root) -> _blocks.Series:
    """The series ``r / root``."""
    return lambda a, b: r[a:b] / root


def _nanmean(x: np.ndarray, keep: np.ndarray) -> float:
    """``np.nanmean(x[keep])``, the same number (the kept samples, NaN as 0, summed as
    one array, over the count of the others), without the copies ``np.nanmean`` makes
    of ``x[keep]``: one array of the kept samples."""
    kept = np.empty(int(np.count_nonzero(keep)))
    missing = 0
    m = 0
    for a, b in _blocks.ranges(len(x)):
        v = x[a:b][keep[a:b]]
        nan = np.isnan(v)
        missing += int(np.count_nonzero(nan))
        v[nan] = 0.0
        kept[m:m + len(v)] = v
        m += len(v)
    count = len(kept) - missing
    return float(np.sum(kept) / count) if count else float("nan")


def _nanmedian(v: np.ndarray) -> float:
    v = v[np.isfinite(v)]
    return float(np.median(v)) if v.size else float("nan")


def _spikes(z: _blocks.Series, n: int, k: float) -> list[tuple[int, int, str]]:
    return [(int(i), int(i) + 1, "spike") for i in _above(z, n, k)]


def _bursts(z: _blocks.Series, n: int, valid: np.ndarray | None, w: int, p_window: float,
            dof: float, k_spike: float, isolated: np.ndarray, tail_dof: float,
            raw: _blocks.Series | None = None) -> list[tuple[int, int, str]]:
    """Stretches where the sliding energy exceeds its threshold, cut to the
    maximum-likelihood segment of raised variance (``valid``: the rows with a sample,
    None for all).

    The energy sees z clipped at the spike threshold (one spike, however large, is
    a spike, not a burst); the change points do not see ``isolated`` samples (an
    outlier just before a burst would otherwise become its start). With ``raw``
    (the record before whitening, when ``z`` is whitened) a burst ends where the
    later of the two says: a ringing burst's tail is partly predictable, so its
    prediction errors end before the shaking does."""

    def squares(lo: int, hi: int) -> np.ndarray:
        z2 = np.clip(z(lo, hi), -k_spike, k_spike)
        z2 *= z2
        if valid is not None:
            z2[~valid[lo:hi]] = 0.0
        return z2

    hot = np.zeros(max(0, n - w + 1), dtype=bool)  # window j covers samples j .. j+w-1
    limits: dict[int, float] = {}  # a window of m valid samples: energy·ν_m/m ~ χ²(ν_m)
    limit_full = _sstats.chi2.isf(p_window, dof * w / w) * w / dof  # m = w
    carry, count_carry = 0.0, 0
    for a, b in _blocks.ranges(len(hot)):
        # the running sums over samples a … b+w−2, from the sum before row a: the
        # numbers of one running sum over the whole record
        csum = np.empty(b - a + w)
        csum[0] = carry
        csum[1:] = squares(a, b + w - 1)
        np.cumsum(csum, out=csum)
        energy = csum[w:] - csum[:-w]
        carry = csum[b - a]
        del csum
        if valid is None:
            hot[a:b] = energy > limit_full
            continue
        count = np.empty(b - a + w, dtype=np.int64)
        count[0] = count_carry
        count[1:] = valid[a:b + w - 1]
        np.cumsum(count, out=count)
        used = count[w:] - count[:-w]
        count_carry = int(count[b - a])
        counts, which = np.unique(used, return_inverse=True)
        for m in counts.tolist():
            if m > 0 and m not in limits:
                limits[m] = _sstats.chi2.isf(p_window, dof * m / w) * w / dof
        hot[a:b] = energy > np.array([limits.get(m, np.inf) for m in counts.tolist()])[which]
    is_valid = np.ones(n, dtype=bool) if valid is None else valid

    def onset(lo: int, hi: int) -> np.ndarray:
        return np.where(is_valid[lo:hi] & ~isolated[lo:hi], squares(lo, hi), np.nan)

    def tail(lo: int, hi: int) -> np.ndarray:
        x = raw(lo, hi)
        return np.where(np.isfinite(x) & ~isolated[lo:hi],
                        np.clip(x, -k_spike, k_spike) ** 2, np.nan)

    out = []
    # windows a .. b-1 flagged: samples a .. b+w-2 involved
    for a, b in zip(*true_runs(hot), strict=True):
        lo, hi = max(0, a - w // 2), min(n, b - 1 + w + w // 2)
        start, end = _change_points(onset(lo, hi), tail_dof)
        if raw is not None and end > start:
            stop = min(n, hi + w)
            raw_start, raw_end = _change_points(tail(lo + start, stop), tail_dof)
            if raw_end > raw_start and raw_start <= w:
                end = max(end, start + raw_end)
        if end > start:
            out.append((lo + start, lo + end, "burst"))
    return out


def _inner_bursts(z, spans, windows, p_v, k_spike, isolated) -> list[tuple[int, int, str]]:
    """Bursts inside a long burst (a shock during a vibration): the burst test run on
    the long burst alone, with its own noise law and whitened by its own predictor."""
    w = windows[0]
    out = []
    for a, b, kind in spans:
        if kind != "burst" or b - a < INNER_MIN_WINDOWS * w:
            continue
        seg = z(a, b)
        valid = np.isfinite(seg)
        scale, rho = _energy_law(_blocks.view(seg), b - a, w)
        for s0, s1, _k in _burst_test(_blocks.view(seg / np.sqrt(scale)), b - a,
                                      None if valid.all() else valid, rho, None, windows,
                                      p_v, k_spike, isolated[a:b], whiten=True):
            if s0 >= w and windows[-1] <= s1 - s0 < (b - a) // 2:
                out.append((a + s0, a + s1, "burst"))
    return out


def _burst_test(z, n, valid, rho, quiet, windows, p_v, k_spike, isolated, *,
                whiten: bool) -> list[tuple[int, int, str]]:
    """The energy test at every window of ``windows`` on the series ``z`` (standardised
    by the law of its ``quiet`` samples (None: all), autocorrelation ``rho``), or, with
    ``whiten``, on its prediction errors, scaled by the law of their quiet samples; the
    Student-t edges take their ν from the tested series' quiet samples."""
    e, rho_e = z, rho
    if whiten:
        errors = _whiten(z, n, valid, rho, k_spike, isolated)
        scale_e, rho_e = _energy_law(_masked(_blocks.view(errors), quiet), n, windows[0])
        errors /= np.sqrt(scale_e)
        e = _blocks.view(errors)
    tail_dof = _tail_dof(_blocks.gather(e, n, quiet))
    return [span for v, p in zip(windows, p_v, strict=True)
            for span in _bursts(e, n, valid, v, p, _dof(rho_e, v), k_spike, isolated,
                                tail_dof, z if whiten else None)]


def _whiten(z: _blocks.Series, n: int, valid: np.ndarray | None, rho: np.ndarray,
            k_spike: float, isolated: np.ndarray) -> np.ndarray:
    """The prediction errors of ``z`` under the autoregression AR(p) that fits its
    autocorrelation ``rho`` (Yule–Walker, p = min(:data:`WHITENING_ORDER`,
    len(rho) − 1)): white where the quiet noise is, while a burst's onset, which
    the past does not predict, passes whole.

    The input is clipped at the spike threshold and its isolated outliers and
    missing samples are zeroed (the filter would smear one outlier over p + 1
    samples); missing samples stay missing. The filter is causal, so a burst
    starts in the errors where it starts in ``z``. Filtered a block at a time, each
    block after the p samples before it: the numbers of one filter over the record."""
    order = min(WHITENING_ORDER, len(rho) - 1)

    def clipped(a: int, b: int) -> np.ndarray:
        # missing samples (NaN) are not kept: no np.nan_to_num needed before the clip
        keep = ~isolated[a:b] if valid is None else valid[a:b] & ~isolated[a:b]
        return np.where(keep, np.clip(z(a, b), -k_spike, k_spike), 0.0)

    out = np.empty(n)
    coefficients = None
    if order >= 1 and np.all(np.isfinite(rho[: order + 1])):
        try:
            ar = _linalg.solve_toeplitz(rho[:order], rho[1:order + 1])
        except (np.linalg.LinAlgError, ValueError):
            ar = None
        if ar is not None and np.all(np.isfinite(ar)):
            coefficients = np.concatenate(([1.0], -ar))
    for a, b in _blocks.ranges(n):
        if coefficients is None:
            out[a:b] = clipped(a, b)
            continue
        before = min(order, a)
        out[a:b] = _signal.lfilter(coefficients, [1.0], clipped(a - before, b))[before:]
    if valid is not None:
        out[~valid] = np.nan
    return out


def _energy_law(z: _blocks.Series, n: int, w: int) -> tuple[float, np.ndarray]:
    """Scale s and autocorrelation ρ_0 … ρ_{w−1} of a quiet record (the series ``z``
    of ``n`` rows, NaN = missing or left out), which set the law of its window
    energy: Σ_window z² ≈ s·(w/ν)·χ²(ν) (Satterthwaite), ν from :func:`_dof`.

    Real sensor noise is not white: correlated samples (a sensor's own filter,
    bias wander faster than the baseline) make the window energy vary more than
    χ²(w), which a white-noise threshold would take for bursts all along the log.
    ν = w / (1 + 2 Σ_{k<w} (1 − k/w) ρ_k²) for a Gaussian process with
    autocorrelation ρ_k (ν = w for white noise); s is the median window mean of
    z² over the median of χ²(ν)/ν: σ̂·√s is the RMS of the quiet noise even where
    the MAD misjudges it (heavy tails, quantization), and both tests use it.
    Both are robust to a few events: ρ is computed from z clipped at ±3, s from
    a median. Two passes over blocks: the valid samples, their clipped mean and the
    complete windows' mean z², then the lag products.
    """
    valid = np.empty(n, dtype=bool)
    clipped = np.empty(n)  # the valid samples clipped, gathered for their mean
    m = 0
    means = []
    full = n // w
    for a, b in _blocks.ranges(n, w):
        x = z(a, b)
        ok = np.isfinite(x)
        valid[a:b] = ok
        k = int(np.count_nonzero(ok))
        # a block with every sample (the usual case) needs no mask: the same numbers
        # without three copies of the block
        every = k == b - a
        if not every:
            x = np.where(ok, x, 0.0)
        np.clip(x if every else x[ok], -3.0, 3.0, out=clipped[m:m + k])
        m += k
        rows = min(b, full * w) - a  # the complete windows' mean z² (windows at rows i·w)
        if rows > 0:
            squares = (x[:rows] ** 2).reshape(rows // w, w)
            if not every:
                squares = squares[ok[:rows].reshape(rows // w, w).all(axis=1)]
            means.append(squares.mean(axis=1))
    centre = clipped[:m].mean() if m else 0.0
    del clipped

    def centred(a: int, b: int) -> np.ndarray:
        ok = valid[a:b]
        if ok.all():
            out = np.clip(z(a, b), -3.0, 3.0)  # a new array, not the series' rows
            out -= centre
            return out
        return np.where(ok, np.clip(np.where(ok, z(a, b), 0.0), -3.0, 3.0) - centre, 0.0)

    acf = _blocks.lag_products(centred, n, w)
    pairs = (n - np.arange(w)).astype(float) if m == n else _valid_pairs(valid, w)
    rho = acf / np.maximum(pairs, 1.0) / (acf[0] / max(pairs[0], 1.0)) if acf[0] > 0 \
        else np.zeros(w)
    dof = _dof(rho, w)
    means = np.concatenate(means) if means else np.zeros(0)
    if not means.size:
        return 1.0, rho
    median = float(np.median(means))
    expected = float(_sstats.chi2.median(dof)) / dof
    return (median / expected if median > 0 else 1.0), rho


#: Most runs of missing samples whose pairs :func:`_valid_pairs` counts directly.
PAIR_RUNS = 512


def _valid_pairs(valid: np.ndarray, lags: int) -> np.ndarray:
    """Σ_i valid_i·valid_(i+k) for k = 0 … lags − 1 (float): the pairs of valid samples
    k apart, counted from the runs of missing ones, (n − k) less those touching one
    (missing at i, at i + k, or both); by :func:`_lag_products` when there are more
    than :data:`PAIR_RUNS` runs."""
    n = len(valid)
    start, stop = true_runs(~valid)
    if start.size > PAIR_RUNS:
        return _blocks.lag_products(lambda a, b: valid[a:b].astype(float), n, lags)
    k = np.arange(lags)

    def missing_below(end: np.ndarray) -> np.ndarray:  # missing samples in [0, end)
        return np.clip(np.minimum(stop[:, None], end[None, :]) - start[:, None], 0,
                       None).sum(axis=0)

    both = np.zeros(lags, dtype=np.int64)  # i and i + k both missing
    for r in range(start.size):
        near = slice(r, int(np.searchsorted(start, stop[r] + lags)))  # runs after it, close
        both += np.clip(np.minimum(stop[r], stop[near, None] - k[None, :])
                        - np.maximum(start[r], start[near, None] - k[None, :]), 0,
                        None).sum(axis=0)
    total = int(stop.sum() - start.sum())
    return ((n - k) - missing_below(n - k) - (total - missing_below(k)) + both).astype(float)


def _dof(rho: np.ndarray, w: int) -> float:
    """Satterthwaite degrees of freedom of the energy of ``w`` samples with
    autocorrelation ``rho`` (ρ_0 … ρ_{w−1} at least)."""
    k = np.arange(1, w)
    return float(w / (1 + 2 * np.sum((1 - k / w) * rho[1:w] ** 2)))


def _tail_dof(z: np.ndarray) -> float:
    """Degrees of freedom ν of the Student-t with the excess kurtosis of the finite
    samples ``z`` (:func:`imunoise._support.blocks.gather`'s: an array of our own, overwritten)
    (6/(ν − 4)), at least :data:`CHANGE_POINT_DOF`: Gaussian-like noise keeps the
    Gaussian likelihood's precision, heavy-tailed noise gets bounded influence."""
    if z.size < 8:
        return CHANGE_POINT_DOF
    excess = _excess_kurtosis(z)
    return 1e6 if excess <= 6 / (1e6 - 4) else max(CHANGE_POINT_DOF, 4 + 6 / excess)


def _excess_kurtosis(z: np.ndarray) -> float:
    """``scipy.stats.kurtosis(z)`` of finite samples, the same operations (its central
    moments m2 = mean(d²), m4 = mean((d²)²)) without its checks and copies (``z`` is
    overwritten)."""
    mean = z.mean()
    square = z
    square -= mean
    square *= square
    m2 = square.mean()
    if m2 <= (np.finfo(np.float64).eps * mean) ** 2:
        return float("nan")
    square *= square
    return float(square.mean() / m2**2.0 - 3)


def _change_points(seg: np.ndarray, nu: float) -> tuple[int, int]:
    """The segment of ``seg`` (squared standardised samples, NaN = no say) whose variance v > 1
    maximises the log-likelihood ratio Σ ℓ_i of v against 1. v is first the mean
    over all of ``seg`` (diluted by the noise around the burst), then the mean
    over the segment found; a second pass that loses the first segment (a
    decaying burst's variance is not one number) keeps the first. The start is then
    placed once more, no later than the segment's loudest quarter (at least 4
    samples) and with that quarter's variance: with a diluted variance the slightly
    raised noise just before a burst would join it. A burst that swells slowly
    starts about where its variance has tripled.

    ℓ_i is the Student-t (ν from :func:`_tail_dof`) log-likelihood ratio of a
    scale change, not the Gaussian z²(1 − 1/v) − ln v: one large sample adds at most
    (ν/2)·ln v, so a few heavy-tailed samples before a burst cannot pull its start
    forward (real gyro noise is heavy-tailed; see docs/events.md)."""
    start, end = 0, len(seg)
    found = (0, 0)
    for _ in range(2):
        inside = seg[start:end]
        inside = inside[np.isfinite(inside)]
        s = _cumulative_log_ratio(seg, inside, nu)
        new_end = int(np.argmax(s))
        new_start = int(np.argmin(s[: new_end + 1]))
        if new_end <= new_start or (found[1] and (new_end <= found[0] or new_start >= found[1])):
            break
        start, end = found = (new_start, new_end)
    start, end = found
    if end > start:
        # the onset, placed with the variance of the segment's loudest quarter: the
        # segment's mean variance (or its first quarter's, when the segment already
        # begins early) is diluted, and raised noise just before the burst then joins it
        length = max(4, (end - start) // 4)
        loudest = start + _loudest_window(seg[start:end], length)
        inside = seg[loudest:loudest + length]
        s = _cumulative_log_ratio(seg[:loudest + length], inside[np.isfinite(inside)], nu)
        found = (int(np.argmin(s[: loudest + 1])), end)
    return found


def _loudest_window(seg: np.ndarray, length: int) -> int:
    """Start of the ``length``-sample window of ``seg`` with the largest mean (NaN =
    no say); 0 if ``seg`` is not longer than ``length``."""
    if len(seg) <= length:
        return 0
    valid = np.isfinite(seg)
    total = np.concatenate(([0.0], np.cumsum(np.where(valid, seg, 0.0))))
    count = np.concatenate(([0], np.cumsum(valid)))
    mean = (total[length:] - total[:-length]) / np.maximum(count[length:] - count[:-length], 1)
    return int(np.argmax(mean))


def _cumulative_log_ratio(seg: np.ndarray, inside: np.ndarray, nu: float) -> np.ndarray:
    """0, ℓ_0, ℓ_0 + ℓ_1, …: the running Student-t log-likelihood ratio of the scale
    v = mean(``inside``) (at least 1) against 1 over ``seg``; NaN samples (spikes,
    missing) have no say."""
    v = max(float(inside.mean()) if inside.size else 1.0, 1.0 + 1e-9)
    ell = -0.5 * np.log(v) - (nu + 1) / 2 * (np.log1p(seg / (nu * v)) - np.log1p(seg / nu))
    ell = np.where(np.isfinite(ell), ell, 0.0)
    return np.concatenate(([0.0], np.cumsum(ell)))


def _peak(z: np.ndarray) -> float:
    a = np.abs(z[np.isfinite(z)])
    return float(a.max()) if a.size else float("nan")


def _join(spans: list[tuple], gap: int, touch: int) -> list[list]:
    """Spans ``(start, stop, kind, channels)`` joined into ``[start, stop, kind, channels]``.

    Spans of one kind closer than ``gap`` samples are joined; a spike joins a burst
    only where it overlaps it or is within ``touch`` samples of it (half the shortest
    energy window, which cannot tell them apart): an isolated outlier next to a
    burst stays a spike of its own, so it neither becomes the burst's start nor
    swallows the burst."""
    ordered = sorted(spans, key=lambda span: span[:3])
    bursts = _join_kind([sp for sp in ordered if sp[2] == "burst"], gap)
    starts = np.array([g[0] for g in bursts], dtype=np.int64)
    alone = []
    for a, b, kind, chans in ordered:
        if kind != "spike":
            continue
        # the last burst starting before the spike's end (+ touch)
        k = int(np.searchsorted(starts, b + touch, side="left")) - 1
        if k >= 0 and a < bursts[k][1] + touch:
            bursts[k][0] = min(bursts[k][0], a)
            bursts[k][1] = max(bursts[k][1], b)
            bursts[k][3] |= set(chans)
        else:
            alone.append((a, b, kind, chans))
    out = bursts + _join_kind(alone, gap)
    return sorted(out, key=lambda g: (g[0], g[1]))


def _join_kind(spans: list[tuple], gap: int) -> list[list]:
    """Sorted spans of one kind joined where closer than ``gap`` samples."""
    out: list[list] = []
    for a, b, kind, chans in spans:
        if out and a - out[-1][1] <= gap:
            out[-1][1] = max(out[-1][1], b)
            out[-1][3] |= set(chans)
        else:
            out.append([a, b, kind, set(chans)])
    return out


def _merge_channels(per_channel, names, fs, n, gap, touch, sigma, standardised,
                    **thresholds) -> Events:
    """One event per overlapping group of the channels' events; a group's peak is the
    largest |z| of its channels in it (``standardised(*key, a, b)``: a channel's z over
    rows a … b − 1, from the key each entry of ``per_channel`` holds)."""
    groups = _join([span for spans, _z, _in in per_channel for span in spans], gap, touch)
    nested = _join_kind(sorted((span for _s, _z, inner in per_channel for span in inner),
                               key=lambda span: span[:3]), gap)
    groups = sorted(groups + nested, key=lambda g: (g[0], g[1]))
    per_group: list[dict[int, float]] = [{} for _g in groups]
    for j in sorted({j for g in groups for j in g[3]}):
        for i, (a, b, _k, chans) in enumerate(groups):
            if j in chans:
                per_group[i][j] = _peak(standardised(*per_channel[j][1], a, b))
    peaks = [max(found[j] for j in g[3]) for g, found in zip(groups, per_group, strict=True)]
    return Events(
        fs=fs,
        n_samples=n,
        names=names,
        start_index=np.array([g[0] for g in groups], dtype=np.int64),
        end_index=np.array([g[1] for g in groups], dtype=np.int64),
        channels=tuple(tuple(names[j] for j in sorted(g[3])) for g in groups),
        peak=np.array(peaks, dtype=np.float64),
        kind=tuple(g[2] for g in groups),
        sigma=sigma,
        spike_threshold=thresholds["k_spike"],
        energy_threshold=thresholds["energy"],
        window=thresholds["window"],
        false_alarm=thresholds["false_alarm"],
    )
