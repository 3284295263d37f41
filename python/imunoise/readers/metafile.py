"""Metadata files: one per data file, read bounded and never blocking, checked
field by field, tied to the data they describe.

Where: the metadata of a file ``F`` is ``F.meta.json`` beside it, whatever ``F``
is: ``log.npy.meta.json``, ``log.csv.meta.json``, a recording's
``run.txt.meta.json`` (a directory written by ``imunoise convert`` keeps its
``meta.json`` inside it; ``.npz`` and Parquet carry theirs inside the file).
Earlier versions named it ``log.meta.json`` for ``log.npy`` and ``log.csv``
alike, which is also the name of the metadata of a recording called ``log``:
such a file cannot say which of them it describes, so it is never read for a
converted file (:func:`legacy_path` names it in the error, to be renamed by
whoever knows).

How it is read (:func:`load`): only a regular file (a FIFO would block the reader
forever), at most :data:`MAX_BYTES`, JSON without ``NaN``/``Infinity`` and at
most :data:`MAX_DEPTH` levels deep. Every fault is a
:class:`~imunoise.errors.ParseError` naming the metadata file and, for a field,
the field (:func:`bad_field`).

Tied to the data: what ``convert`` writes beside a file carries the file's
fingerprint (``"data"``: bytes, modification time and a digest, BLAKE3, or SHA-256
in what earlier versions wrote; see :func:`imunoise._support.atomic.publish_pair`);
:func:`check_tie` refuses metadata whose fingerprint is not that of the file beside it.
"""

from __future__ import annotations

import json
import math
import os
import stat
from pathlib import Path

from imunoise._support import atomic as _atomic
from imunoise.errors import ImunoiseValueError, ParseError

__all__ = ["DIGESTS", "MAX_BYTES", "MAX_COUNT", "MAX_DEPTH", "MAX_FS", "SUFFIX", "bad_field",
           "check_tie", "count", "legacy_path", "load", "meta_path", "parse", "rate", "shown",
           "tie_errors", "tie_fields"]

#: Suffix of a metadata file: ``F.meta.json`` describes ``F``.
SUFFIX = ".meta.json"
#: Largest metadata file read: 256 MiB holds about ten million gaps, more than a
#: log has samples to lose in memory; a larger file is not imunoise's.
MAX_BYTES = 256 << 20
#: Deepest JSON nesting accepted: imunoise's metadata is at most 4 levels deep;
#: deeper text would only exhaust the parser's stack.
MAX_DEPTH = 16
#: Largest count (samples, messages, issues) accepted: what an int64 holds, as
#: numpy and the Rust core store them.
MAX_COUNT = 2**63 - 1
#: Highest rate accepted in metadata, Hz: 1 GHz is above any IMU's output rate,
#: and a rate near the float limit (1e308) overflows every time computed from it.
MAX_FS = 1e9


def meta_path(data) -> Path:
    """The metadata file of the file ``data``: ``data`` + ``.meta.json``."""
    return Path(os.fspath(data) + SUFFIX)


def legacy_path(data) -> Path:
    """The name earlier versions gave the metadata of ``X.npy`` and ``X.csv`` alike:
    ``X.meta.json`` (never read, see the module docstring)."""
    data = Path(os.fspath(data))
    return data.with_name(data.stem + SUFFIX)


def bad_field(where, field: str, reason: str) -> ParseError:
    """The error of metadata field ``field`` of file ``where``."""
    return ParseError(f"metadata field {field!r} {reason}", kind="malformed_field",
                      source=str(where))


def _fault(where, reason: str) -> ParseError:
    return ParseError(reason, kind="malformed_field", source=str(where))


def _no_constant(name: str):
    raise ImunoiseValueError(f"{name} is not a JSON number")


def _depth(value, where) -> None:
    """Refuse nesting deeper than :data:`MAX_DEPTH` (iteratively: no recursion)."""
    stack = [(value, 1)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict | list):
            if depth > MAX_DEPTH:
                raise _fault(where, f"the metadata is nested deeper than {MAX_DEPTH} levels")
            children = item.values() if isinstance(item, dict) else item
            stack.extend((c, depth + 1) for c in children)


def parse(raw: bytes | str, where) -> object:
    """The JSON value of ``raw``, or :class:`ParseError` naming ``where``: invalid
    JSON, ``NaN``/``Infinity``, numbers too long to convert, nesting deeper than
    :data:`MAX_DEPTH`."""
    try:
        value = json.loads(raw, parse_constant=_no_constant)
    except RecursionError:
        raise _fault(where, f"the metadata is nested deeper than {MAX_DEPTH} levels") from None
    except (ValueError, UnicodeDecodeError) as exc:
        raise _fault(where, f"the metadata is not valid JSON ({exc})") from None
    _depth(value, where)
    return value


def load(path) -> object | None:
    """The parsed metadata file at ``path``; ``None`` when there is none.

    Only a regular file is read (opened without blocking, so a FIFO of that name
    is refused at once instead of waiting for a writer forever), at most
    :data:`MAX_BYTES` of it."""
    path = os.fspath(path)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except (FileNotFoundError, NotADirectoryError):
        return None
    except IsADirectoryError:
        raise _fault(path, "the metadata file is a directory, not a regular file") from None
    except OSError as exc:
        raise _fault(path, f"the metadata file cannot be opened ({exc.strerror})") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise _fault(path, "the metadata file is not a regular file (a FIFO, device or "
                         "socket); refusing to wait on it")
        if st.st_size > MAX_BYTES:
            raise _fault(path, f"the metadata file has {st.st_size} bytes, more than the "
                         f"{MAX_BYTES} imunoise reads")
        with os.fdopen(fd, "rb", closefd=False) as f:
            raw = f.read(MAX_BYTES + 1)
    except IsADirectoryError:
        raise _fault(path, "the metadata file is a directory, not a regular file") from None
    finally:
        os.close(fd)
    return parse(raw, path)


def count(value, where, field: str, *, most: int = MAX_COUNT) -> int:
    """``value`` if an integer in ``[0, most]`` (a JSON ``true`` is not one)."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise bad_field(where, field, f"must be an integer count; got {shown(value)}")
    if not 0 <= value <= most:
        raise bad_field(where, field, f"must be a count in [0, {most}]; got {shown(value)}")
    return value


def rate(value, where, field: str = "fs") -> float:
    """``value`` as a rate in Hz: a number (not ``true``) in ``(0, MAX_FS]``."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise bad_field(where, field, f"must be a rate in Hz (a number); got {shown(value)}")
    if isinstance(value, int) and value > MAX_FS:  # before float(): a huge int overflows
        raise bad_field(where, field, f"must be a rate in (0, {MAX_FS:g}] Hz; got {shown(value)}")
    if not (math.isfinite(value) and 0 < value <= MAX_FS):
        raise bad_field(where, field, f"must be a rate in (0, {MAX_FS:g}] Hz; got {shown(value)}")
    return float(value)


def shown(value) -> str:
    """``repr`` of a metadata value for an error, shortened: a field may hold megabytes."""
    text = type(value).__name__ if isinstance(value, dict | list) else repr(value)
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 10**30:
        return f"an integer of {len(str(abs(value)))} digits"
    return text if len(text) <= 60 else text[:57] + "..."


#: The digests a fingerprint may carry, each 64 hex digits, and their names in
#: errors: BLAKE3 is written; SHA-256 is what earlier versions wrote.
DIGESTS = {"blake3": "BLAKE3", "sha256": "SHA-256"}


def tie_fields(tie, where) -> dict:
    """``tie`` if it is a fingerprint (``bytes``, ``mtime_ns`` and exactly one of the
    :data:`DIGESTS`), else a :class:`ParseError` naming the field of ``where``."""
    if not isinstance(tie, dict):
        raise bad_field(where, "data", f"must be an object (bytes, mtime_ns, blake3); got "
                        f"{shown(tie)}")
    for key in ("bytes", "mtime_ns"):
        count(tie.get(key), where, f"data.{key}")
    keys = [key for key in DIGESTS if key in tie]
    if len(keys) != 1:
        raise bad_field(where, "data", "must carry exactly one digest, 'blake3' or 'sha256'; "
                        f"got {' and '.join(map(repr, keys)) or 'neither'}")
    digest = tie[keys[0]]
    if not (isinstance(digest, str) and len(digest) == 64
            and all(c in "0123456789abcdef" for c in digest)):
        raise bad_field(where, f"data.{keys[0]}", f"must be 64 hex digits; got {shown(digest)}")
    return tie


def tie_errors(tie, data: Path, where) -> str | None:
    """Why metadata ``where`` with the fingerprint ``tie`` does not describe the file
    ``data`` (``None`` when it does); a malformed ``tie`` is a :class:`ParseError`."""
    tie = tie_fields(tie, where)
    if _atomic.same_content(data, tie):
        return None
    size = os.stat(data).st_size
    key = next(k for k in DIGESTS if k in tie)
    return (f"{where} describes {tie['bytes']} bytes with {DIGESTS[key]} {tie[key][:12]}... "
            f"but {data} ({size} bytes) is other data: the file was replaced without its "
            "metadata (an interrupted or concurrent write, or an edit)")


def check_tie(tie, data: Path, where) -> None:
    """:class:`ParseError` naming both files when ``tie`` is not ``data``'s fingerprint."""
    why = tie_errors(tie, data, where)
    if why is not None:
        raise ParseError(f"{why}; convert the log again", kind="malformed_field",
                         source=str(data))
