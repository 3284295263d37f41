"""The lossless writer: the raw log and its side files, as append streams.

Why not the atomic write every other imunoise file goes through
(:mod:`imunoise._support.atomic`: a temporary renamed onto the target when complete)?
A recording is hours long and must survive ``kill -9``, a crash or a power cut
with at most the last second lost: a temporary that is renamed only at the end
would lose all of it. So the raw bytes are appended to the log as they arrive
(``O_APPEND``: each write lands after the last, in order) and the file is
``fsync``-ed every :data:`SYNC_EVERY` seconds; the side files (host times,
outages) are appended and synced with it. A killed process loses nothing the
kernel already has; a power cut at most the last second. The reader handles a
record cut at the end. The metadata, rewritten whole, goes through
:mod:`imunoise._support.atomic`.
"""

from __future__ import annotations

import errno
import json
import os
import time

from imunoise._support import atomic as _atomic
from imunoise.readers.recording import GAPS, META, TIMES

__all__ = ["SYNC_EVERY", "RawWriter"]

#: Seconds between two fsyncs of the log and its side files.
SYNC_EVERY = 1.0


def _append(path: str) -> int:
    return os.open(path, os.O_WRONLY | os.O_CREAT | os.O_APPEND | getattr(os, "O_BINARY", 0),
                   0o666)


class RawWriter:
    """Append-only writer of ``path`` (the raw log) and ``path.times`` /
    ``path.gaps``; refuses an existing log (a record is never overwritten)."""

    @staticmethod
    def refuse_existing(path) -> None:
        """``FileExistsError`` when ``path`` exists: a recording is never overwritten
        (``IsADirectoryError`` for a folder: a record is a file beside its side files)."""
        if os.path.isdir(path):
            raise IsADirectoryError(errno.EISDIR, "is a folder: give the record's file name",
                                    os.fspath(path))
        if os.path.lexists(path):
            raise FileExistsError(errno.EEXIST, "exists: a recording is never overwritten; "
                                  "choose another output", os.fspath(path))

    def __init__(self, path) -> None:
        self.path = os.fspath(path)
        self.refuse_existing(self.path)
        self._raw = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_APPEND
                            | getattr(os, "O_BINARY", 0), 0o666)
        self._times = _append(self.path + TIMES)
        self._gaps = -1
        self.size = 0
        self._synced = time.monotonic()

    def write(self, data: bytes, received_ns: int) -> None:
        """Append ``data`` received at host time ``received_ns`` (Unix ns)."""
        if not data:
            return
        view = memoryview(data)
        while view:
            n = os.write(self._raw, view)
            view = view[n:]
        os.write(self._times, f"{self.size} {received_ns}\n".encode())
        self.size += len(data)
        if time.monotonic() - self._synced >= SYNC_EVERY:
            self.sync()

    def outage(self, start: float, end: float) -> None:
        """Record a port outage from ``start`` to ``end`` (Unix s) at the current end."""
        if self._gaps < 0:
            self._gaps = _append(self.path + GAPS)
        os.write(self._gaps, f"{self.size} {start:.6f} {end:.6f}\n".encode())
        self.sync()

    def sync(self) -> None:
        for fd in (self._raw, self._times, self._gaps):
            if fd >= 0:
                os.fsync(fd)
        self._synced = time.monotonic()

    def write_meta(self, meta: dict) -> None:
        """(Re)write ``path.meta.json`` whole, atomically."""
        _atomic.write_text(self.path + META, json.dumps(meta, indent=2, sort_keys=True) + "\n")

    def close(self) -> None:
        self.sync()
        for fd in (self._raw, self._times, self._gaps):
            if fd >= 0:
                os.close(fd)
        self._raw = self._times = self._gaps = -1
