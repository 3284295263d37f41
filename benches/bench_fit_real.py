"""Noise-model fit on real still recordings: imunoise vs allan-variance, one run.

For every long still recording in ../shared/data (skipped when absent): the
overlapping Allan deviation at 20 taus per decade (imunoise.adev), then

* coverage: the share of taus τ ≤ T/10 at which the fitted model lies inside the
  measured 95 % confidence interval (χ² with the result's EDF) or within 5 % of
  the measured deviation, whichever is wider — for imunoise.fit (default,
  terms="auto") and allan_variance.estimate_parameters (its default five terms);
* the model's structure, coefficients and discrepancy δ;
* tau-grid stability: the model's datasheet equivalents N, B, K (NoiseModel.equivalent)
  and the coefficients fitted on octave, 5, 10, 20 and 50 taus per decade; the spread
  is max − min over the grids in units of the largest standard uncertainty.

Then the simulated accuracy table of benches/bench_fit.py (--seeds, default 4).

Run:  python benches/bench_fit_real.py [--seeds 4] [--plots DIR]
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
    terms = [t for t in imunoise.noise.TERMS if bool(model.supported[t])]
    gm = [f"GM({tc:.3g} s)" for _, tc in model.components.gauss_markov()]
    tone = [f"sine({f0:.3g} Hz)" for _, f0 in model.components.sine()]
    res = [f"res({f:.3g} Hz, Q {math.pi * f * tr:.2g})"
           for _, f, tr in model.components.resonance()]
    return "+".join(terms + gm + tone + res)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=4, help="simulated records (0: skip)")
    ap.add_argument("--plots", type=Path, help="write one Allan plot per channel here")
    args = ap.parse_args()
    recs = recordings()
    if not recs:
        print(f"no recordings under {DATA}; nothing to do")
        return 0
    warnings.simplefilter("ignore", RuntimeWarning)
    rows, stab, fit_time = [], [], 0.0
    for name, (x, fs) in recs.items():
        limit = len(x) / fs / 10
        r = imunoise.adev(x, fs, taus=20)
        t0 = time.perf_counter()
        model = imunoise.fit(r)
        fit_time += time.perf_counter() - t0
        ours = coverage(r.taus, r.dev, r.edf, model.predict(r.taus).dev, limit)
        theirs = coverage(r.taus, r.dev, r.edf, allan_variance_dev(r.taus, r.var), limit)
        rows.append((name, ours, theirs, structure(model), float(model.discrepancy)))
        if args.plots:
            args.plots.mkdir(parents=True, exist_ok=True)
            fig = imunoise.plot.allan(r, model=model, title=name)
            fig.savefig(args.plots / (name.replace(" ", "_") + ".png"), dpi=70)
        eq, co = {}, {}
        for label, grid in GRIDS.items():
            m = imunoise.fit(imunoise.adev(x, fs, taus=grid))
            eq[label] = [float(m.value(t)[0]) for t in ("N", "B", "K")]
            co[label] = [(float(m.value(t)[0]), float(m.std(t)[0])) for t in ("N", "B", "K")]
        stab.append((name, eq, co))
    print(f"{len(rows)} real channels; imunoise.fit total {fit_time:.2f} s")
    print()
    print("| channel | imunoise coverage | allan-variance coverage | imunoise model | δ |")
    print("|---|---|---|---|---|")
    for name, ours, theirs, struct, delta in rows:
        print(f"| {name} | {ours:.0%} | {theirs:.0%} | {struct} | {delta:.3f} |")
    ours = np.array([r[1] for r in rows])
    theirs = np.array([r[2] for r in rows])
    print(f"| **median / worst** | **{np.median(ours):.0%} / {ours.min():.0%}** | "
          f"**{np.median(theirs):.0%} / {theirs.min():.0%}** | | |")
    print()
    print("Tau-grid stability (octave, 5, 10, 20, 50 per decade): spread of the model's")
    print("datasheet equivalents (max/min − 1) and of the coefficients in units of their")
    print("largest standard uncertainty (—: the term is not in every grid's model)")
    print()
    print("| channel | N_eq spread | B_eq spread | K_eq spread | N, B, K coefficient spread / u |")
    print("|---|---|---|---|---|")
    worst = 0.0
    for name, eq, co in stab:
        e = np.array(list(eq.values()))
        cells = []
        for j in range(3):
            col = e[:, j]
            cells.append(f"{col.max() / col.min() - 1:.1%}" if col.min() > 0 else "—")
        spread = []
        for j in range(3):
            vals = np.array([co[g][j][0] for g in co])
            stds = np.array([co[g][j][1] for g in co])
            if np.all(vals > 0) and np.all(np.isfinite(stds)):
                z = (vals.max() - vals.min()) / stds.max()
                worst = max(worst, z)
                spread.append(f"{z:.1f}")
            else:
                spread.append("—")
        print(f"| {name} | " + " | ".join(cells) + " | " + ", ".join(spread) + " |")
    print(f"\nlargest coefficient spread: {worst:.1f} standard uncertainties")
    if args.seeds:
        print()
        sys.argv = [sys.argv[0], "--seeds", str(args.seeds)]
        sys.path.insert(0, str(HERE))
        import bench_fit

        bench_fit.main()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
