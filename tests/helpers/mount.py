"""Logs of sensors on one mount: one motion, each sensor its own white noise, its own
clock (an offset) and its own start and end."""

from __future__ import annotations

import imunoise
import numpy as np


def mount_logs(n: int, fs: float, white, *, starts, ends, clock_offsets=None,
               motion: float = 1.5, jitter: float = 0.0, channels: str = "gyro",
               seed: int = 100) -> list[imunoise.ImuLog]:
    """One log per sensor: the sensors sample at the same instants k/fs, sensor i
    records rows ``starts[i]`` to ``ends[i]`` of ``n`` and stamps them on its own
    clock (``clock_offsets[i]`` s ahead) with uniform jitter of ``±jitter`` steps.
    The mount's motion: a Gauss–Markov sway (σ ``motion``·4/3, 5 s) and a 0.7 Hz
    rocking of amplitude ``motion``."""
    t = np.arange(n) / fs
    sway = imunoise.simulate(n, fs, gm=[(motion * 4 / 3, 5.0)], channels=3, seed=seed)
    common = sway + motion * np.sin(2 * np.pi * 0.7 * t + 0.3)[:, None]
    offsets = clock_offsets if clock_offsets is not None else [0.0] * len(white)
    rng = np.random.default_rng(seed + 1)
    logs = []
    for i, (w, a, b, off) in enumerate(zip(white, starts, ends, offsets, strict=True)):
        own = imunoise.simulate(b - a, fs, N=w, channels=3, seed=seed + 10 + i)
        stamps = t[a:b] + off + jitter / fs * rng.uniform(-1, 1, size=b - a)
        logs.append(imunoise.ImuLog.from_arrays(fs, **{channels: common[a:b] + own},
                                                time=stamps, source=f"<sensor {i}>"))
    return logs
