"""Two logs hold the same data: what a round trip through a file must keep."""

from __future__ import annotations

import numpy as np


def _bits(a: np.ndarray) -> np.ndarray:
    """float64 bit patterns, NaN normalised (a NaN row is a gap, its payload is not data)."""
    a = np.where(np.isnan(a), np.nan, np.asarray(a, dtype=np.float64))
    return a.view(np.int64)


def assert_same_log(back, log, *, source: bool = False) -> None:
    """Same fs (exactly), samples (bit for bit), time (to 1 ns), gaps, issues,
    messages and format; and the same ``source`` when asked."""
    assert back.fs == log.fs
    assert len(back) == len(log)
    assert back.channels == log.channels
    for ch in log.channels:
        np.testing.assert_array_equal(_bits(getattr(back, ch)), _bits(getattr(log, ch)), ch)
    if log.time is None:
        assert back.time is None
    else:
        assert np.max(np.abs(back.time - log.time), initial=0.0) <= 1e-9
    np.testing.assert_array_equal(back.gaps.index, log.gaps.index)
    np.testing.assert_array_equal(back.gaps.samples, log.gaps.samples)
    assert dict(back.issues.counts) == dict(log.issues.counts)
    assert dict(back.issues.first) == dict(log.issues.first)
    assert dict(back.messages) == dict(log.messages)
    assert back.format == log.format
    if source:
        assert back.source == log.source
