"""What the report's sections share: the logs, the options and the analyses, each
computed once on first use (:class:`Context`), apart from the sections that read it
and the build that runs them, so neither imports the other."""

from __future__ import annotations

import gc
import time
import warnings
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np

from imunoise import allan as _allan
from imunoise import noise, plot, stats
from imunoise._analysis.align import Aligned
from imunoise._analysis.events import Baselines, Events, events, search
from imunoise._analysis.mount import OwnNoise, own_noise
from imunoise._analysis.thermal import Thermal, thermal
from imunoise._analysis.warmup import Warmup, warmup
from imunoise._support import schema as _schema
from imunoise._support import stream as _stream
from imunoise._support.schema import ALLAN_SENSORS, SAMPLE_SENSORS, sensor_label
from imunoise.errors import ImunoiseWarning
from imunoise.readers.log import ImuLog
from imunoise.report import sections
from imunoise.report.document import Doc
from imunoise.spectrum import Spectrum

__all__ = ["TAUS_PER_DECADE", "Context", "clock", "peak_mib", "since"]

#: Tau grid of the Allan analysis: log-spaced points per decade.
TAUS_PER_DECADE = _schema.TAUS_PER_DECADE


@dataclass
class Context:
    """What the sections share: the logs, the options, the analyses (each computed
    once, on first use, so sections may be reordered) and the figures written."""

    short: ImuLog
    long: ImuLog
    one_log: bool
    spec: str | None
    out_dir: Path
    taus_per_decade: int = TAUS_PER_DECADE
    figures: list[Path] = field(default_factory=list)
    #: The long log before ``--trim auto`` cut its warm-up (None: not trimmed).
    untrimmed: ImuLog | None = None
    #: What ``--trim auto`` cut, in words ("" when nothing was cut).
    trim_note: str = ""
    #: True when the logs are memory maps read a block or a channel at a time
    #: (:mod:`imunoise._support.stream`): the analyses then hold one channel, not the log.
    streamed: bool = False
    #: Rows per block of the streamed path.
    block: int = _stream.BLOCK_ROWS
    #: (stage, seconds, peak RSS in MiB so far, CPU seconds) of each stage, for the
    #: appendix.
    timings: list[tuple[str, float, float, float]] = field(default_factory=list)
    #: Units of the noise coefficients in every table (None: the defaults, or
    #: "datasheet"; :meth:`imunoise.noise.NoiseModel.table`).
    units: str | None = None
    #: Whether :meth:`stage` freezes the objects that survive it (the build then
    #: unfreezes them): only when the process had frozen none.
    freeze: bool = False
    #: The long log and the logs of the other sensors on its mount on one grid
    #: (``--mount``); None without them.
    aligned: Aligned | None = None

    @property
    def logs(self) -> list[tuple[str, ImuLog]]:
        """``[("both", log)]`` for one log, else ``[("short", …), ("long", …)]``."""
        if self.one_log:
            return [("both", self.short)]
        return [("short", self.short), ("long", self.long)]

    @cached_property
    def description(self) -> stats.Description:
        """Sample statistics of the short log."""
        if self.streamed:
            return _stream.describe(self.short, self.block)
        return stats.describe(self.short)

    @cached_property
    def sensor_distributions(self) -> dict[str, dict[str, stats.Distribution]]:
        """``{"gyro": {"gyro X": Distribution, …}, …}`` of the short log."""
        out: dict[str, dict[str, stats.Distribution]] = {}
        for sensor in SAMPLE_SENSORS:
            y = getattr(self.short, sensor)
            if y is not None:
                # streamed: the column read is the distribution's own, sorted in place
                def one(j, y=y):
                    if self.streamed:
                        return stats.distribution(_stream.column(y, j, self.block),
                                                  overwrite_input=True)
                    return stats.distribution(y[:, j])

                found = _stream.each_channel(one, y.shape[1])
                out[sensor] = {sensor_label(sensor, j, y.shape[1]): d
                               for j, d in enumerate(found)}
        return out

    @cached_property
    def has_attitude(self) -> bool:
        """Whether the short log has an attitude channel with a finite value."""
        ypr = self.short.ypr
        if ypr is None:
            return False
        if not self.streamed:
            return bool(np.any(np.isfinite(ypr)))
        return any(np.isfinite(rows).any() for _a, rows in _stream.blocks(ypr, self.block))

    def attitude(self) -> dict[str, np.ndarray] | None:
        """``{"yaw": …, "pitch": …, "roll": …}`` (degrees) of the short log, yaw
        unwrapped about its circular mean so that a heading near ±180° stays in
        one piece; None when the log has no attitude. Computed on each call, not
        kept (three channels of the log)."""
        if not self.has_attitude:
            return None
        ypr = self.short.ypr
        if not self.streamed:
            return stats.attitude_angles(ypr)
        # yaw first: unwrapped before the other two are read
        angles = {"yaw": stats.unwrap_about_circular_mean(_stream.column(ypr, 0, self.block))}
        for j, name in enumerate(_schema.ATTITUDE_NAMES[1:], start=1):
            angles[name] = _stream.column(ypr, j, self.block)
        return angles

    @cached_property
    def attitude_distributions(self) -> dict[str, stats.Distribution]:
        """Normal fit of each attitude angle of the short log (missing samples left out)."""
        if not self.streamed or not self.has_attitude:
            return {name: stats.distribution(v[np.isfinite(v)], overwrite_input=True)
                    for name, v in (self.attitude() or {}).items()}
        out = {}  # an angle at a time
        for j, name in enumerate(_schema.ATTITUDE_NAMES):
            v = _stream.column(self.short.ypr, j, self.block)
            if name == "yaw":
                v = stats.unwrap_about_circular_mean(v)
            out[name] = stats.distribution(v[np.isfinite(v)], overwrite_input=True)
        return out

    @property
    def distributions(self) -> dict[str, stats.Distribution]:
        """``{"gyro X": Distribution, …}`` of the short log."""
        return {name: d for per_axis in self.sensor_distributions.values()
                for name, d in per_axis.items()}

    @cached_property
    def allan(self) -> dict[str, _allan.AllanResult]:
        """Overlapping Allan deviation per sensor of the long log on the report's grid."""
        out = {}
        for sensor in ALLAN_SENSORS:
            y = getattr(self.long, sensor)
            if y is not None:
                out[sensor] = _stream.adev(y, self.long.fs, self.taus_per_decade,
                                           self.streamed, self.block)
                _stream.release(y)  # a memory map's pages, before the next sensor's
        return out

    @cached_property
    def own_noise(self) -> dict[str, OwnNoise]:
        """Per sensor every aligned log has, each sensor's own Allan deviation beside
        its plain one on the report's grid (empty without ``aligned``). The negative
        variances are said by the section, not warned about."""
        if self.aligned is None:
            return {}
        out = {}
        for sensor in ALLAN_SENSORS:
            if all(getattr(log, sensor) is not None for log in self.aligned):
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", ImunoiseWarning)
                    out[sensor] = own_noise(self.aligned, sensor=sensor,
                                            taus=self.taus_per_decade)
        return out

    @cached_property
    def spectra(self) -> dict[str, Spectrum]:
        """Welch PSD per sensor of the long log (the log the models are fitted to), on
        the linear grid; a sensor without 256 present samples or an unbroken stretch
        of 16 has none."""
        from imunoise import spectrum

        out = {}
        for sensor in ALLAN_SENSORS:
            y = getattr(self.long, sensor)
            if y is None or np.count_nonzero(_stream.present_rows(y)) < 256:
                continue
            try:  # segments with a missing sample are left out
                out[sensor] = spectrum.psd(y, self.long.fs)
            except ValueError:  # no unbroken stretch of 16 samples
                pass
            _stream.release(y)
        return out

    @cached_property
    def models(self) -> dict[str, noise.NoiseModel]:
        """The noise model per sensor, its tones checked against the same log's
        spectrum; a poor fit is said in the report's words
        (:func:`~imunoise.report.model_sentences`), not warned about."""
        return {sensor: noise.fit(r, warn_coverage=False, spectrum=self.spectra.get(sensor))
                for sensor, r in self.allan.items()}

    @cached_property
    def event_search(self) -> tuple[Events, Baselines] | None:
        """Events of the short log's gyro and accel and the baselines the search
        standardised them by (None without gyro and accel)."""
        if not any(getattr(self.short, s) is not None for s in ALLAN_SENSORS):
            return None
        return search(self.short)

    @property
    def events(self) -> Events | None:
        """Events of the short log's gyro and accel (None without them)."""
        return None if self.event_search is None else self.event_search[0]

    @cached_property
    def long_events(self) -> Events | None:
        """Events of the long log's gyro and accel, as analysed (after any trim);
        the short log's when there is one log. None without gyro and accel."""
        if self.one_log:
            return self.events
        if not any(getattr(self.long, s) is not None for s in ALLAN_SENSORS):
            return None
        return events(self.long)

    @cached_property
    def warmup(self) -> Warmup | None:
        """Warm-up of the whole long log (before any trim); None when it is shorter
        than ``sections.WARMUP_MIN_DURATION`` or has no gyro/accel."""
        log = self.untrimmed or self.long
        if log.duration < sections.WARMUP_MIN_DURATION or not any(
                getattr(log, s) is not None for s in ALLAN_SENSORS):
            return None
        return warmup(log)

    @cached_property
    def thermal(self) -> Thermal | None:
        """Bias-vs-temperature fit of the long log; None without temperature or
        with less than ``sections.THERMAL_MIN_RANGE`` °C of it."""
        log = self.untrimmed or self.long  # the warm-up holds most of the range
        t = log.temperature
        if t is None or not np.isfinite(t).any() or np.nanmax(t) - np.nanmin(t) < \
                sections.THERMAL_MIN_RANGE or not any(
                getattr(log, s) is not None for s in ALLAN_SENSORS):
            return None
        fit = thermal(log)
        lo, hi = fit.temperature_range
        return fit if hi - lo >= sections.THERMAL_MIN_RANGE else None

    def stage(self, name: str, start: tuple[float, float]) -> None:
        """Record a stage that began at ``start`` (:func:`clock`); on the streamed
        path, give the memory maps' pages back after it."""
        if self.streamed:
            for log in (self.short, self.long, self.untrimmed):
                _stream.release_log(log)
            # arrays a section's reference cycles still hold (its figures), then the heap:
            # without the collection 7 channel lengths outlived the attitude section.
            # What survives is frozen (build unfreezes it at its end), unless the caller
            # froze objects of its own: the next stage's collection then scans only that
            # stage's objects, not matplotlib's and scipy's again (0.1 s a stage)
            gc.collect()
            if self.freeze:
                gc.freeze()
            _stream.trim_heap()
        wall, cpu = since(start)
        self.timings.append((name, wall, peak_mib(), cpu))

    def add_figure(self, doc: Doc, fig, name: str, caption: str) -> None:
        """Save ``fig`` as ``figures/<name>.png`` and ``.svg`` and show it in ``doc``."""
        path = self.out_dir / "figures" / name
        plot.plain_ticks(fig)  # no offset in a corner: it goes into the axis label
        self.figures += plot.save(fig, path)
        doc.figure(path.with_suffix(".png"), caption)


def clock() -> tuple[float, float]:
    """Now, as wall time and the process's CPU time (every thread's), for :func:`since`."""
    return time.perf_counter(), time.process_time()


def since(start: tuple[float, float]) -> tuple[float, float]:
    """Wall and CPU seconds from ``start`` (:func:`clock`) to now."""
    wall, cpu = clock()
    return wall - start[0], cpu - start[1]


def peak_mib() -> float:
    """Peak resident memory of this process so far, MiB (ru_maxrss: KiB on Linux);
    NaN where the platform does not say (Windows has no ``resource``)."""
    try:
        import resource
    except ImportError:  # pragma: no cover - not on Linux
        return float("nan")
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


