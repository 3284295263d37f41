"""``imunoise.read``: one entry point for every log format, auto-detected."""

from __future__ import annotations

import contextlib
import dataclasses
import os
import stat
import warnings
from collections.abc import Callable, Mapping, Sequence

from imunoise._support import warn as _warn
from imunoise._support.deprecation import old_call_forms
from imunoise.errors import ImunoiseTypeError, ImunoiseValueError, ParseError
from imunoise.readers import registry
from imunoise.readers.log import ImuLog
from imunoise.readers.probe import Confidence, Probe

#: Values of ``format=``: ``"auto"`` and every format of the registry.
FORMATS = ("auto", *registry.names())


def detect_format(source: str | os.PathLike | bytes) -> str:
    """Guess the format of ``source`` from its extension and first 64 KB.

    ROS bags by magic number (ROS 1 ``#ROSBAG V2.0``, MCAP, sqlite3), extension or
    by being a ROS 2 bag directory; ``.csv``/``.tsv`` files as CSV; anything with a
    ``$VN`` sentence or a ``0xFA`` sync byte as VectorNav (binary if binary packets
    are more likely: more ``0xFA`` than ``$VN``); other delimited text as CSV.
    Each format's ``sniff`` in :mod:`imunoise.readers.registry` says how sure it
    is; the surest wins.

    Raises
    ------
    FileNotFoundError
        When ``source`` is a path that does not exist (sniffers read the file).
    ValueError
        When no format recognises the source.
    """
    probe = Probe(source)
    best, best_confidence = None, Confidence.NO
    for fmt in registry.FORMATS:
        confidence = fmt.sniff(probe)
        if confidence > best_confidence:
            best, best_confidence = fmt.name, confidence
    if best is not None:
        return best
    if probe.is_dir:
        raise ImunoiseValueError(f"source {str(probe.path)!r} is a directory but not a ROS 2 bag")
    name = "the bytes" if probe.path is None else repr(str(probe.path))
    raise ImunoiseValueError(
        f"format='auto' could not recognise {name} (no VN sentence or packet, no ROS bag "
        "magic, no .npy/.npz/Parquet of imunoise convert, no delimited text); pass format= "
        f"one of {FORMATS[1:]}, or build the log from arrays with "
        "imunoise.ImuLog.from_arrays(fs, gyro=..., accel=...)"
    )


_BYTES = "<bytes>"  # the readers' name of a log given as bytes

#: Name of a log read from a file object without a ``name`` (e.g. a pipe's buffer).
STREAM_NAME = "<stream>"


def is_stream(source) -> bool:
    """True for what can be read only once, start to end: a binary file object, or
    a path that is not a regular file or directory (a FIFO, ``/dev/stdin``, a
    character device)."""
    if hasattr(source, "read"):
        return True
    if not isinstance(source, str | os.PathLike):
        return False
    try:
        mode = os.stat(os.fspath(source)).st_mode
    except OSError:
        return False
    return not (stat.S_ISREG(mode) or stat.S_ISDIR(mode))


def stream_name(source) -> str:
    """The name a stream's log is known by: its path, or the file object's name."""
    if isinstance(source, str | os.PathLike):
        return os.fspath(source)
    name = getattr(source, "name", None)
    return name if isinstance(name, str) and not name.isdigit() else STREAM_NAME


def read_stream(source) -> bytes:
    """Every byte of a stream, read once from where it stands to its end (a pipe, a
    FIFO or stdin cannot be rewound, so formats are detected from these bytes and
    the reader is given them: nothing is read twice, nothing is lost)."""
    if isinstance(source, str | os.PathLike):
        with open(os.fspath(source), "rb") as f:
            return f.read()
    data = source.read()
    if isinstance(data, str):
        raise ImunoiseTypeError(f"{stream_name(source)}: a stream must be opened in binary mode "
                        "(e.g. sys.stdin.buffer, open(path, 'rb'))")
    return bytes(data)


@old_call_forms(keyword_only=("format",))
def read(
    source: str | os.PathLike | bytes,
    *,
    format: str = "auto",
    strict: bool = False,
    fs: float | None = None,
    progress: Callable[[int, int], object] | None = None,
    columns: Mapping[str, Sequence[int | str] | int | str] | None = None,
    units: Mapping[str, str] | None = None,
    delimiter: str | None = None,
    time_column: int | str | None = None,
) -> ImuLog:
    """Read an IMU log into an :class:`~imunoise.readers.log.ImuLog`.

    Parameters
    ----------
    source : str, os.PathLike, bytes or binary file object
        A file (or ROS 2 bag directory), the bytes of a log, or a stream: a
        binary file object (``sys.stdin.buffer``) or the path of a FIFO or of
        ``/dev/stdin``. A stream is read once, start to end, its format detected
        from those bytes; the log is named by the path or the object's ``name``.
    format : {"auto", "vn-ascii", "vn-binary", "csv", "rosbag", "columnar"}
        ``"auto"`` detects the format from the extension and content
        (:func:`detect_format`). Both VN formats use the same reader, which
        accepts ASCII and binary interleaved in one stream; ``"columnar"`` is
        what ``imunoise convert`` writes (:mod:`imunoise.readers.columnar`).
    strict : bool
        Raise :class:`~imunoise.errors.ParseError` (a ``ValueError``) at the first
        damaged record, with its issue kind, line (or message number, or byte
        offset) and reason as attributes, instead of skipping and counting it in
        ``log.issues``.
    fs : float, optional
        Sample rate in Hz, used when the log has no timestamps.
    progress : callable, optional
        ``progress(bytes_done, bytes_total)`` for a progress bar.
    columns, units, delimiter, time_column : optional
        The layout of a delimited text log, for files whose header does not say
        it (or that have none): channel -> 0-based column indices or header names,
        e.g. ``columns={"gyro": [6, 7, 8], "accel": [3, 4, 5]}``,
        ``units={"gyro": "deg/s"}``. See :func:`~imunoise.readers.csv_reader.read_csv`.
        Given with ``format="auto"`` they select the CSV reader; with another
        format they are an error.

    Returns
    -------
    ImuLog

    Raises
    ------
    FileNotFoundError
        When ``source`` is a path that does not exist.

    Examples
    --------
    >>> log = imunoise.read("capture.txt")            # doctest: +SKIP
    >>> log.gyro.shape, log.fs, log.issues.counts     # doctest: +SKIP
    """
    choices = ("auto", *registry.names())
    if format not in choices:
        raise ImunoiseValueError(f"format must be one of {choices}; got {format!r}")
    if is_stream(source):
        name = stream_name(source)
        with warnings.catch_warnings(record=True) as caught, naming(name):
            warnings.simplefilter("always")
            log = read(read_stream(source), format=format, strict=strict, fs=fs,
                       progress=progress, columns=columns, units=units, delimiter=delimiter,
                       time_column=time_column)
        for w in caught:  # name the stream, not "<bytes>"
            _warn.warn(str(w.message).replace(_BYTES, name), w.category)
        return dataclasses.replace(log, source=name) if log.source == _BYTES else log
    if not isinstance(source, (bytes, bytearray, memoryview, str, os.PathLike)):
        raise ImunoiseTypeError(f"source must be a path, bytes or a binary file object; got "
                        f"{type(source).__name__}")
    layout = {k: v for k, v in (("columns", columns), ("units", units),
                                 ("delimiter", delimiter), ("time_column", time_column))
              if v is not None}
    if layout:
        if format not in ("auto", "csv"):
            raise ImunoiseValueError(
                f"{', '.join(layout)} describe a delimited text log; format must be 'auto' "
                f"or 'csv' with them; got {format!r}"
            )
        with naming(source):
            return registry.get("csv").read(source, strict=strict, fs=fs, progress=progress,
                                            **layout)
    with naming(source):
        if format == "auto":
            format = detect_format(source)
        return registry.get(format).read(source, strict=strict, fs=fs, progress=progress)


@contextlib.contextmanager
def naming(source):
    """Every error of reading ``source`` names it: a :class:`ParseError` without a
    file gets it, a ``ValueError`` whose text lacks the name gets it in front, and
    ``OverflowError``/``RecursionError`` (a number or nesting in the file beyond what
    can be computed) become a ``ParseError`` naming the file. Bytes have no name."""
    if not isinstance(source, str | os.PathLike):
        yield
        return
    name = os.fspath(source)
    try:
        yield
    except ParseError as exc:
        if exc.source is not None:
            raise
        raise ParseError(exc.reason, kind=exc.kind, line=exc.line, offset=exc.offset,
                         source=name) from exc
    except (OverflowError, RecursionError) as exc:
        raise ParseError(f"{type(exc).__name__}: {exc}", kind="malformed_field",
                         source=name) from exc
    except ValueError as exc:
        if name in str(exc):
            raise
        raise ImunoiseValueError(f"{name}: {exc}") from exc
