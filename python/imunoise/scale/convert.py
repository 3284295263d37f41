"""Logs larger than memory: stream a log into a columnar file, memory-map it back.

:func:`convert` streams a log into a columnar file without holding it in memory:
the file is read in pieces of ``chunk_bytes`` and fed to one streaming parser
(:class:`imunoise._core.vn.VnStream`), which hands back the rows of the records
each piece completes (a record cut by the end of a piece waits for the next), and
those rows are appended to the output. Three things overlap: the next piece is read
(into one of two reused buffers) while one is parsed, and a piece's rows are written by a
thread while the next is parsed. Memory stays about five pieces (two buffers, the
columns being decoded, those being written, their growth) whatever the size of the log:
about 400 MB at the default 64 MiB. :func:`load` opens the result as an
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
    ``OUT.npy.meta.json`` (with the array file's fingerprint: the two are published
    together, see :func:`imunoise._support.atomic.publish_pair`).
``OUT.parquet``
    a column per axis (``gyro_x`` ...) written row group by row group (needs
    pyarrow); the metadata are the file's key-value metadata (``fs``, ``source``,
    ``imunoise``: the JSON of ``meta.json``). :func:`load` reads Parquet into
    memory.

VN-100 logs (ASCII, binary, or both) larger than one piece are streamed; smaller
ones, CSV and ROS bags are read whole by :func:`imunoise.read` and then written
the same way (so a log of one piece converts to exactly what ``read`` gives).
"""

from __future__ import annotations

import io
import json
import os
import shutil
from collections.abc import Callable, Iterable, Iterator, Mapping
from concurrent.futures import Future, ThreadPoolExecutor
from concurrent.futures import wait as futures_wait
from contextlib import ExitStack
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from imunoise._core import records as _core_records
from imunoise._core import vn as _core_vn
from imunoise._support import atomic as _atomic
from imunoise._support import summary as _summary
from imunoise._support.schema import CHANNELS, column_names
from imunoise.errors import ImunoiseTypeError, ImunoiseValueError
from imunoise.readers import metafile, registry
from imunoise.readers.columnar import META_KEY, log_meta, read_columnar
from imunoise.readers.grid import (
    FIRST_KEPT,
    OUTLIER_WINDOW,
    RESET_STEPS,
    SAME_STEP,
    Gaps,
    TimeGrid,
    outlier_stamps,
)
from imunoise.readers.log import ImuLog, ParseIssues, fs_from_median_step
from imunoise.readers.vn import richest_table, table_channels, tables_of

__all__ = ["CHUNK_BYTES", "Conversion", "convert", "load"]

#: Default bytes read per piece by :func:`convert`.
CHUNK_BYTES = 64 << 20
#: Largest piece read at once from a stream, whose size is unknown (a file piece is
#: at most the file).
MAX_STREAM_PIECE = 1 << 30


@dataclass(frozen=True, repr=False)
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

    def _facts(self) -> list[str]:
        return [f"{self.samples} samples at {_summary.number(self.fs)} Hz = "
                f"{_summary.duration(self.samples / self.fs)}",
                "channels " + " ".join(self.channels),
                f"{_summary.plural(len(self.files), 'file')}, {self.bytes_read} bytes read",
                str(self.gaps), f"issues: {self.issues}" if self.issues.total else "no issues"]

    def __repr__(self) -> str:
        return _summary.lines(f"Conversion({_summary.source_name(str(self.out))!r}",
                              self._facts(), sep=", ")

    def _repr_html_(self) -> str:
        """The output, what it holds and what the reader skipped, one fact a row."""
        return _summary.html_table(
            ["output", "samples", "channels", "files", "gaps", "issues"],
            [[str(self.out), *self._facts()]],
            caption=f"Conversion: {_summary.source_name(str(self.out))}")


def _width(channel: str) -> int:
    return 1 if channel == "time" else CHANNELS[channel][0]


def _order(channels: Iterable[str]) -> list[str]:
    """Channels in a fixed order: ``time`` first, then :data:`CHANNELS` order."""
    have = set(channels)
    return [c for c in ("time", *CHANNELS) if c in have]


class _NpyAppender:
    """A float64 ``.npy`` file (plain, or structured of float64 fields) grown by
    appending rows.

    The header is written first for zero rows and rewritten in place at the end
    (numpy reserves room in the header for any row count, so its length does
    not change). The rows go from the arrays given (views of the parser's
    tables) straight into the file, gathered, written and hashed by the core with
    the GIL released (:class:`imunoise._core.records.RecordFile`); :meth:`close`
    gives the file's fingerprint, the final header hashed with them.
    """

    def __init__(self, path: Path, dtype: np.dtype, row_shape: tuple[int, ...]):
        self.path = path
        self.dtype = np.dtype(dtype)
        self.row_shape = row_shape
        with open(path, "xb") as f:
            self._header(f, 0)
            self.data_start = f.tell()
        width = self.dtype.itemsize // 8 * int(np.prod(row_shape, dtype=np.int64))
        self.records = _core_records.RecordFile(str(path), width)

    def _header(self, f, rows: int) -> None:
        np.lib.format.write_array_header_1_0(
            f,
            {"descr": np.lib.format.dtype_to_descr(self.dtype), "fortran_order": False,
             "shape": (rows, *self.row_shape)},
        )

    @property
    def rows(self) -> int:
        return self.records.rows

    def append(self, *blocks: np.ndarray) -> None:
        """Append one row per row of the blocks (1-D: one value, 2-D: its columns),
        row r of each block in turn."""
        arrays = []
        for a in blocks:
            a = np.asarray(a, dtype=np.float64)
            if any(st < 0 or st % 8 for st in a.strides) or not a.flags.aligned:
                a = np.ascontiguousarray(a)  # the core reads non-negative 8-byte strides
            arrays.append(a)
        self.records.append(arrays)

    def close(self) -> dict:
        """Write the final header; returns the file's fingerprint."""
        head = io.BytesIO()
        self._header(head, self.records.rows)
        if head.tell() != self.data_start:  # pragma: no cover - numpy guarantees room
            raise OSError(f"{self.path}: the .npy header grew when rewritten")
        digest = self.records.digest(head.getvalue())
        self.records.close()
        self.records = None
        with open(self.path, "r+b") as f:
            f.write(head.getvalue())
        return _atomic.hashed_fingerprint(self.path, digest)


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
        self.marks = {f"{ch}.npy": f.close() for ch, f in self.files.items()}

    def publish(self, out, meta):
        # each channel file's fingerprint: a directory whose files were replaced one
        # by one (below) and interrupted is refused by the reader, not mixed
        _atomic.write_text(self.staging / "meta.json",
                           json.dumps({**meta, "data": self.marks}, indent=1))
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
        self.file.append(*(cols[ch] for ch in self.channels))
        self.rows += len(cols[self.channels[0]])

    def close(self, meta):
        self.mark = self.file.close()

    def publish(self, out, meta):
        meta_file = metafile.meta_path(out)
        _atomic.publish_pair(self.staging, out,
                             lambda tie: json.dumps({**meta, "data": tie}, indent=1), meta_file,
                             mark=self.mark)
        return [out, meta_file]


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
                "fs": repr(meta["fs"]), "source": meta["source"], META_KEY: json.dumps(meta),
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
        raise ImunoiseValueError(
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
    timestamp that goes back) is dropped and counted. As in ``read``, an outlier
    stamp (:func:`~imunoise.readers.grid.outlier_stamps`, judged with the last
    stamps of the piece before) is replaced by its neighbours' time and a jump
    back of more than :data:`~imunoise.readers.grid.RESET_STEPS` steps starts a
    new segment right after the last row; the rate is the least-squares line
    through (row, time) of the samples kept (:meth:`rate`). Without timestamps, every
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
        self.time_outlier = 0
        self.time_reset = 0
        self.first: dict[str, list[int]] = {}  # 1-based sample numbers, as TimeGrid.first
        self.seen = 0  # timestamped samples so far
        self.tail = np.zeros(0)  # the last kept stamps: context for outliers
        # per segment of the clock (a reset starts one): the least-squares line
        # through (row, time) of its kept samples, about its first
        self.segments: list[dict] = []
        self.single = True  # every step one nominal step so far
        self.piece_resets = np.zeros(0, np.int64)  # where the clock restarted in a piece
        self.held: dict[str, np.ndarray] | None = None  # the last samples, for the next piece

    def _note(self, kind: str, where: np.ndarray) -> None:
        kept = self.first.setdefault(kind, [])
        kept.extend(int(self.seen + i + 1) for i in where[:FIRST_KEPT - len(kept)])

    def _fit(self, rows: np.ndarray, t: np.ndarray, new_segment: bool = False) -> None:
        if not len(rows):
            return
        if new_segment or not self.segments:
            self.segments.append({"origin": (float(rows[0]), float(t[0])), "sums": np.zeros(5),
                                  "span": (float(t[0]), float(t[0])), "steps": _Steps()})
        seg = self.segments[-1]
        x, y = rows - seg["origin"][0], t - seg["origin"][1]
        seg["sums"] += (len(x), x.sum(), y.sum(), x @ x, x @ y)  # n, Σx, Σy, Σx², Σxy
        seg["span"] = (seg["span"][0], float(t[-1]))

    def _fit_piece(self, rows: np.ndarray, t: np.ndarray, kept: np.ndarray) -> None:
        """Fit the kept samples of a piece, a new segment after each reset."""
        bounds = [0, *self.piece_resets.tolist(), len(kept)]
        for i, (a, b) in enumerate(zip(bounds[:-1], bounds[1:], strict=True)):
            sel = kept[a:b]
            self._fit(rows[a:b][sel], t[a:b][sel], new_segment=i > 0)
            if self.segments:
                self.segments[-1]["steps"].add(t[a:b])

    def rate(self, median: float | None) -> float | None:
        """1 / the nominal step, decided as :meth:`TimeGrid.from_timestamps` decides
        it for the longest segment of the clock: the span over its samples when
        every step was one nominal step, else the least-squares slope; its median
        step when either agrees with it to ``SAME_STEP`` (``median``, the whole
        table's, when the segment has too few samples)."""
        if median is None:
            return None
        seg = max(self.segments, key=lambda g: g["sums"][0], default=None)
        if seg is None or seg["sums"][0] < 3:
            return 1.0 / median
        n, sx, sy, sxx, sxy = seg["sums"]
        median = seg["steps"].median() or median  # the segment's own, as read has it
        if self.single:
            dt = (seg["span"][1] - seg["span"][0]) / (n - 1)
        else:
            denom = n * sxx - sx * sx
            dt = (n * sxy - sx * sy) / denom if denom > 0 else median
            if not 0.5 * median < dt < 2.0 * median:
                dt = median
        if abs(dt - median) <= SAME_STEP * median:
            dt = median
        return 1.0 / dt

    def flush(self) -> dict[str, np.ndarray] | None:
        """The rows of the samples held back at the end of the last piece, placed."""
        if self.held is None or not len(self.held["time"]):
            return None
        held, self.held = self.held, None
        return self.place(held, None, final=True)

    def place(self, chans: dict[str, np.ndarray], missing, *,
              final: bool = False) -> dict[str, np.ndarray]:
        """The rows of a piece on the grid. With timestamps the last
        :data:`~imunoise.readers.grid.OUTLIER_WINDOW` samples wait for the next
        piece (or :meth:`flush`): an outlier is judged with samples on both sides."""
        t = chans.get("time")
        ahead = np.zeros(0)
        if t is not None:
            if self.held is not None:
                chans = {c: np.concatenate([self.held[c], a]) for c, a in chans.items()}
                self.held = None
            if not final:
                cut = max(len(chans["time"]) - OUTLIER_WINDOW, 0)
                self.held = {c: a[cut:] for c, a in chans.items()}
                chans = {c: a[:cut] for c, a in chans.items()}
                ahead = self.held["time"]
        n = len(next(iter(chans.values())))
        t = chans.get("time")
        if t is not None:
            grid, t = self._time_grid(t, ahead)
            chans = {**chans, "time": t}
            if grid is not None:
                keep = grid.slot >= 0
                self._fit_piece(self.rows + grid.slot, t, keep)
                self.tail = np.concatenate([self.tail, t[keep]])[-OUTLIER_WINDOW:]
        else:
            grid = self._missing_grid(n, missing)
        if grid is None or grid.is_identity:
            if t is not None and n and grid is None:
                self._fit(self.rows + np.arange(n), t)
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

    def _time_grid(self, t: np.ndarray, ahead: np.ndarray) -> tuple[TimeGrid | None, np.ndarray]:
        """The grid of one piece's stamps and the stamps with outliers replaced
        (``ahead``: the stamps that follow, held for the next piece)."""
        t = np.asarray(t, dtype=np.float64)
        if self.dt is None:
            pos = np.diff(t)[np.diff(t) > 0]
            if len(pos) < 2:
                self.seen += len(t)
                return None, t
            self.dt = float(np.median(pos))
        if not len(t):
            return None, t
        context = np.concatenate([self.tail, t, ahead])
        if len(context) >= 3:
            out, out_t = outlier_stamps(context, np.diff(context), self.dt)
            mine = (out >= len(self.tail)) & (out < len(self.tail) + len(t))
            if mine.any():
                t = t.copy()
                t[out[mine] - len(self.tail)] = out_t[mine]
                self.time_outlier += int(mine.sum())
                self._note("time_outlier", out[mine] - len(self.tail))
        first = [t[0] - self.dt] if self.last_t is None else [self.last_t]
        steps = np.diff(t, prepend=first)
        reset = steps < -RESET_STEPS * self.dt
        self.piece_resets = np.flatnonzero(reset)
        with np.errstate(over="ignore", invalid="ignore"):
            k = np.where(reset, 1, np.rint(steps / self.dt)).astype(np.int64)
        drop = k < 1
        back = (steps < 0) & ~reset
        self.time_reversed += int(back.sum())
        self.time_reset += int(reset.sum())
        self.duplicate_time += int((drop & (steps >= 0)).sum())
        self._note("time_reversed", np.flatnonzero(back))
        self._note("time_reset", np.flatnonzero(reset))
        self._note("duplicate_time", np.flatnonzero(drop & (steps >= 0)))
        self.single = self.single and bool(np.all(k[1 if self.last_t is None else 0:] == 1))
        self.seen += len(t)
        k[drop] = 0
        slot = np.cumsum(k) - 1
        slot[drop] = -1
        n_out = int(slot.max()) + 1 if (~drop).any() else 0
        return TimeGrid(slot=slot, n=n_out), t

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


def _blocks(f, first: bytes | None, chunk_bytes: int) -> Iterator[bytes | memoryview]:
    """``first`` (a piece already read, or None), then the rest of the open file ``f``
    in pieces of ``chunk_bytes``.

    Each piece is read while the one before is parsed, into one of two reused
    buffers (fresh ``bytes`` per piece would cost page faults and a pass over
    memory); a piece's view is released when the next is asked for, so use it
    before.
    """
    if first is not None:
        if not first:
            return
        short = len(first) < chunk_bytes
        yield first
        del first  # not held for the rest of the run
        if short:
            return
    buffers = [bytearray(chunk_bytes), bytearray(chunk_bytes)]
    with ThreadPoolExecutor(1, thread_name_prefix="imunoise-read") as pool:
        k = 0
        pending = pool.submit(_fill, f, buffers[k])
        while True:
            got = pending.result()
            if not got:
                return
            if got == chunk_bytes:
                pending = pool.submit(_fill, f, buffers[1 - k])
            view = memoryview(buffers[k])[:got]
            try:
                yield view
            finally:
                view.release()
            if got < chunk_bytes:
                return
            k = 1 - k


def _fill(f, buf: bytearray) -> int:
    """Read into ``buf`` until it is full or ``f`` ends; bytes read."""
    got = 0
    with memoryview(buf) as view:
        while got < len(buf):
            n = f.readinto(view[got:])
            if not n:
                break
            got += n
    return got


class _WriteBehind:
    """``writer.append`` one call behind, in a thread: the rows of a piece are written
    while the next piece is parsed (the parse runs without the GIL). At most one
    append is pending, so memory holds at most two pieces' rows."""

    def __init__(self, writer: _Writer):
        self.writer = writer
        self.pool = ThreadPoolExecutor(1, thread_name_prefix="imunoise-write")
        self.pending: Future | None = None

    def append(self, table: str, cols: Mapping[str, np.ndarray]) -> None:
        self.wait()
        self.pending = self.pool.submit(self.writer.append, table, cols)

    def wait(self) -> None:
        pending, self.pending = self.pending, None
        if pending is not None:
            pending.result()

    def close(self, *, raise_errors: bool) -> None:
        try:
            if raise_errors:
                self.wait()
            elif self.pending is not None:
                futures_wait([self.pending])
        finally:
            self.pool.shutdown(wait=True)


def _stream_vn(blocks: Iterable[bytes], total: int | None, writer: _Writer, progress) -> tuple:
    """Parse the pieces ``blocks`` (``total`` bytes, None for a stream) into ``writer``
    with one streaming parser (issues, locations and binary configurations run on
    across pieces as in one read).

    Returns the parse summary (:class:`~imunoise.readers.vn.VnTables` without rows),
    the timestamp steps and the ``(channels filled, rows)`` of every table, and the
    grids the rows were placed on.
    """
    stream = _core_vn.VnStream()
    grids: dict[str, _GridStream] = {}
    steps: dict[str, _Steps] = {}
    shape: dict[str, tuple[int, int]] = {}
    behind = _WriteBehind(writer)

    def write(rows) -> None:
        for name, cols in rows.tables.items():
            chans = table_channels(cols)
            if not chans:
                continue
            grid = grids.setdefault(name, _GridStream())
            n = len(next(iter(chans.values())))
            if n == 0:
                if "time" not in chans:
                    grid.place(chans, rows.missing.get(name))  # damaged records only
                continue
            filled = sum(1 for k in chans if k != "time")
            prev = shape.get(name, (filled, 0))
            shape[name] = (filled, prev[1] + n)
            if "time" in chans:
                steps.setdefault(name, _Steps()).add(chans["time"])
            behind.append(name, grid.place(chans, rows.missing.get(name)))

    done = 0
    try:
        for block in blocks:
            done += len(block)
            write(stream.feed(block))
            if progress is not None:
                progress(done, max(total or done, done))
            del block
        summary = stream.finish()
        write(summary)
        for name, grid in grids.items():  # the stamps held back for the outlier window
            rest = grid.flush()
            if rest is not None:
                behind.append(name, rest)
    except BaseException:
        behind.close(raise_errors=False)
        raise
    behind.close(raise_errors=True)
    return tables_of(summary), steps, shape, grids


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
    path : str, os.PathLike or binary file object
        The log. VN-100 logs (ASCII, binary or both) larger than ``chunk_bytes``
        are streamed with memory bounded by it; CSV and ROS bags are read whole.
        A stream (a binary file object such as ``sys.stdin.buffer``, a FIFO) is
        read once, start to end: its format is detected from the first piece.
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
    from imunoise.readers.read import FORMATS, detect_format, is_stream, stream_name

    stream = is_stream(path)
    name = stream_name(path) if stream else str(Path(os.fspath(path)))
    out = Path(os.fspath(out))
    if isinstance(chunk_bytes, bool) or not isinstance(chunk_bytes, (int, np.integer)):
        raise ImunoiseTypeError(f"chunk_bytes must be an int; got {type(chunk_bytes).__name__}")
    if chunk_bytes < 4096:
        raise ImunoiseValueError(f"chunk_bytes must be at least 4096; got {chunk_bytes}")
    if format not in FORMATS:
        raise ImunoiseValueError(f"format must be one of {FORMATS}; got {format!r}")
    layout = _layout(out)
    if layout == "parquet":
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise ImportError("Parquet output needs pyarrow (pip install pyarrow)") from None
    chunk_bytes = int(chunk_bytes)
    with ExitStack() as stack:
        # A log that fits in one piece is converted from imunoise.read's own result
        # (same grid, same fs to the bit); only larger VN logs are streamed.
        if stream:  # read once: the format is detected from the first piece, kept
            chunk_bytes = min(chunk_bytes, MAX_STREAM_PIECE)
            f = path if hasattr(path, "read") else stack.enter_context(open(path, "rb"))
            first = f.read(chunk_bytes)
            if format == "auto":
                format = detect_format(first)
            total = None
            streamed = registry.get(format).streamable and len(first) == chunk_bytes
            if not streamed:
                source = first + f.read()
                total = len(source)
        else:
            path = source = Path(os.fspath(path))
            if not path.exists():
                raise FileNotFoundError(2, "no such file", str(path))
            if format == "auto":
                format = detect_format(path)
            _atomic.refuse_input(out, [path])
            if layout == "dir" and out.exists() and not out.is_dir():
                raise ImunoiseValueError(f"out {str(out)!r} exists and is not a directory")
            if layout == "dir" and out.is_dir():
                for our_file in _OUR_FILES:
                    _atomic.refuse_input(out / our_file, [path])
            total = path.stat().st_size if path.is_file() else None
            if total is not None:  # a piece never asks for more than the file
                chunk_bytes = min(chunk_bytes, total + 1)
            streamed = (registry.get(format).streamable and total is not None
                        and total > chunk_bytes)
            if streamed:
                f = stack.enter_context(open(path, "rb"))
                first = None
        if streamed:
            source = _blocks(f, first, chunk_bytes)
            del first
        out.parent.mkdir(parents=True, exist_ok=True)
        return _convert(name, source, out, layout, fs=fs, format=format, total=total,
                        streamed=streamed, chunk_bytes=chunk_bytes, progress=progress)


def _convert(name: str, source, out: Path, layout: str, *, fs, format: str,
             total: int | None, streamed: bool, chunk_bytes: int, progress) -> Conversion:
    """:func:`convert` of ``source``: the pieces of a log to stream, or what
    :func:`imunoise.read` reads whole (a path, or the bytes of a stream)."""
    from imunoise.readers.read import read

    writer = _Writer(out, layout)
    done = 0
    try:
        if streamed:
            pieces = _counted(source)
            parsed, steps, shape, grids = _stream_vn(pieces, total, writer, progress)
            done = pieces.done
            primary = richest_table(shape)
            step_histogram = steps.get(primary) if primary else None
            grid = grids[primary] if primary else _GridStream()
            median = step_histogram.median() if step_histogram is not None else None
            line = grid.rate(median)
            rate = fs_from_median_step(None if line is None else 1.0 / line, fs, name)
            kinds = ("duplicate_time", "time_reversed", "time_outlier", "time_reset")
            counts = {**parsed.issues.counts, **{k: getattr(grid, k) for k in kinds}}
            first = {**parsed.issues.first, **{k: tuple(grid.first.get(k, ())) for k in kinds}}
            issues = replace(parsed.issues, counts=counts, first=first)
            messages, fmt = parsed.messages, parsed.format
            gaps = Gaps(index=[g[0] for g in grid.gaps], samples=[g[1] for g in grid.gaps],
                        fs=rate)
        else:
            log = read(source, format=format, fs=fs, progress=progress)
            if log.source == "<bytes>":
                log = replace(log, source=name)
            done = len(source) if isinstance(source, bytes) else total
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
            raise ImunoiseValueError(f"{name}: no usable records ({issues})")
        sink = writer.sinks[primary]
        meta = log_meta(fs=rate, source=name, fmt=fmt, issues=issues, messages=messages,
                     samples=sink.rows, channels=sink.channels, table=primary, gaps=gaps)
        files = writer.finish(primary, meta)
    except BaseException:
        writer.abort()
        raise
    issues = replace(issues, samples_missing=gaps.total, gaps=len(gaps), samples=sink.rows)
    return Conversion(out=out, files=tuple(files), samples=sink.rows,
                      channels=tuple(sink.channels), fs=rate, issues=issues,
                      bytes_read=done or 0, gaps=gaps)


class _counted:
    """The pieces of an iterable, counting their bytes in ``done``."""

    def __init__(self, blocks: Iterable[bytes]):
        self.blocks = blocks
        self.done = 0

    def __iter__(self) -> Iterator[bytes]:
        for block in self.blocks:
            self.done += len(block)
            yield block




def load(out) -> ImuLog:
    """Open the output of :func:`convert` as an :class:`ImuLog`.

    The channels of a directory or ``.npy`` output are read-only memory maps:
    nothing is read until used, and :func:`imunoise.adev` reads them in place.
    A ``.parquet`` output is read into memory. :func:`imunoise.read` reads the
    same outputs (format ``"columnar"``).

    Parameters
    ----------
    out : str, os.PathLike or Conversion

    Returns
    -------
    ImuLog
        ``source``, ``format``, ``fs``, ``issues``, ``messages`` and ``gaps`` are
        those of the converted log.

    Raises
    ------
    ValueError
        When the metadata is missing or contradicts itself or the arrays (the
        error names the field), e.g. a negative count of missing samples.
    """
    if isinstance(out, Conversion):
        out = out.out
    out = Path(os.fspath(out))
    if not out.exists():
        raise FileNotFoundError(2, "no such file or directory", str(out))
    if not out.is_dir():
        _layout(out)  # a suffix convert does not write is an error naming the layouts
    from imunoise.readers.read import naming

    with naming(out):
        return read_columnar(out)
