"""Helpers for the noise-model tests.

Allan deviations come from ``imunoise.adev``; :class:`StandInResult` carries the
documented ``AllanResult`` fields for synthetic (exact model) curves.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

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


@cache
def clean_five_term_fits(seed: int) -> tuple[tuple[object, imunoise.NoiseModel], ...]:
    """(grid, default fit) at octave, 10 and 20 taus per decade of a 2 h, 100 Hz,
    3-channel record of N, B and K only: the tone and resonance tests both ask it
    for terms it must not choose, so it is fitted once."""
    fs = 100.0
    x = imunoise.simulate(int(2 * 3600 * fs), fs, N=1e-3, B=3e-5, K=2e-6, channels=3,
                          seed=seed)
    return tuple((grid, quiet_fit(imunoise.adev(x, fs, taus=grid)))
                 for grid in ("octave", 10, 20))
