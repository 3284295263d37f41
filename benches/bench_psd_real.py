"""N from the spectrum (imunoise.psd) vs N from the Allan fit (imunoise.fit, the
model's N read-off), on simulated white + flicker + random-walk records and on the real
still logs in ../shared/data (absent files skipped). One row per channel: both N, their
ratio, the difference in units of the combined standard uncertainty, the white band
chosen, and — beyond 5 % — what the spectrum shows above the band (a line or a filter).

Run:  python benches/bench_psd_real.py [--seeds 40]
"""

from __future__ import annotations

import argparse
import math
import warnings
from pathlib import Path

import imunoise
import numpy as np
from imunoise._support import cpu as _cpu

HERE = Path(__file__).resolve().parent
DATA = HERE.parent.parent / "shared" / "data"


def recordings():
    """name -> (samples (n, k), fs) of the real still logs that are present."""
    other = DATA / "other-imu"
    out = {}
    for run in ("adis16405_static_2h47m", "adis16405_static_run3", "adis16405_static_run4"):
        path = other / f"{run}.npz"
        if path.exists():
            z = np.load(path)
            fs = float(z["sample_rate_hz"])
            out[f"{run} gyro [deg/s]"] = (z["gyro_counts"] * float(z["gyro_scale_dps_per_count"]),
                                          fs)
            out[f"{run} accel [g]"] = (z["accel_counts"] * float(z["accel_scale_g_per_count"]),
                                       fs)
    phone = other / "phone_gyro_static.txt"
    if phone.exists():
        out["phone gyro (5 Hz)"] = (np.loadtxt(phone, usecols=(2, 3, 4)), 5.0)
    mtig = other / "mtig_gyro_x_outliers.npz"
    if mtig.exists():
        z = np.load(mtig)
        out["mti-g gyro x (outliers)"] = (z["gyro_x"], float(z["sample_rate_hz"]))
    from imunoise.cli import bundled_log

    log = imunoise.read(bundled_log(), fs=40.0)
    out["vn100 bundled 5 min gyro"] = (log.gyro, log.fs)
    out["vn100 bundled 5 min accel"] = (log.accel, log.fs)
    vn = DATA / "vn100-ascii" / "live_capture.txt"
    if vn.exists():
        log = imunoise.read(vn, fs=40.0)
        out["vn100 live_capture gyro"] = (log.gyro, log.fs)
        out["vn100 live_capture accel"] = (log.accel, log.fs)
    return out


def compare(y, fs):
    s = imunoise.psd(y, fs)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = imunoise.fit(imunoise.adev(y, fs, taus=20))
    n_fit = np.atleast_1d(model.value("N"))
    n_fit_std = np.atleast_1d(model.std("N"))
    return s, n_fit, n_fit_std


def why(s, j):
    if s.lines[j].size:
        return "lines at " + ", ".join(f"{v:.3g}" for v in s.lines[j][:3]) + " Hz"
    p = np.reshape(s.psd, (len(s.f), -1))[:, j]
    top = np.reshape(s.band, (-1, 2))[j, 1]
    white = np.atleast_1d(s.white)[j]
    above = s.f > top
    if not above.any():
        return ""
    if p[above].max() > 3 * white:
        return f"line at {s.f[above][np.argmax(p[above])]:.3g} Hz"
    if p[above][-1] < 0.7 * white:
        return f"filter above {top:.3g} Hz"
    return ""


def main() -> None:
    print(f"machine: {_cpu.describe()}", flush=True)
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=40)
    args = parser.parse_args()
    fs, n_true = 100.0, 1e-3
    scores, ratios = [], []
    for seed in range(args.seeds):
        y = imunoise.simulate(2**18, fs, N=n_true, B=1e-4, K=2e-5, seed=seed)
        s, n_fit, n_fit_std = compare(y, fs)
        scores.append((s.N - n_fit[0]) / math.hypot(s.N_std, n_fit_std[0]))
        ratios.append(s.N / n_true)
    scores = np.array(scores)
    print(f"simulated N={n_true:g} + B + K, {args.seeds} records of 2^18 samples at {fs:g} Hz")
    print(f"  |N_psd - N_fit| < 2 sigma_comb in {np.mean(np.abs(scores) < 2):.0%} "
          f"(mean z {scores.mean():+.2f}, rms z {np.sqrt(np.mean(scores**2)):.2f}); "
          f"N_psd/N_true mean {np.mean(ratios):.4f} sd {np.std(ratios):.4f}")
    print()
    print(f"{'recording':34s} {'ax':>2s} {'N psd':>11s} {'N fit':>11s} {'psd/fit':>8s} "
          f"{'z':>6s} {'band [Hz]':>16s}  note")
    for name, (y, rate) in recordings().items():
        y = np.asarray(y, dtype=float).reshape(len(y), -1)
        s, n_fit, n_fit_std = compare(y, rate)
        n, n_std = np.atleast_1d(s.N), np.atleast_1d(s.N_std)
        band = np.reshape(s.band, (-1, 2))
        for j in range(y.shape[1]):
            ratio = n[j] / n_fit[j] if n_fit[j] > 0 else float("nan")
            z = (n[j] - n_fit[j]) / math.hypot(n_std[j], n_fit_std[j])
            note = "" if abs(ratio - 1) <= 0.05 else why(s, j)
            print(f"{name:34s} {'xyz'[j] if y.shape[1] > 1 else 'x':>2s} {n[j]:11.4e} "
                  f"{n_fit[j]:11.4e} {ratio:8.3f} {z:6.1f} "
                  f"{band[j, 0]:7.3g}-{band[j, 1]:<8.3g}  {note}")


if __name__ == "__main__":
    main()
