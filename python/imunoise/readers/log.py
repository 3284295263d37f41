"""The in-memory result of reading a log: channels as arrays plus what was skipped."""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

#: Sample rate assumed when neither timestamps nor ``fs=`` tell it (the VN-100's
#: factory default asynchronous output rate).
DEFAULT_FS = 40.0

#: Kinds of problem a reader counts. Every skipped byte or record lands in one.
ISSUE_KINDS = (
    "bad_checksum",  # 8-bit checksum or CRC-16 mismatch
    "malformed_field",  # a field that does not parse as its type, or a wrong field count
    "unknown_message",  # a well-formed record of a type we do not decode
    "truncated_record",  # a record cut short (end of file, or next record started)
    "bytes_skipped",  # bytes that belong to no record (noise between records)
    "device_error",  # $VNERR replies, recorded not decoded
)


@dataclass(frozen=True)
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
        for bags.
    location : str
        ``"line"``, ``"byte"`` or ``"message"``: what the numbers in ``first`` are.
    """

    counts: Mapping[str, int]
    first: Mapping[str, tuple[int, ...]] = field(default_factory=dict)
    location: str = "line"

    def __post_init__(self) -> None:
        counts = {kind: int(self.counts.get(kind, 0)) for kind in ISSUE_KINDS}
        unknown = set(self.counts) - set(ISSUE_KINDS)
        if unknown:
            raise ValueError(f"counts has unknown issue kinds {sorted(unknown)}")
        object.__setattr__(self, "counts", MappingProxyType(counts))
        first = {kind: tuple(self.first.get(kind, ())) for kind in ISSUE_KINDS}
        object.__setattr__(self, "first", MappingProxyType(first))

    @property
    def total(self) -> int:
        """Records skipped (``bytes_skipped`` counts bytes, so it is not included)."""
        return sum(v for k, v in self.counts.items() if k != "bytes_skipped")

    @classmethod
    def none(cls) -> ParseIssues:
        return cls(counts={})

    def __str__(self) -> str:
        parts = [f"{k}={v}" for k, v in self.counts.items() if v]
        return "no issues" if not parts else ", ".join(parts)


#: Channel name -> (columns, unit). Every channel is float64 (n, columns).
CHANNELS: Mapping[str, tuple[int, str]] = MappingProxyType(
    {
        "gyro": (3, "rad/s"),
        "accel": (3, "m/s^2"),
        "mag": (3, "Gauss"),
        "ypr": (3, "deg"),
        "quaternion": (4, "1"),
        "temperature": (1, "degC"),
        "pressure": (1, "kPa"),
        "delta_theta": (3, "deg"),
        "delta_velocity": (3, "m/s"),
    }
)


@dataclass(frozen=True)
class ImuLog:
    """An IMU recording: uniform-rate channels plus the record of what was skipped.

    Channels the log does not contain are ``None``. Arrays are float64 with one
    row per sample: ``gyro``, ``accel``, ``mag``, ``ypr``, ``delta_theta``,
    ``delta_velocity`` are (n, 3); ``quaternion`` (n, 4); ``temperature`` and
    ``pressure`` (n,). ``time`` (n,) in seconds when the log carries timestamps.

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

    def __post_init__(self) -> None:
        if not (np.isfinite(self.fs) and self.fs > 0):
            raise ValueError(f"fs must be a positive finite number of Hz; got {self.fs!r}")
        lengths = {}
        for name, (cols, _unit) in CHANNELS.items():
            value = getattr(self, name)
            if value is None:
                continue
            arr = np.asarray(value, dtype=np.float64)
            expected_ndim = 1 if cols == 1 else 2
            if arr.ndim != expected_ndim or (cols > 1 and arr.shape[1] != cols):
                want = "(n,)" if cols == 1 else f"(n, {cols})"
                raise ValueError(f"{name} must have shape {want}; got {arr.shape}")
            arr.flags.writeable = False
            object.__setattr__(self, name, arr)
            lengths[name] = len(arr)
        if self.time is not None:
            t = np.asarray(self.time, dtype=np.float64)
            t.flags.writeable = False
            object.__setattr__(self, "time", t)
            lengths["time"] = len(t)
        if len(set(lengths.values())) > 1:
            raise ValueError(f"channels must have equal lengths; got {lengths}")
        object.__setattr__(self, "messages", MappingProxyType(dict(self.messages)))

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
        """Length of the record in seconds (samples / fs)."""
        return len(self) / self.fs

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
        """Wrap arrays already in memory (SI units as in :data:`CHANNELS`)."""
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


def resolve_fs(time: np.ndarray | None, fs: float | None, source: str) -> float:
    """The sample rate: median timestamp step, else ``fs``, else the default with a warning."""
    median_step = None
    if time is not None and len(time) > 1:
        steps = np.diff(np.asarray(time, dtype=np.float64))
        steps = steps[steps > 0]
        if len(steps):
            median_step = float(np.median(steps))
    return fs_from_median_step(median_step, fs, source, stacklevel=4)


def fs_from_median_step(
    median_step: float | None, fs: float | None, source: str, *, stacklevel: int = 3
) -> float:
    """1 / ``median_step`` when the log had timestamps, else ``fs``, else
    :data:`DEFAULT_FS` with a warning (``stacklevel`` points it at the caller's caller)."""
    if median_step is not None:
        return float(1.0 / median_step)
    if fs is not None:
        fs = float(fs)
        if not (np.isfinite(fs) and fs > 0):
            raise ValueError(f"fs must be a positive finite number of Hz; got {fs!r}")
        return fs
    warnings.warn(
        f"{source}: no timestamps and no fs given; assuming {DEFAULT_FS:g} Hz "
        "(pass fs= to set the sample rate)",
        stacklevel=stacklevel,
    )
    return DEFAULT_FS
