"""VectorNav VN-100 logs: ASCII sentences and binary packets, decoded in Rust.

The Rust reader walks the byte stream once (ASCII and binary may be interleaved,
with noise between records), checks every XOR-8 checksum and CRC-16, and returns
one column table per message type. This module turns those tables into an
:class:`~imunoise.readers.log.ImuLog`.

Several message types in one stream
-----------------------------------
Each message type is decoded into its own table (``$VNYMR``, ``$VNIMU``, one per
binary output configuration ...). ``ImuLog.messages`` counts the records of every
type; the channels of the ``ImuLog`` come from *one* table, the richest one: the
table that fills the most channels (gyro, accel, mag, ypr, quaternion,
temperature, pressure, delta-theta/velocity), ties broken by the number of
records. All tables, with every column, are available from :func:`read_vn_tables`.

Units are the sensor's (spec §3.1, §5.3), which are already those of
:data:`~imunoise.readers.log.CHANNELS`: gyro rad/s, accel m/s², mag Gauss, yaw/
pitch/roll deg, temperature °C, pressure kPa, delta-theta deg, delta-velocity m/s.
Where a message carries compensated and uncompensated values, the compensated
ones are used.

Time grid and gaps
------------------
``time`` is the binary ``TimeStartup`` (s since power-up) when the packets carry
it, else ``TimeGps``, else ``TimeSyncIn`` (only when it never runs backwards, i.e.
no SyncIn pulse reset it); the grid, the rate and the dropouts come from it
(:mod:`imunoise.readers.grid`). ASCII sentences with an appended ``T`` counter
(register 30) that only increases are placed by that counter (its unit is not
known, so the rate is ``fs=``). Otherwise the log has no timestamps, and every
damaged record of the main message stream (bad checksum or CRC, malformed field,
truncated) whose message type can still be read stands for one missing sample at
its place in the sequence.
"""

from __future__ import annotations

import errno
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType

import numpy as np

from imunoise._core import vn as _core_vn
from imunoise.errors import ImunoiseTypeError, ParseError
from imunoise.readers import recording
from imunoise.readers.grid import MAX_GRID_RATIO, TimeGrid
from imunoise.readers.log import ISSUE_KINDS, ImuLog, ParseIssues, log_on_grid

#: channel -> candidate column triples (compensated first), names without group prefix.
_CHANNEL_COLUMNS: Mapping[str, tuple[tuple[str, ...], ...]] = {
    "gyro": (("gyro_x", "gyro_y", "gyro_z"), ("uncomp_gyro_x", "uncomp_gyro_y", "uncomp_gyro_z")),
    "accel": (
        ("accel_x", "accel_y", "accel_z"),
        ("uncomp_accel_x", "uncomp_accel_y", "uncomp_accel_z"),
    ),
    "mag": (("mag_x", "mag_y", "mag_z"), ("uncomp_mag_x", "uncomp_mag_y", "uncomp_mag_z")),
    "ypr": (("yaw", "pitch", "roll"),),
    "quaternion": (("qx", "qy", "qz", "qw"),),
    "temperature": (("temperature",),),
    "pressure": (("pressure",),),
    "delta_theta": (("delta_theta_x", "delta_theta_y", "delta_theta_z"),),
    "delta_velocity": (("delta_vel_x", "delta_vel_y", "delta_vel_z"),),
}
_GROUPS = ("common", "imu", "attitude", "time")


@dataclass(frozen=True)
class VnTables:
    """Everything the VN reader decoded, before choosing channels.

    Attributes
    ----------
    tables : Mapping[str, Mapping[str, np.ndarray]]
        Per message type (``"VNYMR"``, ``"VNERR"``, ``"binary_143e003a00"`` ...)
        the float64 columns by field name; binary column names are qualified by
        group (``"common.yaw"``, ``"imu.uncomp_gyro_x"``). The columns of one
        type are strided views of one row-major (records, fields) array, so the
        channels built from them are views too (no copy).
    messages : Mapping[str, int]
        Records per message type, including command responses (``"VNRRG"``).
    issues : ParseIssues
        Skipped records and bytes; ``first`` holds line numbers when the stream
        is mostly ASCII, byte offsets otherwise.
    bytes_total, bytes_parsed, bytes_in_bad_records, bytes_skipped : int
        Byte accounting: ``bytes_parsed + bytes_in_bad_records + bytes_skipped ==
        bytes_total`` for every input.
    ascii_records, binary_records : int
        Decoded records of each framing.
    missing : Mapping[str, numpy.ndarray]
        Per message type, for every damaged record of that type (bad checksum or
        CRC, malformed field, truncated record, whose type could still be read):
        the number of good records of the type before it (int64, increasing).
    format : str
        ``"vn-binary"`` if binary packets outnumber sentences, else ``"vn-ascii"``.
    """

    tables: Mapping[str, Mapping[str, np.ndarray]]
    messages: Mapping[str, int]
    issues: ParseIssues
    bytes_total: int
    bytes_parsed: int
    bytes_in_bad_records: int
    bytes_skipped: int
    ascii_records: int
    binary_records: int
    missing: Mapping[str, np.ndarray] = field(default_factory=dict)
    format: str = "vn-ascii"


def _source_arg(source) -> bytes | str:
    if isinstance(source, (bytes, bytearray, memoryview)):
        return bytes(source)
    if isinstance(source, (str, os.PathLike)):
        path = os.fspath(source)
        if not os.path.exists(path):
            raise FileNotFoundError(errno.ENOENT, "no such file", path)
        return path
    raise ImunoiseTypeError(f"source must be a path or bytes; got {type(source).__name__}")


def read_vn_tables(
    source,
    *,
    strict: bool = False,
    progress: Callable[[int, int], object] | None = None,
) -> VnTables:
    """Decode a VN stream (path or bytes) into per-message-type column tables.

    Parameters
    ----------
    source : str, os.PathLike or bytes
        A file (read in chunks, never whole into memory) or the bytes of a stream.
    strict : bool
        Raise :class:`~imunoise.errors.ParseError` (a ``ValueError``) with the
        kind, line and byte offset of the first damaged record (bad checksum or
        CRC, malformed field, truncated record) instead of skipping and counting it.
    progress : callable, optional
        ``progress(bytes_done, bytes_total)``, called every chunk (8 MB) of a file.

    Returns
    -------
    VnTables
    """
    raw = _core_vn.parse_vn(_source_arg(source), strict, progress)
    return tables_of(raw)


def tables_of(raw: _core_vn.VnResult) -> VnTables:
    """:class:`VnTables` of a Rust parse result (read-only mappings, locations as
    lines for ASCII streams and byte offsets for binary ones)."""
    binary = raw.format == "vn-binary"
    pick = 0 if binary else 1
    first = {k: tuple(loc[pick] for loc in raw.first.get(k, ())) for k in ISSUE_KINDS}
    location = "byte" if binary else "line"
    issues = ParseIssues(counts=dict(raw.issues), first=first, location=location)
    tables = MappingProxyType(
        {name: MappingProxyType(dict(cols)) for name, cols in raw.tables.items()}
    )
    return VnTables(
        tables=tables,
        messages=MappingProxyType(dict(raw.messages)),
        issues=issues,
        bytes_total=raw.bytes_total,
        bytes_parsed=raw.bytes_parsed,
        bytes_in_bad_records=raw.bytes_in_bad_records,
        bytes_skipped=raw.bytes_skipped,
        ascii_records=raw.ascii_records,
        binary_records=raw.binary_records,
        missing=MappingProxyType(
            {k: np.asarray(v, dtype=np.int64) for k, v in raw.missing.items()}
        ),
        format=raw.format,
    )


def _lookup(cols: Mapping[str, np.ndarray], names: tuple[str, ...]) -> list[np.ndarray] | None:
    for prefix in ("", *(g + "." for g in _GROUPS)):
        found = [cols.get(prefix + n) for n in names]
        if all(c is not None for c in found):
            return found  # type: ignore[return-value]
    return None


def _stack(cols: list[np.ndarray]) -> np.ndarray:
    """``np.column_stack(cols)``, without the copy when the columns are adjacent.

    The Rust reader returns each table as one row-major matrix and its columns as
    views of it, so ``gyro_x, gyro_y, gyro_z`` sit 8 bytes apart in every row: the
    (n, 3) channel is then a read-only view of those rows. Element ``(r, j)`` of
    the view is the very element ``cols[j][r]``, so this is exact whatever the
    columns' origin; anything else is stacked.
    """
    first = cols[0]
    step = first.itemsize
    addr = first.__array_interface__["data"][0]
    adjacent = all(
        c.ndim == 1
        and c.dtype == first.dtype
        and len(c) == len(first)
        and c.strides == first.strides
        and c.__array_interface__["data"][0] == addr + j * step
        for j, c in enumerate(cols)
    )
    if adjacent and len(first) > 1:
        return np.lib.stride_tricks.as_strided(
            first, shape=(len(first), len(cols)), strides=(first.strides[0], step), writeable=False
        )
    return np.column_stack(cols)


def table_channels(cols: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The :class:`ImuLog` channels (and ``time``) one table can fill."""
    out: dict[str, np.ndarray] = {}
    for channel, candidates in _CHANNEL_COLUMNS.items():
        for names in candidates:
            found = _lookup(cols, names)
            if found is not None:
                out[channel] = found[0] if len(found) == 1 else _stack(found)
                break
    for name in ("time_startup", "time_gps", "time_syncin"):
        time = _lookup(cols, (name,))
        if time is not None and (name != "time_syncin" or np.all(np.diff(time[0]) >= 0)):
            out["time"] = time[0]
            break
    return out


def richest_table(shapes: Mapping[str, tuple[int, int]]) -> str | None:
    """The table the channels come from, given ``(channels filled, rows)`` per
    table: the most channels, then the most rows (``None`` if none fills one)."""
    best: tuple[int, int] = (-1, -1)
    chosen = None
    for name, (filled, n) in shapes.items():
        if filled and (filled, n) > best:
            best, chosen = (filled, n), name
    return chosen


def _primary(tables: Mapping[str, Mapping[str, np.ndarray]]) -> tuple[str, dict[str, np.ndarray]]:
    channels = {name: table_channels(cols) for name, cols in tables.items()}
    shapes = {
        name: (
            sum(1 for k in channels[name] if k != "time"),
            len(next(iter(cols.values()))) if cols else 0,
        )
        for name, cols in tables.items()
    }
    name = richest_table(shapes)
    return ("", {}) if name is None else (name, channels[name])


def _grid(tables: VnTables, name: str, time: np.ndarray | None, n: int) -> TimeGrid | None:
    """The grid of the main table: ``None`` when it has timestamps (the grid is
    theirs), else from its ``T`` counter, else from the places of its damaged
    records (see the module docstring)."""
    if time is not None:
        return None
    counter = tables.tables[name].get("serial_count") if name else None
    if counter is not None and len(counter) > 2 and np.all(np.diff(counter) > 0):
        try:
            grid = TimeGrid.from_timestamps(counter)
        except ValueError:
            pass  # not a sample counter
        else:
            return TimeGrid(grid.slot, grid.n, duplicate_time=grid.duplicate_time)
    return TimeGrid.from_missing(n, tables.missing.get(name, ()))


def vn_log(tables: VnTables, *, fs: float | None, source: str, grid: bool = True) -> ImuLog:
    """Build the :class:`ImuLog` from decoded tables (channels from the richest table).

    ``grid=False`` keeps one row per decoded record (for sentences embedded in a
    container that has its own timestamps).
    """
    name, channels = _primary(tables.tables)
    time = channels.pop("time", None)
    n = len(next(iter(channels.values()))) if channels else 0
    return log_on_grid(
        fs=fs,
        source=source,
        format=tables.format,
        issues=tables.issues,
        channels=channels,
        time=time,
        messages=tables.messages,
        grid=_grid(tables, name, time, n) if grid else TimeGrid.identity(n),
    )


def read_vn(
    source,
    *,
    strict: bool = False,
    fs: float | None = None,
    progress: Callable[[int, int], object] | None = None,
) -> ImuLog:
    """Read a VN-100 log (ASCII, binary or both interleaved) into an :class:`ImuLog`.

    See :func:`read_vn_tables` for the arguments and the module docstring for how
    channels are chosen when the stream has several message types. A log written
    by ``imunoise record`` brings its side files (:mod:`imunoise.readers.recording`):
    ``fs`` defaults to the rate the recorder set, and without timestamps each port
    outage is a gap of its length at its place.
    """
    if isinstance(source, (bytes, bytearray, memoryview)):
        return vn_log(read_vn_tables(source, strict=strict, progress=progress), fs=fs,
                      source="<bytes>")
    name = os.fspath(source)
    tables = read_vn_tables(source, strict=strict, progress=progress)
    fs = fs if fs is not None else recording.recorded_fs(name)
    cut = recording.outages(name)
    if cut:
        tables = _with_outages(tables, name, cut, fs)
    return vn_log(tables, fs=fs, source=name)


def _with_outages(tables: VnTables, path: str, cut, fs: float | None) -> VnTables:
    """``tables`` with ``round(seconds * fs)`` missing records of the main table at
    every outage (the good records before its byte offset), when the main table
    has no timestamps and the rate is known."""
    name, channels = _primary(tables.tables)
    if not name or "time" in channels or fs is None:
        return tables
    stream = _core_vn.VnStream(False)
    before, rows, done = [], 0, 0
    records = len(next(iter(tables.tables[name].values()), ()))
    # the grid's own bound (MAX_GRID_RATIO), checked before the rows are listed: an
    # outage of 1e12 s must be an error naming its line, not a MemoryError
    room, side = (MAX_GRID_RATIO - 1) * records, path + recording.GAPS
    with open(path, "rb") as f:
        for outage in sorted(cut, key=lambda o: o.offset):
            while done < outage.offset:
                piece = f.read(min(outage.offset - done, 1 << 23))
                if not piece:
                    break
                done += len(piece)
                cols = stream.feed(piece).tables.get(name, {})
                rows += len(next(iter(cols.values()))) if cols else 0
            missing = max(0, round(outage.seconds * fs) - 1)
            room -= missing
            if room < 0:
                raise ParseError(
                    f"the outages up to this one leave more than {MAX_GRID_RATIO - 1}x the "
                    f"{records} records missing (this one: {outage.seconds:.6g} s at {fs:g} "
                    f"Hz, {missing} samples); not a gap of this recording",
                    kind="malformed_field", line=outage.line, source=side)
            before.extend([rows] * missing)
    missing = dict(tables.missing)
    missing[name] = np.sort(np.concatenate([np.asarray(missing.get(name, ()), np.int64),
                                            np.asarray(before, np.int64)]))
    return replace(tables, missing=MappingProxyType(missing))


def parse_vn_sentences(
    data: bytes, *, strict: bool = False, fs: float | None = None, source: str = "<bytes>"
) -> ImuLog:
    """Decode raw VN sentences found elsewhere (a CSV column, a ROS string field).

    ``data`` is the sentences' bytes, e.g. joined with newlines; text around the
    sentences is counted as skipped bytes, not an error.
    """
    if not isinstance(data, (bytes, bytearray, memoryview)):
        raise ImunoiseTypeError(f"data must be bytes; got {type(data).__name__}")
    return vn_log(read_vn_tables(bytes(data), strict=strict), fs=fs, source=source, grid=False)
