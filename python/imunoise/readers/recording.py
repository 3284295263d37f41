"""The side files ``imunoise record`` writes beside a raw log, as the readers see them.

``LOG`` is the raw byte stream exactly as the sensor sent it; beside it:

- ``LOG.times``: one line ``<byte offset> <host time, Unix ns>`` per chunk
  received (the offset of the chunk's first byte), to check the time grid;
- ``LOG.gaps``: one line ``<byte offset> <start> <end>`` per port outage (Unix
  seconds: the last chunk before it, the first recorded after it); the raw log
  simply continues at that offset, nothing is spliced;
- ``LOG.meta.json``: the sensor's identity, the settings recorded with (``fs``:
  the main output's rate) and those restored.

:func:`outages` feeds a log's outages to the VN reader, which puts them on the
time grid of logs without timestamps (logs with timestamps show them already).
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass

import numpy as np

__all__ = ["GAPS", "META", "TIMES", "Outage", "host_times", "outages", "recorded_fs"]

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

    @property
    def seconds(self) -> float:
        return self.end - self.start


def outages(path) -> list[Outage]:
    """The outages recorded beside the log at ``path`` (none without a ``.gaps``
    file; malformed lines, e.g. one cut by a kill, are left out)."""
    side = os.fspath(path) + GAPS
    try:
        with open(side, encoding="ascii", errors="replace") as f:
            lines = f.read().splitlines()
    except (FileNotFoundError, IsADirectoryError):
        return []
    found = []
    for line in lines:
        parts = line.split()
        try:
            found.append(Outage(int(parts[0]), float(parts[1]), float(parts[2])))
        except (ValueError, IndexError):
            continue
    return found


def host_times(path) -> tuple[np.ndarray, np.ndarray]:
    """``(offsets, seconds)``: byte offset of each chunk received and its host time
    (Unix s), from ``LOG.times`` (empty arrays without one; a line cut by a kill is
    left out)."""
    offsets, seconds = [], []
    try:
        with open(os.fspath(path) + TIMES, encoding="ascii", errors="replace") as f:
            for line in f:
                parts = line.split()
                if len(parts) == 2 and line.endswith("\n"):
                    try:
                        offset, ns = int(parts[0]), int(parts[1])
                    except ValueError:
                        continue
                    offsets.append(offset)
                    seconds.append(ns / 1e9)
    except (FileNotFoundError, IsADirectoryError):
        pass
    return np.asarray(offsets, dtype=np.int64), np.asarray(seconds, dtype=np.float64)


def recorded_fs(path) -> float | None:
    """The main output's rate in the log's metadata (``None`` without one)."""
    try:
        with open(os.fspath(path) + META, encoding="utf-8") as f:
            fs = json.load(f).get("fs")
    except (FileNotFoundError, IsADirectoryError, ValueError, AttributeError):
        return None
    return float(fs) if isinstance(fs, int | float) and fs > 0 else None
