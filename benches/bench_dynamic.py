"""Dynamic Allan deviation: imunoise.dynamic_adev vs the naive loop of imunoise.adev
over every window, in one run, on the issue's case: a 5 h, 40 Hz, 3-channel log,
30 min windows every 5 min, octave taus. Prints both times, the ratio and the largest
relative difference of the deviations (they must be the same numbers).

Run:  python benches/bench_dynamic.py [--hours 5] [--repeat 3]
"""

from __future__ import annotations

import argparse
import time

import imunoise
import numpy as np
from imunoise._support import cpu as _cpu


def best_of(repeat: int, call):
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = call()
        best = min(best, time.perf_counter() - t0)
    return best, out


def naive(y, fs, window: float, step: float, taus):
    width, stride = round(window * fs), round(step * fs)
    return np.stack([imunoise.adev(y[s:s + width], fs, taus=taus).dev
                     for s in range(0, len(y) - width + 1, stride)])


def main() -> None:
    print(f"machine: {_cpu.describe()}", flush=True)
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hours", type=float, default=5.0)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    fs, window, step = 40.0, 1800.0, 300.0
    y = imunoise.simulate(int(args.hours * 3600 * fs), fs, N=1e-3, B=2e-5, K=1e-6,
                          channels=3, seed=1)
    fast_s, d = best_of(args.repeat, lambda: imunoise.dynamic_adev(y, fs, window=window,
                                                                   step=step))
    slow_s, dev = best_of(args.repeat, lambda: naive(y, fs, window, step, d.taus))
    diff = float(np.max(np.abs(d.dev / dev - 1)))
    print(f"{args.hours:g} h x 3 channels at {fs:g} Hz: {len(d.times)} windows of "
          f"{window / 60:g} min every {step / 60:g} min, {len(d.taus)} octave taus")
    print(f"  imunoise.dynamic_adev        {fast_s:8.3f} s   (whole-record adev for the "
          f"EDF included)")
    print(f"  loop of imunoise.adev        {slow_s:8.3f} s")
    print(f"  ratio loop / dynamic_adev    {slow_s / fast_s:8.1f} x")
    print(f"  max relative difference      {diff:.1e}")


if __name__ == "__main__":
    main()
