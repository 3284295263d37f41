"""A fleet of sensors compared with each other: which unit stands out, and on what.

:func:`fleet` characterises one log per unit (the loop of :func:`imunoise.batch`,
on Dask or in this process), then compares the units' datasheet values N, B, K,
Q, R per sensor and axis: the fleet's median and robust spread, the outliers, and
each unit's datasheet verdict (:func:`imunoise.compare`).

The outlier rule (docs/fleet.md)
--------------------------------
Per sensor, axis and coefficient, over the units that resolve it (a value the data
do not resolve is NaN, never 0, and takes no part: the counts say how many units
resolve each value), on x = ln(value):

* the fleet's centre is m = median(x) and its spread the robust σ
  s = 1.4826·MAD(x), MAD = median(|x − m|) (1.4826 makes s the standard
  deviation of a normal population);
* a unit's distance is the modified z-score of Iglewicz & Hoaglin,
  z = (x − m)/√(s² + u²), where u = std/value is the unit's own relative standard
  uncertainty (a unit measured too briefly is not called an outlier for its noisy
  estimate alone);
* it is an outlier when |z| > cut(n): the larger of 3.5 (Iglewicz & Hoaglin's cut)
  and the value that max |z| of n units drawn from one log-normal population
  exceeds with probability ``false_alarm`` (1 %, Monte Carlo with a fixed seed).
  The MAD of a few units is itself uncertain, so small fleets need a larger
  distance: cut(4) ≈ 16, cut(10) ≈ 6.8, cut(100) ≈ 4.3. A fleet without outliers
  thus shows a false one on a given coefficient at most ``false_alarm`` of the
  time, whatever its size;
* with fewer than :data:`MIN_UNITS` resolving units no outlier is judged (two
  units are always equally far from their median).

Values are shown in the datasheet's units: the spec's unit where it specifies the
coefficient, :data:`imunoise.units.DATASHEET_UNITS` elsewhere.

References
----------
B. Iglewicz, D. C. Hoaglin, "How to Detect and Handle Outliers", ASQC Basic
References in Quality Control 16, 1993 (the modified z-score and its 3.5 cut).
"""

from __future__ import annotations

import functools
import math
import os
from dataclasses import dataclass

import numpy as np

from imunoise import display as _display
from imunoise import units as _units
from imunoise._support import summary as _summary
from imunoise.datasheet import VERDICTS, Spec, load_spec
from imunoise.errors import ImunoiseValueError
from imunoise.scale.batch import BATCH_SENSORS, analyse_logs, expand

__all__ = ["FALSE_ALARM", "Fleet", "MAD_SCALE", "MIN_UNITS", "TERMS", "Z_CUT", "cut",
           "fleet", "robust_z"]

#: Coefficients compared across units (the datasheet values of every model).
TERMS = ("N", "B", "K", "Q", "R")
#: The modified z-score's cut of Iglewicz & Hoaglin: the smallest cut at any fleet size.
Z_CUT = 3.5
#: MAD to standard deviation of a normal population.
MAD_SCALE = 1.4826
#: Chance that a fleet without outliers shows one on a given coefficient (default).
FALSE_ALARM = 0.01
#: Fewest units resolving a coefficient for its outliers to be judged.
MIN_UNITS = 3
_VERDICT_RANK = {w: i for i, w in enumerate(VERDICTS)}  # 0 = most concerning
_DRAWS = 20_000


@functools.lru_cache(maxsize=256)
def cut(units: int, false_alarm: float = FALSE_ALARM) -> float:
    """The outlier cut on ``|z|`` for a coefficient ``units`` units resolve.

    The larger of :data:`Z_CUT` and the (1 − ``false_alarm``) quantile of
    max ``|z|`` over ``units`` draws of one normal population (z with the MAD of those
    draws; Monte Carlo, fixed seed, so the same fleet gets the same cut); ``inf``
    below :data:`MIN_UNITS`.
    """
    units = int(units)
    if not 0.0 < false_alarm < 0.5:
        raise ImunoiseValueError(f"false_alarm must be in (0, 0.5); got {false_alarm!r}")
    if units < MIN_UNITS:
        return math.inf
    draws = max(2_000, min(_DRAWS, 20_000_000 // units))
    x = np.random.default_rng(20_240_938).standard_normal((draws, units))
    med = np.median(x, axis=1, keepdims=True)
    dev = np.abs(x - med)
    s = MAD_SCALE * np.median(dev, axis=1, keepdims=True)
    zmax = np.max(dev / s, axis=1)
    return max(Z_CUT, float(np.quantile(zmax, 1.0 - false_alarm)))


def robust_z(values, stds=None) -> tuple[float, float, np.ndarray]:
    """``(median, robust σ, z)`` of positive ``values`` on a log scale.

    ``median`` is exp(median(ln values)), ``robust σ`` = 1.4826·MAD(ln values) (a
    relative spread: 0.05 ≈ 5 %), and ``z`` the modified z-score of each value,
    (ln value − ln median)/√(σ² + (std/value)²); NaN values (not resolved) get
    NaN and take no part. Where the denominator is 0 (more than half the units
    equal, no uncertainty) z is 0 for a unit at the median and NaN otherwise.
    """
    v = np.asarray(values, dtype=float).reshape(-1)
    u = (np.zeros_like(v) if stds is None
         else np.asarray(stds, dtype=float).reshape(-1) / np.where(v > 0, v, np.nan))
    ok = np.isfinite(v) & (v > 0)
    z = np.full(v.shape, np.nan)
    if not ok.any():
        return math.nan, math.nan, z
    x = np.log(v[ok])
    med = float(np.median(x))
    s = MAD_SCALE * float(np.median(np.abs(x - med))) if x.size > 1 else math.nan
    uu = np.nan_to_num(u[ok], nan=0.0, posinf=0.0)
    denom = np.sqrt((s if math.isfinite(s) else 0.0) ** 2 + uu**2)
    with np.errstate(divide="ignore", invalid="ignore"):
        zz = np.where(denom > 0, (x - med) / denom, np.where(x == med, 0.0, np.nan))
    z[ok] = zz
    return math.exp(med), s, z


@dataclass(frozen=True, repr=False)
class Fleet:
    """Units compared with each other and with a datasheet: :func:`fleet`'s result.

    Attributes
    ----------
    units : tuple of dict
        One per log, in the order given: ``unit`` (its name: the file name, the
        path where two share one), ``path``, ``format``, ``samples``, ``fs``,
        ``duration_s``, ``verdict`` (the most concerning datasheet verdict of its
        rows, datasheet.VERDICTS order; None without a spec or when the log failed),
        ``passed`` (no row fails; None without a spec or when the log failed),
        ``failed`` (``"gyro B X"``… that fail), ``outliers`` (``"gyro N X"``… it
        is an outlier on) and ``error`` (None, or why the log could not be
        analysed: such a unit takes no part in the statistics).
    rows : tuple of dict
        One per unit, sensor, axis and coefficient of :data:`TERMS`: ``unit,
        path, sensor, axis, term, label`` (the unit of the numbers, e.g. ``°/h``),
        ``value`` and ``std`` (NaN where not resolved), ``upper`` (then its 95 %
        upper bound), ``resolved``, ``verdict`` (the datasheet's for that term; None
        where the spec says nothing of it), ``ratio`` (value / fleet median),
        ``z`` (robust z-score, NaN where not judged) and ``outlier``.
    stats : tuple of dict
        One per sensor, axis and coefficient: ``sensor, axis, term, label``,
        ``units`` (units with that sensor), ``resolved`` (how many of them resolve
        the value), ``median`` (over those), ``sigma`` (robust σ of ln value: a
        relative spread), ``low``/``high`` (smallest and largest resolved value),
        ``cut`` (the ``|z|`` beyond which a unit is an outlier; inf when not judged),
        ``judged`` (at least :data:`MIN_UNITS` resolve it) and ``outliers`` (unit
        names), plus ``spec`` and ``limit`` where the datasheet specifies it.
    outliers : tuple of dict
        The outlying rows, farthest first: ``unit, path, sensor, axis, term,
        label, value, std, median, ratio, z, cut``.
    gauss_markov : tuple of dict
        The fitted Gauss–Markov bias terms per unit and axis: ``unit, sensor,
        axis, sigma, sigma_std`` (in the unit of B) ``label``, ``tau_c``,
        ``tau_c_std`` (s). Listed, not compared: how many a fit finds, and where,
        differs from unit to unit.
    spec : Spec or None
        The datasheet the verdicts are against.
    false_alarm : float
        The outlier rule's chance of a false outlier per coefficient.
    """

    units: tuple[dict, ...]
    rows: tuple[dict, ...]
    stats: tuple[dict, ...]
    outliers: tuple[dict, ...]
    gauss_markov: tuple[dict, ...]
    spec: Spec | None
    false_alarm: float = FALSE_ALARM

    # -- views -----------------------------------------------------------------
    @property
    def names(self) -> tuple[str, ...]:
        """Every unit's name, in the order given."""
        return tuple(u["unit"] for u in self.units)

    @property
    def analysed(self) -> tuple[str, ...]:
        """Names of the units whose log could be analysed."""
        return tuple(u["unit"] for u in self.units if u["error"] is None)

    @property
    def failed(self) -> tuple[str, ...]:
        """Names of the units with a failing datasheet verdict."""
        return tuple(u["unit"] for u in self.units if u["passed"] is False)

    def table(self) -> list[dict]:
        """:attr:`rows` as a list of dicts (``pandas.DataFrame(fleet.table())``)."""
        return [dict(r) for r in self.rows]

    def _facts(self) -> list[str]:
        broken = len(self.units) - len(self.analysed)
        facts = [_summary.plural(len(self.units), "unit")
                 + (f" ({broken} not analysed)" if broken else "")]
        if self.spec is not None:
            checked = [u for u in self.units if u["passed"] is not None]
            facts.append(f"{sum(bool(u['passed']) for u in checked)}/{len(checked)} pass "
                         f"{self.spec.name}")
        if self.outliers:
            facts.append(_summary.plural(len(self.outliers), "outlier") + ": "
                         + ", ".join(_outlier_phrase(o) for o in self.outliers[:3]))
        else:
            facts.append("no outlier")
        return facts

    def __repr__(self) -> str:
        return _summary.lines("Fleet(", self._facts(), sep="; ")

    def _repr_html_(self) -> str:
        """One row per unit: its verdict and the coefficients it stands out on."""
        body = [[u["unit"], u["format"] or "—",
                 _summary.duration(u["duration_s"]) if u["error"] is None else "—",
                 _verdict_word(u), ", ".join(u["outliers"]) or "—"]
                for u in self.units]
        return _summary.html_table(["unit", "format", "duration", "verdict", "outlier on"],
                                   body, caption="Fleet: " + "; ".join(self._facts()))

    def text(self) -> str:
        """Fixed-width text: the units, the outliers, and the fleet's median and
        spread per sensor, axis and coefficient."""
        out = ["Units"]
        out += _columns(["unit", "duration", "verdict", "outlier on", "error"],
                        [[u["unit"],
                          _summary.duration(u["duration_s"]) if u["error"] is None else "—",
                          _verdict_word(u), ", ".join(u["outliers"]) or "—",
                          u["error"] or ""] for u in self.units])
        out += ["", f"Outliers ({outlier_rule(self.false_alarm)})"]
        if self.outliers:
            out += _columns(["unit", "sensor", "axis", "term", "value", "median", "ratio", "z"],
                            [_outlier_cells(o) for o in self.outliers])
        else:
            out.append("none")
        out += ["", "Fleet median and spread (over the units that resolve each value)"]
        out += _columns(["sensor", "term", "axis", "resolved", "median", "robust σ", "range",
                         "cut", "outliers"], [_stat_cells(s) for s in self.stats if s["resolved"]])
        none = list(dict.fromkeys(f"{s['sensor']} {s['term']} {s['axis']}" for s in self.stats
                                  if not s["resolved"]))
        if none:
            out.append("resolved by no unit: " + ", ".join(none))
        return "\n".join(out)

    def report(self, out_dir, *, force: bool = False):
        """Write the fleet report (``fleet.md``, ``fleet.html``, one figure per
        coefficient) into ``out_dir``: :func:`imunoise.report.fleet.write`.
        Returns the paths written."""
        from imunoise.report import fleet as _fleet_report

        return _fleet_report.write(self, out_dir, force=force)


def outlier_rule(false_alarm: float = FALSE_ALARM) -> str:
    """The outlier rule in one sentence (the report and :meth:`Fleet.text` print it)."""
    return (f"|z| > cut on ln(value), z = (x − median)/√(s² + u²), s = {MAD_SCALE}·MAD, "
            f"u the unit's relative uncertainty; cut = max({Z_CUT:g}, the "
            f"{100 * (1 - false_alarm):g} % quantile of max |z| in a fleet of that size without "
            f"outliers); judged with ≥ {MIN_UNITS} resolving units")


def _verdict_word(u: dict) -> str:
    if u["error"] is not None:
        return "not analysed"
    if u["passed"] is None:
        return "—"
    return "pass" if u["passed"] else "fail: " + ", ".join(u["failed"])


def _outlier_phrase(o: dict) -> str:
    return f"{o['unit']} {o['sensor']} {o['term']} {o['axis']} ({o['ratio']:.3g}×)"


def _outlier_cells(o: dict) -> list[str]:
    return [o["unit"], o["sensor"], o["axis"], o["term"],
            f"{_display.cell(o['value'], o['std'])} {o['label']}",
            f"{_summary.number(o['median'])} {o['label']}", f"{o['ratio']:.3g}×",
            f"{o['z']:+.3g}"]


def _stat_cells(s: dict) -> list[str]:
    judged = s["judged"]
    return [s["sensor"], s["term"], s["axis"], f"{s['resolved']}/{s['units']}",
            f"{_summary.number(s['median'])} {s['label']}" if s["resolved"] else "—",
            f"{100 * s['sigma']:.2g} %" if math.isfinite(s["sigma"]) else "—",
            (f"{_summary.number(s['low'])}–{_summary.number(s['high'])}" if s["resolved"]
             else "—"),
            f"{s['cut']:.3g}" if judged else "not judged",
            ", ".join(s["outliers"]) or ("—" if judged else "")]


def _columns(header: list[str], rows: list[list[str]]) -> list[str]:
    widths = [max(len(r[i]) for r in [header, *rows]) for i in range(len(header))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip()
             for r in [header, *rows]]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return lines


def _names(paths: list[str]) -> list[str]:
    """A unit per log: its file name, the path where two logs share a file name,
    ``#k`` appended where two paths are the same."""
    base = [_summary.source_name(p) for p in paths]
    names = [b if base.count(b) == 1 else p for b, p in zip(base, paths, strict=True)]
    seen: dict[str, int] = {}
    out = []
    for n in names:
        seen[n] = seen.get(n, 0) + 1
        out.append(n if names.count(n) == 1 else f"{n} #{seen[n]}")
    return out


def _display_units(spec: Spec | None) -> dict[tuple[str, str], _units.Unit]:
    out = {(s, t): _units.unit_info(t, _units.DATASHEET_UNITS[s][t], s)
           for s in BATCH_SENSORS for t in TERMS}
    for item in spec.items if spec is not None else ():
        if item.term in TERMS:
            out[(item.sensor, item.term)] = _units.unit_info(item.term, item.unit, item.sensor)
    return out


def fleet(
    logs,
    spec="vn100",
    *,
    client=None,
    fs: float | None = None,
    progress: bool | None = None,
    false_alarm: float = FALSE_ALARM,
) -> Fleet:
    """Compare a fleet of units: one log per unit, each against the others and the spec.

    Parameters
    ----------
    logs : str, path or sequence of them
        One log per unit, or glob patterns (``"lab/*.bin"``, expanded in sorted
        order). A unit is named by its file name.
    spec : str, path, Spec or None
        Datasheet for the per-unit verdicts (``"vn100"``, a TOML file);
        ``None`` or ``"none"``: no verdicts.
    client : None, False, str or distributed.Client
        Where the logs are analysed, as :func:`imunoise.batch`: ``None``
        (default) a local Dask cluster of 2 worker processes for this call;
        ``False`` one after another in this process (no Dask; the same numbers);
        a scheduler address or a ``Client``.
    fs : float, optional
        Sample rate of logs without timestamps.
    progress : bool, optional
        A progress bar on stderr; default: when stderr is a terminal.
    false_alarm : float
        Chance that a fleet without outliers shows one on a given coefficient
        (default 1 %); sets the outlier cut (:func:`cut`).

    Returns
    -------
    Fleet
        Per unit and axis N, B, K, Q, R with uncertainties (and the fitted
        Gauss–Markov terms), the fleet's median and robust spread, the outliers
        and each unit's verdict.

    Raises
    ------
    FileNotFoundError
        A log that does not exist (a log that exists but cannot be read is a unit
        with an ``error``).
    ValueError
        No log given, a pattern matching nothing, a bad spec, or no log that
        could be analysed.

    Notes
    -----
    The outlier rule is in the module's docstring and docs/fleet.md. A log that
    fails is named in :attr:`Fleet.units` with its error and takes no part in the
    statistics.

    Examples
    --------
    >>> import imunoise
    >>> # f = imunoise.fleet("lab/unit_*.bin", spec="vn100")
    >>> # print(f.text()); f.report("fleet-report")
    """
    if not 0.0 < false_alarm < 0.5:
        raise ImunoiseValueError(f"false_alarm must be in (0, 0.5); got {false_alarm!r}")
    files = expand(logs)
    for p in files:
        if not os.path.isfile(p):
            raise FileNotFoundError(f"{p}: no such log file")
    if isinstance(spec, str) and spec.lower() == "none":
        spec = None
    spec = load_spec(spec) if spec is not None else None
    results = analyse_logs(files, client, spec, fs=fs, progress=progress, components=True,
                           desc="imunoise fleet")
    return _compare(files, results, spec, false_alarm)


def _compare(files: list[str], results: list[list[dict]], spec: Spec | None,
             false_alarm: float) -> Fleet:
    names = _names(files)
    shown = _display_units(spec)
    specified = {(i.sensor, i.term): i for i in spec.items} if spec is not None else {}
    units, rows, gm = [], [], []
    for name, path, log_rows in zip(names, files, results, strict=True):
        head = log_rows[0]
        error = head["error"]
        units.append({"unit": name, "path": path, "format": head["format"],
                      "samples": int(head["samples"]), "fs": float(head["fs"]),
                      "duration_s": float(head["duration_s"]), "error": error})
        if error is not None:
            continue
        for r in log_rows:
            s, axis = r["sensor"], r["axis"]
            for t in TERMS:
                f = shown[(s, t)].factor * _units.input_scale(s)
                value = r[t] * f if r[f"{t}_supported"] else math.nan
                rows.append({
                    "unit": name, "path": path, "sensor": s, "axis": axis, "term": t,
                    "label": shown[(s, t)].label, "value": value,
                    "std": r[f"{t}_std"] * f if math.isfinite(value) else math.nan,
                    "upper": r[f"{t}_upper"] * f if not math.isfinite(value) else math.nan,
                    "resolved": math.isfinite(value), "verdict": r.get(f"verdict_{t}"),
                    "ratio": math.nan, "z": math.nan, "outlier": False})
            f_b = shown[(s, "B")].factor * _units.input_scale(s)
            for sigma, sigma_std, tau_c, tau_c_std in r.get("gauss_markov", ()):
                gm.append({"unit": name, "sensor": s, "axis": axis, "sigma": sigma * f_b,
                           "sigma_std": sigma_std * f_b, "label": shown[(s, "B")].label,
                           "tau_c": tau_c, "tau_c_std": tau_c_std})
    if not rows:
        reasons = "; ".join(f"{u['unit']}: {u['error']}" for u in units)
        raise ImunoiseValueError(f"no log could be analysed ({reasons})")
    stats, outliers = [], []
    groups: dict[tuple[str, str, str], list[dict]] = {}
    for r in rows:
        groups.setdefault((r["sensor"], r["term"], r["axis"]), []).append(r)
    for (s, t, axis), group in groups.items():
        values = np.array([r["value"] for r in group])
        med, sigma, z = robust_z(values, [r["std"] for r in group])
        resolved = int(np.isfinite(values).sum())
        c = cut(resolved, false_alarm)
        flagged = []
        for r, zi in zip(group, z, strict=True):
            r["ratio"] = r["value"] / med if r["resolved"] else math.nan
            r["z"] = float(zi) if math.isfinite(c) else math.nan
            r["outlier"] = bool(math.isfinite(c) and math.isfinite(zi) and abs(zi) > c)
            if r["outlier"]:
                flagged.append(r["unit"])
                outliers.append({k: r[k] for k in ("unit", "path", "sensor", "axis", "term",
                                                   "label", "value", "std", "ratio", "z")}
                                | {"median": med, "cut": c})
        finite = values[np.isfinite(values)]
        stat = {"sensor": s, "axis": axis, "term": t, "label": group[0]["label"],
                "units": len(group), "resolved": resolved, "median": med, "sigma": sigma,
                "low": float(finite.min()) if finite.size else math.nan,
                "high": float(finite.max()) if finite.size else math.nan,
                "cut": c, "judged": math.isfinite(c), "outliers": tuple(flagged)}
        item = specified.get((s, t))
        if item is not None:
            stat |= {"spec": item.value, "limit": item.limit}
        stats.append(stat)
    per_unit: dict[str, list[dict]] = {}
    for r in rows:
        per_unit.setdefault(r["unit"], []).append(r)
    for u in units:
        mine = per_unit.get(u["unit"], [])
        words = [r["verdict"] for r in mine if r["verdict"] is not None]
        checked = spec is not None and u["error"] is None and bool(words)
        u["verdict"] = min(words, key=_VERDICT_RANK.__getitem__) if checked else None
        u["passed"] = ("fail" not in words) if checked else None
        u["failed"] = tuple(f"{r['sensor']} {r['term']} {r['axis']}" for r in mine
                            if r["verdict"] == "fail")
        u["outliers"] = tuple(f"{r['sensor']} {r['term']} {r['axis']}" for r in mine
                              if r["outlier"])
    order = {s: i for i, s in enumerate(BATCH_SENSORS)}
    stats.sort(key=lambda x: (order[x["sensor"]], TERMS.index(x["term"]), x["axis"]))
    outliers.sort(key=lambda o: -abs(o["z"]))
    return Fleet(units=tuple(units), rows=tuple(rows), stats=tuple(stats),
                 outliers=tuple(outliers), gauss_markov=tuple(gm), spec=spec,
                 false_alarm=false_alarm)

