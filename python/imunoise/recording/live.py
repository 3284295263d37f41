"""The live view of a recording: what has come in so far, refreshed once a second.

The recorder hands every chunk it wrote to :meth:`LiveView.feed`, which only
queues it (bytes are immutable: the view parses the very chunk, never touching
the recorder's buffers); a thread of its own parses the queue with the streaming
VN parser and keeps the gyro samples of the main message type. Once a second it
shows elapsed and target time, samples and rate, damaged records, port outages,
per-axis mean and std, the overlapping ADEV's N and B read-offs with their
uncertainties and the planner's answer for K. The view is off when the output is
not a terminal.

The ADEV is an :class:`imunoise.AllanStream` fed only the samples that arrived
since the last refresh, so a refresh costs the same after ten hours as after ten
seconds. With timestamps, a dropped sample (a step of the stamps longer than one
period) is fed as a NaN row, a gap the stream skips as :func:`imunoise.adev` does.
The rate is the configured output rate until timestamps give one; when the rate
or the main message type changes, the stream starts again from the samples kept
(the rate labels every tau and places every gap).
"""

from __future__ import annotations

import math
import queue
import threading
import time
from dataclasses import dataclass

import numpy as np

from imunoise._analysis.allan_stream import AllanStream
from imunoise._core import vn as _core_vn
from imunoise._simulation.log import DEFAULT_K
from imunoise.allan import AllanResult
from imunoise.display import duration
from imunoise.noise._terms import FLICKER
from imunoise.planner import plan as make_plan
from imunoise.readers.log import DEFAULT_FS
from imunoise.readers.vn import richest_table, table_channels

__all__ = ["LiveView", "Snapshot"]

#: Seconds between two refreshes.
REFRESH = 1.0
#: Samples before the live view shows an ADEV.
MIN_SAMPLES = 16
#: Relative change of the rate that restarts the ADEV stream (its taus and gaps
#: follow the rate; the timestamps' median step settles within this early on).
RATE_CHANGE = 1e-3
#: Longest step of the timestamps (s) read as dropped samples; a longer jump forward
#: is the clock's (set, or reset to a later value) and leaves no gap rows.
MAX_GAP = 600.0


@dataclass(frozen=True)
class Snapshot:
    """What the live view knows: ``gyro`` (n, 3) samples of the main message type
    so far, its rate, the ADEV of those samples (``None`` before 16), damaged
    records, outages and ``dropped`` samples (steps of the timestamps, when the
    output has them)."""

    gyro: np.ndarray
    fs: float
    adev: AllanResult | None
    damaged: int
    outages: int
    dropped: int = 0


class _Table:
    def __init__(self) -> None:
        self.gyro: list[np.ndarray] = []
        self.time: list[np.ndarray] = []
        self.rows = 0
        self.damaged = 0
        self.filled = 0


class LiveView:
    """Parse a copy of the stream in a thread; show it on ``stream`` when ``show``.
    ``rates``: the ``"ascii"`` and ``"binary"`` output rates (Hz) set on the sensor,
    for a main message type without timestamps."""

    def __init__(self, *, rates: dict[str, float], target: float | None, stream=None,
                 show: bool = True) -> None:
        self.rates = rates
        self.target = target
        self.stream = stream
        self.show = show
        self.outages = 0
        self.started = time.monotonic()
        self._queue: queue.SimpleQueue = queue.SimpleQueue()
        self._parser = _core_vn.VnStream(False)
        self._tables: dict[str, _Table] = {}
        self._lock = threading.Lock()
        self._lines = 0
        # the ADEV stream: its table, rate, samples fed, last stamp fed
        self._stream: AllanStream | None = None
        self._fed: tuple[str | None, float, int, float | None] = (None, 0.0, 0, None)
        self._stream_lock = threading.Lock()
        self._thread = threading.Thread(target=self._run, name="imunoise-live", daemon=True)
        self._thread.start()

    def feed(self, data: bytes) -> None:
        """Queue a chunk (never blocks, never copies)."""
        self._queue.put(data)

    def outage(self) -> None:
        self.outages += 1

    def _parse(self, data: bytes) -> None:
        rows = self._parser.feed(data)
        with self._lock:
            for name, cols in rows.tables.items():
                channels = table_channels(cols)
                table = self._tables.setdefault(name, _Table())
                table.filled = max(table.filled, sum(1 for k in channels if k != "time"))
                n = len(next(iter(cols.values()))) if cols else 0
                table.rows += n
                if "gyro" in channels:
                    table.gyro.append(np.array(channels["gyro"], dtype=float))
                if "time" in channels:
                    table.time.append(np.array(channels["time"], dtype=float))
            for name, missing in rows.missing.items():
                self._tables.setdefault(name, _Table()).damaged += len(missing)

    def _run(self) -> None:
        shown = time.monotonic()
        while True:
            try:
                data = self._queue.get(timeout=0.1)
            except queue.Empty:
                data = b""
            if data is None:
                return
            if data:
                self._parse(data)
            if self.show and time.monotonic() - shown >= REFRESH:
                shown = time.monotonic()
                self._render(self.snapshot())

    def snapshot(self) -> Snapshot:
        """The samples so far and their ADEV (computed now)."""
        with self._lock:
            shapes = {k: (t.filled if t.gyro else 0, t.rows) for k, t in self._tables.items()}
            name = richest_table(shapes)
            table = self._tables.get(name) if name else None
            gyro = np.concatenate(table.gyro) if table and table.gyro else np.zeros((0, 3))
            stamps = np.concatenate(table.time) if table and table.time else None
            damaged = sum(t.damaged for t in self._tables.values())
        kind = "ascii" if name and name.startswith("VN") else "binary"
        fs = self.rates.get(kind) or next(iter(self.rates.values()), DEFAULT_FS)
        dropped = 0
        if stamps is not None and len(stamps) > 2:
            steps = np.diff(stamps)
            step = np.median(steps)
            if step > 0:
                fs = 1.0 / step
                # samples missing between stamps (a clock reset's backward step counts none)
                dropped = int(np.sum(np.maximum(np.round(steps / step) - 1, 0)))
        result = self._adev(name, gyro, stamps, fs)
        return Snapshot(gyro=gyro, fs=fs, adev=result, damaged=damaged, outages=self.outages,
                        dropped=dropped)

    def _adev(self, name: str | None, gyro: np.ndarray, stamps: np.ndarray | None,
              fs: float) -> AllanResult | None:
        """The ADEV of the main table's gyro so far: the stream fed the samples since
        the last call (NaN rows for the samples its timestamps say were dropped)."""
        with self._stream_lock:
            table, rate, fed, last = self._fed
            if self._stream is None or table != name or abs(fs / rate - 1.0) > RATE_CHANGE:
                self._stream = AllanStream(fs, channels=3)
                table, rate, fed, last = name, fs, 0, None
            new = gyro[fed:]
            if stamps is not None and len(stamps) == len(gyro) and len(new):
                new, last = _with_dropped(new, stamps[fed:], last, rate)
            if len(new):
                self._stream.update(new)
            self._fed = (table, rate, len(gyro), last)
            if len(gyro) < MIN_SAMPLES:
                return None
            try:
                return self._stream.result()
            except ValueError:  # fewer than 3 samples in a row so far
                return None

    def _render(self, snap: Snapshot) -> None:
        elapsed = time.monotonic() - self.started
        n = len(snap.gyro)
        head = (f"recording {duration(elapsed)}"
                + (f" / {duration(self.target)}" if self.target else "")
                + f"  samples {n} at {snap.fs:.4g} Hz  damaged {snap.damaged}"
                + f"  dropped {snap.dropped}  outages {snap.outages}")
        lines = [head]
        if n:
            mean, std = np.nanmean(snap.gyro, axis=0), np.nanstd(snap.gyro, axis=0)
            lines.append("gyro mean " + " ".join(f"{v:+.3e}" for v in mean)
                         + "  std " + " ".join(f"{v:.3e}" for v in std) + " rad/s")
        if snap.adev is not None:
            lines.extend(self._readoffs(snap))
        text = (f"\x1b[{self._lines}F\x1b[J" if self._lines else "") + "\n".join(lines) + "\n"
        self._lines = len(lines)
        self.stream.write(text)
        self.stream.flush()

    def _readoffs(self, snap: Snapshot) -> list[str]:
        r = snap.adev
        taus, dev, edf = r.taus, np.atleast_2d(r.dev.T).T, np.atleast_2d(r.edf.T).T
        i1 = int(np.argmin(np.abs(np.log(taus))))
        N = dev[i1] * math.sqrt(taus[i1])
        imin = np.nanargmin(dev, axis=0)
        B = dev[imin, range(dev.shape[1])] / FLICKER
        uN = 1 / np.sqrt(2 * edf[i1])
        uB = 1 / np.sqrt(2 * edf[imin, range(dev.shape[1])])
        lines = ["N " + " ".join(f"{v:.3g}±{100 * u:.2g}%" for v, u in zip(N, uN, strict=True))
                 + f" rad/s/√Hz (τ {taus[i1]:.3g} s)",
                 "B " + " ".join(f"{v:.3g}±{100 * u:.2g}%" for v, u in zip(B, uB, strict=True))
                 + " rad/s (at the ADEV minimum so far)"]
        try:
            p = make_plan({"N": float(np.median(N)), "B": float(np.median(B)),
                           "K": DEFAULT_K["gyro"]}, fs=snap.fs)
        except ValueError:
            return lines
        elapsed = len(snap.gyro) / snap.fs
        k = p.terms.get("K")
        if k is not None:
            u = p.uncertainty(elapsed)["K"]
            more = max(0.0, k.seconds - elapsed)
            lines.append(f"K resolved to ±{100 * u:.2g} %" if math.isfinite(u)
                         else "K not resolved yet")
            lines[-1] += f" — {duration(more)} more for ±{100 * p.target:g} %"
        return lines

    def close(self) -> Snapshot:
        """Stop the thread once everything queued is parsed; the final snapshot."""
        self._queue.put(None)
        self._thread.join()
        snap = self.snapshot()
        if self.show:
            self._render(snap)
        return snap


def _with_dropped(samples: np.ndarray, stamps: np.ndarray, last: float | None,
                  fs: float) -> tuple[np.ndarray, float]:
    """``samples`` with a NaN row for every sample dropped before each (a step of the
    stamps of k periods leaves k − 1 missing; a step back, a clock reset, none),
    ``last`` the stamp of the sample before them; and the last stamp."""
    steps = np.diff(stamps, prepend=stamps[0] if last is None else last)
    # a NaN stamp or a jump forward beyond MAX_GAP is a clock's fault, not dropped samples
    steps = np.where(np.isfinite(steps) & (steps <= MAX_GAP), steps, 0.0)
    gaps = np.maximum(np.rint(steps * fs) - 1, 0).astype(np.int64)
    if not gaps.any():
        return samples, float(stamps[-1])
    rows = np.arange(len(samples)) + np.cumsum(gaps)
    out = np.full((int(rows[-1]) + 1, samples.shape[1]), np.nan)
    out[rows] = samples
    return out, float(stamps[-1])
