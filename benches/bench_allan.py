"""imunoise vs allantools, same run, same data: medians of repeated timings.

    python benches/bench_allan.py [--quick] [--phase] [--best] [--octave]

Cases: 10^6 and 10^7 samples, octave taus and 50 per decade, 1 and 6 channels.
allantools has no multi-channel call, so its 6-channel time is 6 × one channel
(measured once per size). Prints a Markdown table of medians and ratios
(``--best``: of the least times, the least disturbed runs on a shared machine;
``--octave``: the octave grids only).

``--phase``: MTIE and PDEV against allantools' mtie and pdev instead (octave taus,
one channel; allantools' PDEV loops over every start in Python, O(n²), so its sizes
are smaller). Measured on a shared 2-core machine (values equal to 1e-14): MTIE 10^5
samples 0.032 s against allantools 1.8 s (58×), 10^6 0.23 s against 201 s (875×);
PDEV 10^4 samples 0.005 s against 3.4 s (680×), 2·10^4 0.008 s against 15 s (1900×).
"""

from __future__ import annotations

import argparse
import statistics
import time

import allantools
import imunoise
import numpy as np
from imunoise._support import cpu as _cpu

#: How repeated timings are summarised: their median, or their least (``--best``).
SUMMARY = statistics.median


def median_time(fn, repeats: int, *args, **kwargs) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn(*args, **kwargs)
        times.append(time.perf_counter() - t0)
    return SUMMARY(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="10^6 only, fewer repeats")
    parser.add_argument("--phase", action="store_true",
                        help="MTIE and PDEV against allantools instead of ADEV")
    parser.add_argument("--best", action="store_true",
                        help="least of the repeated timings instead of their median")
    parser.add_argument("--octave", action="store_true", help="octave taus only")
    args = parser.parse_args()
    if args.best:
        global SUMMARY
        SUMMARY = min
    if args.phase:
        phase_statistics(quick=args.quick)
        return
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
        grids = (("octave", "octave"), ("50/decade", 50))
        for label, taus in grids[:1] if args.octave else grids:
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


def phase_statistics(quick: bool) -> None:
    """MTIE and PDEV (octave taus, one channel) against allantools: medians, ratios."""
    rng = np.random.default_rng(0)
    fs = 100.0
    cases = [("mtie", 10**5), ("mtie", 10**6), ("pdev", 10**4), ("pdev", 2 * 10**4)]
    if quick:
        cases = [cases[0], cases[2]]
    print("| statistic | n | imunoise (s) | allantools (s) | ratio | max rel. difference |")
    print("|---|---|---|---|---|---|")
    for name, n in cases:
        y = rng.normal(size=n)
        ours = median_time(getattr(imunoise, name), 5, y, fs)
        peer = median_time(getattr(allantools, name), 1, y, rate=fs, data_type="freq",
                           taus="octave")
        r = getattr(imunoise, name)(y, fs)
        dev = getattr(allantools, name)(y, rate=fs, data_type="freq", taus="octave")[1]
        diff = float(np.max(np.abs(r.dev / dev - 1)))
        print(f"| {name} | {n:.0e} | {ours:.3f} | {peer:.3f} | {peer / ours:.0f}× | "
              f"{diff:.1e} |", flush=True)


if __name__ == "__main__":
    main()
