"""Cost of gaps: ADEV (overlapping, octave taus, with CIs) of one channel of 10^7
samples without gaps and with 10 % of the samples missing in 100 gaps, same run.

    python benches/bench_gaps.py [--n N] [--runs R]

Each run prints the load average and the median of 5 timings of each case, and
their ratio (the goal: gapped at most 1.5 × gap-free). The machine may be shared:
compare ratios, and absolute times only at low load.
"""

from __future__ import annotations

import argparse
import os

import imunoise
import numpy as np
from bench_allan import median_time
from imunoise._support import cpu as _cpu


def with_gaps(y: np.ndarray, gaps: int, share: float, rng) -> np.ndarray:
    """y with ``gaps`` gaps of equal length covering ``share`` of it, at random
    non-overlapping places."""
    n = len(y)
    length = int(share * n / gaps)
    slots = np.sort(rng.choice(n // length, size=gaps, replace=False))
    out = y.copy()
    for s in slots:
        out[s * length : (s + 1) * length] = np.nan
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--n", type=int, default=10**7)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    fs = 100.0
    y = rng.normal(size=args.n) * 1e-3 + 9.81
    gapped = with_gaps(y, 100, 0.10, rng)
    print(
        f"machine: {_cpu.describe()}, "
        f"numpy {np.__version__}, imunoise {imunoise.__version__}; n = {args.n:.0e}, "
        f"{int(np.isnan(gapped).sum())} missing in 100 gaps"
    )
    print("| run | load (1/5/15 min) | gap-free (s) | 10 % in 100 gaps (s) | ratio |")
    print("|---|---|---|---|---|")
    for run in range(1, args.runs + 1):
        load = "/".join(f"{v:.1f}" for v in os.getloadavg())
        free = median_time(imunoise.adev, 5, y, fs)
        gaps = median_time(imunoise.adev, 5, gapped, fs)
        print(f"| {run} | {load} | {free:.3f} | {gaps:.3f} | {gaps / free:.2f} |", flush=True)


if __name__ == "__main__":
    main()
