"""The output filter measured from the spectrum, on real still recordings.

For every long still channel of ../shared/data (``bench_fit_real.recordings``;
skipped when absent) and the VN-100 CSV log of tests/data, the noise model is fitted
twice to the same Allan deviation (20 taus per decade): with the output filter
measured from the channel's Welch PSD (``imunoise.fit(r, spectrum=s)``) and without
it (``output_filter=False``, the fit before the filter). Per channel:

* whether a filter was measured, its white region's top and its gain at fs/2;
* in-sample coverage: the share of taus τ ≤ T/10 where the model (through its
  filter) lies inside the 95 % interval or within 5 % of the measured deviation;
* out of sample, half against half: both variants fitted on the first half (with the
  first half's spectrum) and scored on the second half's curve (τ ≤ T_half/10);
* datasheet N of both, and the structure (tones, resonance, Gauss–Markov terms).

``--plots DIR`` writes each channel's PSD with the white level and the level times the
measured gain (``DIR/<channel>.png``).

Run:  python benches/bench_filter_real.py [--plots DIR] [--only NAME]
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import imunoise
import numpy as np
from bench_fit_real import coverage, recordings
from imunoise._support import cpu as _cpu
from imunoise.noise._typed import structure

HERE = Path(__file__).resolve().parent


def channels():
    out = recordings()
    csv = HERE.parent / "tests" / "data" / "vn100-csv"
    for path in sorted(csv.glob("*.csv")) if csv.exists() else ():
        try:
            log = imunoise.read(path)
        except Exception:  # noqa: BLE001 - a file this bench cannot read is skipped
            continue
        if log.gyro is None or len(log) < 4096:
            continue
        for i, ax in enumerate("xyz"):
            out[f"vn100 csv gyro {ax}"] = (log.gyro[:, i], log.fs)
            if log.accel is not None:
                out[f"vn100 csv acc {ax}"] = (log.accel[:, i], log.fs)
    return out


def fitted(x, fs, output_filter):
    r = imunoise.adev(x, fs, taus=20)
    s = imunoise.psd(x, fs)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = imunoise.fit(r, spectrum=s, output_filter=output_filter)
    return r, s, m


def score(r, m, limit):
    p = np.ravel(m.predict(r.taus).dev)
    return coverage(r.taus, np.ravel(r.dev), np.ravel(r.edf), p, limit)


def plot(name, s, m, out_dir):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    found = m.filter[0]
    fig, ax = plt.subplots(figsize=(7, 4.2))
    ax.loglog(s.f, s.psd, lw=0.4, color="0.6", label="Welch PSD")
    level = float(s.white) + float(s.flicker) / s.f + float(s.walk) / s.f**2
    ax.loglog(s.f, level, "k--", lw=1, label="white read-off h0 + h₋₁/f + h₋₂/f²")
    if found is not None:
        f = found.f[1:]
        low = found.white + found.low[1:]
        ax.loglog(f, low * found.gain[1:], "C3", lw=1.2, label="level × measured G")
        ax.axvline(found.white_top, color="C3", ls=":", lw=1, label="G = 1 below")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("one-sided PSD [unit²/Hz]")
    ax.set_title(f"{name}: filter {'measured' if found is not None else 'none'}; "
                 f"{structure(m.terms[0])}", fontsize=8)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out_dir / (name.replace(" ", "_") + ".png"), dpi=110)
    plt.close(fig)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plots", type=Path)
    ap.add_argument("--only")
    args = ap.parse_args()
    print(_cpu.describe())
    if args.plots:
        args.plots.mkdir(parents=True, exist_ok=True)
    rows = []
    print("| channel | filter (white to, G at fs/2) | coverage off / on | half vs half off / on "
          "| N off / on | structure off | structure on |\n|---|---|---|---|---|---|---|")
    start = time.perf_counter()
    for name, (x, fs) in channels().items():
        if args.only and args.only not in name:
            continue
        x = np.asarray(x, dtype=float)
        limit = len(x) / fs / 10
        half = len(x) // 2
        got = {}
        for v in (False, True):
            r, s, m = fitted(x, fs, v)
            r1, _, m1 = fitted(x[:half], fs, v)
            r2 = imunoise.adev(x[half:2 * half], fs, taus=20)
            got[v] = (score(r, m, limit), score(r2, m1, half / fs / 10), float(np.ravel(m.N)[0]),
                      structure(m.terms[0]), m)
        found = got[True][4].filter[0]
        desc = "none" if found is None else f"{found.white_top:.3g} Hz, {found.gain[-1]:.2g}"
        rows.append((name, got))
        print(f"| {name} | {desc} | {got[False][0]:.0%} / {got[True][0]:.0%} | "
              f"{got[False][1]:.0%} / {got[True][1]:.0%} | {got[False][2]:.4g} / "
              f"{got[True][2]:.4g} | {got[False][3]} | {got[True][3]} |", flush=True)
        if args.plots:
            plot(name, s, got[True][4], args.plots)
    for k, what in ((0, "in sample"), (1, "half against half")):
        off = np.array([g[False][k] for _, g in rows])
        on = np.array([g[True][k] for _, g in rows])
        print(f"\n{what}: coverage median {np.median(off):.0%} → {np.median(on):.0%}, worst "
              f"{off.min():.0%} → {on.min():.0%}; better on {np.sum(on > off + 1e-9)}, worse "
              f"on {np.sum(on < off - 1e-9)} of {len(rows)} channels")
    print(f"\nwall {time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
