"""Logs larger than memory: stream a log into a columnar file, memory-map it back.

:func:`convert` streams a log into a columnar file without holding it in memory:
the file is read in pieces of ``chunk_bytes`` and fed to one streaming parser
(:class:`imunoise._core.vn.VnStream`), which hands back the rows of the records
each piece completes (a record cut by the end of a piece waits for the next), and
those rows are appended to the output.
Memory stays about three pieces (the bytes, their decoded columns, the rows being
written) whatever the size of the log. :func:`load` opens the result as an
:class:`~imunoise.readers.log.ImuLog` whose channels are memory-mapped ``.npy``
arrays, which :func:`imunoise.adev` reads in place (the Allan core takes arrays of
any strides without copying them), so ``convert → load → adev → fit`` analyses a
log larger than RAM.

Output layouts (chosen by ``out``):

``DIR`` (no suffix)
    one ``<channel>.npy`` per channel (``gyro.npy`` (n, 3), ``time.npy`` (n,) ...)
    plus ``meta.json`` (sample rate, source, parse issues, message counts).
``OUT.npy``
    one structured array, a field per channel (``a["gyro"]`` is (n, 3)), plus
    ``OUT.meta.json``.
``OUT.parquet``
    a column per axis (``gyro_x`` ...) written row group by row group (needs
    pyarrow); the metadata are the file's key-value metadata (``fs``, ``source``,
    ``imunoise``: the JSON of ``meta.json``). :func:`load` reads Parquet into
    memory.

VN-100 logs (ASCII, binary, or both) are streamed; CSV and ROS bags are read
whole by :func:`imunoise.read` and then written the same way.
"""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from imunoise import _atomic
from imunoise._core import vn as _core_vn
from imunoise._schema import CHANNELS, column_names
from imunoise.readers import registry
from imunoise.readers.grid import Gaps, TimeGrid
from imunoise.readers.log import ImuLog, ParseIssues, fs_from_median_step
from imunoise.readers.vn import richest_table, table_channels, tables_of

__all__ = ["CHUNK_BYTES", "Conversion", "convert", "load"]

#: Default bytes read per piece by :func:`convert`.
CHUNK_BYTES = 64 << 20
_META_VERSION = 1


@dataclass(frozen=True)
class Conversion:
    """What :func:`convert` wrote.

    Attributes
    ----------
    out : Path
        The output (directory, ``.npy`` or ``.parquet`` file); open it with :func:`load`.
    files : tuple of Path
        Every file written (data files and the metadata file).
    samples : int
        Rows written.
    channels : tuple of str
        Channels written (``time`` included when the log has timestamps).
    fs : float
        Sample rate in Hz, resolved as :func:`imunoise.read` does.
    issues : ParseIssues
        What the reader skipped, summed over the pieces, with the gap totals.
    bytes_read : int
        Size of the input.
    gaps : Gaps
        The missing samples: NaN rows of the output (and ``load(...).gaps``).
    """

    out: Path
    files: tuple[Path, ...]
    samples: int
    channels: tuple[str, ...]
    fs: float
    issues: ParseIssues
    bytes_read: int
    gaps: Gaps


def _width(channel: str) -> int:
    return 1 if channel == "time" else CHANNELS[channel][0]


def _order(channels: Iterable[str]) -> list[str]:
    """Channels in a fixed order: ``time`` first, then :data:`CHANNELS` order."""
    have = set(channels)
    return [c for c in ("time", *CHANNELS) if c in have]


class _NpyAppender:
    """A 1-D or 2-D float64 ``.npy`` file grown by appending rows.

    The header is written first for zero rows and rewritten in place at the end
    (numpy reserves room in the header for any row count, so its length does
    not change).
    """

    def __init__(self, path: Path, dtype: np.dtype, row_shape: tuple[int, ...]):
        self.path = path
        self.dtype = np.dtype(dtype)
        self.row_shape = row_shape
        self.rows = 0
        self.f = open(path, "xb")  # noqa: SIM115 - closed in close()
        self._header()
        self.data_start = self.f.tell()

    def _header(self) -> None:
        np.lib.format.write_array_header_1_0(
            self.f,
            {"descr": np.lib.format.dtype_to_descr(self.dtype), "fortran_order": False,
             "shape": (self.rows, *self.row_shape)},
        )

    def append(self, rows: np.ndarray) -> None:
        rows = np.ascontiguousarray(rows, dtype=self.dtype)
        self.f.write(memoryview(rows).cast("B"))
        self.rows += len(rows)

    def close(self) -> None:
        if self.f.closed:
            return
        end = self.f.tell()
        self.f.seek(0)
        self._header()
        if self.f.tell() != self.data_start:  # pragma: no cover - numpy guarantees room
            self.f.close()
            raise OSError(f"{self.path}: the .npy header grew when rewritten")
        self.f.seek(end)
        self.f.close()


class _Sink:
    """Where one message type's rows go; subclasses per output layout."""

    def __init__(self, staging: Path, channels: list[str]):
        self.staging = staging
        self.channels = channels
        self.rows = 0

    def append(self, cols: Mapping[str, np.ndarray]) -> None:
        raise NotImplementedError

    def close(self, meta: dict) -> None:
        raise NotImplementedError

    def publish(self, out: Path, meta: dict) -> list[Path]:
        """Move the finished files to ``out``; returns the files."""
        raise NotImplementedError

    def discard(self) -> None:
        if self.staging.is_dir():
            shutil.rmtree(self.staging, ignore_errors=True)
        else:
            self.staging.unlink(missing_ok=True)


class _DirSink(_Sink):
    def __init__(self, staging: Path, channels: list[str]):
        super().__init__(staging, channels)
        staging.mkdir()
        self.files = {
            ch: _NpyAppender(staging / f"{ch}.npy", np.float64,
                             () if _width(ch) == 1 else (_width(ch),))
            for ch in channels
        }

    def append(self, cols):
        for ch, f in self.files.items():
            f.append(cols[ch])
        self.rows += len(cols[self.channels[0]])

    def close(self, meta):
        for f in self.files.values():
            f.close()

    def publish(self, out, meta):
        _atomic.write_text(self.staging / "meta.json", json.dumps(meta, indent=1))
        _atomic.sync(self.staging)
        names = [f"{ch}.npy" for ch in self.channels] + ["meta.json"]
        if not out.exists():
            os.rename(self.staging, out)
        elif out.is_dir() and _only_ours(out) and _atomic.exchange_dir(self.staging, out):
            shutil.rmtree(self.staging, ignore_errors=True)  # the old output, swapped out
        else:
            # files of others in out: replace ours one by one, meta.json last, so a
            # directory whose meta.json is old still has every old channel file
            for name in names:
                _atomic.publish(self.staging / name, out / name)
            for stale in _OUR_FILES.difference(names):
                (out / stale).unlink(missing_ok=True)
            shutil.rmtree(self.staging, ignore_errors=True)
        return [out / name for name in names]


#: Every file a directory output may hold.
_OUR_FILES = frozenset(["meta.json", *(f"{c}.npy" for c in ("time", *CHANNELS))])


def _only_ours(out: Path) -> bool:
    return all(p.name in _OUR_FILES for p in out.iterdir())


def _record_dtype(channels: list[str]) -> np.dtype:
    return np.dtype([
        (ch, np.float64) if _width(ch) == 1 else (ch, np.float64, (_width(ch),))
        for ch in channels
    ])


class _NpySink(_Sink):
    def __init__(self, staging: Path, channels: list[str]):
        super().__init__(staging, channels)
        self.dtype = _record_dtype(channels)
        self.file = _NpyAppender(staging, self.dtype, ())

    def append(self, cols):
        m = len(cols[self.channels[0]])
        rows = np.empty(m, dtype=self.dtype)
        for ch in self.channels:
            rows[ch] = cols[ch]
        self.file.append(rows)
        self.rows += m

    def close(self, meta):
        self.file.close()

    def publish(self, out, meta):
        meta_path = _npy_meta_path(out)
        _atomic.publish(self.staging, out)
        _atomic.write_text(meta_path, json.dumps(meta, indent=1))
        return [out, meta_path]


def _npy_meta_path(out: Path) -> Path:
    return out.with_name(out.stem + ".meta.json")


class _ParquetSink(_Sink):
    def __init__(self, staging: Path, channels: list[str]):
        super().__init__(staging, channels)
        import pyarrow as pa
        import pyarrow.parquet as pq

        self.pa = pa
        self.names = [n for ch in channels for n in column_names(ch)]
        self.schema = pa.schema([(n, pa.float64()) for n in self.names])
        self.writer = pq.ParquetWriter(staging, self.schema)

    def append(self, cols):
        arrays = []
        for ch in self.channels:
            a = np.asarray(cols[ch])
            if a.ndim == 1:
                arrays.append(self.pa.array(a))
            else:
                arrays += [self.pa.array(np.ascontiguousarray(a[:, j])) for j in range(a.shape[1])]
        self.writer.write_batch(self.pa.record_batch(arrays, schema=self.schema))
        self.rows += len(cols[self.channels[0]])

    def close(self, meta):
        if meta is not None:
            self.writer.add_key_value_metadata({
                "fs": repr(meta["fs"]), "source": meta["source"], "imunoise": json.dumps(meta),
            })
        self.writer.close()

    def publish(self, out, meta):
        _atomic.publish(self.staging, out)
        return [out]


def _layout(out: Path) -> str:
    suffix = out.suffix.lower()
    if suffix == ".npy":
        return "npy"
    if suffix == ".parquet":
        return "parquet"
    if suffix:
        raise ValueError(
            f"out must be a directory (no suffix), a .npy or a .parquet file; got {str(out)!r}"
        )
    return "dir"


class _Writer:
    """Routes each message type's rows to its own staging sink; publishes one."""

    def __init__(self, out: Path, layout: str):
        self.out = out
        self.layout = layout
        self.sinks: dict[str, _Sink] = {}

    def _staging(self) -> Path:
        return _atomic.temporary_beside(self.out)

    def append(self, table: str, cols: Mapping[str, np.ndarray]) -> None:
        sink = self.sinks.get(table)
        if sink is None:
            channels = _order(cols)
            cls = {"dir": _DirSink, "npy": _NpySink, "parquet": _ParquetSink}[self.layout]
            sink = cls(self._staging(), channels)
            self.sinks[table] = sink
        sink.append(cols)

    def finish(self, primary: str | None, meta: dict) -> list[Path]:
        for name, sink in self.sinks.items():
            sink.close(meta if name == primary else None)
        files: list[Path] = []
        for name, sink in self.sinks.items():
            if name == primary:
                files = sink.publish(self.out, meta)
            else:
                sink.discard()
        return files

    def abort(self) -> None:
        for sink in self.sinks.values():
            try:
                sink.close(None)
            except Exception:  # noqa: BLE001 - best effort clean-up
                pass
            sink.discard()


class _Steps:
    """Exact median of the positive timestamp steps, from per-piece histograms."""

    def __init__(self):
        self.last: float | None = None
        self.values = np.empty(0)
        self.counts = np.empty(0, dtype=np.int64)
        self._pending: list[tuple[np.ndarray, np.ndarray]] = []
        self._pending_len = 0

    def add(self, t: np.ndarray) -> None:
        if len(t) == 0:
            return
        t = np.asarray(t, dtype=np.float64)
        steps = np.diff(t, prepend=t[:1] if self.last is None else np.array([self.last]))
        if self.last is None:
            steps = steps[1:]
        self.last = float(t[-1])
        steps = steps[steps > 0]
        if len(steps):
            v, c = np.unique(steps, return_counts=True)
            self._pending.append((v, c))
            self._pending_len += len(v)
            if self._pending_len > 1 << 20:
                self._compact()

    def _compact(self) -> None:
        if not self._pending:
            return
        vals = np.concatenate([self.values, *(v for v, _ in self._pending)])
        cnts = np.concatenate([self.counts, *(c for _, c in self._pending)])
        self.values, inverse = np.unique(vals, return_inverse=True)
        self.counts = np.bincount(inverse, weights=cnts, minlength=len(self.values)).astype(
            np.int64
        )
        self._pending, self._pending_len = [], 0

    def median(self) -> float | None:
        """``np.median`` of all positive steps (None without any)."""
        self._compact()
        total = int(self.counts.sum())
        if total == 0:
            return None
        cum = np.cumsum(self.counts)
        lo = self.values[np.searchsorted(cum, (total - 1) // 2, side="right")]
        hi = self.values[np.searchsorted(cum, total // 2, side="right")]
        return float(lo) if total % 2 else float(np.mean(np.array([lo, hi])))


class _GridStream:
    """One table's rows put on its time grid piece by piece, as :func:`imunoise.read`
    does for the whole log (:mod:`imunoise.readers.grid`).

    With timestamps, the nominal step is the median positive step of the first
    piece that has two, and every sample goes ``round(step / dt)`` rows after the
    one before; a sample that does not advance the grid (a duplicate, or a
    timestamp that goes back) is dropped and counted. Without timestamps, every
    damaged record of the table is a NaN row at its place; damaged records after
    the last good one of a piece wait for the next piece (at the end they are the
    capture's edge, not a gap).
    """

    def __init__(self):
        self.rows = 0
        self.dt: float | None = None
        self.last_t: float | None = None
        self.pending = 0
        self.gaps: list[list[int]] = []  # [first row, rows] of NaN runs, merged
        self.duplicate_time = 0
        self.time_reversed = 0

    def place(self, chans: dict[str, np.ndarray], missing) -> dict[str, np.ndarray]:
        n = len(next(iter(chans.values())))
        t = chans.get("time")
        grid = self._time_grid(t) if t is not None else self._missing_grid(n, missing)
        if grid is None or grid.is_identity:
            self.rows += n
            if t is not None and n:
                self.last_t = float(t[-1])
            return chans
        before = self.last_t
        out = {c: grid.place(a) for c, a in chans.items() if c != "time"}
        if t is not None:
            keep = grid.slot >= 0
            out["time"] = grid.place_time(t, before)
            self.last_t = float(np.asarray(t)[keep][-1]) if keep.any() else self.last_t
        runs = Gaps.from_valid(grid.valid, 1.0)
        for run_start, run in zip(runs.index, runs.samples, strict=True):
            start = self.rows + int(run_start)
            if self.gaps and self.gaps[-1][0] + self.gaps[-1][1] == start:
                self.gaps[-1][1] += int(run)
            else:
                self.gaps.append([start, int(run)])
        self.rows += grid.n
        return out

    def _time_grid(self, t: np.ndarray) -> TimeGrid | None:
        t = np.asarray(t, dtype=np.float64)
        if self.dt is None:
            pos = np.diff(t)[np.diff(t) > 0]
            if len(pos) < 2:
                return None
            self.dt = float(np.median(pos))
        if not len(t):
            return None
        first = [t[0] - self.dt] if self.last_t is None else [self.last_t]
        steps = np.diff(t, prepend=first)
        k = np.rint(steps / self.dt).astype(np.int64)
        drop = k < 1
        self.time_reversed += int((steps < 0).sum())
        self.duplicate_time += int((drop & (steps >= 0)).sum())
        k[drop] = 0
        slot = np.cumsum(k) - 1
        slot[drop] = -1
        n_out = int(slot.max()) + 1 if (~drop).any() else 0
        return TimeGrid(slot=slot, n=n_out)

    def _missing_grid(self, n: int, missing) -> TimeGrid | None:
        p = np.sort(np.asarray(missing if missing is not None else (), dtype=np.int64))
        if not n:
            if self.rows:
                self.pending += len(p)
            return None
        inner = p[p < n]
        if not self.rows:
            inner = inner[inner > 0]  # before the first good record: the capture's edge
        inner = np.concatenate([np.zeros(self.pending, dtype=np.int64), inner])
        self.pending = int((p >= n).sum())
        if not len(inner):
            return None
        shift = np.searchsorted(inner, np.arange(n), side="right")
        return TimeGrid(slot=np.arange(n, dtype=np.int64) + shift, n=n + len(inner))


def _stream_vn(path: Path, writer: _Writer, chunk_bytes: int, progress) -> tuple:
    """Parse ``path`` piece by piece into ``writer`` with one streaming parser (issues,
    locations and binary configurations run on across pieces as in one read).

    Returns the parse summary (:class:`~imunoise.readers.vn.VnTables` without rows),
    the timestamp steps and the ``(channels filled, rows)`` of every table, and the
    grids the rows were placed on.
    """
    stream = _core_vn.VnStream()
    grids: dict[str, _GridStream] = {}
    steps: dict[str, _Steps] = {}
    shape: dict[str, tuple[int, int]] = {}

    def write(rows) -> None:
        for name, cols in rows.tables.items():
            chans = table_channels(cols)
            if not chans:
                continue
            grid = grids.setdefault(name, _GridStream())
            n = len(next(iter(chans.values())))
            if n == 0:
                grid.place(chans, rows.missing.get(name))  # damaged records only
                continue
            filled = sum(1 for k in chans if k != "time")
            prev = shape.get(name, (filled, 0))
            shape[name] = (filled, prev[1] + n)
            if "time" in chans:
                steps.setdefault(name, _Steps()).add(chans["time"])
            writer.append(name, grid.place(chans, rows.missing.get(name)))

    total = path.stat().st_size
    chunk_bytes = min(chunk_bytes, total + 1)  # a piece never asks for more than the file
    done = 0
    with open(path, "rb") as f:
        while True:
            block = f.read(chunk_bytes)
            done += len(block)
            write(stream.feed(block))
            if progress is not None:
                progress(done, max(total, done))
            if len(block) < chunk_bytes:
                break
            del block
    summary = stream.finish()
    write(summary)
    return tables_of(summary), steps, shape, grids


def _meta(*, fs, source, fmt, issues: ParseIssues, messages, samples, channels, table,
          gaps: Gaps) -> dict:
    return {
        "imunoise_columnar": _META_VERSION,
        "fs": fs,
        "source": source,
        "format": fmt,
        "samples": samples,
        "channels": list(channels),
        "table": table,
        "messages": dict(messages),
        "issues": {
            "counts": dict(issues.counts),
            "first": {k: list(v) for k, v in issues.first.items()},
            "location": issues.location,
        },
        "gaps": {"index": gaps.index.tolist(), "samples": gaps.samples.tolist()},
    }


def convert(
    path,
    out,
    *,
    fs: float | None = None,
    chunk_bytes: int = CHUNK_BYTES,
    format: str = "auto",
    progress: Callable[[int, int], object] | None = None,
) -> Conversion:
    """Convert a log into a columnar file that :func:`load` memory-maps.

    Parameters
    ----------
    path : str or os.PathLike
        The log. VN-100 logs (ASCII, binary or both) are streamed with memory
        bounded by ``chunk_bytes``; CSV and ROS bags are read whole.
    out : str or os.PathLike
        A directory (no suffix), a ``.npy`` or a ``.parquet`` file (see the module
        docstring for the layouts). An existing output is replaced.
    fs : float, optional
        Sample rate of logs without timestamps, as for :func:`imunoise.read`.
    chunk_bytes : int
        Bytes read per piece (default 64 MiB, at least 4096; at most the file's
        size is read at once); peak memory is a few times this.
    format : str
        As for :func:`imunoise.read` (``"auto"`` detects it).
    progress : callable, optional
        ``progress(bytes_done, bytes_total)`` after every piece.

    Returns
    -------
    Conversion

    Notes
    -----
    The channels come from one message type, chosen as :func:`imunoise.read`
    chooses (the table filling the most channels, then the longest), so
    ``load(convert(p, out).out)`` holds exactly the arrays of ``imunoise.read(p)``,
    with the same ``fs`` and parse issue counts.
    """
    from imunoise.readers.read import FORMATS, detect_format

    path = Path(os.fspath(path))
    out = Path(os.fspath(out))
    if isinstance(chunk_bytes, bool) or not isinstance(chunk_bytes, (int, np.integer)):
        raise TypeError(f"chunk_bytes must be an int; got {type(chunk_bytes).__name__}")
    if chunk_bytes < 4096:
        raise ValueError(f"chunk_bytes must be at least 4096; got {chunk_bytes}")
    if format not in FORMATS:
        raise ValueError(f"format must be one of {FORMATS}; got {format!r}")
    layout = _layout(out)
    if layout == "parquet":
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise ImportError("Parquet output needs pyarrow (pip install pyarrow)") from None
    if not path.exists():
        raise FileNotFoundError(2, "no such file", str(path))
    _atomic.refuse_input(out, [path])
    if layout == "dir" and out.exists() and not out.is_dir():
        raise ValueError(f"out {str(out)!r} exists and is not a directory")
    if layout == "dir" and out.is_dir():
        for name in _OUR_FILES:
            _atomic.refuse_input(out / name, [path])
    if format == "auto":
        format = detect_format(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    writer = _Writer(out, layout)
    try:
        if registry.get(format).streamable and path.is_file():
            parsed, steps, shape, grids = _stream_vn(path, writer, int(chunk_bytes), progress)
            primary = richest_table(shape)
            step_histogram = steps.get(primary) if primary else None
            rate = fs_from_median_step(
                step_histogram.median() if step_histogram is not None else None, fs, str(path)
            )
            grid = grids[primary] if primary else _GridStream()
            counts = {**parsed.issues.counts, "duplicate_time": grid.duplicate_time,
                      "time_reversed": grid.time_reversed}
            issues = replace(parsed.issues, counts=counts)
            messages, fmt = parsed.messages, parsed.format
            gaps = Gaps(index=[g[0] for g in grid.gaps], samples=[g[1] for g in grid.gaps],
                        fs=rate)
        else:
            from imunoise.readers.read import read

            log = read(path, format=format, fs=fs, progress=progress)
            chans = {ch: getattr(log, ch) for ch in _order([*log.channels, "time"])
                     if getattr(log, ch) is not None}
            primary = "log" if chans and len(log) else None
            shape = {}
            if primary:
                step = max(1, chunk_bytes // (8 * sum(_width(c) for c in chans)))
                for i in range(0, len(log), step):
                    writer.append(primary, {c: a[i:i + step] for c, a in chans.items()})
            rate, issues, messages, fmt = log.fs, log.issues, log.messages, log.format
            gaps = log.gaps
        if primary is None:
            raise ValueError(f"{path}: no usable records ({issues})")
        sink = writer.sinks[primary]
        meta = _meta(fs=rate, source=str(path), fmt=fmt, issues=issues, messages=messages,
                     samples=sink.rows, channels=sink.channels, table=primary, gaps=gaps)
        files = writer.finish(primary, meta)
    except BaseException:
        writer.abort()
        raise
    issues = replace(issues, samples_missing=gaps.total, gaps=len(gaps), samples=sink.rows)
    return Conversion(out=out, files=tuple(files), samples=sink.rows,
                      channels=tuple(sink.channels), fs=rate, issues=issues,
                      bytes_read=path.stat().st_size, gaps=gaps)


def _read_meta(out: Path, layout: str) -> dict:
    if layout == "parquet":
        import pyarrow.parquet as pq

        kv = pq.read_metadata(out).metadata or {}
        raw = kv.get(b"imunoise")
        if raw is None:
            raise ValueError(f"{out}: not written by imunoise convert (no 'imunoise' metadata)")
        return json.loads(raw)
    meta_path = out / "meta.json" if layout == "dir" else _npy_meta_path(out)
    if not meta_path.exists():
        raise ValueError(f"{out}: not written by imunoise convert (no {meta_path.name})")
    return json.loads(meta_path.read_text())


def load(out) -> ImuLog:
    """Open the output of :func:`convert` as an :class:`ImuLog`.

    The channels of a directory or ``.npy`` output are read-only memory maps:
    nothing is read until used, and :func:`imunoise.adev` reads them in place.
    A ``.parquet`` output is read into memory.

    Parameters
    ----------
    out : str, os.PathLike or Conversion

    Returns
    -------
    ImuLog
        ``source``, ``format``, ``fs``, ``issues`` and ``messages`` are those of
        the converted log.
    """
    if isinstance(out, Conversion):
        out = out.out
    out = Path(os.fspath(out))
    if not out.exists():
        raise FileNotFoundError(2, "no such file or directory", str(out))
    layout = "dir" if out.is_dir() else _layout(out)
    meta = _read_meta(out, layout)
    channels = meta["channels"]
    if layout == "dir":
        arrays = {ch: np.load(out / f"{ch}.npy", mmap_mode="r") for ch in channels}
    elif layout == "npy":
        rec = np.load(out, mmap_mode="r")
        arrays = {ch: rec[ch] for ch in channels}
    else:
        import pyarrow.parquet as pq

        table = pq.read_table(out)
        arrays = {}
        for ch in channels:
            cols = [table.column(n).to_numpy() for n in column_names(ch)]
            arrays[ch] = cols[0] if len(cols) == 1 else np.column_stack(cols)
    iss = meta["issues"]
    issues = ParseIssues(counts=iss["counts"], first={k: tuple(v) for k, v in
                                                      iss["first"].items()},
                         location=iss["location"])
    fs = float(meta["fs"])
    # the gaps as convert found them: no pass over memory-mapped channels for NaN
    gaps = meta.get("gaps")
    gaps = None if gaps is None else Gaps(gaps["index"], gaps["samples"], fs)
    return ImuLog(fs=fs, source=meta["source"], format=meta["format"],
                  issues=issues, messages=meta["messages"], gaps=gaps, **arrays)
