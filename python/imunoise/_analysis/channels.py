"""The rate channels an analysis of still logs works on: a log's gyro/accel columns
or an array's, with their names and the sample rate (events, warm-up, thermal)."""

from __future__ import annotations

import numpy as np

from imunoise._support import schema as _schema
from imunoise._support.validate import sample_rate
from imunoise.errors import ImunoiseTypeError, ImunoiseValueError
from imunoise.readers.log import ImuLog


class Columns:
    """The rate channels of a log one column at a time: ``len(cols)`` channels of
    ``cols.n`` samples, ``cols[j]`` a contiguous float64 copy of channel ``j`` (read a
    block at a time from a memory-mapped log, so one channel is in memory, never the
    whole log: :mod:`imunoise._support.stream`)."""

    def __init__(self, parts: list[tuple[np.ndarray, int | None]], n: int) -> None:
        self._parts = parts
        self.n = n

    def __len__(self) -> int:
        return len(self._parts)

    def __getitem__(self, j: int) -> np.ndarray:
        from imunoise._support import stream as _stream

        arr, col = self._parts[j]
        return _stream.column(arr, col)

    def owned(self, j: int) -> np.ndarray:
        """Channel ``j`` as a float64 array of its own (free to overwrite), read as
        ``cols[j]`` reads it."""
        col = self[j]
        arr, _col = self._parts[j]
        return col if col is not arr and col.base is None else col.copy()

    def rows(self, j: int, a: int, b: int) -> np.ndarray:
        """Rows ``a`` … ``b − 1`` of channel ``j`` as float64 (only those read)."""
        arr, col = self._parts[j]
        return np.asarray(arr[a:b] if col is None else arr[a:b, col], dtype=np.float64)

    def stacked(self, which, a: int, b: int) -> np.ndarray:
        """Rows ``a`` … ``b − 1`` of the channels ``which`` side by side, (b − a, k)
        float64 (``np.column_stack`` of them), read a block of rows at a time (a memory
        map's pages given back behind each block)."""
        from imunoise._support import stream as _stream

        out = np.empty((b - a, len(which)))
        for c, j in enumerate(which):
            arr, col = self._parts[j]
            for lo in range(a, b, _stream.BLOCK_ROWS):
                hi = min(b, lo + _stream.BLOCK_ROWS)
                out[lo - a:hi - a, c] = arr[lo:hi] if col is None else arr[lo:hi, col]
                _stream.release(arr)
        return out

    def arrays(self) -> list[np.ndarray]:
        """The arrays the columns are read from, in column order, each as (n, k) (a
        memory map stays one): a sensor's columns together, for reductions that read
        them side by side."""
        out: list[np.ndarray] = []
        for arr, _col in self._parts:
            if not any(arr is seen for seen in out):
                out.append(arr)
        return [a.reshape(len(a), -1) for a in out]


def rate_columns(data, fs, channels) -> tuple[Columns, float, tuple[str, ...]]:
    """:func:`rate_channels` a column at a time: the same checks, names and rate, the
    samples as :class:`Columns` (nothing copied until a column is asked for)."""
    if isinstance(data, ImuLog):
        wanted = _wanted(data, channels)
        parts, names = [], []
        for c in wanted:
            arr = getattr(data, c)
            k = 1 if arr.ndim == 1 else arr.shape[1]
            parts += [(arr, None if arr.ndim == 1 else j) for j in range(k)]
            names += [_schema.sensor_label(c, j, k) for j in range(k)]
        return Columns(parts, len(data)), sample_rate(data.fs if fs is None else fs), \
            tuple(names)
    x, fs, names = rate_channels(data, fs, channels)
    return Columns([(x, j) for j in range(x.shape[1])], len(x)), fs, names


def _wanted(data: ImuLog, channels) -> list[str]:
    """The log channels asked for (default: gyro and accel, those the log has)."""
    wanted = [c for c in _schema.ALLAN_SENSORS if getattr(data, c) is not None]
    if channels is not None:
        wanted = [channels] if isinstance(channels, str) else list(channels)
        missing = [c for c in wanted if c not in data.channels]
        if missing:
            raise ImunoiseValueError(
                f"channels {missing} are not in the log; it has {list(data.channels)}"
            )
    if not wanted:
        raise ImunoiseValueError(f"data has no gyro or accel channel; got {list(data.channels)}")
    return wanted


def rate_channels(data, fs, channels) -> tuple[np.ndarray, float, tuple[str, ...]]:
    """(n, k) float samples, the rate and the channel names (``"gyro X"`` …) of a log's
    ``channels`` (default: its gyro and accel) or of an array (``fs`` required)."""
    if isinstance(data, ImuLog):
        fs = data.fs if fs is None else fs
        blocks, names = [], []
        for c in _wanted(data, channels):
            arr = np.asarray(getattr(data, c), dtype=np.float64)
            arr = arr.reshape(len(arr), -1)
            blocks.append(arr)
            names += [_schema.sensor_label(c, j, arr.shape[1]) for j in range(arr.shape[1])]
        x = np.hstack(blocks)
    else:
        if channels is not None:
            raise ImunoiseValueError("channels= selects log channels; data is an array")
        if fs is None:
            raise ImunoiseValueError("fs is required when data is an array")
        try:
            x = np.asarray(data, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise ImunoiseTypeError(f"data must be an ImuLog or numeric array; got {exc}") from None
        if x.ndim not in (1, 2):
            raise ImunoiseValueError(f"data must have shape (n,) or (n, k); got {x.shape}")
        if np.isinf(x).any():
            raise ImunoiseValueError("data has infinite values (NaN marks a missing sample)")
        x = x.reshape(len(x), -1)
        names = ["x"] if x.shape[1] == 1 else [f"ch{j}" for j in range(x.shape[1])]
    return x, sample_rate(fs), tuple(names)
