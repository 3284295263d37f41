"""Delimited text logs: CSV exported from a bag, logger output, whitespace columns.

:func:`read_csv` maps columns (by header name or 0-based index) to the channels of
:class:`~imunoise.readers.log.ImuLog`, converts units to the SI units of
:data:`~imunoise.readers.log.CHANNELS`, and accounts for every data line: each one
becomes a sample or is counted as ``malformed_field`` with its 1-based line number.
A column that carries raw VN-100 sentences (``$VNYMR,...*hh``) is decoded by the VN
parser and wins over parsed numeric columns of the same channels.
"""

from __future__ import annotations

import csv
import io
import math
import os
import re
import warnings
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

from imunoise._support import warn as _warn
from imunoise._support.schema import CHANNELS, COLUMN_SUFFIXES, G
from imunoise.errors import (
    AssumptionWarning,
    DataWarning,
    ImunoiseTypeError,
    ImunoiseValueError,
    ParseError,
)
from imunoise.readers import metafile
from imunoise.readers._sentences import IssueTally, sentence_rows
from imunoise.readers.columnar import check_meta, log_from_meta
from imunoise.readers.log import ImuLog, log_on_grid
from imunoise.readers.probe import Confidence, Probe

__all__ = ["LAYOUT_CHANNELS", "SUFFIXES", "UNITS", "read_csv", "sniff"]

#: Names ``columns=`` may map: the log's channels, its time, a column of VN sentences.
LAYOUT_CHANNELS = (*CHANNELS, "time", "raw")

#: Extensions read as delimited text whatever the content.
SUFFIXES = (".csv", ".tsv")

#: Unit name -> (channel family, factor to SI, offset) with SI = value * factor + offset.
UNITS: Mapping[str, tuple[str, float, float]] = {
    **{u: ("angular_rate", 1.0, 0.0) for u in ("rad/s", "rad/sec", "rps")},
    **{u: ("angular_rate", math.pi / 180, 0.0) for u in ("deg/s", "deg/sec", "dps", "°/s")},
    "deg/h": ("angular_rate", math.pi / 180 / 3600, 0.0),
    "mrad/s": ("angular_rate", 1e-3, 0.0),
    **{u: ("acceleration", 1.0, 0.0) for u in ("m/s^2", "m/s2", "m/s²", "mps2")},
    "g": ("acceleration", G, 0.0),
    "mg": ("acceleration", G * 1e-3, 0.0),
    "gauss": ("magnetic", 1.0, 0.0),
    "mgauss": ("magnetic", 1e-3, 0.0),
    **{u: ("magnetic", 1e4, 0.0) for u in ("t", "tesla")},
    "mt": ("magnetic", 10.0, 0.0),
    **{u: ("magnetic", 1e-2, 0.0) for u in ("ut", "µt", "microtesla")},
    "nt": ("magnetic", 1e-5, 0.0),
    "deg": ("angle", 1.0, 0.0),
    "rad": ("angle", 180 / math.pi, 0.0),
    "1": ("unitless", 1.0, 0.0),
    **{u: ("temperature", 1.0, 0.0) for u in ("degc", "c", "°c")},
    "k": ("temperature", 1.0, -273.15),
    "kpa": ("pressure", 1.0, 0.0),
    "pa": ("pressure", 1e-3, 0.0),
    **{u: ("pressure", 0.1, 0.0) for u in ("hpa", "mbar")},
    "bar": ("pressure", 100.0, 0.0),
    "m/s": ("velocity", 1.0, 0.0),
    "s": ("time", 1.0, 0.0),
    "ms": ("time", 1e-3, 0.0),
    **{u: ("time", 1e-6, 0.0) for u in ("us", "µs")},
    "ns": ("time", 1e-9, 0.0),
}

_FAMILY = {
    "gyro": "angular_rate",
    "accel": "acceleration",
    "mag": "magnetic",
    "ypr": "angle",
    "quaternion": "unitless",
    "temperature": "temperature",
    "pressure": "pressure",
    "delta_theta": "angle",
    "delta_velocity": "velocity",
    "time": "time",
}

# Header-name patterns, matched against the normalised name (lower case, separators
# replaced by "_", unit suffix removed, a leading "field_" dropped).
_VECTOR_PREFIXES = {
    "gyro": ("gyro", "gyr", "gyroscope", "g", "w", "omega", "angular_velocity", "ang_vel"),
    "accel": ("acc", "accel", "accelerometer", "acceleration", "a", "linear_acceleration"),
    "mag": ("mag", "magnetometer", "m", "magnetic_field", "b"),
    # the names imunoise's own writers give (_schema.column_names)
    "ypr": ("ypr",),
    "delta_theta": ("delta_theta",),
    "delta_velocity": ("delta_velocity",),
}
_TIME_NAMES = (
    "time",
    "timestamp",
    "t",
    "stamp",
    "header_stamp",
    "ros_t",
    "bag_t",
    "%time",
    "time_s",
    "time_ns",
    "timestamp_ns",
)
_RAW_NAMES = ("raw", "sentence", "raw_imu_string", "vnymr")
_SENTENCE = re.compile(r"\$VN[A-Z]{3}[,*]")

_CHUNK_BYTES = 1 << 22


def sniff(probe: Probe) -> Confidence:
    """A ``.csv``/``.tsv`` file; a header of names followed by a row of as many
    fields (as sure as an extension: a stream has none, and VN sentences in a
    column must not make it a VN log); else a first line with a delimiter (a weak
    guess)."""
    if probe.is_dir:
        return Confidence.NO
    if probe.suffix in SUFFIXES:
        return Confidence.NAME
    if _has_header(probe.head):
        return Confidence.NAME
    first_line = probe.head.split(b"\n", 1)[0]
    if any(d in first_line for d in (b",", b"\t", b";", b" ")):
        return Confidence.GUESS
    return Confidence.NO


def _has_header(head: bytes) -> bool:
    """A first line (after ``#`` comments) of at least two names, then a line with
    as many fields."""
    lines = [ln for ln in head.decode("latin-1").splitlines()
             if ln.strip() and not ln.lstrip().startswith("#")][:2]
    if len(lines) < 2 or "$VN" in lines[0]:
        return False
    delimiter = next((d for d in (",", "\t", ";") if d in lines[0]), None)
    if delimiter is None:
        return False
    names = _split(lines[0], delimiter)
    return (len(names) >= 2
            and all(re.match(r"\s*\"?[A-Za-z_%]", f) and not _is_number(f) for f in names)
            and len(_split(lines[1], delimiter)) == len(names))


def _normalise(name: str) -> tuple[str, str | None]:
    """Normalised header name and the unit written in it (``gx [deg/s]``), if any."""
    name = name.strip().strip('"').strip()
    unit = None
    m = re.match(r"^(.*?)\s*[\[(]([^\])]+)[\])]\s*$", name)
    if m:
        name, unit = m.group(1), m.group(2).strip()
    norm = re.sub(r"[.\-\s/:]+", "_", name.lower()).strip("_")
    if norm.startswith("field_"):
        norm = norm[len("field_") :]
    return norm, unit


def _unit_factor(channel: str, unit: str) -> tuple[float, float]:
    key = unit.strip().lower().replace(" ", "")
    if key not in UNITS and channel == "mag" and key in ("g", "mg"):
        key = {"g": "gauss", "mg": "mgauss"}[key]
    if key not in UNITS:
        raise ImunoiseValueError(
            f"units[{channel!r}]: unknown unit {unit!r}; known units: {sorted(UNITS)}")
    family, factor, offset = UNITS[key]
    if family != _FAMILY[channel]:
        raise ImunoiseValueError(
            f"units[{channel!r}]: {unit!r} is a unit of {family}, not of {_FAMILY[channel]}"
        )
    return factor, offset


_BYTES = "<bytes>"  # the name of a log given as bytes


def _open(source) -> tuple[io.BufferedIOBase, int, str]:
    """The open file, its size and its name; ``FileNotFoundError`` if missing."""
    if isinstance(source, bytes | bytearray | memoryview):
        data = bytes(source)
        return io.BytesIO(data), len(data), _BYTES
    if isinstance(source, str | os.PathLike):
        path = os.fspath(source)
        return open(path, "rb"), os.path.getsize(path), path
    raise ImunoiseTypeError(f"source must be a path or bytes; got {type(source).__name__}")


def _lines(fh, total: int, progress: Callable[[int, int], None] | None):
    """Yield (first_line_number, list_of_lines) chunks; lines without line endings."""
    line_no = 1
    rest = b""
    done = 0
    first = True
    while True:
        block = fh.read(_CHUNK_BYTES)
        done += len(block)
        if first:
            if block.startswith(b"\xef\xbb\xbf"):
                block = block[3:]
            first = False
        if not block:
            if rest:
                yield line_no, [rest.decode("latin-1").rstrip("\r")]
            if progress is not None:
                progress(done, total)
            return
        block = rest + block
        cut = block.rfind(b"\n")
        if cut < 0:
            rest = block
            continue
        rest = block[cut + 1 :]
        lines = block[:cut].decode("latin-1").split("\n")
        yield line_no, [ln[:-1] if ln.endswith("\r") else ln for ln in lines]
        line_no += len(lines)
        if progress is not None:
            progress(done, total)


def _split(line: str, delimiter: str | None) -> list[str]:
    if delimiter is None:
        return line.split()
    if '"' in line:
        try:
            return next(csv.reader([line], delimiter=delimiter))
        except (csv.Error, StopIteration):
            return line.split(delimiter)
    return line.split(delimiter)


def _number(text: str) -> float:
    """``float(text)``, without Python's digit separators (``1_000``): a logger never
    writes them, so a field with one is damaged, not a thousand."""
    if "_" in text:
        raise ImunoiseValueError(f"digit separator in {text!r}")
    return float(text)


def _is_number(text: str) -> bool:
    try:
        _number(text)
    except ValueError:
        return False
    return True


def _prefixed(index: dict[str, int], prefix: str, suffixes: Sequence[str]) -> list[int]:
    """Columns named ``<prefix>_<suffix>`` or ``<prefix><suffix>``; -1 where absent."""
    return [index.get(f"{prefix}_{c}", index.get(f"{prefix}{c}", -1)) for c in suffixes]


def _auto_columns(names: list[str], raw_col: int | None) -> dict[str, list[int]]:
    """Channel -> column indices from common header names."""
    norm = [_normalise(n)[0] for n in names]
    index = {n: i for i, n in reversed(list(enumerate(norm)))}
    found: dict[str, list[int]] = {}
    if raw_col is None:
        for channel, prefixes in _VECTOR_PREFIXES.items():
            for prefix in prefixes:
                cols = _prefixed(index, prefix, COLUMN_SUFFIXES[3])
                if min(cols) >= 0:
                    found[channel] = cols
                    break
        if "ypr" not in found and all(n in index for n in ("yaw", "pitch", "roll")):
            found["ypr"] = [index["yaw"], index["pitch"], index["roll"]]
        for prefix in ("q", "quat", "quaternion", "orientation"):
            cols = _prefixed(index, prefix, COLUMN_SUFFIXES[4])
            if min(cols) >= 0:
                found["quaternion"] = cols
                break
        for channel, options in (
            ("temperature", ("temperature", "temp")),
            ("pressure", ("pressure", "pres", "baro")),
        ):
            for opt in options:
                if opt in index:
                    found[channel] = [index[opt]]
                    break
    for opt in _TIME_NAMES:
        if opt in index and index[opt] != raw_col:
            found["time"] = [index[opt]]
            break
    return found


def _resolve(spec, names: list[str] | None, ncols: int, what: str) -> int:
    if isinstance(spec, bool) or not isinstance(spec, int | str | np.integer):
        raise ImunoiseTypeError(f"{what}: a column is a name or a 0-based index; got {spec!r}")
    if isinstance(spec, str):
        if names is None:
            raise ImunoiseValueError(
                f"{what}: column {spec!r} given by name but the file has no header")
        if spec in names:
            return names.index(spec)
        norm = [_normalise(n)[0] for n in names]
        if _normalise(spec)[0] in norm:
            return norm.index(_normalise(spec)[0])
        raise ImunoiseValueError(f"{what}: no column named {spec!r}; columns are {names}")
    if not 0 <= int(spec) < ncols:
        raise ImunoiseValueError(f"{what}: column index {spec} outside 0..{ncols - 1}")
    return int(spec)


def read_csv(
    source,
    *,
    strict: bool = False,
    fs: float | None = None,
    progress: Callable[[int, int], None] | None = None,
    columns: Mapping[str, Sequence[int | str] | int | str] | None = None,
    units: Mapping[str, str] | None = None,
    delimiter: str | None = None,
    time_column: int | str | None = None,
) -> ImuLog:
    """Read an IMU log from delimited text.

    Parameters
    ----------
    source : str, os.PathLike or bytes
        The file, or its contents.
    strict : bool
        Raise :class:`~imunoise.errors.ParseError` (``kind="malformed_field"``,
        ``.line`` the 1-based line) at the first data line that does not parse,
        instead of counting it as ``malformed_field``.
    fs : float, optional
        Sample rate in Hz, used when the file has no time column.
    progress : callable, optional
        Called as ``progress(done_bytes, total_bytes)`` after each chunk read.
    columns : mapping, optional
        Channel -> columns, each a header name or a 0-based index, e.g.
        ``{"gyro": ["gx", "gy", "gz"], "accel": [3, 4, 5], "time": "t"}``.
        Channels are those of :data:`~imunoise.readers.log.CHANNELS` plus ``"time"``
        and ``"raw"`` (a column of VN sentences). Default: recognised from the
        header (``gyro_x``/``gx``/``wx``/``angular_velocity.x``, ``acc_x``/``ax``/
        ``linear_acceleration.x``, ``mag_x``/``mx``, ``yaw``/``pitch``/``roll``,
        ``qx..qw``, ``temperature``, ``pressure``, ``time``/``timestamp``/``t``/
        ``stamp``/``ros_t``/``bag_t``), or a column holding ``$VN`` sentences.
    units : mapping, optional
        Channel -> unit of the file's values (see :data:`UNITS`), e.g.
        ``{"gyro": "deg/s", "accel": "g", "mag": "uT", "time": "ns"}``. Default: a
        unit written in the header (``gx [deg/s]``, ``acc_x (g)``), else the SI unit
        of the channel. A time column without a unit is in the unit its name
        ends with (``time_ns``, ``t_us``, ``stamp_ms``), else the one its values
        and rate say together (epoch times, an IMU's rate: see ``_time_unit``),
        with a warning when that guess is not seconds.
    delimiter : str, optional
        Field separator. Default: ``,`` if the first line has one, else tab, else
        ``;``, else runs of whitespace.
    time_column : int or str, optional
        Shortcut for ``columns["time"]``.

    Returns
    -------
    ImuLog
        ``format="csv"``; ``fs`` from the time column where present. With a time
        column the rows are put on the time grid: lines missing from the file
        become NaN rows and ``log.gaps`` (:mod:`imunoise.readers.grid`); a
        malformed line is one missing sample only then.

    Notes
    -----
    Blank lines and ``#`` comment lines before the header are not data. A data line
    with a different number of fields than the header (or first line), a field that
    is not a number, an infinite value in a used column or a NaN time is
    ``malformed_field``. ``nan`` in a channel column is a missing value (as
    ``imunoise convert`` writes the rows of missing samples).
    Fields with quoted line breaks are not supported.
    """
    units = dict(units or {})
    columns = dict(columns or {})
    if time_column is not None:
        columns["time"] = time_column
    for ch in columns:
        if ch not in LAYOUT_CHANNELS:
            raise ImunoiseValueError(
                f"columns: unknown channel {ch!r}; use {list(LAYOUT_CHANNELS)}")
    for ch in units:
        if ch not in _FAMILY:
            raise ImunoiseValueError(f"units: unknown channel {ch!r}; use {list(_FAMILY)}")
    if delimiter is not None and (not isinstance(delimiter, str) or len(delimiter) != 1):
        raise ImunoiseValueError(f"delimiter must be one character or None; got {delimiter!r}")

    fh, total, name = _open(source)
    tally = IssueTally()
    with fh:
        chunks = _lines(fh, total, progress)
        state = _Reader(name, strict, columns, units, delimiter, tally)
        state.meta = _convert_meta(name)
        state.total = total
        for first_line, lines in chunks:
            state.feed(first_line, lines)
    return state.finish(fs)


class _Reader:
    """Streaming state of one :func:`read_csv` call."""

    def __init__(self, name, strict, columns, units, delimiter, tally):
        self.name = name
        self.strict = strict
        self.user_columns = columns
        self.user_units = units
        self.delimiter = delimiter
        self.tally = tally
        self.layout_done = False
        self.numeric: dict[str, list[int]] = {}
        self.raw_col: int | None = None
        self.buf: np.ndarray | None = None  # (capacity, used numeric columns), grown as needed
        self.total = 0
        self.raw_items: list[bytes] = []  # VN fields of the current chunk
        self.raw_lines: list[int] = []
        self.vn_parts: list[dict[str, np.ndarray]] = []
        self.vn_time: list[np.ndarray | None] = []
        self.messages: dict[str, int] = {}
        self.rows = 0
        self.meta: dict | None = None  # of a CSV written by imunoise convert

    # -- layout -------------------------------------------------------------------
    def _layout(self, line: str, line_no: int, next_line: str | None) -> bool:
        """Decide delimiter, header and columns from the first data line.

        Returns True when ``line`` was a header (and so is not data).
        """
        if self.delimiter is None:
            self.delimiter = next((d for d in (",", "\t", ";") if d in line), None)
        fields = _split(line, self.delimiter)
        header = any(
            not _is_number(f) and "$VN" not in f and re.match(r"\s*[A-Za-z_%\"]", f) is not None
            for f in fields
        )
        names = [f.strip() for f in fields] if header else None
        self.ncols = len(fields)
        sample = line if not header else next_line
        sample_fields = _split(sample, self.delimiter) if sample is not None else []

        explicit = any(ch in CHANNELS for ch in self.user_columns)
        auto = _auto_columns(names, None) if names is not None and not explicit else {}
        raw_col = self._raw_column(names, sample_fields, explicit, auto)
        numeric = self._numeric_columns(names, raw_col, explicit, auto)
        if not numeric and raw_col is None:
            raise ImunoiseValueError(_no_columns_message(self.name, names, sample_fields))
        self.numeric = numeric
        self.raw_col = raw_col
        self.names = names
        self.used = sorted({i for idx in numeric.values() for i in idx})
        self.pos = {i: k for k, i in enumerate(self.used)}
        # NaN is a missing sample in a channel column, but a time must be a number
        self.time_pos = self.pos[numeric["time"][0]] if "time" in numeric else None
        self.conv = self._conversions(names, numeric)
        self.layout_done = True
        return header

    def _raw_column(
        self, names: list[str] | None, sample_fields: list[str], explicit: bool, auto
    ) -> int | None:
        """The column of VN sentences: as given, else (with no channel given) the
        first free column holding a sentence, else one with a raw-sentence name."""
        if "raw" in self.user_columns:
            return _resolve(self.user_columns["raw"], names, self.ncols, "columns['raw']")
        if explicit:
            return None
        taken = {i for idx in auto.values() for i in idx}
        for i, f in enumerate(sample_fields[: self.ncols]):
            if i not in taken and _SENTENCE.search(f):
                return i
        if names is None:
            return None
        norm = [_normalise(n)[0] for n in names]
        for opt in _RAW_NAMES:
            i = norm.index(opt) if opt in norm else -1
            if (
                i >= 0
                and i not in taken
                and not (i < len(sample_fields) and _is_number(sample_fields[i]))
            ):
                return i
        return None

    def _numeric_columns(
        self, names: list[str] | None, raw_col: int | None, explicit: bool, auto
    ) -> dict[str, list[int]]:
        """Channel (and ``time``) -> column indices: from the header unless channels
        were given, a time column from the header if none was, then the given ones."""
        numeric: dict[str, list[int]] = {}
        if names is not None and not explicit:
            numeric = auto if raw_col is None else _auto_columns(names, raw_col)
        elif names is not None and "time" not in self.user_columns:
            time_auto = _auto_columns(names, raw_col).get("time")
            if time_auto is not None:
                numeric["time"] = time_auto
        for ch, spec in self.user_columns.items():
            if ch == "raw":
                continue
            specs = [spec] if isinstance(spec, int | str | np.integer) else list(spec)
            want = 1 if ch == "time" else CHANNELS[ch][0]
            if len(specs) != want:
                raise ImunoiseValueError(f"columns[{ch!r}] needs {want} column(s); got {spec!r}")
            numeric[ch] = [_resolve(s, names, self.ncols, f"columns[{ch!r}]") for s in specs]
        return numeric

    def _conversions(
        self, names: list[str] | None, numeric: dict[str, list[int]]
    ) -> dict[str, tuple[float, float] | None]:
        """Channel -> (factor, offset) to the SI unit, from ``units=`` or else the
        unit in the header of its first column; ``None`` for values already in it."""
        header_units: dict[str, str] = {}
        if names is not None:
            for ch, idx in numeric.items():
                unit = _normalise(names[idx[0]])[1]
                if unit is not None and ch not in self.user_units:
                    header_units[ch] = unit
        conv = {}
        for ch in numeric:
            unit = self.user_units.get(ch, header_units.get(ch))
            conv[ch] = None if unit is None else _unit_factor(ch, unit)
        return conv

    # -- rows -----------------------------------------------------------------------
    def _bad(self, line_no: int, reason: str) -> None:
        if self.strict:
            if self.raw_items:  # a bad sentence on an earlier line is reported first
                sentence_rows(
                    self.raw_items, self.raw_lines, self.tally, strict=True, source=self.name
                )
            source = None if self.name == _BYTES else self.name
            raise ParseError(reason, kind="malformed_field", line=line_no, source=source)
        self.tally.add("malformed_field", line_no)

    def feed(self, first_line: int, lines: list[str]) -> None:
        start = 0
        if not self.layout_done:
            while start < len(lines) and (
                not lines[start].strip() or lines[start].lstrip().startswith("#")
            ):
                start += 1
            if start == len(lines):
                return
            nxt = next((ln for ln in lines[start + 1 :] if ln.strip()), None)
            if self._layout(lines[start], first_line + start, nxt):
                start += 1
        if self.raw_col is None and self._fast(first_line, lines, start):
            return
        self._slow(first_line, lines, start)

    def _fast(self, first_line: int, lines: list[str], start: int) -> bool:
        """Whole-chunk numeric parse; False sends the chunk to the line-by-line path."""
        body = lines[start:]
        line_idx = np.array([i for i, ln in enumerate(body) if ln.strip()], dtype=np.int64)
        if not len(line_idx):
            return True
        text = "\n".join(body)
        if self.delimiter is not None and '"' not in text:
            if text.count(self.delimiter) != len(line_idx) * (self.ncols - 1):
                return False
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                arr = np.loadtxt(
                    io.StringIO(text),
                    delimiter=self.delimiter,
                    dtype=np.float64,
                    comments=None,
                    ndmin=2,
                    quotechar='"' if self.delimiter is not None else None,
                )
        except (ValueError, UserWarning):
            return False
        if arr.shape != (len(line_idx), self.ncols):
            return False
        arr = arr[:, self.used]
        if np.isinf(arr).any() or (
            self.time_pos is not None and np.isnan(arr[:, self.time_pos]).any()
        ):
            return False
        self._append(arr, len(text))
        return True

    def _slow(self, first_line: int, lines: list[str], start: int) -> None:
        out = np.empty((len(lines) - start, len(self.used)), dtype=np.float64)
        keep_lines = []
        n = 0
        for k in range(start, len(lines)):
            line = lines[k]
            if not line.strip():
                continue
            line_no = first_line + k
            fields = _split(line, self.delimiter)
            if len(fields) != self.ncols:
                self._bad(line_no, f"{len(fields)} fields, expected {self.ncols}")
                continue
            row = out[n]
            ok = True
            for j, col in enumerate(self.used):
                text = fields[col].strip()
                try:
                    value = _number(text)
                except ValueError:
                    self._bad(line_no, f"column {col + 1} is not a number: {text[:40]!r}")
                    ok = False
                    break
                if math.isinf(value) or (math.isnan(value) and j == self.time_pos):
                    self._bad(line_no, f"column {col + 1} is not finite: {text[:40]!r}")
                    ok = False
                    break
                row[j] = value
            if not ok:
                continue
            if self.raw_col is not None:
                self.raw_items.append(fields[self.raw_col].encode("latin-1"))
                self.raw_lines.append(line_no)
            keep_lines.append(line_no)
            n += 1
        out = out[:n].copy()
        if self.raw_col is not None:
            rows = sentence_rows(
                self.raw_items, self.raw_lines, self.tally, strict=self.strict, source=self.name
            )
            self.raw_items, self.raw_lines = [], []
            out = out[rows.kept]
            self.vn_parts.append(rows.channels)
            self.vn_time.append(rows.time)
            for key, count in rows.messages.items():
                self.messages[key] = self.messages.get(key, 0) + count
        self._append(out, sum(len(ln) + 1 for ln in lines))

    # -- result ---------------------------------------------------------------------
    def _append(self, rows: np.ndarray, chunk_chars: int) -> None:
        """Copy a chunk's rows into one buffer sized from the file size (memory ~ output)."""
        need = self.rows + len(rows)
        if self.buf is None or need > len(self.buf):
            per_char = max(len(rows), 1) / max(chunk_chars, 1)
            estimate = int(per_char * self.total * 1.02) + 16
            cap = max(need, estimate if self.buf is None else int(len(self.buf) * 1.5))
            buf = np.empty((cap, len(self.used)), dtype=np.float64)
            if self.buf is not None:
                buf[: self.rows] = self.buf[: self.rows]
            self.buf = buf
        self.buf[self.rows : need] = rows
        self.rows = need

    def finish(self, fs: float | None) -> ImuLog:
        if not self.layout_done:
            raise ImunoiseValueError(f"{self.name}: no data lines")
        data = self.buf[: self.rows] if self.buf is not None else np.zeros((0, len(self.used)))
        if self.buf is not None and len(self.buf) > 1.1 * self.rows + 16:
            data = data.copy()  # do not keep a much larger buffer alive through views
        self.buf = None
        channels: dict[str, np.ndarray] = {}
        messages: dict[str, int] = dict(self.messages)
        time = None
        vn_time = None
        if self.raw_col is not None:
            parts = [p for p in self.vn_parts if p]
            for name in parts[0] if parts else ():
                channels[name] = np.concatenate([p[name] for p in parts])
            times = [t for p, t in zip(self.vn_parts, self.vn_time, strict=True) if p]
            if times and all(t is not None for t in times):
                vn_time = np.concatenate(times)
            self.vn_parts = []
        else:
            messages["csv"] = len(data)
        for ch, idx in self.numeric.items():
            pos = [self.pos[i] for i in idx]
            if pos == list(range(pos[0], pos[0] + len(pos))):
                values = data[:, pos[0] : pos[0] + len(pos)]  # a view: no copy
            else:
                values = data[:, pos]
            conv = self.conv[ch]
            if ch == "time":
                t = values[:, 0]
                if conv is None:
                    conv = _time_unit(t, self.names[idx[0]] if self.names else None, self.name)
                if conv is not None:
                    t = t * conv[0] + conv[1]
                time = t
                continue
            if conv is not None:
                values = values * conv[0] + conv[1]
            channels[ch] = values[:, 0] if CHANNELS[ch][0] == 1 else values
        if time is None:
            time = vn_time
        restored = _restore_meta(self, channels, time)
        if restored is not None:
            return restored
        return log_on_grid(
            fs=fs,
            source=self.name,
            format="csv",
            issues=self.tally.issues("line"),
            channels=channels,
            time=time,
            messages=messages,
            values_may_be_nan=True,
        )


def _convert_meta(name: str) -> dict | None:
    """The metadata ``imunoise convert`` wrote beside a CSV (``OUT.csv.meta.json``),
    checked (a malformed one is a :class:`ParseError` naming it and the field);
    ``None`` when there is none, or when it describes other bytes than the CSV's (the
    CSV was edited or replaced: it is read as a plain CSV, with a warning)."""
    if name == _BYTES:
        return None
    path = Path(name)
    meta_file = metafile.meta_path(path)
    meta = metafile.load(meta_file)
    if meta is None:
        _legacy_note(path)
        return None
    meta = check_meta(meta, meta_file, tied=True)
    why = metafile.tie_errors(meta["data"], path, meta_file)
    if why is not None:
        _warn.warn(f"{why}; its metadata is not used: read as a plain CSV", DataWarning)
        return None
    return meta


def _legacy_note(path: Path) -> None:
    """Say that the metadata an earlier version wrote under the shared name is not used."""
    legacy = metafile.legacy_path(path)
    try:
        meta = metafile.load(legacy)
    except ParseError:
        return  # not imunoise's, or not readable: nothing of ours to mention
    if isinstance(meta, dict) and "imunoise_columnar" in meta:
        _warn.warn(f"{path}: {legacy.name} beside it is the metadata name earlier versions "
                   f"gave {path.stem}.csv and {path.stem}.npy alike, so it is not used (read as "
                   f"a plain CSV); rename it to {path.name}{metafile.SUFFIX} if it is this "
                   "file's, or convert the log again", DataWarning)


def _restore_meta(reader: _Reader, channels, time) -> ImuLog | None:
    """The log a CSV of ``imunoise convert`` was written from, when every row is there
    as written: its rows are that log's grid, with its rate, issues and gaps."""
    meta = reader.meta
    if meta is None:
        return None
    arrays = dict(channels)
    if time is not None:
        arrays["time"] = time
    n = len(next(iter(arrays.values()), ()))
    if reader.tally.issues("line").total or n != meta["samples"] or set(arrays) != set(
            meta["channels"]):
        _warn.warn(
            f"{reader.name}: the rows no longer match the imunoise metadata beside it "
            f"({n} rows of {sorted(arrays)}, metadata {meta['samples']} of "
            f"{sorted(meta['channels'])}); read as a plain CSV", DataWarning
        )
        return None
    return log_from_meta(meta, arrays, reader.name)


#: Rates (Hz) a time unit may give an IMU log before another unit is looked for.
PLAUSIBLE_RATES = (1.0, 1e5)
#: Epoch times (s) between 2001 and 2103: a time column this large in some unit is
#: an epoch time in that unit.
EPOCH_SECONDS = (1e9, 4.3e9)
#: Units a time column without one is tried in, in this order (seconds first).
_TIME_UNITS = ("s", "ms", "us", "ns")


def _time_unit(t: np.ndarray, header: str | None, source: str) -> tuple[float, float] | None:
    """(factor, offset) of a time column whose unit neither ``units=`` nor the header
    says; ``None`` for seconds.

    A name ending in ``_ns``/``_us``/``_ms``/``_s`` says it. Else the values and the
    rate decide together: an epoch time (:data:`EPOCH_SECONDS`) in one of s, ms, µs,
    ns is in that unit; else seconds when they give a rate in
    :data:`PLAUSIBLE_RATES`, else the first of ms, µs, ns that does, with a
    warning (a guess: pass ``units={"time": ...}``).
    """
    norm = _normalise(header)[0] if header else ""
    for unit in _TIME_UNITS:
        if norm.endswith("_" + unit):
            return None if unit == "s" else UNITS[unit][1:]
    steps = np.diff(t)
    pos = steps[steps > 0]
    if not len(pos) and len(steps):
        pos = -steps[steps < 0]  # time that only goes back still has a step
    if not len(pos):
        return None
    step = float(np.median(pos))
    size = float(np.median(np.abs(t)))
    rate = {u: 1.0 / (step * UNITS[u][1]) for u in _TIME_UNITS}
    epoch = [u for u in _TIME_UNITS if EPOCH_SECONDS[0] <= size * UNITS[u][1] <= EPOCH_SECONDS[1]]
    if epoch:  # the magnitude of a date leaves no doubt
        return None if epoch[0] == "s" else UNITS[epoch[0]][1:]
    fits = [u for u in _TIME_UNITS if PLAUSIBLE_RATES[0] <= rate[u] <= PLAUSIBLE_RATES[1]]
    chosen = fits[0] if fits else "s"
    if chosen != "s":
        column = f"time column {header!r}" if header else "time column"
        _warn.warn(
            f"{source}: {column} has no unit; taken as {chosen}: a median step of {step:.6g} "
            f"gives {rate[chosen]:.6g} Hz in {chosen} ({rate['s']:.6g} Hz in seconds); pass "
            "units={'time': ...} (CLI: --units time=...) to say it", AssumptionWarning
        )
    return None if chosen == "s" else UNITS[chosen][1:]


def _no_columns_message(name: str, names: list[str] | None, first: list[str]) -> str:
    """Why no channel was found, with the first data row numbered and a ``columns=``
    example built from it (3-axis channels on consecutive numeric columns)."""
    what = names if names is not None else f"{len(first)} unnamed columns"
    shown = "  ".join(f"[{i}] {f.strip()}" for i, f in enumerate(first[:16]))
    more = f"  … ({len(first)} fields)" if len(first) > 16 else ""
    numeric = [i for i, f in enumerate(first) if _is_number(f)]
    example = ""
    if len(numeric) >= 3:
        picks = {ch: numeric[3 * k: 3 * k + 3]
                 for k, ch in enumerate(("gyro", "accel")) if len(numeric) >= 3 * k + 3}
        python = ", ".join(f"{ch!r}: {idx}" for ch, idx in picks.items())
        cli = " ".join(f"--columns {ch}={','.join(map(str, idx))}" for ch, idx in picks.items())
        example = (f"; say which column holds what (0-based), e.g. columns={{{python}}}, "
                   f"units={{'gyro': 'deg/s'}} (imunoise CLI: {cli} --units gyro=deg/s)")
    else:
        example = "; pass columns={'gyro': [...], ...}"
    return (f"{name}: no IMU columns recognised in {what}; first data row: {shown}{more}"
            f"{example}")
