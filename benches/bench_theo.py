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
Part 3 (``--fast-size``, 0 to skip): the fast ThêoBR (``ratio_block=b``) against the exact
bias ratio on white PM, white FM, flicker FM and random-walk FM (``--fast-seeds`` records
each): median and largest |ThêoBR_b / ThêoBR − 1| (the same at every tau: κ_b/κ) and
the time of each.
Part 4 (``--ladder-size``, 0 to skip): the "sp1065" ladder (n = ⌊N/6⌋ − 3) against the
default one: time and κ ratio.
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
from imunoise._support import cpu as _cpu


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


def noise_type(kind: str, n: int, rng: np.random.Generator) -> np.ndarray:
    """Rate samples of white PM, white FM, flicker FM or random-walk FM."""
    if kind == "white PM":
        return np.diff(rng.normal(size=n + 1))
    if kind == "white FM":
        return rng.normal(size=n)
    if kind == "flicker FM":
        spectrum = np.fft.rfft(rng.normal(size=n))
        f = np.arange(spectrum.size, dtype=float)
        f[0] = 1.0
        return np.fft.irfft(spectrum / np.sqrt(f), n)
    return np.cumsum(rng.normal(size=n))


def fast_error(size: int, seeds: int, blocks: list[int]) -> None:
    print(f"\nFast ThêoBR against exact, {size} samples, {seeds} records per noise type "
          f"(load {os.getloadavg()[0]:.1f}):\n")
    print("| noise | exact (s) | " + " | ".join(f"b = {b}: median / max error, s" for b in blocks)
          + " |\n|---|---|" + "---|" * len(blocks))
    for kind in ("white PM", "white FM", "flicker FM", "random-walk FM"):
        errors = {b: [] for b in blocks}
        times = {b: [] for b in [1, *blocks]}
        for seed in range(seeds):
            y = noise_type(kind, size, np.random.default_rng(100 + seed))
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                t, exact = timed(imunoise.theobr, y, 1.0)
                times[1].append(t)
                for b in blocks:
                    t, fast = timed(lambda y=y, b=b: imunoise.theobr(y, 1.0, ratio_block=b))
                    times[b].append(t)
                    errors[b].append(float(np.max(np.abs(fast.dev / exact.dev - 1))))
        cells = [f"{np.median(errors[b]) * 100:.1f} % / {np.max(errors[b]) * 100:.1f} %, "
                 f"{np.median(times[b]):.2g}" for b in blocks]
        print(f"| {kind} | {np.median(times[1]):.2g} | " + " | ".join(cells) + " |", flush=True)


def ladder_cost(size: int) -> None:
    y = np.random.default_rng(5).normal(size=size)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t_default, c_default, default = timed_cpu(imunoise.theobr, y, 1.0)
        t_sp, c_sp, sp = timed_cpu(lambda: imunoise.theobr(y, 1.0, ratio_ladder="sp1065"))
    predicted = [_core_allan.theobr_seconds(size + 1, [int(m) for m in default.m],
                                            ratio_ladder=ladder)
                 for ladder in ("taylor-howe", "sp1065")]
    print(f"\nRatio ladders, {size} samples, white FM (load {os.getloadavg()[0]:.1f}):\n\n"
          "| ladder | wall / CPU (s) | predicted (s) | κ relative to taylor-howe |\n"
          "|---|---|---|---|\n"
          f"| taylor-howe, n = ⌊N/30⌋ − 3 | {t_default:.3g} / {c_default:.3g} "
          f"| {predicted[0]:.3g} | 1 |\n"
          f"| sp1065, n = ⌊N/6⌋ − 3 | {t_sp:.3g} / {c_sp:.3g} | {predicted[1]:.3g} "
          f"| {float(np.mean(sp.var / default.var)):.4f} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000, 720_000])
    parser.add_argument("--channels", type=int, nargs="+", default=[1, 3])
    parser.add_argument("--no-theoh", action="store_true", help="time theobr only")
    parser.add_argument("--baseline", help="another tree's python folder to time theobr against")
    parser.add_argument("--baseline-sizes", type=int, nargs="+", default=[20_000, 50_000])
    parser.add_argument("--peer-size", type=int, default=2000)
    parser.add_argument("--fast-size", type=int, default=100_000)
    parser.add_argument("--fast-seeds", type=int, default=8)
    parser.add_argument("--fast-blocks", type=int, nargs="+", default=[2, 4, 8, 16])
    parser.add_argument("--ladder-size", type=int, default=100_000)
    parser.add_argument("--only-options", action="store_true",
                        help="parts 3 and 4 only")
    args = parser.parse_args()
    if args.only_options:
        if args.fast_size:
            fast_error(args.fast_size, args.fast_seeds, args.fast_blocks)
        if args.ladder_size:
            ladder_cost(args.ladder_size)
        return
    print(
        f"machine: {_cpu.describe()}, "
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
    if args.fast_size:
        fast_error(args.fast_size, args.fast_seeds, args.fast_blocks)
    if args.ladder_size:
        ladder_cost(args.ladder_size)


if __name__ == "__main__":
    main()
