"""imunoise vs allantools, same run, same data: medians of repeated timings.

    python benches/bench_allan.py [--quick]

Cases: 10^6 and 10^7 samples, octave taus and 50 per decade, 1 and 6 channels.
allantools has no multi-channel call, so its 6-channel time is 6 × one channel
(measured once per size). Prints a Markdown table of medians and ratios.
"""

from __future__ import annotations

import argparse
import statistics
import time

import allantools
import imunoise
import numpy as np
from imunoise import _cpu


def median_time(fn, repeats: int, *args, **kwargs) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn(*args, **kwargs)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="10^6 only, fewer repeats")
    args = parser.parse_args()
    sizes = [10**6] if args.quick else [10**6, 10**7]
    rng = np.random.default_rng(0)
    fs = 100.0
    print(f"machine: {_cpu.describe()}, "
          f"numpy {np.__version__}, allantools {allantools.__version__}, "
          f"imunoise {imunoise.__version__}")
    print("| n | taus | channels | imunoise (s) | allantools (s) | ratio |")
    print("|---|---|---|---|---|---|")
    for n in sizes:
        data = rng.normal(size=(n, 6)) * 1e-3 + np.array([0, 0, 9.81, 0, 0, 0])
        one = np.ascontiguousarray(data[:, 0])
        for label, taus in (("octave", "octave"), ("50/decade", 50)):
            ours_taus = imunoise.adev(one, fs, taus=taus).taus
            peer_taus = "octave" if taus == "octave" else ours_taus
            repeats_peer = 3 if n <= 10**6 else 1
            peer = median_time(
                allantools.oadev, repeats_peer, one, rate=fs, data_type="freq", taus=peer_taus
            )
            for channels in (1, 6):
                x = one if channels == 1 else data
                ours = median_time(imunoise.adev, 5, x, fs, taus=taus)
                peer_c = peer * channels
                print(f"| {n:.0e} | {label} | {channels} | {ours:.3f} | {peer_c:.3f}"
                      f"{' (6×1)' if channels > 1 else ''} | {peer_c / ours:.0f}× |", flush=True)


if __name__ == "__main__":
    main()
