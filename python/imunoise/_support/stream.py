"""Bounded memory for logs larger than memory: parse once into memory maps, then
read them a block or a column at a time and give the mapped pages back.

The report's streamed path (``imunoise report --stream``, automatic for VN logs
above :data:`STREAM_BYTES`) parses the log once with :func:`imunoise.scale.convert`
into a folder of ``.npy`` files (memory bounded by its pieces) and opens them as
memory maps (:func:`open_mapped`). A memory map costs no anonymous memory, but every
page it has touched counts in the process's resident set until the kernel needs it
back; :func:`release` hands them back (``madvise(MADV_DONTNEED)``: the pages stay in
the page cache, a later read maps them again), and :func:`column` and :func:`blocks`
read a channel a block at a time and release behind them. The statistics of the
whole log that need no more than running sums (:func:`describe`) come from one
pass over the blocks; the others take one channel (a column) at a time.
"""

from __future__ import annotations

import mmap
import os
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import TypeVar

import numpy as np

from imunoise._support import schema as _schema
from imunoise.errors import DataWarning
from imunoise.readers.log import ImuLog

__all__ = ["BLOCK_ROWS", "CHANNEL_WORKERS", "PARSE_BYTES", "STREAM_BYTES", "adev", "blocks",
           "column", "describe", "each_channel", "is_mapped", "open_mapped", "present_rows",
           "release", "release_log", "trim_heap", "workdir_for"]

T = TypeVar("T")

#: VN logs larger than this are streamed by default (parsed once into memory maps).
STREAM_BYTES = 256 << 20
#: Rows read at once from a memory map.
BLOCK_ROWS = 1 << 20
#: Bytes :func:`open_mapped` parses at a time (None: ``imunoise.scale.convert``'s 64 MiB,
#: which set a 0.59 GB floor of the streamed report; 16 MiB costs ~0.2 GB less).
PARSE_BYTES: int | None = 16 << 20


def open_mapped(source, workdir: Path, *, fs: float | None = None,
                chunk_bytes: int | None = None, progress=None) -> ImuLog:
    """Parse ``source`` once into ``workdir`` (``.npy`` per channel) and open it as
    an :class:`ImuLog` of read-only memory maps; the same arrays, rate, gaps and
    issues as :func:`imunoise.read` (:func:`imunoise.scale.convert`'s contract)."""
    from imunoise.scale import convert, load
    from imunoise.scale.convert import CHUNK_BYTES

    convert(source, workdir, fs=fs, chunk_bytes=chunk_bytes or PARSE_BYTES or CHUNK_BYTES,
            progress=progress)
    return load(workdir)  # named by its source, as convert records it


def _mapping(arr) -> mmap.mmap | None:
    """The memory map under ``arr`` (a memmap or a view of one), or None."""
    while arr is not None:
        m = getattr(arr, "_mmap", None)
        if isinstance(m, mmap.mmap):
            return m
        if isinstance(arr, mmap.mmap):
            return arr
        arr = getattr(arr, "base", None)
    return None


def is_mapped(arr) -> bool:
    """True when ``arr`` reads a memory-mapped file."""
    return _mapping(arr) is not None


def release(*arrays) -> None:
    """Give the resident pages of the memory maps under ``arrays`` back to the kernel
    (no-op for in-memory arrays and where ``madvise`` is not available)."""
    for arr in arrays:
        m = _mapping(arr)
        if m is not None and hasattr(m, "madvise") and not m.closed:
            try:
                m.madvise(mmap.MADV_DONTNEED)
            except (OSError, ValueError):  # pragma: no cover - not on this platform
                pass


def trim_heap() -> None:
    """Give the C heap's free memory back to the system (glibc's ``malloc_trim``):
    arrays numpy freed below malloc's mmap threshold (up to 32 MiB, which it raises
    as larger blocks come and go) otherwise stay resident. No-op elsewhere."""
    global _LIBC
    if _LIBC is None:
        import ctypes
        import ctypes.util

        try:
            _LIBC = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
            _LIBC.malloc_trim  # noqa: B018 - present on glibc only
        except (OSError, AttributeError):
            _LIBC = False
    if _LIBC:
        _LIBC.malloc_trim(0)


_LIBC = None


def release_log(log: ImuLog | None) -> None:
    """:func:`release` every channel of ``log``."""
    if log is not None:
        release(*(getattr(log, ch) for ch in (*log.channels, "time")
                  if getattr(log, ch, None) is not None))


def blocks(arr: np.ndarray, block: int = BLOCK_ROWS) -> Iterator[tuple[int, np.ndarray]]:
    """``(start, rows)`` of ``arr`` ``block`` rows at a time, as float64 copies,
    releasing a memory map's pages behind each block."""
    mapped = is_mapped(arr)
    for a in range(0, len(arr), block):
        rows = np.array(arr[a:a + block], dtype=np.float64)
        if mapped:
            release(arr)
        yield a, rows


def column(arr: np.ndarray, j: int | None = None, block: int = BLOCK_ROWS) -> np.ndarray:
    """Column ``j`` of ``arr`` (the whole of a 1-D ``arr``) as a contiguous float64
    array in memory, read ``block`` rows at a time (a memory map's pages released
    behind each block): one channel in memory, never the whole sensor's map."""
    if not is_mapped(arr):
        v = arr if j is None else arr[:, j]
        return np.ascontiguousarray(v, dtype=np.float64)
    out = np.empty(len(arr), dtype=np.float64)
    for a, rows in blocks(arr, block):
        out[a:a + len(rows)] = rows if j is None else rows[:, j]
    return out


class _Moments:
    """Per column of one sensor: count, sums, extremes and missing samples (first
    pass), then the centred sums of squares and of the cross product with time
    (second pass)."""

    def __init__(self, k: int) -> None:
        self.n = np.zeros(k, dtype=np.int64)
        self.sx, self.st = np.zeros(k), np.zeros(k)
        self.lo, self.hi = np.full(k, np.inf), np.full(k, -np.inf)
        self.sxx, self.stt, self.stx = np.zeros(k), np.zeros(k), np.zeros(k)

    def first(self, v: np.ndarray, t: np.ndarray) -> None:
        sx = v.sum(axis=0)
        # finite sums: no NaN in the block (one would make its column's sum NaN)
        if np.isfinite(sx).all() or not np.isnan(v).any():
            self.n += len(v)
            self.sx += sx
            self.st += t.sum()
            self.lo = np.minimum(self.lo, _extreme(v, np.min))
            self.hi = np.maximum(self.hi, _extreme(v, np.max))
            return
        ok = ~np.isnan(v)
        for j in range(v.shape[1]):
            w = v[ok[:, j], j]
            if w.size:
                self.n[j] += w.size
                self.sx[j] += w.sum()
                self.st[j] += t[ok[:, j]].sum()
                self.lo[j], self.hi[j] = min(self.lo[j], w.min()), max(self.hi[j], w.max())

    def second(self, v: np.ndarray, t: np.ndarray) -> None:
        with np.errstate(invalid="ignore"):
            mean, tmean = self.sx / self.n, self.st / self.n
        d = _less(v, mean)
        tc = _less(np.broadcast_to(t[:, None], v.shape), tmean)
        sums = [np.einsum("ij,ij->j", a, b) for a, b in ((d, d), (tc, tc), (tc, d))]
        # finite sums: no missing sample in the block (it would make them NaN)
        if not all(np.isfinite(x).all() for x in sums):
            ok = ~np.isnan(d)
            if not ok.all():
                d = np.where(ok, d, 0.0)
                tc = np.where(ok, tc, 0.0)
                sums = [np.einsum("ij,ij->j", a, b) for a, b in ((d, d), (tc, tc), (tc, d))]
        self.sxx += sums[0]
        self.stt += sums[1]
        self.stx += sums[2]


def present_rows(arr: np.ndarray) -> np.ndarray:
    """Boolean (rows,): the rows of ``arr`` (rows, k) without a NaN, as
    ``~np.isnan(arr).any(axis=1)``, a column at a time: numpy reduces a (rows, 3)
    array's rows with an inner loop of 3 values, four times slower, and through a
    (rows, 3) array of flags."""
    if arr.ndim == 1:
        return ~np.isnan(arr)
    missing = np.isnan(arr[:, 0])
    for j in range(1, arr.shape[1]):
        missing |= np.isnan(arr[:, j])
    return ~missing


def _less(v: np.ndarray, mean: np.ndarray) -> np.ndarray:
    """``v - mean`` of a block (rows, k) less a value per column, as a (rows, k)
    array, a column at a time: the same numbers; broadcast over the whole block numpy
    runs an inner loop of k values per row, several times slower."""
    out = np.empty(v.shape)
    for j in range(v.shape[1]):
        np.subtract(v[:, j], mean[j], out=out[:, j])
    return out


def _extreme(v: np.ndarray, f) -> np.ndarray:
    """``f(v, axis=0)`` (np.min or np.max) of a block ``v`` (rows, k) without NaN, a
    column at a time: numpy reduces a (rows, 3) block over its rows at 10–20 ns a value
    (an inner loop of 3), a column at well under 1. The same values, as no two other
    numbers compare equal; where one is a zero, ``v``'s row order decides its sign as
    before."""
    out = np.array([f(v[:, j]) for j in range(v.shape[1])])
    return f(v, axis=0) if (out == 0).any() else out


#: Channels analysed at once by :func:`each_channel`: two, because numpy's sort and
#: scipy's normal CDFs release the GIL (two run in about 0.6× the time of one after the
#: other, docs/benchmarks.md) and each holds about one channel length, so two stay
#: within the streamed report's memory.
CHANNEL_WORKERS = 2


def each_channel(work: Callable[[int], T], channels: int) -> list[T]:
    """``[work(0), work(1), …]``, up to :data:`CHANNEL_WORKERS` at a time (threads):
    for per-channel work that releases the GIL and holds about a channel length."""
    workers = min(CHANNEL_WORKERS, channels, os.cpu_count() or 1)
    if workers <= 1:
        return [work(j) for j in range(channels)]
    with ThreadPoolExecutor(workers) as pool:
        return list(pool.map(work, range(channels)))


def adev(arr: np.ndarray, fs: float, taus, streamed: bool, block: int = BLOCK_ROWS):
    """:func:`imunoise.adev` of a sensor's samples ``arr``; ``streamed``: a column at
    a time (:func:`imunoise.allan.adev_by_column`: one column and the core's arrays for
    it in memory, not the sensor's map and its phase), the same result."""
    from imunoise import allan

    if not streamed or arr.ndim == 1:
        return allan.adev(arr, fs, taus=taus)
    return allan.adev_by_column(lambda j: column(arr, j, block), arr.shape[1], fs, taus=taus)


def _yaw_centre(ypr: np.ndarray, block: int) -> float | None:
    """Circular mean of the yaw column (degrees), None when it has no finite value."""
    s = c = 0.0
    count = 0
    for _a, rows in blocks(ypr, block):
        r = rows[:, 0]
        r = np.radians(r[np.isfinite(r)])
        s += float(np.sum(np.sin(r)))
        c += float(np.sum(np.cos(r)))
        count += r.size
    return float(np.degrees(np.arctan2(s / count, c / count))) if count else None


def describe(log: ImuLog, block: int = BLOCK_ROWS):
    """:func:`imunoise.describe` of a log in two passes over blocks of ``block``
    rows: memory of one block whatever the log's length. The same statistics to
    rounding (sums of blocks instead of numpy's pairwise sums over the whole
    channel: 1e-13 relative, the report's six digits agree)."""
    from imunoise import stats

    if len(log) < 2:
        return stats.describe(log)  # its error for a log too short
    fs = float(log.fs)
    names, sensors, units, parts = [], [], [], []
    for sensor in _schema.STATISTICS_CHANNELS:
        arr = getattr(log, sensor)
        if arr is None:
            continue
        centre = None
        if sensor == "ypr":
            centre = _yaw_centre(arr, block)
            if centre is None:  # as describe: a ypr channel with no finite value is left out
                continue
            labels = list(_schema.ATTITUDE_NAMES)
        else:
            k = 1 if arr.ndim == 1 else arr.shape[1]
            labels = [_schema.sensor_label(sensor, j, k) for j in range(k)]
        names += labels
        sensors += [sensor] * len(labels)
        units += [_schema.CHANNELS[sensor][1]] * len(labels)
        parts.append((arr, centre, _Moments(len(labels))))
    if not parts:
        return stats.describe(log)  # its error for a log without these channels
    for pass_ in (1, 2):
        for arr, centre, mo in parts:
            for a, rows in blocks(arr, block):
                rows = rows.reshape(len(rows), -1)
                if centre is not None:  # yaw about its circular mean, as attitude_angles
                    rows[:, 0] = centre + (rows[:, 0] - centre + 180.0) % 360.0 - 180.0
                t = np.arange(a, a + len(rows), dtype=np.float64) / fs
                if pass_ == 1:
                    mo.first(rows, t)
                else:
                    mo.second(rows, t)
    n_valid = np.concatenate([mo.n for _a, _c, mo in parts])
    with np.errstate(divide="ignore", invalid="ignore"):
        mean = np.concatenate([mo.sx for _a, _c, mo in parts]) / n_valid
        var = np.where(n_valid > 1, np.concatenate([mo.sxx for _a, _c, mo in parts])
                       / (n_valid - 1), np.nan)
        drift = np.where(n_valid > 1, np.concatenate([mo.stx / mo.stt for _a, _c, mo in parts])
                         * 3600.0, np.nan)
    lo = np.where(n_valid > 0, np.concatenate([mo.lo for _a, _c, mo in parts]), np.nan)
    hi = np.where(n_valid > 0, np.concatenate([mo.hi for _a, _c, mo in parts]), np.nan)
    if "yaw" in names:
        mean[names.index("yaw")] = stats.heading(mean[names.index("yaw")])
    return stats.Description(
        names=tuple(names), sensors=tuple(sensors), units=tuple(units), n=len(log), fs=fs,
        mean=mean, std=np.sqrt(var), var=var, min=lo, max=hi, drift_per_hour=drift,
        missing=(len(log) - n_valid).astype(np.int64))


def workdir_for(out_dir: Path) -> Path:
    """A fresh folder beside ``out_dir`` for the parsed log (removed after the report)."""
    parent = Path(os.path.abspath(out_dir)).parent
    parent.mkdir(parents=True, exist_ok=True)
    return fresh_workdir(parent, ".imunoise-stream-")


def fresh_workdir(parent: Path, prefix: str) -> Path:
    """A new folder ``<prefix><pid>-…`` in ``parent``, after removing those of runs
    whose process is gone (killed before they could clean up), with a warning."""
    import shutil
    import tempfile

    from imunoise._support import warn as _warn

    for old in Path(parent).glob(f"{prefix}*"):
        pid = old.name[len(prefix):].split("-", 1)[0]
        if old.is_dir() and pid.isdigit() and not _alive(int(pid)):
            shutil.rmtree(old, ignore_errors=True)
            _warn.warn(f"removed {old}, the parsed log of an earlier run that was killed",
                       DataWarning)
    return Path(tempfile.mkdtemp(prefix=f"{prefix}{os.getpid()}-", dir=parent))


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # exists, owned by another user
        return True
    return True
