"""Noise-model fit on simulated sensor classes that ../shared/data does not hold.

The recordings a model is judged on are other makers, grades and rates than the
ones it was developed on. Where no public still log of a class was found,
the class is simulated here (``imunoise.simulate`` plus scipy filters and
integer counting) as its physics describes it, and the fit is scored as
``bench_fit_real.py`` scores real channels: the share of taus τ ≤ T/10, at 20
taus per decade, at which the model lies inside the 95 % interval or within 5 %,
per axis, with the structure chosen on the first axis and the datasheet N
against the generating process's: the level of its −½ line at τ = 1 s, which
is the white noise plus every Gauss–Markov term whose hump (1.89 τc) lies
before 1 s (at τ ≫ τc such a term's Allan variance is 2σ²τc/τ, a white line).

Classes (each three axes, independent noise):

* ``rlg``: navigation-grade ring-laser gyro, 30.8 min at 100 Hz, integer 0.1″
  angle increments, a short-τ disturbance (Gauss–Markov 0.04 s), lines at 1.2
  and 2.1 Hz, on a parked vehicle rocking (angle Gauss–Markov, τc 25 s);
* ``rlg still``: the same gyro on a bench, without the rocking or the hump;
* ``rlg accel``: its accelerometers, integer 125 µg·s velocity increments, on the
  parked vehicle: white 20 µg/√Hz, flicker, the engine's hump (Gauss–Markov
  0.04 s), the tilt's g·θ (Gauss–Markov 25 s), the body's bounded sway
  (velocity, τc 2 s) and the two lines;
* ``increments``: 400 Hz, 1 h, angle increments of 1 µrad;
* ``counts``: 200 Hz, 1 h, rate rounded to a 1e-3 LSB;
* ``slow``: 5 Hz, 10 h, N + B + K;
* ``mpu <dlpf>``: MPU-6050-like, 100 Hz, 7.5 min, 16-bit counts, no DLPF or a
  2nd-order Butterworth DLPF at 44, 20 or 10 Hz;
* ``lp100``, ``lp30 4th``: 1 kHz, 5 min, a 2nd-order 100 Hz / 4th-order 30 Hz
  Butterworth low-pass;
* ``two lines``: 100 Hz, 30 min, lines at 3.3 and 0.2 Hz (a building's sway and
  a dither).

Run:  python benches/bench_fit_classes.py [--only NAME]
"""

from __future__ import annotations

import argparse
import time
import warnings

import imunoise
import numpy as np
from imunoise._support import cpu as _cpu
from imunoise.noise._typed import structure
from scipy.signal import butter, lfilter

ARCSEC = np.pi / 180 / 3600
G = 9.80665


def coverage(taus, dev, edf, model_dev, limit):
    """Share of taus ≤ limit with the model inside the 95 % interval or within 5 %
    (the measure of ``bench_fit_real.py``)."""
    from scipy.stats import chi2

    keep = taus <= limit
    lo = dev * np.sqrt(edf / chi2.ppf(0.975, edf))
    hi = dev * np.sqrt(edf / chi2.ppf(0.025, edf))
    ok = ((model_dev >= lo) & (model_dev <= hi)) | (np.abs(model_dev / dev - 1) <= 0.05)
    return float(ok[keep].mean())


def counted(rate, fs, step):
    """Rate from integer angle counts of ``step`` (the remainder carried)."""
    counts = np.floor(np.cumsum(rate, axis=0) / fs / step)
    return np.diff(np.vstack([np.zeros((1, rate.shape[1])), counts]), axis=0) * step * fs


def datasheet_n(white, gm=()):
    """The −½ line's level at τ = 1 s: white noise plus the Gauss–Markov tails
    whose hump lies before 1 s."""
    return float(np.sqrt(white**2 + sum(2 * s**2 * tc for s, tc in gm if 1.89 * tc < 1.0)))


def rlg(seed, *, still=False):
    fs, n = 100.0, int(30.8 * 60 * 100)
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    axes = []
    for k in range(3):
        s = 3 * seed + k
        white, gm = (5.8e-7, [(2e-6, 0.05)]) if still else (8.7e-7, [(2e-4, 0.04)])
        x = imunoise.simulate(n, fs, N=white, B=1.5e-8, seed=s, gm=gm,
                              motion=None if still else (3.7e-4, 25.0))
        lines = (3e-6, 2e-6) if still else (1.2e-4, 7e-5)
        x = (x + lines[0] * np.sin(2 * np.pi * 1.2 * t + rng.uniform(0, 6))
             + lines[1] * np.sin(2 * np.pi * 2.1 * t + rng.uniform(0, 6)))
        axes.append(x)
    return counted(np.stack(axes, 1), fs, 0.1 * ARCSEC), fs, datasheet_n(white, gm)


def rlg_accel(seed):
    fs, n = 100.0, int(30.8 * 60 * 100)
    rng = np.random.default_rng(100 + seed)
    t = np.arange(n) / fs
    axes = []
    gm = [(5e-3, 0.04), (G * 3.7e-4, 25.0)]
    for k in range(3):
        x = imunoise.simulate(n, fs, N=2e-4, B=5e-5, seed=50 + 3 * seed + k, gm=gm,
                              motion=(1e-3, 2.0))
        axes.append(x + 2e-3 * np.sin(2 * np.pi * 1.2 * t + rng.uniform(0, 6))
                    + 1e-3 * np.sin(2 * np.pi * 2.1 * t + rng.uniform(0, 6)))
    return counted(np.stack(axes, 1), fs, 125e-6 * G), fs, datasheet_n(2e-4, gm)


def lowpass(x, fs, fc, order):
    b, a = butter(order, fc / (fs / 2))
    return lfilter(b, a, x, axis=0)


def mpu(seed, dlpf):
    fs, n = 100.0, 45_000
    x = imunoise.simulate(n, fs, N=8.7e-5, B=2e-5, K=5e-7, channels=3, seed=seed)
    if dlpf:
        x = lowpass(x, fs, dlpf, 2)
    return np.round(x / 1.33e-4) * 1.33e-4, fs, 8.7e-5


def classes():
    """name → function(seed) → (samples (n, 3), fs, true N)."""
    out = {
        "rlg": lambda s: rlg(s),
        "rlg still": lambda s: rlg(s, still=True),
        "rlg accel": rlg_accel,
        "increments": lambda s: (counted(imunoise.simulate(
            1_440_000, 400.0, N=5e-6, B=1e-6, K=1e-8, channels=3, seed=s), 400.0, 1e-6),
            400.0, 5e-6),
        "counts": lambda s: (np.round(imunoise.simulate(
            720_000, 200.0, N=3e-4, B=5e-5, K=3e-6, channels=3, seed=s) / 1e-3) * 1e-3,
            200.0, 3e-4),
        "slow": lambda s: (imunoise.simulate(180_000, 5.0, N=1e-4, B=2e-5, K=1e-6, channels=3,
                                             seed=s), 5.0, 1e-4),
        "lp100": lambda s: (lowpass(imunoise.simulate(300_000, 1000.0, N=1e-4, B=2e-5, K=1e-6,
                                                      channels=3, seed=s), 1000.0, 100, 2),
                            1000.0, 1e-4),
        "lp30 4th": lambda s: (lowpass(imunoise.simulate(300_000, 1000.0, N=1e-4, B=2e-5,
                                                         K=1e-6, channels=3, seed=s),
                                       1000.0, 30, 4), 1000.0, 1e-4),
        "two lines": lambda s: (imunoise.simulate(
            180_000, 100.0, N=2e-5, B=5e-6, channels=3, seed=s,
            sinusoid=[(3e-4, 3.3), (1e-4, 0.2)]), 100.0, 2e-5),
    }
    for dlpf in (None, 44, 20, 10):
        out[f"mpu {dlpf or 'no'} dlpf"] = lambda s, d=dlpf: mpu(s, d)
    return out


def main() -> int:
    print(f"machine: {_cpu.describe()}", flush=True)
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", help="one class")
    ap.add_argument("--seeds", type=int, default=2, help="records per class")
    ap.add_argument("--filter", action="store_true",
                    help="fit with the record's Welch PSD: the output filter measured")
    args = ap.parse_args()
    rows = []
    print("| class | seed | coverage X / Y / Z | structure (X) | datasheet N error (median) "
          "| filter | fit |\n|---|---|---|---|---|---|---|")
    for name, make in classes().items():
        if args.only and name != args.only:
            continue
        for seed in range(args.seeds):
            x, fs, n_true = make(seed)
            r = imunoise.adev(x, fs, taus=20)
            spectrum = imunoise.psd(x, fs) if args.filter else None
            start = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                m = imunoise.fit(r, spectrum=spectrum)
            took = time.perf_counter() - start
            p = m.predict(r.taus).dev
            limit = len(x) / fs / 10
            cov = [coverage(r.taus, r.dev[:, c], r.edf[:, c], p[:, c], limit) for c in range(3)]
            n_err = np.abs(np.ravel(m.N) / n_true - 1)
            measured = sum(f is not None for f in m.filter)
            rows.append((name, seed, cov, structure(m.terms[0]), n_err, took))
            print(f"| {name} | {seed} | {' / '.join(f'{c:.0%}' for c in cov)} | "
                  f"{structure(m.terms[0])} | {np.median(n_err):.1%} | {measured}/3 | "
                  f"{took:.2f} s |", flush=True)
    every = [c for row in rows for c in row[2]]
    if every:
        print(f"\n{len(rows)} records, {len(every)} axes: coverage median {np.median(every):.0%}, "
              f"worst {min(every):.0%}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
