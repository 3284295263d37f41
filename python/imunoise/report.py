"""The one-command noise report: statistics, distributions, Allan deviation, noise model.

:func:`build` turns a short log (sample statistics, distributions) and a long log
(Allan deviation, noise model) into a directory::

    report.html    self-contained (figures embedded as data URIs), plain HTML + CSS
    report.md      the same content, figures linked from figures/
    figures/       every figure as PNG and SVG
    noise.json     fitted noise model (when the noise model is available)
    imu.yaml       Kalibr IMU noise file (when the noise model is available)
    ekf_bias_model.yaml  white noise, random walk and Gauss–Markov bias states per axis

With one log both analyses run on it. Sections follow a lab report: recording
summary (duration, rate, what the reader skipped), sample statistics, distribution
fits, Allan deviation per sensor, noise coefficients per axis in datasheet units
with uncertainties, datasheet comparison.

The report reaches the rest of the package through a handful of small functions
(``_read_log``, ``_allan``, ``_fit``, ``_model_sentences``, ``_datasheet_rows``,
``_compare_rows``, ``_write_model_files``); each is the single place that knows
the API it calls.
"""

from __future__ import annotations

import base64
import datetime as _dt
import html as _html
import math
import sys
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import imunoise
from imunoise import plot as _plot
from imunoise import stats as _stats
from imunoise.readers.log import CHANNELS, ImuLog

__all__ = ["Report", "build"]

#: Sensors whose Allan deviation and noise model the report computes.
ALLAN_SENSORS = ("gyro", "accel")
#: Sensors whose time series and distributions the report shows.
SAMPLE_SENSORS = ("gyro", "accel", "mag")
#: Tau grid of the Allan analysis: log-spaced points per decade.
TAUS_PER_DECADE = 10
_AXES = ("X", "Y", "Z")


# ---------------------------------------------------------------------------
# Dependencies: each used through exactly one function.
# ---------------------------------------------------------------------------


def _read_log(
    path, fs: float | None = None, progress: Callable[[int, int], None] | None = None
) -> ImuLog:
    """Read a log file with :func:`imunoise.read`."""
    read = getattr(imunoise, "read", None)
    if read is None:
        raise ValueError("reading log files needs imunoise.read, which this build lacks")
    return read(path, fs=fs, progress=progress)


def _allan(x: np.ndarray, fs: float):
    """Overlapping Allan deviation of (n, 3) samples on the report's tau grid."""
    return imunoise.adev(x, fs, taus=TAUS_PER_DECADE)


def _fit(result):
    """Fit the noise model to an Allan result (a poor fit is said in the report's
    words, per axis, rather than warned about)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="the noise model follows",
                                category=RuntimeWarning)
        return imunoise.fit(result)


def _model_sentences(model, sensor: str) -> list[str]:
    """Per axis, in words: the terms, how well the model follows the curve, the
    Gauss–Markov terms, and whether model and datasheet read-offs agree."""
    from imunoise import units as _units

    b_unit = _units.unit_info("B", None, sensor)
    n_unit = _units.unit_info("N", None, sensor)
    out = []
    for c, axis in enumerate(_AXES[: model.channels]):
        terms = [t for t in ("N", "B", "K", "Q", "R") if np.atleast_1d(model.supported[t])[c]]
        gm = model.gauss_markov(c)
        parts = [f"{axis}: {' + '.join(terms + [f'{len(gm)} Gauss–Markov'] * bool(gm))}"]
        cover = float(np.atleast_1d(model.coverage)[c])
        delta = float(np.atleast_1d(model.discrepancy)[c])
        parts.append(f"follows {cover:.0%} of the taus (inside the 95 % interval or within 5 %)"
                     + (f", residual discrepancy {delta / 2:.1%} in σ" if delta > 0.01 else ""))
        if cover < 0.8:
            parts.append("**the model does not describe this curve: read its coefficients "
                         "as a summary only** (see the data/model panel)")
        for sigma, tau_c in gm:
            value = _units.convert(sigma, "B", b_unit.name, sensor=sensor)
            parts.append(f"Gauss–Markov bias σ = {_num(value)} {b_unit.label}, "
                         f"τc = {_num(tau_c)} s")
        for term, unit in (("N", n_unit), ("B", b_unit)):
            read = float(np.atleast_1d(model.readoff[term]["value"])[c])
            std = float(np.atleast_1d(model.readoff[term]["std"])[c])
            eq = float(np.atleast_1d(model.equivalent(term))[c])
            if not (np.isfinite(read) and eq > 0):
                continue
            conv = _units.convert(np.array([read, eq, std]), term, unit.name, sensor=sensor)
            diff = abs(read - eq) / max(std, 1e-300)
            verdict = ("agree" if diff <= 2 or abs(read / eq - 1) <= 0.05 else
                       "differ: the curve is not the ideal slope there (filter, bumps)")
            parts.append(f"{term} read-off {_num(conv[0])} vs model {_num(conv[1])} "
                         f"{unit.label} ({verdict})")
        out.append("; ".join(parts) + ".")
    return out


def _datasheet_rows(model, sensor: str) -> tuple[list[str], list[list[str]]]:
    """Noise coefficients per axis in datasheet units: ``value ± std`` cells."""
    rows = model.table(sensor)
    axes = [a for a in _AXES if rows and a in rows[0]]
    header = ["quantity", "term", "unit", *axes]
    out = []
    for r in rows:
        cells = [r["quantity"], r["term"], r["unit"]]
        for a in axes:
            if not r[f"{a}_supported"]:
                cells.append("not resolved")
            else:
                cells.append(f"{_num(r[a])} ± {_num(r[f'{a}_std'])}")
        out.append(cells)
    return header, out


def _compare_rows(models: dict, spec: str) -> tuple[list[str], list[list[str]]]:
    """Measured vs datasheet table from :func:`imunoise.compare`."""
    cmp = imunoise.compare(models, spec)
    header = ["sensor", "quantity", "axis", "unit", "measured", "spec", "ratio", "verdict"]
    out = []
    for r in cmp.rows:
        bound = "<" if r["limit"] == "max" else "typ."
        out.append([
            r["sensor"], f"{r['quantity']} ({r['term']})", r["axis"], r["unit"],
            _num(r["measured"]), f"{bound} {_num(r['spec'])}", _num(r["ratio"]), r["verdict"],
        ])
    return header, out


def _write_model_files(models: dict, out_dir: Path, fs: float) -> list[Path]:
    """noise.json, Kalibr imu.yaml and the EKF bias model through :mod:`imunoise.export`."""
    from imunoise import export

    json_path, yaml_path = out_dir / "noise.json", out_dir / "imu.yaml"
    ekf_path = out_dir / "ekf_bias_model.yaml"
    export.write_json(json_path, **models)
    export.write_kalibr(yaml_path, gyro=models.get("gyro"), accel=models.get("accel"),
                        update_rate=fs)
    export.write_ekf(ekf_path, gyro=models.get("gyro"), accel=models.get("accel"))
    return [json_path, yaml_path, ekf_path]


# ---------------------------------------------------------------------------
# Document model: blocks rendered both to Markdown and to HTML.
# ---------------------------------------------------------------------------


@dataclass
class _Doc:
    blocks: list = field(default_factory=list)

    def h(self, level: int, text: str) -> None:
        self.blocks.append(("h", level, text))

    def p(self, text: str) -> None:
        self.blocks.append(("p", text))

    def table(self, header: Sequence[str], rows: Sequence[Sequence[str]], caption="") -> None:
        self.blocks.append(("table", list(header), [list(r) for r in rows], caption))

    def figure(self, png: Path, caption: str) -> None:
        self.blocks.append(("figure", png, caption))

    def markdown(self, out_dir: Path) -> str:
        lines = []
        for b in self.blocks:
            if b[0] == "h":
                lines += ["#" * b[1] + " " + b[2], ""]
            elif b[0] == "p":
                lines += [b[1], ""]
            elif b[0] == "table":
                _, header, rows, caption = b
                if caption:
                    lines += [f"*{caption}*", ""]
                lines.append("| " + " | ".join(header) + " |")
                lines.append("|" + "|".join("---" for _ in header) + "|")
                lines += ["| " + " | ".join(r) + " |" for r in rows]
                lines.append("")
            elif b[0] == "figure":
                rel = b[1].relative_to(out_dir).as_posix()
                lines += [f"![{b[2]}]({rel})", "", f"*{b[2]}*", ""]
        return "\n".join(lines)

    def html(self, title: str) -> str:
        e = _html.escape
        body = []
        for b in self.blocks:
            if b[0] == "h":
                body.append(f"<h{b[1]}>{e(b[2])}</h{b[1]}>")
            elif b[0] == "p":
                body.append(f"<p>{_inline(b[1])}</p>")
            elif b[0] == "table":
                _, header, rows, caption = b
                cap = f"<caption>{e(caption)}</caption>" if caption else ""
                th = "".join(f"<th>{e(h)}</th>" for h in header)
                trs = "".join(
                    "<tr>" + "".join(f"<td>{e(c)}</td>" for c in r) + "</tr>" for r in rows
                )
                body.append(
                    f'<div class="tw"><table>{cap}<thead><tr>{th}</tr></thead>'
                    f"<tbody>{trs}</tbody></table></div>"
                )
            elif b[0] == "figure":
                data = base64.b64encode(b[1].read_bytes()).decode("ascii")
                body.append(
                    f'<figure><img src="data:image/png;base64,{data}" alt="{e(b[2])}">'
                    f"<figcaption>{e(b[2])}</figcaption></figure>"
                )
        return _HTML.format(title=e(title), css=_CSS, body="\n".join(body))


def _inline(text: str) -> str:
    """Escape and turn `code` spans into <code>."""
    parts = _html.escape(text).split("`")
    return "".join(f"<code>{p}</code>" if i % 2 else p for i, p in enumerate(parts))


_CSS = """
:root{--fg:#1d2330;--mut:#5b6475;--bd:#d9dee7;--bg:#fff;--hd:#f3f5f9;--ac:#1f5fbf}
*{box-sizing:border-box}
body{font:15px/1.55 -apple-system,"Segoe UI",Roboto,Helvetica,Arial,sans-serif;color:var(--fg);
background:var(--bg);max-width:1100px;margin:2rem auto;padding:0 1.25rem}
h1{font-size:1.9rem;margin:.2rem 0 .6rem;border-bottom:3px solid var(--ac);padding-bottom:.4rem}
h2{font-size:1.35rem;margin-top:2.4rem;border-bottom:1px solid var(--bd);padding-bottom:.25rem}
h3{font-size:1.1rem;margin-top:1.6rem;color:var(--mut)}
p{margin:.5rem 0 .9rem}
code{font:13px/1.4 ui-monospace,SFMono-Regular,Menlo,Consolas,monospace;background:var(--hd);
padding:.05rem .3rem;border-radius:3px}
.tw{overflow-x:auto;margin:.6rem 0 1.2rem}
table{border-collapse:collapse;font-size:13px;font-variant-numeric:tabular-nums}
caption{caption-side:top;text-align:left;color:var(--mut);font-style:italic;padding:.2rem 0}
th,td{border:1px solid var(--bd);padding:.3rem .6rem;text-align:right;white-space:nowrap}
th{background:var(--hd);font-weight:600}
td:first-child,th:first-child{text-align:left}
tbody tr:nth-child(even){background:#fafbfd}
figure{margin:1rem 0 1.6rem}
img{max-width:100%;height:auto;border:1px solid var(--bd);border-radius:4px}
figcaption{color:var(--mut);font-size:13px;margin-top:.3rem}
footer{margin-top:3rem;color:var(--mut);font-size:12px;border-top:1px solid var(--bd);
padding-top:.6rem}
"""

_HTML = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title><style>{css}</style></head>
<body>
{body}
</body></html>
"""


def terms_used(result, i: int) -> str:
    """Terms behind tau ``i``: one count, or ``lo–hi`` over channels whose gaps differ."""
    n = np.reshape(result.n, (len(result.taus), -1))[i]
    lo, hi = int(n.min()), int(n.max())
    return str(lo) if lo == hi else f"{lo}–{hi}"


def _num(v: float) -> str:
    return "—" if not math.isfinite(v) else f"{v:.6g}"


# ---------------------------------------------------------------------------
# The report.
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Report:
    """What :func:`build` wrote and computed.

    Attributes
    ----------
    out_dir, html, markdown : Path
    figures : tuple of Path
        Every file under ``figures/``.
    model_files : tuple of Path
        ``noise.json`` and ``imu.yaml`` (empty without the noise model).
    description : imunoise.stats.Description
        Sample statistics of the short log.
    distributions : dict
        ``{"gyro X": Distribution, ...}`` of the short log.
    allan : dict
        ``{"gyro": AllanResult, "accel": AllanResult}`` of the long log.
    models : dict
        ``{"gyro": NoiseModel, "accel": NoiseModel}`` (empty without the noise model).
    logs : tuple of ImuLog
        The logs analysed (short, then long when it is another log).
    """

    out_dir: Path
    html: Path
    markdown: Path
    figures: tuple[Path, ...]
    model_files: tuple[Path, ...]
    description: object
    distributions: dict
    allan: dict
    models: dict
    logs: tuple = ()


class _Progress:
    """A tqdm bar on stderr when stderr is a terminal (or when forced), else nothing."""

    def __init__(self, enabled: bool | None, total: int):
        if enabled is None:
            enabled = sys.stderr.isatty()
        self.bar = None
        if enabled:
            from tqdm import tqdm

            self.bar = tqdm(total=total, file=sys.stderr, unit="step", leave=False)

    def step(self, what: str) -> None:
        if self.bar is not None:
            self.bar.set_description(what)
            self.bar.update(1)

    def reader(self, label: str):
        """A ``progress(done, total)`` callback for the reader, or None."""
        if self.bar is None:
            return None
        from tqdm import tqdm

        bar = tqdm(total=0, file=sys.stderr, unit="B", unit_scale=True, desc=label,
                   leave=False)

        def cb(done: int, total: int) -> None:
            bar.total = total
            bar.n = done
            bar.refresh()
            if done >= total:
                bar.close()

        return cb

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


#: Share of missing samples above which the report prints a warning line.
GAP_WARN_SHARE = 0.01
#: Gaps listed in the summary table / shaded on the time plots (the largest).
GAP_ROWS = 10
GAP_SHADE = 200


def gap_note(source: str, issues, gaps) -> str | None:
    """One line saying that (and how much of) a log is missing, or None without gaps."""
    if not len(gaps):
        return None
    (start, length, _k), = gaps.largest(1).rows()
    plural = "s" if issues.gaps != 1 else ""
    return (f"{source}: {issues.samples_missing} samples ({100 * issues.share_missing:.3g} %) "
            f"missing in {issues.gaps} gap{plural} (largest {_duration(length)} at "
            f"{_duration(start - gaps.t0)}); left out of the statistics, not spliced over")


def _missing(issues) -> str:
    """``"30000 (15 %) in 1 gap"`` or ``"0"``."""
    if not issues.samples_missing:
        return "0"
    plural = "s" if issues.gaps != 1 else ""
    return (f"{issues.samples_missing} ({100 * issues.share_missing:.3g} %) in "
            f"{issues.gaps} gap{plural}")


def _load(source, label: str, progress: _Progress, fs: float | None = None) -> ImuLog:
    if isinstance(source, ImuLog):
        return source
    path = Path(source)
    if not path.exists():
        raise OSError(f"{label} log {str(path)!r} does not exist")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        log = _read_log(path, fs, progress.reader(f"reading {path.name}"))
    if len(log) == 0:  # the error says it all; drop warnings such as the assumed rate
        raise ValueError(f"{label} log {str(path)!r}: no usable records ({log.issues})")
    for w in caught:
        warnings.warn(w.message, w.category, stacklevel=2)
    return log


def build(
    short,
    long=None,
    out_dir="imunoise-report",
    *,
    spec: str | None = "vn100",
    fs: float | None = None,
    progress: bool | None = None,
) -> Report:
    """Analyse the logs and write the report directory.

    Parameters
    ----------
    short : path or ImuLog
        Short still recording (minutes): sample statistics and distributions.
    long : path or ImuLog, optional
        Long still recording (hours): Allan deviation and noise model. Default: ``short``.
    out_dir : path
        Directory to write (created; existing report files are replaced).
    spec : str or None
        Datasheet to compare against (name or file, see :func:`imunoise.compare`);
        None skips the comparison.
    fs : float, optional
        Sample rate in Hz for logs without timestamps (VN ASCII); passed to the reader.
    progress : bool or None
        Progress bars on stderr; None shows them when stderr is a terminal.
    """
    out = Path(out_dir)
    bar = _Progress(progress, total=6)
    try:
        return _build(short, long, out, spec, fs, bar)
    finally:
        bar.close()


def _build(short, long, out: Path, spec, fs, bar: _Progress) -> Report:
    short_log = _load(short, "short", bar, fs)
    long_log = short_log if long is None else _load(long, "long", bar, fs)
    bar.step("statistics")
    figdir = out / "figures"
    figdir.mkdir(parents=True, exist_ok=True)
    figures: list[Path] = []
    doc = _Doc()
    title = "IMU noise report"
    doc.h(1, title)
    stamp = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    doc.p(f"Generated by imunoise {imunoise.__version__} on {stamp}.")

    # 1. Recording summary
    doc.h(2, "1. Recording summary")
    logs = [("both", short_log)] if long is None else [("short", short_log), ("long", long_log)]
    rows = []
    for label, log in logs:
        rows.append([
            label, log.source if log.source.startswith("<") else Path(log.source).name,
            log.format, str(len(log)), _duration(log.duration), f"{log.fs:.6g}",
            ", ".join(log.channels), _missing(log.issues), str(log.issues.total), str(log.issues),
        ])
    doc.table(
        ["log", "source", "format", "samples", "duration", "rate [Hz]", "channels",
         "samples missing", "records skipped", "parse issues"],
        rows,
    )
    doc.p("Duration is the true length of the recording (grid rows, missing samples "
          "included); a missing sample is left out of every statistic, never spliced over.")
    if long is None:
        doc.p("One log given: the statistics and the Allan analysis both use it.")
    for label, log in logs:
        which = "the log" if label == "both" else f"the {label} log"
        if log.issues.share_missing > GAP_WARN_SHARE:
            doc.p(f"**Warning**: {100 * log.issues.share_missing:.3g} % of {which} is "
                  f"missing ({_missing(log.issues)}); the statistics use the samples "
                  "that are there.")
        if len(log.gaps):
            top = log.gaps.largest(GAP_ROWS)
            t0 = log.gaps.t0
            doc.table(
                ["start [s from first sample]", "duration [s]", "samples"],
                [[_num(a - t0), _num(d), str(k)] for a, d, k in top.rows()],
                caption=f"Largest gaps of {which} ({len(log.gaps)} in all)",
            )
    for label, log in logs:
        shade = [(a - log.gaps.t0, d) for a, d, _k in log.gaps.largest(GAP_SHADE).rows()]
        for sensor in SAMPLE_SENSORS:
            y = getattr(log, sensor)
            if y is None:
                continue
            unit = CHANNELS[sensor][1]
            which = "the log" if label == "both" else f"the {label} log"
            fig = _plot.time_series(y, log.fs, title=f"{sensor} ({which})", unit=unit,
                                    gaps=shade)
            figures += _plot.save(fig, figdir / f"timeseries_{label}_{sensor}")
            doc.figure(figdir / f"timeseries_{label}_{sensor}.png",
                       f"Time series of {which}: {sensor} [{unit}] (min/max per pixel)")

    # 2. Sample statistics
    doc.h(2, "2. Sample statistics")
    desc = _stats.describe(short_log)
    doc.p(f"Short log, {desc.n} samples at {_num(desc.fs)} Hz; std and variance with ddof = 1; "
          "drift is the least-squares slope against time.")
    doc.table(
        ["channel", "unit", "mean", "std", "variance", "min", "max", "drift [unit/h]"],
        [[r["name"], r["unit"], *(_num(r[k]) for k in
          ("mean", "std", "var", "min", "max", "drift_per_hour"))] for r in desc.rows()],
        caption="Sample statistics (short log)",
    )

    # 3. Distribution fits
    bar.step("distributions")
    doc.h(2, "3. Distribution fits")
    doc.p("Normal fit by maximum likelihood; histogram bins are whole multiples of the "
          "detected quantization step (or of the level spacing, where the sensor uses only "
          "some of the printed grid), centred on the levels. With this many samples any "
          "real sensor fails a normality test: read KS D, A², skewness and excess kurtosis "
          "as sizes of the departure from normal.")
    dists: dict[str, object] = {}
    drows = []
    for sensor in SAMPLE_SENSORS:
        y = getattr(short_log, sensor)
        if y is None:
            continue
        per_axis = []
        for j in range(y.shape[1]):
            d = _stats.distribution(y[:, j])
            name = f"{sensor} {_AXES[j]}"
            dists[name] = d
            per_axis.append(d)
            drows.append([
                name, CHANNELS[sensor][1], _num(d.step) if d.step else "—",
                _num(d.level_spacing) if d.level_spacing else "—", str(len(d.counts)),
                _num(d.mu), _num(d.sigma), _num(d.ks_statistic), _num(d.ks_pvalue),
                _num(d.ad_statistic), _num(d.skewness), _num(d.excess_kurtosis),
            ])
        fig = _plot.histograms(per_axis, title=f"{sensor} distribution (short log)",
                               unit=CHANNELS[sensor][1])
        figures += _plot.save(fig, figdir / f"hist_{sensor}")
        doc.figure(figdir / f"hist_{sensor}.png",
                   f"Histogram of {sensor} with the fitted normal density")
    doc.table(
        ["channel", "unit", "quantization step", "level spacing", "bins", "μ", "σ", "KS D",
         "KS p", "AD A²", "skewness", "excess kurtosis"],
        drows,
        caption="Distribution fits (short log)",
    )

    # 4. Allan deviation + 5. noise model
    bar.step("Allan deviation")
    allan: dict[str, object] = {}
    models: dict[str, object] = {}
    for sensor in ALLAN_SENSORS:
        y = getattr(long_log, sensor)
        if y is not None:
            allan[sensor] = _allan(y, long_log.fs)
    bar.step("noise model")
    for sensor, r in allan.items():
        models[sensor] = _fit(r)
    doc.h(2, "4. Allan deviation")
    doc.p(f"Overlapping Allan deviation of the {'long' if long is not None else 'only'} log, "
          f"{TAUS_PER_DECADE} taus per decade, error bars at the "
          f"{next(iter(allan.values())).confidence:.1%} confidence level (χ² with Greenhall "
          "EDF)." if allan else "The log has no gyro or accelerometer channel.")
    for sensor, r in allan.items():
        unit = CHANNELS[sensor][1]
        model = models.get(sensor)
        fig = _plot.allan(r, model, title=f"{sensor} Allan deviation", unit=unit)
        figures += _plot.save(fig, figdir / f"adev_{sensor}")
        doc.h(3, sensor)
        doc.figure(figdir / f"adev_{sensor}.png",
                   f"Allan deviation of {sensor} [{unit}]"
                   + (" with the fitted model, its terms, the read-off points and the "
                      "data/model ratio" if model is not None else ""))
        rows = []
        for i, tau in enumerate(r.taus):
            row = [_num(tau), terms_used(r, i)]
            for j in range(r.dev.shape[1]):
                row += [_num(r.dev[i, j]), f"{_num(r.ci_low[i, j])} – {_num(r.ci_high[i, j])}"]
            rows.append(row)
        header = ["τ [s]", "n"]
        for a in _AXES[: r.dev.shape[1]]:
            header += [f"σ {a} [{unit}]", f"CI {a}"]
        doc.table(header, rows, caption=f"Allan deviation of {sensor}")

    doc.h(2, "5. Noise coefficients")
    model_files: list[Path] = []
    doc.p("Fit of σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)B² + K²τ/3 + R²τ²/2 (IEEE Std 952) "
          "plus up to three first-order Gauss–Markov bias terms, on ln σ², each octave of τ "
          "weighted alike, the terms chosen by BIC; standard uncertainties from the fit "
          "(docs/noise.md). Read-offs: N on the −½ line at τ = 1 s, B = σ_min/0.664.")
    for sensor, m in models.items():
        header, rows = _datasheet_rows(m, sensor)
        doc.table(header, rows, caption=f"{sensor} noise coefficients per axis")
        for sentence in _model_sentences(m, sensor):
            doc.p(sentence)
    model_files = _write_model_files(models, out, long_log.fs)

    doc.h(2, "6. Datasheet comparison")
    if spec is None:
        doc.p("No datasheet given (`--spec`).")
    else:
        header, rows = _compare_rows(models, spec)
        doc.table(header, rows, caption=f"Measured vs datasheet ({spec})")

    bar.step("writing")
    md_path, html_path = out / "report.md", out / "report.html"
    md_path.write_text(doc.markdown(out), encoding="utf-8")
    html_path.write_text(doc.html(title), encoding="utf-8")
    bar.step("done")
    return Report(
        out_dir=out,
        html=html_path,
        markdown=md_path,
        figures=tuple(figures),
        model_files=tuple(model_files),
        description=desc,
        distributions=dists,
        allan=allan,
        models=models,
        logs=tuple(log for _label, log in logs),
    )


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.1f} s"
    if seconds < 7200:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.2f} h"
