"""The in-memory result of reading a log: channels as arrays plus what was skipped."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import TYPE_CHECKING

import numpy as np

from imunoise._core import vn as _core_vn
from imunoise._support import schema as _schema
from imunoise._support import summary as _summary
from imunoise._support import warn as _warn
from imunoise._support.validate import sample_rate
from imunoise.errors import (
    AssumptionWarning,
    DataWarning,
    GapWarning,
    ImunoiseTypeError,
    ImunoiseValueError,
)
from imunoise.readers.grid import Gaps, TimeGrid

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: Sample rate assumed when neither timestamps nor ``fs=`` tell it (the VN-100's
#: factory default asynchronous output rate).
DEFAULT_FS = 40.0

#: Kinds of problem a reader counts. Every skipped byte or record lands in one.
#: The parser's own kinds come from Rust, in its order:
#:
#: - ``bad_checksum``: 8-bit checksum or CRC-16 mismatch
#: - ``malformed_field``: a field that does not parse as its type, or a wrong field count
#: - ``unknown_message``: a well-formed record of a type we do not decode
#: - ``truncated_record``: a record cut short (end of file, or next record started)
#: - ``bytes_skipped``: bytes that belong to no record (noise between records)
#: - ``device_error``: ``$VNERR`` replies, recorded not decoded
#:
#: then the time grid's (:mod:`imunoise.readers.grid`):
#:
#: - ``duplicate_time``: a sample whose grid slot was taken (same or too-close
#:   timestamp): dropped
#: - ``time_reversed``: a timestamp smaller than the one before: kept, placed by its time
#: - ``time_outlier``: a timestamp its neighbours do not follow (one corrupt value):
#:   the sample kept, placed and timed by its neighbours
#: - ``time_reset``: the clock restarted (time jumped back): the log continues with
#:   a new segment, in file order
#:
#: The locations (``first``) of these four time kinds are 1-based sample numbers
#: in the order the samples were read, whatever the format.
ISSUE_KINDS = (*_core_vn.ISSUE_KINDS, "duplicate_time", "time_reversed", "time_outlier",
               "time_reset")

#: Issue kinds found on the time grid, located by sample number.
TIME_KINDS = ("duplicate_time", "time_reversed", "time_outlier", "time_reset")

#: Locations of each issue kind a summary (repr) shows.
FIRST_SHOWN = 3

#: Kinds that count something other than a skipped record.
_NOT_RECORDS = ("bytes_skipped", "time_reversed", "time_outlier", "time_reset")


@dataclass(frozen=True, repr=False)
class ParseIssues:
    """What a reader skipped, by kind.

    Attributes
    ----------
    counts : Mapping[str, int]
        Number of records (or, for ``bytes_skipped``, bytes) per kind in
        :data:`ISSUE_KINDS`; every kind is present, zero when nothing happened.
    first : Mapping[str, tuple[int, ...]]
        The first few locations of each kind: 1-based line numbers for text
        formats, 0-based byte offsets for binary ones, 1-based message numbers
        for bags; for the time kinds (:data:`TIME_KINDS`) 1-based sample numbers.
    location : str
        ``"line"``, ``"byte"`` or ``"message"``: what the numbers in ``first`` are.
    samples_missing : int
        Samples missing on the time grid (the NaN rows of the log).
    gaps : int
        Runs of consecutive missing samples (rows of ``ImuLog.gaps``).
    samples : int
        Rows of the grid, missing ones included (``len(log)``).
    """

    counts: Mapping[str, int]
    first: Mapping[str, tuple[int, ...]] = field(default_factory=dict)
    location: str = "line"
    samples_missing: int = 0
    gaps: int = 0
    samples: int = 0

    def __post_init__(self) -> None:
        counts = {kind: int(self.counts.get(kind, 0)) for kind in ISSUE_KINDS}
        unknown = set(self.counts) - set(ISSUE_KINDS)
        if unknown:
            raise ImunoiseValueError(f"counts has unknown issue kinds {sorted(unknown)}")
        object.__setattr__(self, "counts", MappingProxyType(counts))
        first = {kind: tuple(self.first.get(kind, ())) for kind in ISSUE_KINDS}
        object.__setattr__(self, "first", MappingProxyType(first))

    @property
    def total(self) -> int:
        """Records skipped (``bytes_skipped`` counts bytes and ``time_reversed`` kept
        samples, so neither is included)."""
        return sum(v for k, v in self.counts.items() if k not in _NOT_RECORDS)

    @property
    def share_missing(self) -> float:
        """Fraction of the grid's samples that are missing (0 for an empty log)."""
        return self.samples_missing / self.samples if self.samples else 0.0

    @classmethod
    def none(cls) -> ParseIssues:
        return cls(counts={})

    def __str__(self) -> str:
        parts = [f"{k}={v}" for k, v in self.counts.items() if v]
        if self.samples_missing:
            parts.append(
                f"{self.samples_missing} samples missing ({100 * self.share_missing:.3g} %) "
                f"in {self.gaps} gap{'s' if self.gaps != 1 else ''}"
            )
        return "no issues" if not parts else ", ".join(parts)

    def _first(self, kind: str) -> str:
        """``"lines 12, 40, 77, …"``: where the first records of ``kind`` were."""
        where = self.first[kind]
        if not where:
            return ""
        shown = ", ".join(str(w) for w in where[:FIRST_SHOWN])
        more = ", …" if self.counts[kind] > FIRST_SHOWN else ""
        unit = "sample" if kind in TIME_KINDS else self.location
        return f"{unit}{'s' if len(where) > 1 else ''} {shown}{more}"

    def _missing(self) -> list[str]:
        """``["4 of 13223 samples missing (0.03 %) in 2 gaps"]``, or nothing."""
        if not self.samples_missing:
            return []
        return [f"{self.samples_missing} of {self.samples} samples missing "
                f"({100 * self.share_missing:.3g} %) in {_summary.plural(self.gaps, 'gap')}"]

    def __repr__(self) -> str:
        parts = [f"{k}={v}" + (f" ({self._first(k)})" if self.first[k] else "")
                 for k, v in self.counts.items() if v]
        return _summary.lines("ParseIssues(", parts + self._missing() or ["no issues"],
                              sep=", ")

    def _repr_html_(self) -> str:
        rows = [[k, v, self._first(k)] for k, v in self.counts.items() if v]
        counts = [f"{k}={v}" for k, v in self.counts.items() if v]
        return _summary.html_table(
            ["kind", "count", "first locations"],
            rows or [["no issues", 0, ""]],
            caption="ParseIssues: " + (", ".join(counts + self._missing()) or "no issues"),
        )


# The channel table and column naming live in the one schema module.
CHANNELS = _schema.CHANNELS
column_names = _schema.column_names


@dataclass(frozen=True, repr=False)
class ImuLog:
    """An IMU recording: uniform-rate channels plus the record of what was skipped.

    Channels the log does not contain are ``None``. Arrays are float64 with one
    row per sample: ``gyro``, ``accel``, ``mag``, ``ypr``, ``delta_theta``,
    ``delta_velocity`` are (n, 3); ``quaternion`` (n, 4); ``temperature`` and
    ``pressure`` (n,). ``time`` (n,) in seconds when the log carries timestamps.

    The rows are the log's **uniform time grid**: a sample lost in the recording
    (a dropout between timestamps, a damaged record of the main stream) is a row
    of NaN in every channel, never spliced over. ``time`` holds the measured
    timestamp of every sample that is there and, in a missing row, the time
    interpolated between the samples around the gap. ``len(log)`` counts
    grid rows, missing ones included, and ``duration`` is ``len(log) / fs``: the
    true length of the recording. ``gaps`` lists the dropouts and ``valid`` marks the rows present;
    ``issues`` repeats the totals (samples missing, share, number of gaps).

    Attributes
    ----------
    fs : float
        Sample rate in Hz: from timestamps where present, else the ``fs`` the
        reader was given, else :data:`DEFAULT_FS` with a warning.
    source : str
        Path of the file, or ``"<bytes>"`` / ``"<arrays>"``.
    format : str
        ``"vn-ascii"``, ``"vn-binary"``, ``"csv"``, ``"rosbag"`` or ``"arrays"``.
    issues : ParseIssues
        Counts of skipped records by kind.
    messages : Mapping[str, int]
        Records decoded per message type (e.g. ``{"VNYMR": 30178}``).
    gaps : Gaps
        Runs of missing samples (grid row, samples; start time, duration). When
        not given, the rows with a NaN in any channel.
    """

    fs: float
    source: str
    format: str
    issues: ParseIssues
    gyro: np.ndarray | None = None
    accel: np.ndarray | None = None
    mag: np.ndarray | None = None
    ypr: np.ndarray | None = None
    quaternion: np.ndarray | None = None
    temperature: np.ndarray | None = None
    pressure: np.ndarray | None = None
    delta_theta: np.ndarray | None = None
    delta_velocity: np.ndarray | None = None
    time: np.ndarray | None = None
    messages: Mapping[str, int] = field(default_factory=dict)
    gaps: Gaps | None = None

    def __post_init__(self) -> None:
        sample_rate(self.fs)
        lengths = {}
        for name, (cols, _unit) in CHANNELS.items():
            value = getattr(self, name)
            if value is None:
                continue
            arr = np.asarray(value, dtype=np.float64)
            expected_ndim = 1 if cols == 1 else 2
            if arr.ndim != expected_ndim or (cols > 1 and arr.shape[1] != cols):
                want = "(n,)" if cols == 1 else f"(n, {cols})"
                raise ImunoiseValueError(f"{name} must have shape {want}; got {arr.shape}")
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)
            lengths[name] = len(arr)
        if self.time is not None:
            t = np.asarray(self.time, dtype=np.float64)
            t.flags.writeable = False
            object.__setattr__(self, "time", t)
            lengths["time"] = len(t)
        if len(set(lengths.values())) > 1:
            raise ImunoiseValueError(f"channels must have equal lengths; got {lengths}")
        object.__setattr__(self, "messages", MappingProxyType(dict(self.messages)))
        gaps = self.gaps
        if gaps is None:
            gaps = Gaps.from_valid(self._rows_without_nan(), self.fs)
        elif not isinstance(gaps, Gaps):
            raise ImunoiseTypeError(f"gaps must be a Gaps table or None; got {type(gaps).__name__}")
        object.__setattr__(self, "gaps", gaps)
        n = len(self)
        if (self.issues.samples_missing, self.issues.gaps, self.issues.samples) != (
            gaps.total,
            len(gaps),
            n,
        ):
            issues = replace(self.issues, samples_missing=gaps.total, gaps=len(gaps), samples=n)
            object.__setattr__(self, "issues", issues)

    def _rows_without_nan(self) -> np.ndarray:
        """Rows with no NaN in any channel (column by column: fast on strided views)."""
        nan = np.zeros(len(self), dtype=bool)
        scratch = np.empty(len(self), dtype=bool)
        for name in self.channels:
            values = getattr(self, name)
            for col in [values] if values.ndim == 1 else values.T:
                nan |= np.isnan(col, out=scratch)
        return ~nan

    @property
    def valid(self) -> np.ndarray:
        """Boolean (n,) mask: ``True`` where the sample is there, ``False`` in gaps."""
        return self.gaps.valid(len(self))

    @property
    def channels(self) -> tuple[str, ...]:
        """Names of the channels present, in :data:`CHANNELS` order."""
        return tuple(name for name in CHANNELS if getattr(self, name) is not None)

    def __len__(self) -> int:
        for name in self.channels:
            return len(getattr(self, name))
        return 0 if self.time is None else len(self.time)

    @property
    def duration(self) -> float:
        """Length of the record in seconds: grid rows (missing samples included) / fs."""
        return len(self) / self.fs

    def _facts(self) -> list[str]:
        """Rate, length, channels, gaps and issues, short."""
        n = len(self)
        missing = self.gaps.total
        parts = [
            f"{_summary.number(self.fs)} Hz",
            f"{n} samples = {_summary.duration(self.duration)}",
            "channels " + (" ".join(self.channels) or "none")
            + (" + time" if self.time is not None else ""),
            f"{missing} missing in {_summary.plural(len(self.gaps), 'gap')}"
            if missing else "no gaps",
        ]
        issues = _summary.nonzero(self.issues.counts)
        parts.append(f"issues: {issues}" if issues else "no issues")
        return parts

    def _origin(self) -> str:
        """``"vn-ascii 'capture.txt'"``, ``"vn-binary <bytes>"``, ``"arrays"``."""
        if self.source == f"<{self.format}>":
            return self.format
        if self.source.startswith("<"):
            return f"{self.format} {self.source}"
        return f"{self.format} {_summary.source_name(self.source)!r}"

    def __repr__(self) -> str:
        return _summary.lines(f"ImuLog({self._origin()}", self._facts(), sep=", ")

    def _repr_html_(self) -> str:
        """The log's facts and one row per channel; its issues and gaps when it has any."""
        caption = f"ImuLog: {self._origin()}, " + ", ".join(self._facts())
        rows = [[name, " ".join(column_names(name)), CHANNELS[name][1]]
                for name in self.channels]
        if self.messages:
            caption += "; messages " + _summary.nonzero(self.messages)
        out = _summary.html_table(["channel", "columns", "unit"], rows, caption=caption)
        if self.issues.total or self.issues.counts["bytes_skipped"]:
            out += self.issues._repr_html_()
        if len(self.gaps):
            out += self.gaps._repr_html_()
        return out

    def plot(self, channels: str | Sequence[str] | None = None, **kwargs) -> Figure:
        """Time series of the log's channels, one panel per axis, gaps shaded: see
        :func:`imunoise.plot.time_series` (``channels`` default: all the log has)."""
        from imunoise import plot

        return plot.time_series(self, channels=channels, **kwargs)

    @classmethod
    def from_arrays(
        cls,
        fs: float,
        *,
        gyro=None,
        accel=None,
        mag=None,
        ypr=None,
        quaternion=None,
        temperature=None,
        pressure=None,
        delta_theta=None,
        delta_velocity=None,
        time=None,
        source: str = "<arrays>",
    ) -> ImuLog:
        """Wrap arrays already in memory, in the units of :data:`CHANNELS` (rad/s, m/s²,
        Gauss, deg, degC, kPa).

        The arrays are taken to be on a uniform grid at ``fs``: a row with NaN in
        any channel is a missing sample, and runs of them are the log's ``gaps``.
        """
        return cls(
            fs=float(fs),
            source=source,
            format="arrays",
            issues=ParseIssues.none(),
            gyro=gyro,
            accel=accel,
            mag=mag,
            ypr=ypr,
            quaternion=quaternion,
            temperature=temperature,
            pressure=pressure,
            delta_theta=delta_theta,
            delta_velocity=delta_velocity,
            time=time,
        )


def log_on_grid(
    *,
    fs: float | None,
    source: str,
    format: str,
    issues: ParseIssues,
    channels: Mapping[str, np.ndarray],
    time: np.ndarray | None = None,
    messages: Mapping[str, int] | None = None,
    grid: TimeGrid | None = None,
    values_may_be_nan: bool = False,
) -> ImuLog:
    """The :class:`ImuLog` of a reader: one value per decoded sample, put on the grid.

    Every reader ends here, so that rate, gaps and timestamp problems are decided
    in one place (:mod:`imunoise.readers.grid`). ``grid`` defaults to the grid of
    ``time`` (or, without timestamps, every sample in its own row); the rate is the
    grid's where it has one, else ``fs``, else :data:`DEFAULT_FS` with a warning.
    Duplicate and reversed timestamps are added to ``issues``. The gaps are the
    grid's missing rows; with ``values_may_be_nan`` (a CSV, where ``nan`` marks a
    missing value) every row with a NaN, found by one scan of the channels.
    """
    n = len(time) if time is not None else len(next(iter(channels.values()), ()))
    if grid is None and time is not None:
        try:
            grid = TimeGrid.from_timestamps(time)
        except ValueError as exc:
            _warn.warn(f"{source}: {exc}; samples kept one per row, gaps not detected", GapWarning)
    if grid is None:
        grid = TimeGrid.identity(n)
    rate = grid.fs if grid.fs is not None else fs_from_median_step(None, fs, source)
    found = {kind: getattr(grid, kind) for kind in TIME_KINDS}
    if any(found.values()):
        counts = {k: v + found.get(k, 0) for k, v in issues.counts.items()}
        first = {k: issues.first[k] + tuple(grid.first.get(k, ())) for k in ISSUE_KINDS}
        issues = replace(issues, counts=counts, first=first)
        _warn_time(source, n, found, grid)
    return ImuLog(
        fs=rate,
        source=source,
        format=format,
        issues=issues,
        time=grid.place_time(time),
        messages=messages or {},
        gaps=None if values_may_be_nan else grid.gaps(rate),
        **{name: grid.place(values) for name, values in channels.items()},
    )


def _warn_time(source: str, n: int, found: Mapping[str, int], grid: TimeGrid) -> None:
    """One warning for timestamps that needed a decision: time that only goes back,
    outliers, resets."""
    notes = []
    if found["time_reversed"] and found["time_reversed"] >= n - 1:
        notes.append("the time decreases at every step: samples kept in file order at the "
                     "rate of its steps")
    if found["time_outlier"]:
        notes.append(f"{found['time_outlier']} timestamp(s) far off their neighbours' line "
                     f"(samples {list(grid.first.get('time_outlier', ()))}...) taken as "
                     "corrupt: placed by their neighbours (time_outlier)")
    if found["time_reset"]:
        notes.append(f"the clock restarts {found['time_reset']} time(s) (at samples "
                     f"{list(grid.first.get('time_reset', ()))}...): the log is "
                     f"{found['time_reset'] + 1} segments in file order (time_reset)")
    if notes:
        _warn.warn(f"{source}: " + "; ".join(notes), DataWarning)


def fs_from_median_step(
    median_step: float | None, fs: float | None, source: str
) -> float:
    """1 / ``median_step`` when the log had timestamps, else ``fs``, else
    :data:`DEFAULT_FS` with a warning (at the user's line that read the log)."""
    if median_step is not None:
        return float(1.0 / median_step)
    if fs is not None:
        return sample_rate(fs)
    _warn.warn(
        f"{source}: no timestamps and no fs given; assuming {DEFAULT_FS:g} Hz "
        "(pass fs= to set the sample rate; on the command line, --fs)", AssumptionWarning
    )
    return DEFAULT_FS
