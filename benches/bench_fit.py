"""Noise-model fit accuracy: imunoise wls vs imunoise slopes vs allan-variance.

For each seed, simulate 5 h at 40 Hz of a 3-axis VN-100-like gyro (rad/s):
N = 0.0035 °/s/√Hz (datasheet noise density), B = 5 °/h (half the datasheet
bound), K = 20 °/h/√h (a typical MEMS rate random walk; the VN-100 datasheet
gives none), no Q or R. Compute the overlapping Allan deviation at octave taus
(imunoise.adev), then estimate N, B, K with

* imunoise.fit(method="wls")     weighted NNLS on σ², EDF weights (Rust, faer)
* imunoise.fit(method="slopes")  IEEE 952 / MATLAB read-off
* allan_variance.estimate_parameters  NNLS with relative weights (PyPI allan-variance)

and print the median (and 90th percentile) relative error over all seeds and axes.

Run:  python benches/bench_fit.py [--seeds 20]
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import time

import allan_variance
import imunoise
import numpy as np

DEG = math.pi / 180
FS = 40.0
N_SAMPLES = int(5 * 3600 * FS)
TRUTH = {
    "N": 0.0035 * DEG,  # rad/√s
    "B": 5.0 * DEG / 3600,  # rad/s
    "K": 20.0 * DEG / 3600 / 60,  # rad/s/√s
}


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return (f"{cpu}, {os.cpu_count()} logical cores, Python {platform.python_version()}, "
            f"numpy {np.__version__}, {platform.system()} {platform.release()}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=20)
    args = ap.parse_args()
    err = {m: {k: [] for k in TRUTH} for m in ("wls", "slopes", "allan-variance")}
    t0 = time.perf_counter()
    for seed in range(args.seeds):
        x = imunoise.simulate(N_SAMPLES, FS, channels=3, seed=seed, **TRUTH)
        r = imunoise.adev(x, FS, taus="octave", overlapping=True)
        for method in ("wls", "slopes"):
            m = imunoise.fit(r, method=method)
            for k, v in TRUTH.items():
                err[method][k].extend(np.abs(m.value(k) / v - 1))
        params, _ = allan_variance.estimate_parameters(r.taus, r.var)
        for k, col in (("N", "white"), ("B", "flicker"), ("K", "walk")):
            err["allan-variance"][k].extend(np.abs(params[col].to_numpy() / TRUTH[k] - 1))
    elapsed = time.perf_counter() - t0
    print(f"{args.seeds} seeds x 3 axes, 5 h at 40 Hz, imunoise.adev octave taus; {elapsed:.0f} s")
    print(f"machine: {machine()}")
    print()
    print("| method | N median (p90) | B median (p90) | K median (p90) |")
    print("|---|---|---|---|")
    for method, e in err.items():
        cells = [f"{100 * np.median(e[k]):.2f} % ({100 * np.percentile(e[k], 90):.1f} %)"
                 for k in TRUTH]
        print(f"| {method} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
