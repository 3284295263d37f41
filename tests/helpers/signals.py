"""Test signals with known noise types."""

import numpy as np


def flicker(n: int, rng: np.random.Generator) -> np.ndarray:
    """1/f noise by spectral shaping of white noise (test data only)."""
    spectrum = np.fft.rfft(rng.normal(size=n))
    f = np.arange(spectrum.size, dtype=float)
    f[0] = 1.0
    return np.fft.irfft(spectrum / np.sqrt(f), n)


def noise(kind: str, n: int, seed: int = 0, channels: int | None = None) -> np.ndarray:
    rng = np.random.default_rng(seed)
    cols = 1 if channels is None else channels
    out = np.empty((n, cols))
    for c in range(cols):
        if kind == "white":
            out[:, c] = rng.normal(size=n)
        elif kind == "flicker":
            out[:, c] = flicker(n, rng)
        elif kind == "walk":
            out[:, c] = np.cumsum(rng.normal(size=n))
        else:
            raise ValueError(kind)
    return out[:, 0] if channels is None else out
