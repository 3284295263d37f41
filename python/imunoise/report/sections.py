"""The report's sections, in reading order: one function ``(ctx, doc) -> None`` each,
writing its text, tables and figures below the heading that :mod:`.build` numbers.

A section reads the logs and the analyses from the :class:`~.build.Context` (which
computes each analysis once, on first use) and adds its figures through it.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from imunoise import numbers, plot
from imunoise._schema import CHANNELS, SAMPLE_SENSORS, axis_names
from imunoise.report.formatting import (
    format_duration,
    format_number,
    missing_text,
    terms_used,
)
from imunoise.report.model_text import comparison_rows, datasheet_rows, model_sentences

if TYPE_CHECKING:
    from imunoise.report.build import Context
    from imunoise.report.document import Doc

__all__ = [
    "GAP_ROWS",
    "GAP_SHADE",
    "GAP_WARN_SHARE",
    "allan_deviation",
    "attitude",
    "datasheet_comparison",
    "distribution_fits",
    "noise_coefficients",
    "recording_summary",
    "sample_statistics",
]

#: Share of missing samples above which the report prints a warning line.
GAP_WARN_SHARE = 0.01
#: Gaps listed in the summary table / shaded on the time plots (the largest).
GAP_ROWS = 10
GAP_SHADE = plot.SHADED_GAPS


def _which(label: str) -> str:
    """How the text names a log: "the log" (one log for both) or "the short log"."""
    return "the log" if label == "both" else f"the {label} log"


def recording_summary(ctx: Context, doc: Doc) -> None:
    """Per log: source, format, length, rate, channels, what is missing or skipped;
    the largest gaps; the time series with the gaps shaded."""
    rows = []
    for label, log in ctx.logs:
        rows.append([
            label, log.source if log.source.startswith("<") else Path(log.source).name,
            log.format, str(len(log)), format_duration(log.duration), f"{log.fs:.6g}",
            ", ".join(log.channels), missing_text(log.issues), str(log.issues.total),
            str(log.issues),
        ])
    doc.table(
        ["log", "source", "format", "samples", "duration", "rate [Hz]", "channels",
         "samples missing", "records skipped", "parse issues"],
        rows,
    )
    doc.p("Duration is the true length of the recording (grid rows, missing samples "
          "included); a missing sample is left out of every statistic, never spliced over.")
    if ctx.one_log:
        doc.p("One log given: the statistics and the Allan analysis both use it.")
    for label, log in ctx.logs:
        which = _which(label)
        if log.issues.share_missing > GAP_WARN_SHARE:
            doc.p(f"**Warning**: {100 * log.issues.share_missing:.3g} % of {which} is "
                  f"missing ({missing_text(log.issues)}); the statistics use the samples "
                  "that are there.")
        if len(log.gaps):
            top = log.gaps.largest(GAP_ROWS)
            t0 = log.gaps.t0
            doc.table(
                ["start [s from first sample]", "duration [s]", "samples"],
                [[format_number(a - t0), format_number(d), str(k)] for a, d, k in top.rows()],
                caption=f"Largest gaps of {which} ({len(log.gaps)} in all)",
            )
    for label, log in ctx.logs:
        shade = [(a - log.gaps.t0, d) for a, d, _k in log.gaps.largest(GAP_SHADE).rows()]
        for sensor in SAMPLE_SENSORS:
            y = getattr(log, sensor)
            if y is None:
                continue
            unit = CHANNELS[sensor][1]
            which = _which(label)
            fig = plot.time_series(y, log.fs, title=f"{sensor} ({which})", unit=unit,
                                   gaps=shade)
            ctx.add_figure(doc, fig, f"timeseries_{label}_{sensor}",
                           f"Time series of {which}: {sensor} [{unit}] (min/max per pixel)")


def sample_statistics(ctx: Context, doc: Doc) -> None:
    """Mean, std, variance, min, max and drift per channel of the short log."""
    desc = ctx.description
    doc.p(f"Short log, {desc.n} samples at {format_number(desc.fs)} Hz; std and variance "
          "with ddof = 1; drift is the least-squares slope against time.")
    doc.table(
        ["channel", "unit", "mean", "std", "variance", "min", "max", "drift [unit/h]"],
        [[r["name"], r["unit"], *(format_number(r[k]) for k in
          ("mean", "std", "var", "min", "max", "drift_per_hour"))] for r in desc.rows()],
        caption="Sample statistics (short log)",
    )


def distribution_fits(ctx: Context, doc: Doc) -> None:
    """Normal fit and normality statistics per axis of the short log, with histograms."""
    doc.p("Normal fit by maximum likelihood; histogram bins are whole multiples of the "
          "detected quantization step (or of the level spacing, where the sensor uses only "
          "some of the printed grid), centred on the levels. With this many samples any "
          "real sensor fails a normality test: read KS D, A², skewness and excess kurtosis "
          "as sizes of the departure from normal.")
    rows = []
    for sensor, per_axis in ctx.sensor_distributions.items():
        unit = CHANNELS[sensor][1]
        for name, d in per_axis.items():
            rows.append([
                name, unit, format_number(d.step) if d.step else "—",
                format_number(d.level_spacing) if d.level_spacing else "—",
                str(len(d.counts)), format_number(d.mu, d.mu_std),
                format_number(d.sigma, d.sigma_std), *(numbers.cell(v) for v in (
                    d.ks_statistic, d.ks_pvalue, d.ad_statistic, d.skewness,
                    d.excess_kurtosis)),
            ])
        fig = plot.histograms(list(per_axis.values()),
                              title=f"{sensor} distribution (short log)", unit=unit)
        ctx.add_figure(doc, fig, f"hist_{sensor}",
                       f"Histogram of {sensor} with the fitted normal density")
    doc.table(
        ["channel", "unit", "quantization step", "level spacing", "bins", "μ", "σ", "KS D",
         "KS p", "AD A²", "skewness", "excess kurtosis"],
        rows,
        caption="Distribution fits (short log)",
    )


def attitude(ctx: Context, doc: Doc) -> None:
    """Yaw, pitch and roll of the short log: statistics, time series, histograms
    with the normal fit, and why a filter's output need not be normal."""
    angles = ctx.attitude
    dists = ctx.attitude_distributions
    doc.p("Yaw, pitch and roll are the output of the sensor's attitude filter, not "
          "measurements: the filter blends the gyro, accelerometer and magnetometer, so its "
          "output is smoothed, correlated from sample to sample and follows slow magnetic "
          "disturbances (yaw most of all). Nothing makes it normal; the normal fit "
          "describes its spread, and the goodness-of-fit figures say how far from normal it "
          "is. Yaw is taken about its circular mean (whole turns removed), so a heading "
          "near ±180° is not split into two clusters 360° apart; its mean is given in "
          "(−180°, 180°].")
    rows = []
    for name, v in angles.items():
        ok = v[np.isfinite(v)]
        mean = float(ok.mean())
        if name == "yaw":  # back into (−180°, 180°]
            mean = (mean + 180.0) % 360.0 - 180.0
            mean = 180.0 if mean == -180.0 else mean
        d = dists[name]
        rows.append([name, "deg", format_number(mean), format_number(float(ok.std(ddof=1))),
                     format_number(float(ok.var(ddof=1))), format_number(float(ok.min())),
                     format_number(float(ok.max())), *(format_number(x) for x in (
                         d.ks_statistic, d.ks_pvalue, d.ad_statistic, d.skewness,
                         d.excess_kurtosis))])
    doc.table(
        ["angle", "unit", "mean", "std", "variance", "min", "max", "KS D", "KS p", "AD A²",
         "skewness", "excess kurtosis"],
        rows,
        caption="Attitude statistics and normality (short log; std and variance with ddof = 1)",
    )
    names = list(angles)
    stacked = np.column_stack([angles[n] for n in names])
    fig = plot.time_series(stacked, ctx.short.fs, title="attitude (short log)", unit="deg",
                           names=names)
    ctx.add_figure(doc, fig, "timeseries_attitude",
                   "Yaw (about its circular mean), pitch and roll of the short log [deg]")
    fig = plot.histograms([dists[n] for n in names], title="attitude distribution (short log)",
                          unit="deg", names=names)
    ctx.add_figure(doc, fig, "hist_attitude",
                   "Histograms of yaw, pitch and roll with the fitted normal density")


def allan_deviation(ctx: Context, doc: Doc) -> None:
    """Per sensor of the long log: the Allan deviation with the fitted model (figure)
    and the table of τ, terms, σ and confidence interval per axis."""
    allan, models = ctx.allan, ctx.models
    doc.p(f"Overlapping Allan deviation of the {'only' if ctx.one_log else 'long'} log, "
          f"{ctx.taus_per_decade} taus per decade, error bars at the "
          f"{next(iter(allan.values())).confidence:.1%} confidence level (χ² with Greenhall "
          "EDF)." if allan else "The log has no gyro or accelerometer channel.")
    for sensor, r in allan.items():
        unit = CHANNELS[sensor][1]
        model = models.get(sensor)
        fig = plot.allan(r, model, title=f"{sensor} Allan deviation", unit=unit)
        doc.h(3, sensor)
        ctx.add_figure(doc, fig, f"adev_{sensor}",
                       f"Allan deviation of {sensor} [{unit}]"
                       + (" with the fitted model, its terms, the read-off points and the "
                          "data/model ratio" if model is not None else ""))
        rows = []
        for i, tau in enumerate(r.taus):
            row = [format_number(tau), terms_used(r, i)]
            for j in range(r.dev.shape[1]):
                row += [format_number(r.dev[i, j]),
                        f"{format_number(r.ci_low[i, j])} – {format_number(r.ci_high[i, j])}"]
            rows.append(row)
        header = ["τ [s]", "n"]
        for a in axis_names(r.dev.shape[1]):
            header += [f"σ {a} [{unit}]", f"CI {a}"]
        doc.table(header, rows, caption=f"Allan deviation of {sensor}")


def noise_coefficients(ctx: Context, doc: Doc) -> None:
    """The fitted noise model per sensor: datasheet table and one sentence per axis."""
    doc.p("Fit of σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)B² + K²τ/3 + R²τ²/2 (IEEE Std 952) "
          "plus up to three first-order Gauss–Markov bias terms, on ln σ², each octave of τ "
          "weighted alike, the terms chosen by BIC; standard uncertainties from the fit "
          "(docs/noise.md). Read-offs: N on the −½ line at τ = 1 s, B = σ_min/0.664.")
    for sensor, m in ctx.models.items():
        header, rows = datasheet_rows(m, sensor)
        doc.table(header, rows, caption=f"{sensor} noise coefficients per axis")
        for sentence in model_sentences(m, sensor):
            doc.p(sentence)


def datasheet_comparison(ctx: Context, doc: Doc) -> None:
    """Measured vs the datasheet named by ``spec``, with ratio and verdict."""
    if ctx.spec is None:
        doc.p("No datasheet given (`--spec`).")
        return
    header, rows = comparison_rows(ctx.models, ctx.spec)
    doc.table(header, rows, caption=f"Measured vs datasheet ({ctx.spec})")

