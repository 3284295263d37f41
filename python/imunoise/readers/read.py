"""``imunoise.read``: one entry point for every log format, auto-detected."""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence

from imunoise._deprecation import old_call_forms
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
        raise ValueError(f"source {str(probe.path)!r} is a directory but not a ROS 2 bag")
    raise ValueError(
        "format='auto' could not recognise the source (no VN sentence or packet, no ROS "
        "bag magic, no delimited text); pass format= one of "
        f"{FORMATS[1:]}"
    )


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
    source : str, os.PathLike or bytes
        A file (or ROS 2 bag directory), or the bytes of a log.
    format : {"auto", "vn-ascii", "vn-binary", "csv", "rosbag"}
        ``"auto"`` detects the format from the extension and content
        (:func:`detect_format`). Both VN formats use the same reader, which
        accepts ASCII and binary interleaved in one stream.
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
        raise ValueError(f"format must be one of {choices}; got {format!r}")
    if not isinstance(source, (bytes, bytearray, memoryview, str, os.PathLike)):
        raise TypeError(f"source must be a path or bytes; got {type(source).__name__}")
    layout = {k: v for k, v in (("columns", columns), ("units", units),
                                 ("delimiter", delimiter), ("time_column", time_column))
              if v is not None}
    if layout:
        if format not in ("auto", "csv"):
            raise ValueError(
                f"{', '.join(layout)} describe a delimited text log; format must be 'auto' "
                f"or 'csv' with them; got {format!r}"
            )
        return registry.get("csv").read(source, strict=strict, fs=fs, progress=progress,
                                        **layout)
    if format == "auto":
        format = detect_format(source)
    return registry.get(format).read(source, strict=strict, fs=fs, progress=progress)
