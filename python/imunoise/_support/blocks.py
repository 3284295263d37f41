"""Whole-channel quantities from passes over blocks, with the whole array's numbers.

The event search (:mod:`imunoise._analysis.events`) needs quantities of a whole channel (its
noise law: a mean, lag products, a median of window energies; running sums of
squares) but should hold only a block of the arrays derived from it at a time. A
*series* is a function ``f(a, b)`` giving its rows ``a`` … ``b − 1`` as float64 (a
fresh array or a view the caller does not write to); the reductions here read it a
block of :data:`SERIES_BLOCK` rows at a time and give the numbers the whole-array
computation gives, bit for bit, whatever the block size:

- running sums (``np.cumsum``) are sequential: a block's sums start from the last
  sum of the block before (prepended, so every addition is the one the whole
  array's sum does);
- means and medians of values picked from the whole channel gather those values
  into one contiguous array (its pages only as far as they are written) and reduce
  it as the whole-array code reduces its compressed copy;
- lag products keep their FFT blocks at the same absolute rows
  (:func:`lag_products`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np

__all__ = ["SERIES_BLOCK", "Series", "gather", "lag_products", "ranges", "running_sums_at",
           "view"]

#: Rows of a series read at once.
SERIES_BLOCK = 1 << 18
#: Fewest rows per block (a short block would change how a filter of that many
#: taps is evaluated at its edges).
MIN_BLOCK = 64
#: Bytes of block transforms :func:`lag_products` holds at once.
LAG_GROUP_BYTES = 32 << 20

Series = Callable[[int, int], np.ndarray]


def ranges(n: int, unit: int = 1) -> Iterator[tuple[int, int]]:
    """``(a, b)`` covering rows 0 … ``n − 1``, :data:`SERIES_BLOCK` rows (at least
    :data:`MIN_BLOCK`) at a time, rounded up to a multiple of ``unit`` rows (blocks
    that start at a multiple of ``unit``)."""
    step = -(-max(MIN_BLOCK, SERIES_BLOCK) // unit) * unit
    for a in range(0, n, step):
        yield a, min(n, a + step)


def view(arr: np.ndarray) -> Series:
    """The series of an array in memory (its rows, not copied)."""
    return lambda a, b: arr[a:b]


def gather(series: Series, n: int, keep: np.ndarray | None = None) -> np.ndarray:
    """The finite values of ``series`` (at rows where ``keep`` is True, every row
    for None) in order, as one contiguous array: ``x[keep][np.isfinite(x[keep])]``
    of the whole array."""
    out = np.empty(n)
    m = 0
    for a, b in ranges(n):
        x = series(a, b)
        ok = np.isfinite(x) if keep is None else keep[a:b] & np.isfinite(x)
        k = int(np.count_nonzero(ok))
        out[m:m + k] = x[ok]
        m += k
    return out[:m]


def running_sums_at(series: Series, n: int, rows: np.ndarray) -> np.ndarray:
    """``s[rows]`` of the running sum ``s = [0, x0, x0 + x1, …]`` (length n + 1) of
    ``series``, the numbers ``np.concatenate(([0.0], np.cumsum(x)))`` gives; ``rows``
    sorted, in 0 … n."""
    rows = np.asarray(rows, dtype=np.int64)
    out = np.empty(len(rows))
    carry = 0.0
    for a, b in ranges(n):
        lo = int(np.searchsorted(rows, a, side="left"))
        hi = int(np.searchsorted(rows, b, side="right"))
        sums = np.empty(b - a + 1)
        sums[0] = carry
        sums[1:] = series(a, b)
        np.cumsum(sums, out=sums)  # sums[i] = s[a + i]: each addition the whole array's
        out[lo:hi] = sums[rows[lo:hi] - a]
        carry = sums[-1]
    return out


def lag_products(series: Series, n: int, lags: int) -> np.ndarray:
    """Σ_i x_i·x_(i+k) for k = 0 … lags − 1, by FFT over blocks of 8·lags samples (at
    least 1024) at fixed rows: n·log(lags) work, where one FFT of the whole record
    costs n·log(n) for the few lags the energy law needs. The blocks' transforms a
    group at a time (:data:`LAG_GROUP_BYTES`), their lag sums added block after
    block: the numbers do not depend on how the series is read."""
    block = max(8 * lags, 1024)
    size = 1 << int(np.ceil(np.log2(block + lags)))
    count = -(-n // block)
    total = np.zeros(lags)
    rows = max(1, LAG_GROUP_BYTES // (16 * size))
    for g in range(0, count, rows):
        k = min(rows, count - g)
        a = g * block
        padded = np.zeros(k * block + lags)  # rows a … of the record, zeros past its end
        b = min(n, a + len(padded))
        padded[:b - a] = series(a, b)
        heads = padded[:k * block].reshape(k, block)
        spans = np.lib.stride_tricks.sliding_window_view(padded, block + lags)[::block]
        products = np.conj(np.fft.rfft(heads, size, axis=1)) * np.fft.rfft(
            spans, size, axis=1)
        for row in np.fft.irfft(products, size, axis=1)[:, :lags]:
            total += row
    return total
