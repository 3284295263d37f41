"""The side files ``imunoise record`` writes beside a raw log, as the readers see them.

``LOG`` is the raw byte stream exactly as the sensor sent it; beside it:

- ``LOG.times``: one line ``<byte offset> <host time, Unix ns>`` per chunk
  received (the offset of the chunk's first byte), to check the time grid;
- ``LOG.gaps``: one line ``<byte offset> <start> <end>`` per port outage (Unix
  seconds: the last chunk before it, the first recorded after it); the raw log
  simply continues at that offset, nothing is spliced;
- ``LOG.meta.json``: the sensor's identity, the settings recorded with (``fs``:
  the main output's rate) and those restored (:func:`recording_meta` checks it
  field by field; every field is optional, unknown ones are ignored).

A malformed side file is a :class:`~imunoise.errors.ParseError` naming it (and
the line or field); only its last line may be cut (a kill), and is left out.

:func:`outages` feeds a log's outages to the VN reader, which puts them on the
time grid of logs without timestamps (logs with timestamps show them already).
"""

from __future__ import annotations

import math
import os
import stat
from dataclasses import dataclass, field

import numpy as np

from imunoise._support import warn as _warn
from imunoise.errors import DataWarning, ImunoiseValueError, ParseError
from imunoise.readers import metafile

__all__ = ["GAPS", "MAX_OUTAGE", "META", "SPAN_SLACK", "TIMES", "Outage", "host_times",
           "outages", "recorded_fs", "recording_meta"]

TIMES = ".times"
GAPS = ".gaps"
META = ".meta.json"


@dataclass(frozen=True)
class Outage:
    """The port was gone from ``start`` to ``end`` (Unix s); the log resumes at byte
    ``offset``."""

    offset: int
    start: float
    end: float
    #: 1-based line of ``LOG.gaps`` it was read from (``None`` when not read from one).
    line: int | None = field(default=None, compare=False)

    @property
    def seconds(self) -> float:
        return self.end - self.start


#: Seconds an outage may reach beyond the recording's host-time span: the times of
#: ``.gaps`` and ``.times`` are taken by separate clock calls.
SPAN_SLACK = 1.0
#: Longest outage accepted where the recording's span is unknown (no ``.times``,
#: no ``seconds`` in the metadata), s: 30 days, longer than any recording; without
#: a bound, ``100 0 1e12`` asks the reader for 10^13 missing samples.
MAX_OUTAGE = 30 * 86400.0


def _lines(side: str) -> list[tuple[int, str]] | None:
    """Numbered complete lines of a side file (``None`` without one); a last line
    without its newline was cut by a kill and is left out. Only a regular file is
    read (a FIFO would block)."""
    try:
        fd = os.open(side, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except (FileNotFoundError, NotADirectoryError):
        return None
    except OSError as exc:
        raise ParseError(f"cannot be opened ({exc.strerror})", kind="malformed_field",
                         source=side) from None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise ParseError("not a regular file (a FIFO, device, socket or directory); "
                             "refusing to wait on it", kind="malformed_field", source=side)
        with os.fdopen(fd, "rb", closefd=False) as f:
            text = f.read().decode("ascii", errors="replace")
    finally:
        os.close(fd)
    lines = text.split("\n")
    return [(i + 1, line) for i, line in enumerate(lines[:-1])]  # the last: "" or cut


def _bad_line(side: str, line_no: int, reason: str) -> ParseError:
    return ParseError(reason, kind="malformed_field", line=line_no, source=side)


def host_times(path) -> tuple[np.ndarray, np.ndarray]:
    """``(offsets, seconds)``: byte offset of each chunk received and its host time
    (Unix s), from ``LOG.times`` (empty arrays without one; a last line cut by a kill
    is left out; any other line that is not two integers >= 0 is a
    :class:`ParseError` naming the file and line)."""
    side = os.fspath(path) + TIMES
    offsets, ns = [], []
    for line_no, line in _lines(side) or ():
        parts = line.split()
        if len(parts) != 2 or not all(p.isdigit() and len(p) <= 19 for p in parts):
            raise _bad_line(side, line_no, f"must be '<byte offset> <host time, Unix ns>' "
                            f"(two integers >= 0 of at most 19 digits); got {line[:60]!r}")
        offsets.append(int(parts[0]))
        ns.append(int(parts[1]))
    return (np.asarray(offsets, dtype=np.int64),
            np.asarray(ns, dtype=np.int64).astype(np.float64) / 1e9)


def _times_span(path) -> float | None:
    """Seconds from the first to the last complete line of ``LOG.times`` (``None``
    without two); only those two lines are read: a day's recording has millions."""
    side = os.fspath(path) + TIMES
    try:
        if not stat.S_ISREG(os.stat(side).st_mode):
            return None  # host_times says what is wrong with it
        with open(side, "rb") as f:
            first = f.readline()
            f.seek(max(0, os.fstat(f.fileno()).st_size - 4096))
            tail = f.read().split(b"\n")[:-1]  # the last element: "" or a cut line
    except (FileNotFoundError, NotADirectoryError):
        return None
    if not first.endswith(b"\n") or not tail:
        return None
    stamps = []
    for line in (first[:-1], tail[-1]):
        parts = line.split()
        if len(parts) != 2 or not parts[1].isdigit() or len(parts[1]) > 19:
            raise ParseError(f"its first and last lines must be '<byte offset> <host time, "
                             f"Unix ns>'; got {line[:60]!r}", kind="malformed_field",
                             source=side)
        stamps.append(int(parts[1]) / 1e9)
    return stamps[1] - stamps[0]


def _span(path) -> float:
    """The longest an outage of the recording at ``path`` can be, s: its host-time
    span (``LOG.times``, or ``seconds`` in the metadata if longer: an outage that
    ends the record comes after the last chunk) plus :data:`SPAN_SLACK`, else
    :data:`MAX_OUTAGE`."""
    times = _times_span(path)
    meta = recording_meta(path) or {}
    spans = [times] if times is not None else []
    if "seconds" in meta:
        spans.append(meta["seconds"])
    return max(spans) + SPAN_SLACK if spans else MAX_OUTAGE


def outages(path) -> list[Outage]:
    """The outages recorded beside the log at ``path`` (none without a ``.gaps``
    file; a last line cut by a kill is left out).

    Every other line must be ``<byte offset> <start> <end>``: an offset inside the
    log, finite times with ``start <= end``, and an outage no longer than the
    recording (:func:`_span`); else a :class:`ParseError` naming the file and line.
    """
    side = os.fspath(path) + GAPS
    lines = _lines(side)
    if not lines:
        return []
    size = os.path.getsize(path) if os.path.isfile(path) else None
    longest = _span(path)
    found = []
    for line_no, line in lines:
        parts = line.split()
        try:
            if len(parts) != 3 or not parts[0].isdigit() or len(parts[0]) > 19:
                raise ImunoiseValueError
            outage = Outage(int(parts[0]), float(parts[1]), float(parts[2]), line=line_no)
        except ValueError:
            raise _bad_line(side, line_no, f"must be '<byte offset> <start> <end>' (an integer "
                            f">= 0, two Unix times); got {line[:60]!r}") from None
        if not (math.isfinite(outage.start) and math.isfinite(outage.end)):
            raise _bad_line(side, line_no, f"start and end must be finite; got {line[:60]!r}")
        if not 0 <= outage.seconds <= longest:
            raise _bad_line(side, line_no, f"the outage must last from 0 to {longest:.6g} s "
                            f"(the recording's span); got {outage.seconds:.6g} s")
        if size is not None and outage.offset > size:
            raise _bad_line(side, line_no, f"byte offset {outage.offset} is beyond the log's "
                            f"{size} bytes")
        found.append(outage)
    return found


def recording_meta(path) -> dict | None:
    """The metadata of the recording at ``path`` (``LOG.meta.json``), checked; ``None``
    without one. A malformed field is a :class:`ParseError` naming the file and the
    field: ``fs`` a rate (or null), ``started``/``seconds`` finite times >= 0,
    ``bytes``/``baud`` counts, ``outages`` a count or a list (of objects or lists
    of finite numbers), ``port``/``ascii``
    text (or null), ``identity`` an object of texts, ``previous``/``written``
    objects of lists of texts."""
    where = os.fspath(path) + META
    meta = metafile.load(where)
    if meta is None:
        return None
    bad = metafile.bad_field
    if not isinstance(meta, dict):
        raise ParseError(f"the metadata is not a JSON object; got {metafile.shown(meta)}",
                         kind="malformed_field", source=where)
    if "imunoise_columnar" in meta:
        # the name earlier versions of convert gave the metadata of LOG.csv/LOG.npy: it
        # describes one of those, not this recording (see imunoise.readers.metafile)
        stem = os.path.basename(os.fspath(path))
        _warn.warn(f"{where} is the metadata an earlier imunoise convert wrote for {stem}.csv "
                   f"or {stem}.npy, not {stem}'s own; not used (rename it to "
                   f"{stem}.csv.meta.json or {stem}.npy.meta.json, whichever it is)", DataWarning)
        return None
    if meta.get("fs") is not None:
        metafile.rate(meta["fs"], where)
    for key in ("started", "seconds"):
        value = meta.get(key)
        if key in meta and (isinstance(value, bool) or not isinstance(value, int | float)
                            or not (math.isfinite(value) and 0 <= value <= 1e11)):
            raise bad(where, key, f"must be a time in [0, 1e11] s; got {metafile.shown(value)}")
    for key in ("bytes", "baud"):
        if key in meta:
            metafile.count(meta[key], where, key)
    if "outages" in meta and not isinstance(meta["outages"], list):
        metafile.count(meta["outages"], where, "outages")
    for i, item in enumerate(meta.get("outages") if isinstance(meta.get("outages"), list)
                             else ()):
        values = list(item.values()) if isinstance(item, dict) else item
        if not isinstance(values, list) or not all(
                isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
                for v in values):
            raise bad(where, f"outages[{i}]", f"must be an object or a list of finite numbers; "
                      f"got {metafile.shown(item)}")
    for key in ("port", "ascii"):
        if meta.get(key) is not None and not isinstance(meta[key], str):
            raise bad(where, key, f"must be a text or null; got {metafile.shown(meta[key])}")
    if "identity" in meta:
        ident = meta["identity"]
        if not isinstance(ident, dict) or not all(isinstance(v, str) for v in ident.values()):
            raise bad(where, "identity", f"must be an object of texts; got "
                      f"{metafile.shown(ident)}")
    for key in ("previous", "written"):
        if key in meta:
            regs = meta[key]
            if not isinstance(regs, dict) or not all(
                    isinstance(v, list) and all(isinstance(x, str) for x in v)
                    for v in regs.values()):
                raise bad(where, key, f"must be an object of lists of texts (register -> "
                          f"fields); got {metafile.shown(regs)}")
    return meta


def recorded_fs(path) -> float | None:
    """The main output's rate in the log's metadata (``None`` without one, or when
    the recorder could not tell it)."""
    meta = recording_meta(path)
    return None if meta is None or meta.get("fs") is None else float(meta["fs"])
