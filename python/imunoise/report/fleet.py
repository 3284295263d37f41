"""The fleet report: one Markdown and one HTML file comparing units (``imunoise fleet``).

:func:`write` turns a :class:`~imunoise.Fleet` into a folder::

    fleet.html    self-contained (figures embedded)
    fleet.md      the same, figures linked from figures/
    figures/      one figure per coefficient across units (PNG and SVG)

Sections: the units (every one named, with its verdict and what it stands out
on), the outliers and the rule that found them, the fleet's median and spread,
the datasheet verdicts per unit, the coefficients per unit with their
uncertainties and Gauss–Markov terms, and the figures. The folder is handled as
the noise report's (:mod:`imunoise.report.folder`): every file written
atomically, an existing folder that is not a report refused unless ``force``.
"""

from __future__ import annotations

import datetime as _dt
import math
import os
from pathlib import Path

import numpy as np

from imunoise import display as _display
from imunoise import plot
from imunoise._analysis.fleet import MIN_UNITS, TERMS, Fleet, outlier_rule
from imunoise._core import __version__
from imunoise._support import atomic as _atomic
from imunoise._support import summary as _summary
from imunoise._support.schema import ALLAN_SENSORS
from imunoise.report import folder
from imunoise.report.document import Doc

__all__ = ["FILES", "TITLE", "figure", "write"]

TITLE = "imunoise fleet report"
#: The report's two documents.
FILES = ("fleet.md", "fleet.html")
#: Units beyond which the per-unit coefficient tables are collapsed in the HTML.
_OPEN_ROWS = 30


def _plotted(f: Fleet) -> list[tuple[str, str]]:
    """(sensor, term) pairs with a figure: resolved by a unit, or specified."""
    specified = {(i.sensor, i.term) for i in f.spec.items} if f.spec is not None else set()
    seen = {(r["sensor"], r["term"]) for r in f.rows if r["resolved"]}
    return [(s, t) for s in ALLAN_SENSORS for t in TERMS if (s, t) in seen | specified
            and any(r["sensor"] == s for r in f.rows)]


def figure(f: Fleet, sensor: str, term: str):
    """One coefficient across units: each unit's value per axis with its standard
    uncertainty (a down-pointing triangle at the 95 % upper bound where the unit
    does not resolve it), the fleet's median per axis (dashed), the spec (black)
    and the outliers ringed in red; log scale."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure

    names = f.analysed
    rows = [r for r in f.rows if r["sensor"] == sensor and r["term"] == term]
    axes = sorted({r["axis"] for r in rows}, key=lambda a: "XYZ".find(a) % 10)
    stats = {s["axis"]: s for s in f.stats if s["sensor"] == sensor and s["term"] == term}
    label = rows[0]["label"] if rows else ""
    at = {n: i for i, n in enumerate(names)}
    width = min(max(7.0, 0.22 * len(names) + 3.5), 24.0)
    with plot.style():
        fig = Figure(figsize=(width, 3.6))
        ax = fig.add_subplot(1, 1, 1)
        step = 0.6 / max(len(axes), 1)
        for k, a in enumerate(axes):
            color = plot.AXIS_COLORS[k % len(plot.AXIS_COLORS)]
            mine = [r for r in rows if r["axis"] == a]
            x = np.array([at[r["unit"]] for r in mine], float) + (k - (len(axes) - 1) / 2) * step
            v = np.array([r["value"] for r in mine])
            e = np.array([r["std"] for r in mine])
            up = np.array([r["upper"] for r in mine])
            ok = np.isfinite(v)
            ax.errorbar(x[ok], v[ok], yerr=np.where(np.isfinite(e[ok]), e[ok], 0.0), fmt="o",
                        ms=4, color=color, elinewidth=0.9, capsize=1.5, label=f"{a}")
            bound = ~ok & np.isfinite(up)
            if bound.any():
                ax.plot(x[bound], up[bound], "v", ms=5, mfc="none", color=color)
            out = np.array([r["outlier"] for r in mine])
            if out.any():
                ax.plot(x[out], v[out], "o", ms=11, mfc="none", mec="#d62728", mew=1.6)
            med = stats.get(a, {}).get("median", math.nan)
            if math.isfinite(med):
                ax.axhline(med, color=color, ls="--", lw=0.8, alpha=0.8)
        spec = next((s for s in stats.values() if "spec" in s), None)
        if spec is not None:
            ax.axhline(spec["spec"], color="black", lw=1.1, ls="-" if spec["limit"] != "typical"
                       else ":", label=f"spec {spec['limit']} {spec['spec']:g}")
        if any(r["outlier"] for r in rows):
            ax.plot([], [], "o", ms=9, mfc="none", mec="#d62728", label="outlier")
        if any(not r["resolved"] and math.isfinite(r["upper"]) for r in rows):
            ax.plot([], [], "v", mfc="none", color="0.4", label="not resolved: 95 % bound")
        ax.set_yscale("log")
        ax.set_xticks(range(len(names)))
        small = len(names) > 8
        ax.set_xticklabels(names, rotation=90 if small else 0,
                           fontsize=6 if len(names) > 40 else (7 if small else 8))
        ax.set_xlim(-0.6, len(names) - 0.4)
        ax.set_ylabel(f"{sensor} {term} [{label}]")
        ax.set_title(f"{sensor} {term} across {_summary.plural(len(names), 'unit')}")
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
        bottom = 0.45 + (0.07 * max(len(n) for n in names) if small else 0.0)
        h = 3.6 + (bottom - 0.45)
        fig.set_size_inches(width, h)
        fig.subplots_adjust(left=0.8 / width, right=1 - 1.9 / width, bottom=bottom / h,
                            top=1 - 0.35 / h)
    return fig


def _value(r: dict) -> str:
    if r["resolved"]:
        return _display.cell(r["value"], r["std"])
    return _display.upper_bound(r["upper"])


def write(f: Fleet, out_dir, *, force: bool = False, inputs=None) -> tuple[Path, ...]:
    """Write the fleet report into ``out_dir``; returns the paths written (the two
    documents first). ``inputs``: files never to overwrite (default: the logs)."""
    out = Path(os.fspath(out_dir))
    inputs = [u["path"] for u in f.units] if inputs is None else list(inputs)
    previous = folder.claim(out, force=force, inputs=inputs)
    for name in FILES:
        _atomic.refuse_input(out / name, inputs)
    folder.mark(out, previous)
    doc = Doc()
    doc.h(1, TITLE)
    stamp = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    against = f"against {f.spec.name}" if f.spec is not None else "without a datasheet"
    doc.p(f"Generated by imunoise {__version__} on {stamp}: "
          f"{_summary.plural(len(f.units), 'unit')} compared with each other and {against}.")
    _units_section(doc, f)
    _outliers_section(doc, f)
    _stats_section(doc, f)
    if f.spec is not None:
        _verdicts_section(doc, f)
    _coefficients_section(doc, f)
    figures: list[Path] = []
    pairs = _plotted(f)
    if pairs:
        doc.h(2, "6. Each coefficient across units")
        doc.p("One figure per coefficient: each unit's value per axis with its standard "
              "uncertainty, a hollow triangle at the 95 % upper bound where a unit does not "
              "resolve it, the fleet's median per axis dashed, the datasheet value in black "
              "(dotted for a typical value) and the outliers ringed in red.")
        (out / "figures").mkdir(parents=True, exist_ok=True)
        for sensor, term in pairs:
            fig = figure(f, sensor, term)
            path = out / "figures" / f"fleet_{sensor}_{term}"
            figures += plot.save(fig, path)
            doc.figure(path.with_suffix(".png"), f"{sensor} {term} across units")
    md, html = out / FILES[0], out / FILES[1]
    _atomic.write_text(md, doc.markdown(out), inputs=inputs)
    _atomic.write_text(html, doc.html(TITLE), inputs=inputs)
    folder.settle(out, [md, html, *figures], previous, inputs=inputs)
    return (md, html, *figures)


def _units_section(doc: Doc, f: Fleet) -> None:
    doc.h(2, "1. Units")
    broken = [u for u in f.units if u["error"] is not None]
    text = (f"{_summary.plural(len(f.units), 'unit')}, one log each"
            + (f"; {len(broken)} could not be analysed and take no part below" if broken
               else "") + ".")
    doc.p(text)
    rows = []
    for u in f.units:
        ok = u["error"] is None
        verdict = ("not analysed" if not ok else "—" if u["passed"] is None
                   else "pass" if u["passed"] else "fail")
        rows.append([u["unit"], u["path"], u["format"] or "—",
                     _summary.duration(u["duration_s"]) if ok else "—",
                     f"{u['fs']:.6g} Hz" if ok else "—", verdict,
                     ", ".join(u["failed"]) or "—", ", ".join(u["outliers"]) or "—",
                     u["error"] or ""])
    doc.table(["unit", "log", "format", "duration", "rate", "verdict", "fails", "outlier on",
               "error"], rows, "Every unit of the fleet")


def _outliers_section(doc: Doc, f: Fleet) -> None:
    doc.h(2, "2. Outliers")
    doc.p(f"Rule, per sensor, axis and coefficient over the units that resolve it: "
          f"{outlier_rule(f.false_alarm)}. A fleet without outliers shows a false one on a "
          f"given coefficient at most {100 * f.false_alarm:g} % of the time, whatever its size; "
          f"with few units the median absolute deviation is itself uncertain, so the cut "
          f"is large (about 16 robust σ for 4 units, 6.8 for 10, 4.3 for 100).")
    if not f.outliers:
        doc.p("No unit is an outlier on any coefficient.")
        return
    doc.table(["unit", "sensor", "axis", "term", "value", "fleet median", "ratio", "z",
               "cut"],
              [[o["unit"], o["sensor"], o["axis"], o["term"],
                f"{_display.cell(o['value'], o['std'])} {o['label']}",
                f"{_summary.number(o['median'])} {o['label']}", f"{o['ratio']:.3g}×",
                f"{o['z']:+.3g}", f"{o['cut']:.3g}"] for o in f.outliers],
              f"{_summary.plural(len(f.outliers), 'outlier')}, farthest first "
              "(z in robust σ of ln value)")


def _stats_section(doc: Doc, f: Fleet) -> None:
    doc.h(2, "3. Fleet median and spread")
    doc.p("Over the units that resolve each value (a value the data do not resolve takes "
          "no part; `resolved` says how many do). The robust σ is 1.4826·MAD of ln value: "
          "a relative spread. A coefficient fewer than "
          f"{MIN_UNITS} units resolve is not judged for outliers.")
    shown = [s for s in f.stats if s["resolved"]]
    rows = [[s["sensor"], s["term"], s["axis"], f"{s['resolved']}/{s['units']}",
             f"{_summary.number(s['median'])} {s['label']}",
             f"{100 * s['sigma']:.2g} %" if math.isfinite(s["sigma"]) else "—",
             f"{_summary.number(s['low'])} – {_summary.number(s['high'])}",
             f"{s['cut']:.3g}" if s["judged"] else "not judged",
             ", ".join(s["outliers"]) or "—"] for s in shown]
    doc.table(["sensor", "term", "axis", "resolved", "median", "robust σ", "range", "cut",
               "outliers"], rows, "Median and spread per sensor, coefficient and axis")
    none = sorted({f"{s['sensor']} {s['term']}" for s in f.stats if not s["resolved"]},
                  key=lambda x: (ALLAN_SENSORS.index(x.split()[0]), TERMS.index(x.split()[1])))
    if none:
        doc.p("Resolved by no unit on some axis: " + ", ".join(none) + ".")


def _verdicts_section(doc: Doc, f: Fleet) -> None:
    doc.h(2, f"4. Verdicts against {f.spec.name}")
    doc.p("Each unit's fitted values against the datasheet, as `imunoise.compare` judges "
          "one unit (a maximum passes when value + 1.645·u is below it, fails when "
          "value − 1.645·u is above it, is \"not significant\" in between; a typical "
          "value is no limit). A unit passes when none of its values fails.")
    items = [(i.sensor, i.term) for i in f.spec.items]
    axes = sorted({r["axis"] for r in f.rows}, key=lambda a: "XYZ".find(a) % 10)
    cols = [(s, t, a) for s, t in items for a in axes
            if any(r["sensor"] == s for r in f.rows)]
    index = {(r["unit"], r["sensor"], r["term"], r["axis"]): r["verdict"] for r in f.rows}
    rows = []
    for u in f.units:
        if u["error"] is not None:
            continue
        rows.append([u["unit"], "pass" if u["passed"] else "fail",
                     *[index.get((u["unit"], s, t, a)) or "—" for s, t, a in cols]])
    doc.table(["unit", "unit verdict", *[f"{s} {t} {a}" for s, t, a in cols]], rows,
              f"Verdicts per unit: {sum(bool(u['passed']) for u in f.units)} of "
              f"{len(rows)} pass")


def _coefficients_section(doc: Doc, f: Fleet) -> None:
    doc.h(2, "5. Coefficients per unit")
    doc.p("Value ± standard uncertainty; `< x`: not resolved, at most x (95 %); a value "
          "marked ! is an outlier. Gauss–Markov terms are listed as σ (in the unit of B) "
          "and correlation time; they are not compared across units, as how many a fit "
          "finds, and where, differs from unit to unit.")
    gm: dict[tuple[str, str, str], list[str]] = {}
    for g in f.gauss_markov:
        gm.setdefault((g["unit"], g["sensor"], g["axis"]), []).append(
            f"{_display.cell(g['sigma'], g['sigma_std'])} {g['label']} @ "
            f"{_display.cell(g['tau_c'], g['tau_c_std'])} s")
    for sensor in ALLAN_SENSORS:
        mine = [r for r in f.rows if r["sensor"] == sensor]
        if not mine:
            continue
        terms = [t for t in TERMS if any(r["resolved"] or math.isfinite(r["upper"])
                                         for r in mine if r["term"] == t)]
        labels = {r["term"]: r["label"] for r in mine}
        by = {(r["unit"], r["axis"], r["term"]): r for r in mine}
        keys = list(dict.fromkeys((r["unit"], r["axis"]) for r in mine))
        rows = []
        for unit, axis in keys:
            cells = []
            for t in terms:
                r = by[(unit, axis, t)]
                cells.append(_value(r) + (" !" if r["outlier"] else ""))
            rows.append([unit, axis, *cells, "; ".join(gm.get((unit, sensor, axis), [])) or "—"])
        doc.table(["unit", "axis", *[f"{t} [{labels[t]}]" for t in terms], "Gauss–Markov"],
                  rows, f"{sensor}: coefficients per unit and axis",
                  collapsed=len(rows) > _OPEN_ROWS)
