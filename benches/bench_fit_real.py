"""Noise-model fit on real still recordings: imunoise vs allan-variance, one run.

For every long still recording in ../shared/data (skipped when absent), per channel:

* in-sample coverage: the overlapping Allan deviation at 20 taus per decade
  (imunoise.adev); the share of taus τ ≤ T/10 at which the fitted model lies inside
  the measured 95 % confidence interval (χ² with the result's EDF) or within 5 % of
  the measured deviation — imunoise.fit (terms="auto") and
  allan_variance.estimate_parameters (its default five terms);
* out of sample, half against half: fit the first half, and score the coverage of
  the second half's Allan deviation (τ ≤ T_half/10) by that model, by the first
  half's own measured curve and by allan-variance fitted on the first half;
* the fitted structure (model.terms) and the number of its terms;
* tau-grid stability of the datasheet values model.N, B, K fitted on octave, 5, 10,
  20 and 50 taus per decade: the spread max − min in units of the largest
  standard uncertainty, and in brackets without the octave grid (fit warns there);
* B against the data's read-off where the curve has a flat minimum: the
  difference in units of √(u_model² + u_readoff²).

Then the simulated accuracy table of benches/bench_fit.py (--seeds, default 4).

Run:  python benches/bench_fit_real.py [--seeds 4] [--plots DIR] [--only NAME]
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import warnings
from pathlib import Path

import allan_variance
import imunoise
import imunoise.plot
import numpy as np
from imunoise._support import cpu as _cpu

HERE = Path(__file__).resolve().parent
DATA = HERE.parent.parent / "shared" / "data"
GRIDS = {"octave": "octave", "5/dec": 5, "10/dec": 10, "20/dec": 20, "50/dec": 50}
DEG = math.pi / 180


def recordings():
    """name -> (samples, fs) of every real long still channel that is present."""
    other = DATA / "other-imu"
    out = {}
    for run, tag in (("adis16405_static_2h47m", "adis1"), ("adis16405_static_run3", "adis3"),
                     ("adis16405_static_run4", "adis4")):
        path = other / f"{run}.npz"
        if not path.exists():
            continue
        z = np.load(path)
        fs = float(z["sample_rate_hz"])
        gyro = z["gyro_counts"] * float(z["gyro_scale_dps_per_count"])
        acc = z["accel_counts"] * float(z["accel_scale_g_per_count"])
        for i, ax in enumerate("xyz"):
            out[f"{tag} gyro {ax}"] = (gyro[:, i], fs)
            out[f"{tag} acc {ax}"] = (acc[:, i], fs)
    phone = other / "phone_gyro_static.txt"
    if phone.exists():
        g = np.loadtxt(phone, usecols=(2, 3, 4))
        for i, ax in enumerate("xyz"):
            out[f"phone gyro {ax}"] = (g[:, i], 5.0)
    mtig = other / "mtig_gyro_x_outliers.npz"
    if mtig.exists():
        z = np.load(mtig)
        out["mti-g gyro x"] = (z["gyro_x"], float(z["sample_rate_hz"]))
    vn = DATA / "vn100-ascii" / "live_capture.txt"
    if vn.exists():
        log = imunoise.read(vn, fs=40.0)  # $VNWRG,07,40 (SOURCES.md)
        for i, ax in enumerate("xyz"):
            out[f"vn100 gyro {ax}"] = (log.gyro[:, i], log.fs)
            out[f"vn100 acc {ax}"] = (log.accel[:, i], log.fs)
    return out


def coverage(taus, dev, edf, model_dev, limit):
    """Share of taus ≤ limit with the model inside the 95 % interval or within 5 %."""
    from scipy.stats import chi2

    keep = taus <= limit
    lo = dev * np.sqrt(edf / chi2.ppf(0.975, edf))
    hi = dev * np.sqrt(edf / chi2.ppf(0.025, edf))
    ok = ((model_dev >= lo) & (model_dev <= hi)) | (np.abs(model_dev / dev - 1) <= 0.05)
    return float(ok[keep].mean())


def allan_variance_dev(taus, var):
    params, prediction = allan_variance.estimate_parameters(taus, var)
    return np.sqrt(np.asarray(prediction).ravel())


def structure(model):
    fitted = model.terms[0]
    terms = [t.name for t in fitted if hasattr(t, "name")]
    gm = [f"GM({t.tau_c:.3g} s)" for t in fitted if isinstance(t, imunoise.noise.GaussMarkov)]
    tone = [f"sine({t.freq:.3g} Hz)" for t in fitted if isinstance(t, imunoise.noise.Tone)]
    res = [f"res({t.freq:.3g} Hz, Q {math.pi * t.freq * t.tau:.2g}"
           + (f", skew {t.skew:.2g})" if t.skew else ")")
           for t in fitted if isinstance(t, imunoise.noise.Resonance)]
    return "+".join(terms + gm + tone + res)


def half_against_half(x, fs):
    """Coverage of the second half's curve by the model of the first half, by the
    first half's own curve and by allan-variance's fit to the first half."""
    half = len(x) // 2
    first = imunoise.adev(x[:half], fs, taus=20)
    second = imunoise.adev(x[half:2 * half], fs, taus=20)
    limit = half / fs / 10
    model = imunoise.fit(first)
    return (coverage(second.taus, second.dev, second.edf, model.predict(second.taus).dev,
                     limit),
            coverage(second.taus, second.dev, second.edf, first.dev, limit),
            coverage(second.taus, second.dev, second.edf,
                     allan_variance_dev(first.taus, first.var), limit))


def b_against_readoff(model):
    """|B_model − B_readoff| / combined standard uncertainty, NaN without a floor."""
    read, u_read = (float(np.ravel(model.readoff["B"][k])[0]) for k in ("value", "std"))
    b, u_b = float(np.ravel(model.B)[0]), float(np.ravel(model.B_std)[0])
    if not (np.isfinite(read) and b > 0):
        return math.nan
    return abs(b - read) / math.hypot(u_read, u_b if np.isfinite(u_b) else 0.0)


def grid_spread(x, fs):
    """Largest spread (max − min over the grids) of model.N, B, K in units of the
    largest standard uncertainty, over every grid and over the grids of 5 taus per
    decade and more (``fit`` warns below that); NaN where a grid does not resolve
    the value."""
    values = {t: {} for t in ("N", "B", "K")}
    for name, grid in GRIDS.items():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # the octave grid's, on purpose
            m = imunoise.fit(imunoise.adev(x, fs, taus=grid))
        for t in values:
            values[t][name] = (float(np.ravel(m.value(t))[0]), float(np.ravel(m.std(t))[0]))

    def spread(pairs):
        v = np.array([p[0] for p in pairs])
        u = np.array([p[1] for p in pairs])
        return ((v.max() - v.min()) / u.max() if np.all(v > 0) and np.all(np.isfinite(u))
                else (0.0 if np.all(v == 0) else math.nan))

    return ({t: spread(list(by.values())) for t, by in values.items()},
            {t: spread([p for g, p in by.items() if g != "octave"]) for t, by in values.items()})


def main() -> int:
    print(f"machine: {_cpu.describe()}", flush=True)
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=4, help="simulated records (0: skip)")
    ap.add_argument("--plots", type=Path, help="write one Allan plot per channel here")
    ap.add_argument("--only", help="channels whose name contains this")
    args = ap.parse_args()
    recs = recordings()
    if args.only:
        recs = {k: v for k, v in recs.items() if args.only in k}
    if not recs:
        print(f"no recordings under {DATA}; nothing to do")
        return 0
    warnings.simplefilter("ignore", RuntimeWarning)
    rows, fit_time = [], 0.0
    for name, (x, fs) in recs.items():
        limit = len(x) / fs / 10
        r = imunoise.adev(x, fs, taus=20)
        t0 = time.perf_counter()
        model = imunoise.fit(r)
        fit_time += time.perf_counter() - t0
        ours = coverage(r.taus, r.dev, r.edf, model.predict(r.taus).dev, limit)
        theirs = coverage(r.taus, r.dev, r.edf, allan_variance_dev(r.taus, r.var), limit)
        if args.plots:
            args.plots.mkdir(parents=True, exist_ok=True)
            fig = imunoise.plot.allan(r, model=model, title=name)
            fig.savefig(args.plots / (name.replace(" ", "_") + ".png"), dpi=70)
        rows.append(dict(name=name, ours=ours, theirs=theirs, struct=structure(model),
                         count=len(model.terms[0]), b=b_against_readoff(model),
                         halves=half_against_half(x, fs), spread=grid_spread(x, fs)))
    print(f"{len(rows)} real channels; imunoise.fit total {fit_time:.2f} s")
    print()
    print("| channel | coverage: imunoise | allan-variance | half vs half: imunoise | "
          "first half's curve | allan-variance | components | N, B, K grid spread / u "
          "(5–50/dec) | "
          "B vs read-off / u |")
    print("|---|---|---|---|---|---|---|---|---|")

    def z(v):
        return "—" if not np.isfinite(v) else f"{v:.1f}"

    for r in rows:
        h = r["halves"]
        print(f"| {r['name']} | {r['ours']:.0%} | {r['theirs']:.0%} | {h[0]:.0%} | {h[1]:.0%} "
              f"| {h[2]:.0%} | {r['count']}: {r['struct']} | "
              + ", ".join(z(r["spread"][0][t]) for t in ("N", "B", "K"))
              + " (" + ", ".join(z(r["spread"][1][t]) for t in ("N", "B", "K"))
              + f") | {z(r['b'])} |")
    col = {k: np.array([r[k] for r in rows]) for k in ("ours", "theirs", "count", "b")}
    halves = np.array([r["halves"] for r in rows])
    spreads, dense = (np.array([[r["spread"][k][t] for t in ("N", "B", "K")] for r in rows])
                      for k in (0, 1))
    print(f"| **median / worst** | **{np.median(col['ours']):.0%} / {col['ours'].min():.0%}** | "
          f"{np.median(col['theirs']):.0%} / {col['theirs'].min():.0%} | "
          + " | ".join(f"{np.median(halves[:, j]):.0%} / {halves[:, j].min():.0%}"
                       for j in range(3))
          + f" | median {np.median(col['count']):.0f}, most {col['count'].max()} | "
          f"worst {np.nanmax(spreads):.1f} ({np.nanmax(dense):.1f}) | "
          f"worst {np.nanmax(col['b']):.1f} |")
    if args.seeds:
        print()
        sys.argv = [sys.argv[0], "--seeds", str(args.seeds)]
        sys.path.insert(0, str(HERE))
        import bench_fit

        bench_fit.main()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
