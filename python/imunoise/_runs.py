"""Runs of True in a boolean series: the one edge detector of gaps, events, Welch
segments and departures."""

from __future__ import annotations

import numpy as np


def true_runs(flags) -> tuple[np.ndarray, np.ndarray]:
    """Start and stop (one past the end) of each run of True in the 1-D ``flags``."""
    edges = np.diff(np.concatenate(([0], np.asarray(flags, dtype=np.int8), [0])))
    return np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
