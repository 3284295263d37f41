"""ThêoBR and ThêoH timings, and the same ThêoBR assembled from allantools' pieces.

    python benches/bench_theo.py [--sizes 10000 100000] [--peer-size 2000]

Part 1: imunoise.theobr and imunoise.theoh (octave taus, white FM, one channel) at
each size, next to the time the cost warning predicts (the kernel rates in
rust/allan/estimators/theobr.rs: update them from this column's ratio).
Part 2 (``--peer-size``, 0 to skip): allantools (2024.06) has no ThêoBR; its oadev
and theo1 at the bias ratio's averaging factors plus theo1 at the octave taus give
the same numbers (checked), timed once.
Prints Markdown tables.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import platform
import time
import warnings

import allantools
import imunoise
import numpy as np
from imunoise._core import allan as _core_allan


def quiet(fn, *args, **kwargs):
    with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
        warnings.simplefilter("ignore")
        return fn(*args, **kwargs)


def timed(fn, *args):
    t0 = time.perf_counter()
    out = fn(*args)
    return time.perf_counter() - t0, out


def peer_theobr(y, fs, m):
    """ThêoBR from allantools' oadev and theo1, following SP 1065 §5.2.15."""
    n = (len(y) + 1) // 30 - 3
    i = np.arange(n + 1)
    _t, ad, _e, _n = quiet(allantools.oadev, y, rate=fs, data_type="freq", taus=(9 + 3 * i) / fs)
    _t, th, _e, _n = quiet(allantools.theo1, y, rate=fs, data_type="freq", taus=(12 + 4 * i) / fs)
    _t, dev, _e, _n = quiet(allantools.theo1, y, rate=fs, data_type="freq", taus=m / fs)
    return np.sqrt(np.mean(ad**2 / th**2)) * dev


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--no-theoh", action="store_true", help="time theobr only")
    parser.add_argument("--peer-size", type=int, default=2000)
    args = parser.parse_args()
    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"Python {platform.python_version()}, numpy {np.__version__}, "
        f"allantools {allantools.__version__}, imunoise {imunoise.__version__}\n"
    )
    print("| samples | taus | theobr (s) | theoh (s) | predicted (s) |")
    print("|---|---|---|---|---|")
    for size in args.sizes:
        y = np.random.default_rng(1).normal(size=size)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the cost warning, expected at 10^5
            t_br, br = timed(imunoise.theobr, y, 1.0)
            t_h = float("nan") if args.no_theoh else timed(imunoise.theoh, y, 1.0)[0]
        predicted = _core_allan.theobr_seconds(size + 1, [int(m) for m in br.m])
        print(
            f"| {size} | {len(br.taus)} | {t_br:.3g} | {t_h:.3g} | {predicted:.3g} |",
            flush=True,
        )
    if args.peer_size:
        y = np.random.default_rng(2).normal(size=args.peer_size)
        t_ours, br = timed(imunoise.theobr, y, 1.0)
        t_peer, dev = timed(peer_theobr, y, 1.0, br.m.astype(float))
        worst = float(np.max(np.abs(br.dev / dev - 1)))
        print(
            f"\n| {args.peer_size} samples, octave | imunoise (s) | allantools pieces (s) | "
            "ratio | max rel. diff |\n|---|---|---|---|---|\n"
            f"| theobr | {t_ours:.3g} | {t_peer:.3g} | {t_peer / t_ours:.0f}× | {worst:.1e} |"
        )


if __name__ == "__main__":
    main()
