"""ThêoBR and ThêoH timings, against another build and against allantools' pieces.

    python benches/bench_theo.py [--sizes 10000 100000 720000] [--channels 1 3]
        [--baseline /path/to/other/python --baseline-sizes 20000 50000] [--peer-size 2000]

Part 1: imunoise.theobr and imunoise.theoh (octave taus, white FM) at each size and
channel count: wall time, CPU time of all threads (on a shared machine the wall
time depends on the load; CPU time much less), and the time the cost warning
predicts (the kernel rates in rust/allan/estimators/theobr.rs: update them from
this column's ratio).
Part 1b (``--baseline``): theobr of another tree (e.g. the main branch's
``python`` folder, run in a subprocess) on the same data: times, ratio and the
largest relative difference of the deviations.
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
import subprocess
import sys
import tempfile
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


def timed_cpu(fn, *args):
    """(wall s, CPU s of every thread, result)."""
    c0, t0 = time.process_time(), time.perf_counter()
    out = fn(*args)
    return time.perf_counter() - t0, time.process_time() - c0, out


_BASELINE_CHILD = """
import sys, time, warnings
import numpy as np
import imunoise
warnings.simplefilter("ignore")
y = np.load(sys.argv[1])
t0 = time.perf_counter()
r = imunoise.theobr(y, 1.0)
print(time.perf_counter() - t0)
np.save(sys.argv[2], r.dev)
"""


def baseline_theobr(path, y, tmp):
    """theobr of the tree at `path` on y in a subprocess: (seconds, dev)."""
    data, out = os.path.join(tmp, "y.npy"), os.path.join(tmp, "dev.npy")
    np.save(data, y)
    env = dict(os.environ, PYTHONPATH=path)
    proc = subprocess.run([sys.executable, "-c", _BASELINE_CHILD, data, out], env=env,
                          capture_output=True, text=True, check=True)
    return float(proc.stdout.split()[-1]), np.load(out)


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
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000, 720_000])
    parser.add_argument("--channels", type=int, nargs="+", default=[1, 3])
    parser.add_argument("--no-theoh", action="store_true", help="time theobr only")
    parser.add_argument("--baseline", help="another tree's python folder to time theobr against")
    parser.add_argument("--baseline-sizes", type=int, nargs="+", default=[20_000, 50_000])
    parser.add_argument("--peer-size", type=int, default=2000)
    args = parser.parse_args()
    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"Python {platform.python_version()}, numpy {np.__version__}, "
        f"allantools {allantools.__version__}, imunoise {imunoise.__version__}\n"
    )
    print(f"load average before: {os.getloadavg()[0]:.1f}\n")
    print("| samples | channels | taus | theobr wall (s) | theobr CPU (s) | theoh wall (s) "
          "| theoh CPU (s) | predicted (s) |")
    print("|---|---|---|---|---|---|---|---|")
    for size in args.sizes:
        for channels in args.channels:
            y = np.random.default_rng(1).normal(size=(size, channels))
            y = y[:, 0] if channels == 1 else y
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                t_br, c_br, br = timed_cpu(imunoise.theobr, y, 1.0)
                t_h, c_h = (float("nan"),) * 2
                if not args.no_theoh:
                    t_h, c_h, _ = timed_cpu(imunoise.theoh, y, 1.0)
            predicted = channels * _core_allan.theobr_seconds(size + 1, [int(m) for m in br.m])
            print(f"| {size} | {channels} | {len(br.taus)} | {t_br:.3g} | {c_br:.3g} | {t_h:.3g} "
                  f"| {c_h:.3g} | {predicted:.3g} |", flush=True)
    print(f"\nload average after: {os.getloadavg()[0]:.1f}")
    if args.baseline:
        print(f"\n| samples | theobr, {args.baseline} (s) | theobr, this tree (s) | ratio "
              "| max rel. diff |\n|---|---|---|---|---|")
        with tempfile.TemporaryDirectory() as tmp:
            for size in args.baseline_sizes:
                y = np.random.default_rng(3).normal(size=size)
                t_base, dev_base = baseline_theobr(args.baseline, y, tmp)
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    t_ours, br = timed(imunoise.theobr, y, 1.0)
                worst = float(np.max(np.abs(br.dev / dev_base - 1)))
                print(f"| {size} | {t_base:.3g} | {t_ours:.3g} | {t_base / t_ours:.0f}× "
                      f"| {worst:.1e} |", flush=True)
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
