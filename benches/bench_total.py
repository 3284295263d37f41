"""imunoise vs allantools for the total family and Theo1, same run, same data.

    python benches/bench_total.py [--quick] [--million-only]

Part 1: MTOTDEV, HTOTDEV and Theo1 on 10^4 white-FM samples at octave taus
(``--quick``: 2000 samples; allantools needs minutes per statistic at 10^4).
allantools runs once per case (it is the slow side), imunoise three times; the
agreement of the two is printed too.
Part 2: imunoise alone on 10^6 samples over the full octave grid (MTOT/HTOT to
m = n/3, Theo1 to m < n; allantools would need days). See docs/total.md.
Prints Markdown tables of medians and ratios.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import platform
import statistics
import time
import warnings

import allantools
import imunoise
import numpy as np
from imunoise._support import cpu as _cpu

#: (name, imunoise function, allantools function): both libraries use the same names.
CASES = [
    (name, getattr(imunoise, name), getattr(allantools, name))
    for name in ("mtotdev", "htotdev", "theo1")
]


def timed(fn, repeats: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def peer_call(fn, y, fs):
    with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
        warnings.simplefilter("ignore")
        return fn(y, rate=fs, data_type="freq", taus="octave")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="2000 samples for part 1")
    parser.add_argument("--million-only", action="store_true", help="part 2 only")
    args = parser.parse_args()
    print(
        f"machine: {_cpu.describe()}, "
        f"Python {platform.python_version()}, numpy {np.__version__}, "
        f"allantools {allantools.__version__}, imunoise {imunoise.__version__}"
    )
    fs = 100.0
    if not args.million_only:
        compare_with_allantools(2000 if args.quick else 10_000, fs)
    alone_on_a_million(fs)


def compare_with_allantools(n: int, fs: float) -> None:
    timings(n, fs, seed=0, with_peer=True)


def alone_on_a_million(fs: float) -> None:
    timings(1_000_000, fs, seed=1, with_peer=False)


def timings(n: int, fs: float, *, seed: int, with_peer: bool) -> None:
    """One Markdown table of every case at n samples, octave taus; with the
    allantools time and the largest relative difference when ``with_peer``."""
    y = np.random.default_rng(seed).normal(size=n)
    alone = "" if with_peer else ", imunoise alone"
    print(f"\n### {n} samples{alone}, octave taus\n")
    if with_peer:
        print("| statistic | taus | imunoise (s) | allantools (s) | ratio | max rel. diff |")
        print("|---|---|---|---|---|---|")
    else:
        print("| statistic | taus | m | imunoise (s) |")
        print("|---|---|---|---|")
    for name, ours_fn, peer_fn in CASES:
        ours, r = timed(lambda f=ours_fn: f(y, fs), 3 if with_peer else 1)
        if not with_peer:
            print(f"| {name} | {len(r.taus)} | 1 … {int(r.m[-1])} | {ours:.2f} |")
            continue
        peer, (_t, dev, _e, _n) = timed(lambda f=peer_fn: peer_call(f, y, fs), 1)
        diff = float(np.max(np.abs(r.dev / dev - 1.0)))
        print(
            f"| {name} | {len(r.taus)} | {ours:.4f} | {peer:.2f} | {peer / ours:.0f}x "
            f"| {diff:.1e} |"
        )


if __name__ == "__main__":
    main()
