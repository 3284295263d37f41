"""The report's sections, in reading order: one function ``(ctx, doc) -> None`` each,
writing its text, tables and figures below the heading that :mod:`.build` numbers.

A section reads the logs and the analyses from the :class:`~.context.Context` (which
computes each analysis once, on first use) and adds its figures through it.
"""

from __future__ import annotations

import warnings
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from imunoise import allan as _allan
from imunoise import display, noise, plot, stats, units
from imunoise._analysis.events import rms_ratio
from imunoise._support import stream as _stream
from imunoise._support import warn as _warn
from imunoise._support.schema import CHANNELS, SAMPLE_SENSORS, axis_names
from imunoise.display import format_value, percent
from imunoise.planner import fit_line
from imunoise.report.formatting import (
    docs_link,
    format_duration,
    format_number,
    missing_text,
    terms_used,
    unit_text,
)
from imunoise.report.model_text import (
    comparison_rows,
    datasheet_rows,
    lab_rows,
    model_sentences,
    units_of,
)

if TYPE_CHECKING:
    from imunoise.report.context import Context
    from imunoise.report.document import Doc

__all__ = [
    "GAP_ROWS",
    "GAP_SHADE",
    "GAP_WARN_SHARE",
    "allan_deviation",
    "attitude",
    "datasheet_comparison",
    "distribution_fits",
    "dynamic_allan",
    "events_section",
    "long_log_events",
    "noise_coefficients",
    "one_mount",
    "power_spectral_density",
    "recording_summary",
    "sample_statistics",
    "thermal_section",
    "warmup_section",
]

#: Share of missing samples above which the report prints a warning line.
GAP_WARN_SHARE = 0.01
#: Gaps listed in the summary table / shaded on the time plots (the largest).
GAP_ROWS = 10
GAP_SHADE = plot.SHADED_GAPS


def _unit(sensor: str) -> str:
    """Unit of a sensor's samples as the report writes it (``"m/s²"``)."""
    return unit_text(CHANNELS[sensor][1])


def _unit_of(channel: str) -> str:
    """Unit of a channel named like ``"gyro X"``; "" for a name that is no log channel's."""
    sensor = channel.split(" ")[0]
    return _unit(sensor) if sensor in CHANNELS else ""


def _which(label: str) -> str:
    """How the text names a log: "the log" (one log for both) or "the short log"."""
    return "the log" if label == "both" else f"the {label} log"


def _short(ctx: Context) -> str:
    """How the text names the log of the statistics: "the log" when one log is given
    (there is no long log to tell it from), else "the short log"."""
    return "the log" if ctx.one_log else "the short log"


def _tag(ctx: Context, extra: str = "") -> str:
    """A caption's or title's note of which log: " (short log)", nothing for one
    log; ``extra`` joins it ("; std …")."""
    parts = ([] if ctx.one_log else ["short log"]) + ([extra] if extra else [])
    return f" ({'; '.join(parts)})" if parts else ""


def _off_scale(dists) -> str:
    """The caption sentence for histograms that count samples beyond their range
    ("" when none of ``dists`` has any)."""
    if not any(d.off_scale_below or d.off_scale_above for d in dists):
        return ""
    return (". The numbers in a panel's upper corners (\"← 5\", \"7 →\") count the samples "
            "beyond the plotted range, below it on the left and above it on the right; "
            "the fit and the tables use them.")


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
            unit = _unit(sensor)
            which = _which(label)
            fig = plot.time_series(y, log.fs, title=f"{sensor} ({which})", unit=unit,
                                   gaps=shade)
            ctx.add_figure(doc, fig, f"timeseries_{label}_{sensor}",
                           f"Time series of {which}: {sensor} [{unit}] (min/max per pixel)")
            _stream.release(y)  # a memory map's pages, before the next sensor's


def sample_statistics(ctx: Context, doc: Doc) -> None:
    """Mean, std, variance, min, max and drift per channel of the short log."""
    desc = ctx.description
    doc.p(f"{_short(ctx)[4:].capitalize()}, {desc.n} samples at {format_number(desc.fs)} Hz; "
          "std and variance with ddof = 1; drift is the least-squares slope against time.")
    doc.table(
        ["channel", "unit", "mean", "std", "variance", "min", "max", "drift [unit/h]"],
        [[r["name"], unit_text(r["unit"]), *(format_number(r[k]) for k in
          ("mean", "std", "var", "min", "max", "drift_per_hour"))] for r in desc.rows()],
        caption=f"Sample statistics{_tag(ctx)}",
    )


def distribution_fits(ctx: Context, doc: Doc) -> None:
    """Normal fit and normality statistics per axis of the short log, with histograms."""
    doc.p("Normal fit by maximum likelihood; histogram bins are whole multiples of the "
          "detected quantization step (or of the level spacing, where the sensor uses only "
          "some of the printed grid), centred on the levels. With this many samples any "
          "real sensor fails a normality test: read KS D, A², skewness and excess kurtosis "
          "as sizes of the departure from normal.")
    rows, bins = [], []
    for sensor, per_axis in ctx.sensor_distributions.items():
        unit = _unit(sensor)
        for name, d in per_axis.items():
            rows.append([
                name, unit, format_number(d.mu, d.mu_std), format_number(d.sigma, d.sigma_std),
                *(display.cell(v) for v in (d.ks_statistic, d.ks_pvalue, d.ad_statistic,
                                            d.skewness, d.excess_kurtosis)),
            ])
            bins.append([name, unit, format_number(d.step) if d.step else "—",
                         format_number(d.level_spacing) if d.level_spacing else "—",
                         str(len(d.counts))])
        fig = plot.histograms(list(per_axis.values()),
                              title=f"{sensor} distribution{_tag(ctx)}", unit=unit)
        ctx.add_figure(doc, fig, f"hist_{sensor}",
                       f"Histogram of {sensor} with the fitted normal density"
                       + _off_scale(per_axis.values()))
    doc.table(
        ["channel", "unit", "μ", "σ", "KS D", "KS p", "AD A²", "skewness", "excess kurtosis"],
        rows,
        caption=f"Distribution fits{_tag(ctx)}",
    )
    doc.table(["channel", "unit", "quantization step", "level spacing", "bins"], bins,
              caption=f"Histogram bins{_tag(ctx)}: the sensor's quantization step and the "
                      "spacing of the levels it uses")


def attitude(ctx: Context, doc: Doc) -> None:
    """Yaw, pitch and roll of the short log: statistics, time series, histograms
    with the normal fit, and why a filter's output need not be normal."""
    dists = ctx.attitude_distributions  # first: it reads the angles on its own
    angles = ctx.attitude()
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
        ok = v if np.isfinite(v).all() else v[np.isfinite(v)]
        mean = float(ok.mean())
        if name == "yaw":  # back into (−180°, 180°]
            mean = stats.heading(mean)
        d = dists[name]
        var = ok.var(ddof=1)  # std is its square root (numpy's std computes it so)
        rows.append([name, "deg", format_number(mean), format_number(float(np.sqrt(var))),
                     format_number(float(var)), format_number(float(ok.min())),
                     format_number(float(ok.max())), *(format_number(x) for x in (
                         d.ks_statistic, d.ks_pvalue, d.ad_statistic, d.skewness,
                         d.excess_kurtosis))])
    doc.table(
        ["angle", "unit", "mean", "std", "variance", "min", "max", "KS D", "KS p", "AD A²",
         "skewness", "excess kurtosis"],
        rows,
        caption="Attitude statistics and normality"
                + _tag(ctx, "std and variance with ddof = 1"),
    )
    names = list(angles)
    fig = plot.time_series([angles[n] for n in names], ctx.short.fs,  # not stacked: a copy
                           title=f"attitude{_tag(ctx)}", unit="deg", names=names)
    ctx.add_figure(doc, fig, "timeseries_attitude",
                   f"Yaw (about its circular mean), pitch and roll of {_short(ctx)} [deg]")
    fig = plot.histograms([dists[n] for n in names], title=f"attitude distribution{_tag(ctx)}",
                          unit="deg", names=names)
    ctx.add_figure(doc, fig, "hist_attitude",
                   "Histograms of yaw, pitch and roll with the fitted normal density"
                   + _off_scale(dists.values()))


def allan_deviation(ctx: Context, doc: Doc) -> None:
    """Per sensor of the long log: the Allan deviation with the fitted model (figure)
    and the table of τ, terms, σ and confidence interval per axis."""
    allan, models = ctx.allan, ctx.models
    doc.p(f"Overlapping Allan deviation of the {'only' if ctx.one_log else 'long'} log, "
          f"{ctx.taus_per_decade} taus per decade, error bars at the "
          f"{percent(next(iter(allan.values())).confidence, digits=1)} confidence level "
          "(χ² with Greenhall EDF)." if allan else "The log has no gyro or accelerometer channel.")
    for sensor, r in allan.items():
        unit = _unit(sensor)
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
        doc.table(header, rows, caption=f"Allan deviation of {sensor}: every τ", collapsed=True)


def noise_coefficients(ctx: Context, doc: Doc) -> None:
    """The fitted noise model per sensor: datasheet table and one sentence per axis."""
    doc.p("Fit of σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)B² + K²τ/3 + R²τ²/2 (IEEE Std 952) "
          "plus up to three first-order Gauss–Markov bias terms, up to two tones (sinusoids, "
          "IEEE 952 Annex C), a resonance (a damped oscillator) and a bounded motion of the "
          "mount, on ln σ², each octave of τ weighted alike, the terms chosen by BIC; "
          "standard uncertainties from the fit "
          f"({docs_link('noise', 'noise model')}). Read-offs: N on the −½ line at τ = 1 s, "
          "B = σ_min/0.664.")
    if ctx.models:
        header, rows = lab_rows(ctx.models, ctx.spec, ctx.units)
        doc.table(header, rows, caption="Lab table: N, B and K per axis"
                  + (f" beside the datasheet ({ctx.spec}), in one unit" if ctx.spec else "")
                  + "; ± the fit's standard uncertainty (1σ)")
    for sensor, m in ctx.models.items():
        header, rows = datasheet_rows(m, sensor, ctx.units, symbols=True)
        doc.table(header, rows, caption=f"{sensor} noise coefficients per axis")
        # the samples' resolution, read off the short log's levels (the same sensor)
        per_axis = ctx.sensor_distributions.get(sensor, {})
        steps = ([d.step for d in per_axis.values()] if len(per_axis) == m.channels
                 else None)
        for sentence in model_sentences(m, sensor, ctx.units, steps=steps):
            doc.p(sentence)
        r = ctx.allan.get(sensor)
        if r is not None:  # how long to record for the coefficients (imunoise plan)
            line = fit_line(m, r.fs, r.n_samples / r.fs).replace("plan:", f"Plan ({sensor}):")
            if "resolves" in line:  # what its ± are: not the table's
                line += (" (95 % intervals of a read-off of the Allan curve in a record "
                         "this long; the ± in the tables above are the fit's 1σ, and the "
                         "datasheet comparison uses the larger of the two)")
            doc.p(line + ".")


def datasheet_comparison(ctx: Context, doc: Doc) -> None:
    """Measured vs the datasheet named by ``spec``, with ratio and verdict."""
    if ctx.spec is None:
        doc.p("No datasheet given (`--spec`).")
        return
    seconds = {sensor: r.n_samples / r.fs for sensor, r in ctx.allan.items()}
    header, rows = comparison_rows(ctx.models, ctx.spec, ctx.units, seconds=seconds)
    doc.table(header, rows, caption=f"Measured vs datasheet ({ctx.spec})")
    doc.p("The ± of a measured value here is its standard uncertainty (1σ): the larger of "
          "the fit's (the tables above) and what the Allan deviation at the τ the term is "
          "read at allows from a record this long (the plan lines' uncertainty, at "
          "68.3 %). A limit passes when the value plus 1.645 of it (one-sided 95 %) is "
          "below the limit, fails when the value minus 1.645 of it is above, and is "
          "\"not significant\" in between; a typical value is no limit.")



# -- spectrum and dynamic ADEV ---------------------------------------------------------

#: Relative difference between the PSD and ADEV-fit N that the report explains.
N_AGREEMENT = 0.05
#: Shortest long log that gets a dynamic-ADEV map (its tenth is the window).
DYNAMIC_MIN_SECONDS = 600.0


def _n_remark(s, j: int, ratio: float) -> str:
    """Why the PSD's N and the ADEV fit's N differ by more than :data:`N_AGREEMENT`."""
    if not np.isfinite(ratio):
        return "the ADEV fit resolves no white noise"
    if abs(ratio - 1) <= N_AGREEMENT:
        return f"agree within {percent(N_AGREEMENT)}"
    lines = s.lines[j]
    if ratio < 1 and lines.size:
        where = ", ".join(f"{v:.3g}" for v in lines[:3])
        return (f"spectral lines near {where} Hz, left out of the PSD read-off, add to the "
                "ADEV's short taus")
    p = np.reshape(s.psd, (len(s.f), -1))[:, j]
    top = float(np.reshape(s.band, (-1, 2))[j, 1])
    white = float(np.atleast_1d(s.white)[j])
    above = s.f > top
    if ratio < 1 and above.any() and p[above].max() > 3 * white:
        peak = float(s.f[above][np.argmax(p[above])])
        return (f"a spectral line near {peak:.3g} Hz, above the white band, adds to the "
                "ADEV's short taus")
    if above.any() and p[above][-1] < 0.7 * white:
        return (f"the sensor's low-pass filter bends the spectrum above {top:.3g} Hz and the "
                "ADEV fit shares the white level with Gauss–Markov terms")
    return "the ADEV fit shares the white level with its other terms (see the figure)"


def power_spectral_density(ctx: Context, doc: Doc) -> None:
    """Per sensor of the short log: the PSD with its white band, N read-off and the
    long log's noise model overlaid; N from the PSD vs N from the ADEV fit, and why
    they differ where they do."""
    from imunoise import spectrum

    doc.p("One-sided Welch PSD (Hann, 50 % overlap) of the "
          f"{'only' if ctx.one_log else 'short'} log, log-binned, with its 68.3 % band. N is "
          "read off the white region chosen automatically (below a sensor filter's bend or a "
          "spectral line) as √(level/2), the IEEE convention of the noise model (the "
          "one-sided ASD level is √2·N); the noise model fitted to the same log's Allan "
          "deviation is drawn over it and its N compared "
          f"({docs_link('spectrum')}).")
    for sensor in ("gyro", "accel"):
        y = getattr(ctx.short, sensor)
        if y is None:
            continue
        if np.count_nonzero(_stream.present_rows(y)) < 256:
            continue
        _stream.release(y)
        if ctx.one_log:  # the models' own spectrum
            s = ctx.spectra.get(sensor)
            if s is None:
                continue
        else:
            try:  # segments with a missing sample are left out
                s = spectrum.psd(y, ctx.short.fs)
            except ValueError:  # no unbroken stretch of 16 samples
                continue
        model = ctx.models.get(sensor) if ctx.one_log else noise.fit(
            _stream.adev(y, ctx.short.fs, ctx.taus_per_decade, ctx.streamed, ctx.block),
            warn_coverage=False, spectrum=s)
        _stream.release(y)
        unit = _unit(sensor)
        doc.h(3, sensor)
        ctx.add_figure(doc, plot.spectrum(s, model, unit=unit, title=f"{sensor} PSD"),
                       f"psd_{sensor}", f"PSD of {sensor} [({unit})²/Hz], white band shaded, "
                       "N read-off (black)" + (" and the noise model" if model else ""))
        fitted = (model.value("N") if model is not None
                  else np.full(s.channels, np.nan))
        n, n_std = np.atleast_1d(s.N), np.atleast_1d(s.N_std)
        band = np.reshape(s.band, (-1, 2))
        # N in the unit of every other table of the report
        chosen = units.unit_choice(units_of(ctx.units, sensor), sensor)
        n_unit = units.unit_info("N", chosen.get("N"), sensor)
        in_n_unit = partial(units.convert, term="N", unit=n_unit.name, sensor=sensor)
        rows = []
        for j, a in enumerate(axis_names(s.channels)):
            with np.errstate(divide="ignore", invalid="ignore"):
                ratio = n[j] / fitted[j] if fitted[j] > 0 else np.nan
            rows.append([a, format_value(in_n_unit(n[j]), in_n_unit(n_std[j])),
                         f"{band[j, 0]:.3g} – {band[j, 1]:.3g}",
                         format_value(in_n_unit(fitted[j])), f"{ratio:.3g}",
                         _n_remark(s, j, ratio)])
        doc.table(["axis", f"N PSD [{n_unit.label}]", "white band [Hz]",
                   f"N ADEV fit [{n_unit.label}]", "PSD/ADEV", "remark"], rows,
                  caption=f"{sensor}: noise density from the spectrum and from the Allan fit"
                  + (f" ({s.segments_skipped} of {s.segments + s.segments_skipped} Welch "
                     "segments hold a missing sample and are left out)"
                     if s.segments_skipped else ""))


def dynamic_allan(ctx: Context, doc: Doc) -> None:
    """Per sensor of the long log: the dynamic ADEV heat map and one sentence on what it
    shows (stationary, or where the noise departs)."""
    from imunoise import dynamic

    log = ctx.long
    for sensor in ("gyro", "accel"):
        y = getattr(log, sensor)
        if y is None:
            continue
        d = dynamic.dynamic_adev(y, log.fs)
        _stream.release(y)
        st = d.stationarity
        doc.h(3, sensor)
        ctx.add_figure(doc, plot.dynamic(d, title=f"{sensor} dynamic Allan deviation"),
                       f"dadev_{sensor}", f"ADEV of {format_duration(d.window)} windows every "
                       f"{format_duration(d.step)} over the whole-record ADEV")
        share = percent(float(np.max(st.outside)))
        if st.stationary:
            doc.p(f"The {sensor} noise is stationary along the log: no stretch departs from "
                  f"the typical level (1 % false-alarm rate), and {share} of the window "
                  f"intervals exclude the whole-record ADEV (about "
                  f"{percent(st.expected_outside)} expected).")
            continue
        names = axis_names(d.channels)
        where = "; ".join(
            f"{format_duration(v.start)} – {format_duration(v.end)} ({names[v.channel]}, "
            f"ADEV ×{display.rounded(v.ratio, v.ratio_std)})" for v in st.intervals[:6])
        more = f" and {len(st.intervals) - 6} more" if len(st.intervals) > 6 else ""
        doc.p(f"The {sensor} noise is not stationary: it departs from its typical level at "
              f"{where}{more} (from the first sample; {share} of the window intervals exclude "
              f"the whole-record ADEV, about {percent(st.expected_outside)} expected).")


# --- events, warm-up and temperature (issue 13) -------------------------------------

#: Events listed in the report's table (the largest by peak).
EVENT_ROWS = 20
#: Shortest long log whose warm-up the report examines, s.
WARMUP_MIN_DURATION = 1200.0
#: Smallest temperature range (°C) of a log the report fits bias against.
THERMAL_MIN_RANGE = 0.5


def events_section(ctx: Context, doc: Doc) -> None:
    """Events of the short log: table, time series with them marked, statistics
    and normal fits with and without them."""
    found, log = ctx.events, ctx.short
    doc.p(f"Spikes (Hampel test) and bursts (sliding energy, window "
          f"{format_duration(found.window / found.fs)}) per channel of {_short(ctx)}, "
          f"thresholds set for {format_value(found.false_alarm, digits=1)} false events per "
          "sample and channel "
          f"(measured on white noise: {docs_link('events')}). "
          f"{len(found)} events cover {100 * found.share:.3g} % of the samples.")
    # with --trim auto on one log the short log starts at the settle point: times
    # are given from the first sample of the recording
    offset = (len(ctx.untrimmed) - len(log)) / log.fs if ctx.one_log and ctx.untrimmed else 0.0
    order = np.argsort(found.peak)[::-1][:EVENT_ROWS]
    within = found.within

    def kind(i: int) -> str:
        j = within[i]
        return found.kind[i] if j < 0 else (
            f"{found.kind[i]} inside the event from {format_number(found.start[j] + offset)} s")

    # the search's baselines: the same numbers as found.rms_ratio(log), no medians again
    loud = rms_ratio(found, log, ctx.event_search[1])
    column = {name: j for j, name in enumerate(found.names)}

    def loudest(i: int) -> str:
        """RMS ratio of the event's loudest channel, and which."""
        ratios = {c: loud[i, column[c]] for c in found.channels[i]}
        c = max(ratios, key=lambda k: np.nan_to_num(ratios[k]))
        return f"{ratios[c]:.2g} ({c})"

    doc.p("The evidence per event: its peak in sigmas of the quiet noise, its length, and "
          "how much louder it is than the quiet record (RMS over the event ÷ RMS outside "
          "every event, on its loudest channel; 1 = no louder; energy is the square). A "
          "burst is flagged only where its energy is significantly above the quiet "
          "noise's.")
    doc.table(
        ["start [s]", "end [s]", "duration [s]", "kind", "channels", "peak [σ]",
         "RMS ÷ quiet RMS"],
        [[format_number(found.start[i] + offset), format_number(found.end[i] + offset),
          display.cell(found.duration[i], digits=3), kind(i), ", ".join(found.channels[i]),
          f"{found.peak[i]:.3g}", loudest(i)]
         for i in sorted(order)],
        caption=f"Events of {_short(ctx)} ({min(len(found), EVENT_ROWS)} largest of "
                f"{len(found)})",
    )
    rows = []
    for sensor in ("gyro", "accel"):
        y = getattr(log, sensor)
        if y is None:
            continue
        fig = plot.events(y, found, log.fs, title=f"{sensor} with events{_tag(ctx)}",
                          unit=_unit(sensor))
        ctx.add_figure(doc, fig, f"events_{sensor}",
                       f"{sensor} of {_short(ctx)}, events shaded, peak in sigmas above")
        inside = found.mask

        def quiet(j, y=y, inside=inside):
            # a channel at a time, not the sensor: streamed, its column read is ours,
            # and the events are made missing in it in place
            col = _stream.column(y, j, ctx.block) if ctx.streamed else y[:, j]
            # without a missing sample np.std is np.nanstd's arithmetic (the same bits)
            # without its copy and masks: a third of the time
            std = np.nanstd(col, ddof=1) if np.isnan(col).any() else np.std(col, ddof=1)
            z = col if ctx.streamed else np.array(col, dtype=np.float64)
            del col
            z[inside] = np.nan  # found.exclude(col)
            std_without = np.nanstd(z, ddof=1)
            z = z[np.isfinite(z)]
            return std, std_without, stats.distribution(z, overwrite_input=True)

        per_axis = _stream.each_channel(quiet, y.shape[1])
        kept = [without for _, _, without in per_axis]
        for j, axis in enumerate(axis_names(y.shape[1])):
            with_ = list(ctx.sensor_distributions[sensor].values())[j]  # the same samples
            std, std_without, without = per_axis[j]
            rows.append([f"{sensor} {axis}", *(display.cell(v) for v in (
                std, std_without, with_.excess_kurtosis,
                without.excess_kurtosis, with_.ks_statistic, without.ks_statistic))])
        _stream.release(y)
        fig = plot.histograms(kept, title=f"{sensor} without events{_tag(ctx)}",
                              unit=_unit(sensor))
        ctx.add_figure(doc, fig, f"hist_{sensor}_no_events",
                       f"Histogram of {sensor} with the events left out, fitted normal"
                       + _off_scale(kept))
    doc.table(["channel", "std", "std without events", "excess kurtosis",
               "without events", "KS D", "without events"], rows,
              caption="Statistics and normal fits with and without the events"
                      + _tag(ctx))
    doc.p("`imunoise.events(log).exclude(log)` makes the events missing samples; the "
          "Allan statistics then skip every term that touches one "
          f"({docs_link('gaps')}).")


#: Padding (s) around each event of the long log when it is left out of the Allan analysis.
EVENT_PAD = 0.2


def _decade_taus(result) -> np.ndarray:
    """The report grid's taus nearest to each power of ten it spans, where the
    Allan deviation has at least 5 degrees of freedom."""
    edf = np.reshape(result.edf, (len(result.taus), -1)).min(axis=1)
    usable = result.taus[edf >= 5]
    if not usable.size:
        return usable
    decades = 10.0 ** np.arange(np.ceil(np.log10(usable[0])), np.floor(np.log10(usable[-1])) + 1)
    picked = [usable[np.argmin(np.abs(np.log(usable / d)))] for d in decades]
    return np.unique(picked) if picked else usable[[0, -1]]


def long_log_events(ctx: Context, doc: Doc) -> None:
    """Events of the long log and what they do to its Allan deviation: with and
    without them (as missing samples) at a few taus; which result the noise model
    used."""
    found, log = ctx.long_events, ctx.long
    kinds = (f"{found.kind.count('burst')} bursts, {found.kind.count('spike')} spikes")
    doc.p(f"The {'only' if ctx.one_log else 'long'} log holds {len(found)} "
          f"event{'' if len(found) == 1 else 's'} ({kinds}, "
          f"{100 * found.share:.3g} % of the samples; detector as in the events section). "
          f"Left out as missing samples (±{format_duration(EVENT_PAD)}), the gap-aware Allan "
          "statistics skip every term that touches one. The Allan deviation with and "
          "without them:")
    rows, changed, short = [], [], []
    for sensor, with_ in ctx.allan.items():
        taus = _decade_taus(with_)
        if not taus.size:
            continue
        y = getattr(log, sensor)
        both = _stream.adev(y, log.fs, taus, ctx.streamed, ctx.block)
        _stream.release(y)
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            if ctx.streamed:  # a column at a time, the events made missing in it
                inside = found.padded_mask(EVENT_PAD)

                def excluded(j: int, y=y, inside=inside) -> np.ndarray:
                    col = _stream.column(y, j, ctx.block)
                    col[inside] = np.nan
                    return col

                without = _allan.adev_by_column(excluded, y.shape[1], log.fs, taus=both.taus)
            else:
                without = _allan.adev(found.exclude(y, pad=EVENT_PAD), log.fs, taus=both.taus)
        # "taus dropped" here is about the taus this section picked, in adev's words
        # (x, NaN): said below in the report's (the events left out); the rest as is
        for w in said:
            if "taus dropped" not in str(w.message):
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        if without.taus.size < both.taus.size:
            short.append((sensor, both.taus, without.taus))
        # the taus both have (the grid's own, whole samples; gaps may cost the longest)
        taus, a, b = np.intersect1d(both.taus, without.taus, return_indices=True)
        dev, lo, hi = (np.reshape(v, (len(both.taus), -1))[a] for v in (
            both.dev, both.ci_low, both.ci_high))
        dev_out = np.reshape(without.dev, (len(without.taus), -1))[b]
        _stream.release(getattr(log, sensor))
        for j, axis in enumerate(axis_names(dev.shape[1])):
            for i, tau in enumerate(taus):
                outside = not lo[i, j] <= dev_out[i, j] <= hi[i, j]
                if outside:
                    changed.append(f"{sensor} {axis} at {format_duration(tau)}")
                rows.append([f"{sensor} {axis}", _unit(sensor), format_duration(tau),
                             display.cell(dev[i, j]), display.cell(dev_out[i, j]),
                             f"{dev_out[i, j] / dev[i, j]:.3g}" if dev[i, j] > 0 else "—",
                             "yes" if outside else "no"])
    level = f"{100 * next(iter(ctx.allan.values())).confidence:.3g} %"
    if short:
        note = _events_cut_note(ctx, found, short)
        doc.p(note[0].upper() + note[1:] + ".")
        _warn.warn(note)
    doc.table(["channel", "unit", "τ", "ADEV", "without events", "ratio",
               f"outside the {level} interval"], rows,
              caption=f"Allan deviation of the {'only' if ctx.one_log else 'long'} log with "
                      "and without its events")
    if changed:
        doc.p(f"The events change the Allan deviation beyond its {level} confidence interval at "
              f"{len(changed)} of {len(rows)} points ({', '.join(changed[:6])}"
              f"{', …' if len(changed) > 6 else ''}). The noise coefficients above are "
              "those of the log as recorded; for the sensor's own noise, analyse "
              "`imunoise.events(log).exclude(log)` (`imunoise.adev` skips the missing "
              "samples).")
    else:
        doc.p(f"Leaving them out moves no point outside the {level} confidence interval: "
              "the Allan analysis above holds with or without them.")


def _events_cut_note(ctx: Context, found, short) -> str:
    """Why the comparison without the events stops short of the longest taus: the
    events cut the log into stretches too short for them (not the log's length,
    which the taus were picked to fit)."""
    mask = found.padded_mask(EVENT_PAD)
    gaps = ctx.long.issues.samples_missing
    edges = np.concatenate(([-1], np.flatnonzero(mask), [mask.size]))
    stretch = (int(np.diff(edges).max()) - 1) / ctx.long.fs
    sensors = ", ".join(sensor for sensor, _all, _kept in short)
    _sensor, wanted, kept = short[0]
    which, arg = ("the log", "LOG") if ctx.one_log else ("the long log", "LONG_LOG")
    return (
        f"the Allan deviation of {which} without its events stops at τ = "
        f"{format_duration(kept.max())} ({sensors}; "
        f"{wanted.size - kept.size} of the {wanted.size} compared taus dropped): the "
        f"{len(found)} events left out (±{format_duration(EVENT_PAD)} each, "
        f"{100 * found.share:.3g} % of the samples"
        + (f", besides the log's {gaps} missing samples" if gaps else "")
        + f") leave no event-free stretch longer than {format_duration(stretch)}, too "
        f"short for τ = {format_duration(wanted[kept.size:].min())}; the log's length "
        f"is not the limit. A log ({arg}) with fewer disturbances reaches further; "
        f"`imunoise events {arg}` lists them"
    )


def warmup_section(ctx: Context, doc: Doc) -> None:
    """Bias over time of the long log, the fitted transient and the settle point, and
    what ``--trim auto`` cut."""
    w = ctx.warmup
    doc.p(f"Bias of the {'only' if ctx.one_log else 'long'} log over time "
          f"({format_duration(w.block)} means), fitted with b∞ + A·exp(−t/τ) per channel; "
          f"a transient counts when it explains the means better than the sensor's own "
          f"stationary noise does (parametric bootstrap of its noise model, p < {w.alpha:g}) "
          "and has settled when what is left of it is below "
          "the channel's Allan-deviation floor "
          f"({docs_link('events')}).")
    doc.table(
        ["channel", "unit of A and tolerance", "A", "τ", "p", "tolerance", "settled after"],
        [[r["name"], _unit_of(r["name"]),
          format_number(r["amplitude"], r["amplitude_std"]) if r["significant"] else "—",
          format_duration(r["tau"]) if r["significant"] else "—", f"{r['p_value']:.2g}",
          display.cell(r["tolerance"]),
          format_duration(r["settle_time"]) if r["significant"] else
          "slow drift (τ > half the log)" if r["p_value"] < w.alpha else "no transient"]
         for r in w.rows()],
        caption="Warm-up transient per channel",
    )
    if w.temperature is not None:
        doc.p(f"Temperature: τ {format_duration(w.temperature_tau)}, final "
              f"{w.temperature_final:.2f} °C, within 0.1 °C of it after "
              f"{format_duration(w.temperature_settle)}.")
    if w.settle <= 0:
        verdict = "No warm-up transient: the log is analysed whole."
    elif w.settle_index < w.n_samples:
        verdict = (f"The sensor settled after {format_duration(w.settle)} "
                   f"({100 * w.settle_index / w.n_samples:.3g} % of the log)."
                   + ("" if w.settled else " Less than half the log is settled: the long-tau "
                      "analysis of what is left has few averaging times."))
    else:
        verdict = ("The transient has not settled by the end of the log: `--trim auto` does "
                   "not cut it, and the long-tau analysis includes it.")
    doc.p(verdict)
    note = ctx.trim_note or ("The analysis uses the whole log (`--trim auto` would start it "
                             "at the settle point)." if 0 < w.settle_index < w.n_samples else "")
    if note:
        doc.p(note)
    ctx.add_figure(doc, plot.warmup(w), "warmup",
                   "Bias over time (block means), fitted transient, settle point (dotted; "
                   "before it shaded)")


def thermal_section(ctx: Context, doc: Doc) -> None:
    """Bias against temperature per axis of the long log, and the Allan deviation
    before and after compensation."""
    th = ctx.thermal
    lo, hi = th.temperature_range
    doc.p(f"Linear fit of the bias against temperature over {lo:.2f}–{hi:.2f} °C "
          f"({format_duration(len(th.compensated) / th.fs / len(th.block_temperature))} "
          "means), "
          "uncertainties corrected for correlated residuals. Temperature and time "
          f"correlate with |r| = {th.time_correlation:.2f} (at 1 a thermal bias and a "
          "warm-up or drift cannot be told apart; a log with temperature cycles separates "
          "them).")
    doc.table(["channel", "slope", "unit", "R²"],
              [[r["name"], format_number(r["slope"], r["slope_std"]), unit_text(r["unit"]),
                format_number(r["r_squared"])] for r in th.rows()],
              caption="Bias temperature sensitivity (datasheet units)")
    ctx.add_figure(doc, plot.thermal(th), "thermal", "Bias against temperature with the fit")
    log = ctx.untrimmed or ctx.long
    if ctx.untrimmed is not None:
        doc.p("The fit and the Allan deviations of this section use the whole log, warm-up "
              "included (it holds most of the temperature range).")
    k = 0
    for sensor in ("gyro", "accel"):
        y = getattr(log, sensor)
        if y is None:
            continue
        before = _allan.adev(y, log.fs, taus=ctx.taus_per_decade)
        after = _allan.adev(th.compensated[:, k:k + 3], log.fs, taus=before.taus)
        k += 3
        fig = plot.compensation(before, after, title=f"{sensor}: temperature compensation",
                                unit=_unit(sensor))
        ctx.add_figure(doc, fig, f"thermal_adev_{sensor}",
                       f"Allan deviation of {sensor} before and after compensation")


def one_mount(ctx: Context, doc: Doc) -> None:
    """The long log and the logs of the other sensors on its mount: how they were put
    on one grid, then per sensor each one's own Allan deviation beside its plain one,
    the taus where an own variance is negative said in words."""
    al = ctx.aligned
    names = [f"{label} ({_source(log)})" for label, log in
             zip(_mount_labels(len(al)), al, strict=True)]
    method = ("three-cornered hat: σ²_a = ½(σ²_ab + σ²_ac − σ²_bc) from the Allan "
              "variances of the differences" if len(al) == 3 else
              "Groslambert covariance: σ²_own,a = σ²_a − GCOV(a, b)")
    doc.p(f"{len(al)} sensors on one mount, recorded over the same time: the mount's motion "
          "is common to them and cancels, so each sensor's own noise is told from the "
          f"motion ({method}; {docs_link('mount', 'sensors on one mount')}). A sensor's "
          "plain Allan deviation holds the motion and its own noise; where the two curves "
          "agree the sensor's noise dominates, where the plain one is higher the motion does.")
    clock = ("their timestamps, taken to be on one clock" if al.clock == "timestamps" else
             "the motion: the lag of best correlation of the gyro (each log's clock has its "
             "own zero)")
    doc.p(f"The logs were put on the long log's grid, lined up by {clock}. Each log keeps "
          "its own samples, each at the nearest row of the grid; none is interpolated "
          "(interpolation would filter the white noise being measured). Common span: "
          f"{al.n_samples} samples = {format_duration(al.duration)} at {al.fs:.6g} Hz.")
    rows = [[name, *row[1:]] for name, row in zip(names, al.rows(), strict=True)]
    doc.table(list(al.HEADER), rows,
              caption="The logs on one grid: offset of each log's first sample on the long "
              "log's clock, mean timing error of its samples against the grid (phase), the "
              "motion's peak correlation with the long log's (clock 'motion'), and the "
              "samples each lost: cut before and after the common span, dropped as doubled "
              "(a clock faster than the long log's: two samples for one row, the farther "
              "dropped), missing in the span (its own gaps, and rows a slower clock does not "
              "reach)")
    if not ctx.own_noise:
        doc.p("No gyro or accelerometer channel is in every log: nothing to compare.")
        return
    if len(al) == 2:
        doc.p("With two sensors the product of the motion and each sensor's noise does "
              "not cancel: a motion far above the noise leaves the own deviation wide or "
              "negative. A third sensor (the three-cornered hat, differences only) cancels "
              "the motion whatever its size.")
    for sensor, result in ctx.own_noise.items():
        unit = _unit(sensor)
        doc.h(3, sensor)
        fig = plot.own_noise(result, title=f"{sensor}: own and plain Allan deviation",
                             unit=unit, names=_mount_labels(len(al)))
        ctx.add_figure(doc, fig, f"mount_{sensor}",
                       f"Own (markers, {percent(result.own[0].confidence, digits=1)} interval) "
                       "and plain "
                       f"(line) Allan deviation of {sensor} [{unit}] per sensor; an open "
                       "triangle is the upper bound where the own variance is negative")
        axes = axis_names(result.own[0].channels)
        said = False
        for i, name in enumerate(names):
            below = np.asarray(result.negative[i]).reshape(len(result.taus), -1)
            if not below.any():
                continue
            said = True
            where = "; ".join(
                f"{a} at τ = {', '.join(format_number(t) for t in result.taus[below[:, j]])} s"
                for j, a in enumerate(axes) if below[:, j].any())
            doc.p(f"**Negative own variance**, {name}: {where}. There the sensor's noise is "
                  "below what the other sensors' resolve; the table gives the upper bound "
                  "(< value), the figure an open triangle.")
        if not said:
            doc.p(f"No own variance of {sensor} is negative: every τ resolves each sensor's "
                  "own noise.")
        header = ["τ [s]"]
        for label in _mount_labels(len(al)):
            for a in axes:
                header += [f"{label} {a} plain", f"{label} {a} own"]
        table = []
        for t, tau in enumerate(result.taus):
            row = [format_number(tau)]
            for own, plain, neg in zip(result.own, result.plain, result.negative, strict=True):
                dev = np.reshape(own.dev, (len(result.taus), -1))[t]
                high = np.reshape(own.ci_high, (len(result.taus), -1))[t]
                base = np.reshape(plain.dev, (len(result.taus), -1))[t]
                below = np.reshape(neg, (len(result.taus), -1))[t]
                for j in range(len(axes)):
                    row += [format_number(base[j]),
                            f"< {format_number(high[j])}" if below[j] else
                            format_number(dev[j])]
            table.append(row)
        doc.table(header, table, caption=f"Plain and own Allan deviation of {sensor} "
                  f"[{unit}] per sensor ({result.method}); \"< x\": negative own variance, "
                  "x the upper bound", collapsed=True)


def _mount_labels(count: int) -> list[str]:
    """How the section names the sensors: the long log, then the others."""
    return ["long", *(f"mount {i}" for i in range(1, count))]


def _source(log) -> str:
    """A log's file name (``"<arrays>"``-style sources unchanged)."""
    return log.source if log.source.startswith("<") else Path(log.source).name
