"""``imunoise.read``: one entry point for every log format, auto-detected."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from imunoise.readers.log import ImuLog

FORMATS = ("auto", "vn-ascii", "vn-binary", "csv", "rosbag")

_BAG_MAGIC = (b"#ROSBAG V2.0", b"\x89MCAP", b"SQLite format 3\x00")
_BAG_SUFFIXES = (".bag", ".mcap", ".db3")
_CSV_SUFFIXES = (".csv", ".tsv")
_SNIFF = 1 << 16


def _head(source) -> bytes:
    if isinstance(source, (bytes, bytearray, memoryview)):
        return bytes(source[:_SNIFF])
    path = Path(source)
    if path.is_dir():
        return b""
    with open(path, "rb") as f:
        return f.read(_SNIFF)


def detect_format(source) -> str:
    """Guess the format of ``source`` from its extension and first 64 KB.

    ROS bags by magic number (ROS 1 ``#ROSBAG V2.0``, MCAP, sqlite3) or by being a
    ROS 2 bag directory; ``.csv``/``.tsv`` files as CSV; anything with a ``$VN``
    sentence or a ``0xFA`` sync byte as VectorNav (binary if binary packets are
    more likely: more ``0xFA`` than ``$VN``); other delimited text as CSV.
    """
    if not isinstance(source, (bytes, bytearray, memoryview)):
        path = Path(os.fspath(source))
        if path.is_dir():
            if (path / "metadata.yaml").exists() or any(path.glob("*.db3")) or any(
                path.glob("*.mcap")
            ):
                return "rosbag"
            raise ValueError(f"source {str(path)!r} is a directory but not a ROS 2 bag")
        if path.suffix.lower() in _BAG_SUFFIXES:
            return "rosbag"
    head = _head(source)
    if head.startswith(_BAG_MAGIC):
        return "rosbag"
    if not isinstance(source, (bytes, bytearray, memoryview)):
        if Path(os.fspath(source)).suffix.lower() in _CSV_SUFFIXES:
            return "csv"
    n_ascii = head.count(b"$VN")
    n_sync = head.count(b"\xfa")
    if n_ascii or n_sync:
        return "vn-binary" if n_sync > n_ascii else "vn-ascii"
    text = head.split(b"\n", 1)[0]
    if any(d in text for d in (b",", b"\t", b";", b" ")):
        return "csv"
    raise ValueError(
        "format='auto' could not recognise the source (no VN sentence or packet, no ROS "
        "bag magic, no delimited text); pass format= one of "
        f"{FORMATS[1:]}"
    )


def read(
    source,
    format: str = "auto",
    *,
    strict: bool = False,
    fs: float | None = None,
    progress: Callable[[int, int], object] | None = None,
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
        Raise ``ValueError`` naming the line number (or byte offset) and reason of
        the first damaged record, instead of skipping and counting it in
        ``log.issues``.
    fs : float, optional
        Sample rate in Hz, used when the log has no timestamps.
    progress : callable, optional
        ``progress(bytes_done, bytes_total)`` for a progress bar.

    Returns
    -------
    ImuLog

    Examples
    --------
    >>> log = imunoise.read("capture.txt")            # doctest: +SKIP
    >>> log.gyro.shape, log.fs, log.issues.counts     # doctest: +SKIP
    """
    if format not in FORMATS:
        raise ValueError(f"format must be one of {FORMATS}; got {format!r}")
    if not isinstance(source, (bytes, bytearray, memoryview, str, os.PathLike)):
        raise TypeError(f"source must be a path or bytes; got {type(source).__name__}")
    if format == "auto":
        format = detect_format(source)
    if format in ("vn-ascii", "vn-binary"):
        from imunoise.readers.vn import read_vn

        return read_vn(source, strict=strict, fs=fs, progress=progress)
    if format == "csv":
        from imunoise.readers.csv_reader import read_csv

        return read_csv(source, strict=strict, fs=fs, progress=progress)
    from imunoise.readers.rosbag_reader import read_rosbag

    return read_rosbag(source, strict=strict, fs=fs, progress=progress)
