"""Reading the logs a report (or a command of ``imunoise``) analyses."""

from __future__ import annotations

import os
import sys
import warnings
from pathlib import Path

from imunoise._support import warn as _warn
from imunoise._support.progress import byte_bar, wanted
from imunoise.errors import ImunoiseValueError
from imunoise.readers.log import ImuLog
from imunoise.readers.read import read

__all__ = ["read_log", "streams"]


def streams(source, read_options=None, *, forced: bool = False) -> bool:
    """Whether the report parses ``source`` into memory maps first: a log file that
    :func:`imunoise.scale.convert` can write as ``.npy`` (no text-layout options),
    and, unless ``forced``, a VN log larger than ``imunoise._support.stream.STREAM_BYTES``.
    Folders ``convert`` wrote are memory maps already: never."""
    from imunoise._support import stream as _stream
    from imunoise.readers import registry
    from imunoise.readers.read import detect_format

    if not isinstance(source, str | os.PathLike) or source == "-" or read_options:
        return False
    path = Path(source)
    if not path.is_file():
        return False
    try:
        fmt = detect_format(path)
    except (OSError, ValueError):
        return False  # read_log says what is wrong with it
    if fmt == "columnar":
        return False
    return forced or (registry.get(fmt).streamable and path.stat().st_size > _stream.STREAM_BYTES)


def read_log(source, label: str = "input", *, fs: float | None = None,
             progress: bool | None = False, workdir: Path | None = None,
             **read_options) -> ImuLog:
    """Read a log with :func:`imunoise.read`, naming it by its role in errors.

    Parameters
    ----------
    source : path, ``"-"``, binary file object or ImuLog
        A log file (any format :func:`imunoise.read` knows), ``"-"`` for
        standard input, a stream (read once, start to end); an ``ImuLog`` is
        returned as it is.
    label : str
        The log's role in messages, e.g. ``"short"``: "short log 'x.txt' does
        not exist".
    fs : float, optional
        Sample rate of logs without timestamps, passed to the reader.
    progress : bool or None
        A byte progress bar on stderr while reading (None: when stderr is a
        terminal).
    workdir : Path, optional
        Parse the log once into this (empty) folder with
        :func:`imunoise.scale.convert` and return memory maps of it (the streamed
        path: :mod:`imunoise._support.stream`); the same arrays as :func:`imunoise.read`.
    **read_options
        Passed to :func:`imunoise.read`: ``columns``, ``units``, ``delimiter``,
        ``time_column`` for text logs whose header does not say their layout.

    Raises
    ------
    OSError
        When the file does not exist.
    ValueError
        When the log has no usable record (the reader's warnings are dropped:
        the error says it all).
    """
    if isinstance(source, ImuLog):
        return source
    if source == "-":  # the command line's name for standard input
        source = sys.stdin.buffer
    if hasattr(source, "read"):
        path, name = source, getattr(source, "name", "<stream>")
    else:
        path = Path(source)
        name = str(path)
        if not path.exists():
            raise OSError(f"{label} log {name!r} does not exist")
    callback = (byte_bar(f"reading {Path(str(name)).name}")
                if wanted(progress) and not hasattr(path, "read") else None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if workdir is not None:
            from imunoise._support import stream as _stream

            log = _stream.open_mapped(path, workdir, fs=fs, progress=callback)
        else:
            log = read(path, fs=fs, progress=callback, **read_options)
    if len(log) == 0:
        raise ImunoiseValueError(f"{label} log {name!r}: no usable records ({log.issues})")
    for w in caught:
        _warn.warn(w.message, w.category)
    return log
