"""Helpers for the noise-model tests.

Allan deviations come from ``imunoise.adev``; :class:`StandInResult` carries the
documented ``AllanResult`` fields for synthetic (exact model) curves.
"""

from __future__ import annotations

from dataclasses import dataclass

import imunoise
import numpy as np


@dataclass(frozen=True)
class StandInResult:
    kind: str
    overlapping: bool
    taus: np.ndarray
    dev: np.ndarray
    var: np.ndarray
    n: np.ndarray
    edf: np.ndarray
    alpha: np.ndarray
    fs: float
    confidence: float = 0.683


def allan(x, fs):
    """Overlapping ADEV at octave taus."""
    return imunoise.adev(x, fs, taus="octave", overlapping=True)


def quiet_fit(result, **kwargs):
    """``imunoise.fit`` without the coverage warning (the curves these tests fit
    are meant to be hard)."""
    return imunoise.fit(result, warn_coverage=False, **kwargs)
