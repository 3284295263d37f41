"""Runs of True in a boolean series: the one edge detector of gaps, events, Welch
segments and departures."""

from __future__ import annotations

import numpy as np


def true_runs(flags) -> tuple[np.ndarray, np.ndarray]:
    """Start and stop (one past the end) of each run of True in the 1-D ``flags``."""
    flags = np.asarray(flags)
    if flags.dtype == bool and np.count_nonzero(flags) * 8 < flags.size:
        # few True (the usual flags: events, gaps): from their rows, without the
        # series' edges (three arrays of its length)
        rows = np.flatnonzero(flags)
        breaks = np.flatnonzero(np.diff(rows) > 1)
        return (np.concatenate((rows[:1], rows[breaks + 1])),
                np.concatenate((rows[breaks] + 1, rows[-1:] + 1)))
    edges = np.diff(np.concatenate(([0], np.asarray(flags, dtype=np.int8), [0])))
    return np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
