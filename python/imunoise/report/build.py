"""Building the report: the list of sections and :func:`build`, which runs them on
the :class:`~imunoise.report.context.Context` they share and writes the directory.

Adding a section is one function in :mod:`.sections` and one entry in
:data:`SECTIONS`; the numbering and the progress bar follow from the list.
"""

from __future__ import annotations

import datetime as _dt
import gc
import os
import shutil
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from imunoise import export, stats
from imunoise._analysis.align import CLOCKS, align
from imunoise._core import __version__
from imunoise._support import atomic as _atomic
from imunoise._support import interrupt as _interrupt
from imunoise._support import stream as _stream
from imunoise._support import summary as _summary
from imunoise._support.progress import Progress, wanted
from imunoise._support.schema import ALLAN_SENSORS
from imunoise.datasheet import load_spec
from imunoise.errors import ImunoiseValueError
from imunoise.readers.log import DEFAULT_FS, ImuLog
from imunoise.report import folder, sections
from imunoise.report.context import TAUS_PER_DECADE, Context, clock, peak_mib, since
from imunoise.report.document import Doc
from imunoise.report.formatting import format_duration
from imunoise.report.inputs import read_log, streams
from imunoise.report.model_text import report_units

__all__ = ["SECTIONS", "TAUS_PER_DECADE", "TITLE", "Context", "Report", "Section", "build"]

TITLE = "IMU noise report"


def _always(_ctx: Context) -> bool:
    return True


@dataclass(frozen=True)
class Section:
    """A numbered section: its heading, the function that writes its body, and
    whether the logs have what it shows (an absent section takes no number)."""

    title: str
    write: Callable[[Context, Doc], None]
    applies: Callable[[Context], bool] = _always


#: The report's sections in reading order.
SECTIONS: tuple[Section, ...] = (
    Section("Recording summary", sections.recording_summary),
    Section("Sample statistics", sections.sample_statistics),
    Section("Distribution fits", sections.distribution_fits),
    Section("Attitude (yaw, pitch, roll)", sections.attitude,
            applies=lambda ctx: ctx.has_attitude),
    Section("Events (vibration, shocks, spikes)", sections.events_section,
            applies=lambda ctx: ctx.events is not None and len(ctx.events) > 0),
    Section("Warm-up", sections.warmup_section, applies=lambda ctx: ctx.warmup is not None),
    Section("Temperature", sections.thermal_section,
            applies=lambda ctx: ctx.thermal is not None),
    Section("Allan deviation", sections.allan_deviation),
    Section("Noise coefficients", sections.noise_coefficients),
    Section("Sensors on one mount", sections.one_mount,
            applies=lambda ctx: ctx.aligned is not None),
    Section("Events and the Allan deviation", sections.long_log_events,
            applies=lambda ctx: ctx.long_events is not None and len(ctx.long_events) > 0),
    Section("Datasheet comparison", sections.datasheet_comparison),
    Section("Power spectral density", sections.power_spectral_density,
            applies=lambda ctx: any(getattr(ctx.short, s) is not None for s in ALLAN_SENSORS)),
    Section("Dynamic Allan deviation", sections.dynamic_allan,
            applies=lambda ctx: any(getattr(ctx.long, s) is not None for s in ALLAN_SENSORS)
            and len(ctx.long) / ctx.long.fs >= sections.DYNAMIC_MIN_SECONDS),
)


@dataclass(frozen=True)
class Report:
    """What :func:`build` wrote and computed.

    Attributes
    ----------
    out_dir, html, markdown : Path
    figures : tuple of Path
        Every file under ``figures/``.
    model_files : tuple of Path
        ``noise.json``, ``imu.yaml`` and ``ekf_bias_model.yaml``.
    description : imunoise.stats.Description
        Sample statistics of the short log.
    attitude : dict
        ``{"yaw": Distribution, "pitch": …, "roll": …}`` of the short log (empty
        when it has no attitude channel).
    distributions : dict
        ``{"gyro X": Distribution, ...}`` of the short log.
    allan : dict
        ``{"gyro": AllanResult, "accel": AllanResult}`` of the long log.
    models : dict
        ``{"gyro": NoiseModel, "accel": NoiseModel}`` (empty without gyro and accel).
    logs : tuple of ImuLog
        The logs analysed (short, then long when it is another log, then the
        ``mount`` logs).
    own_noise : dict
        ``{"gyro": OwnNoise, …}`` of the long log and the ``mount`` logs (empty
        without them).
    """

    out_dir: Path
    html: Path
    markdown: Path
    figures: tuple[Path, ...]
    model_files: tuple[Path, ...]
    description: stats.Description
    distributions: dict
    allan: dict
    models: dict
    logs: tuple = ()
    attitude: dict = field(default_factory=dict)
    own_noise: dict = field(default_factory=dict)

    def _facts(self) -> list[str]:
        return [_summary.plural(len(self.logs), "log"),
                _summary.plural(len(self.figures), "figure file"),
                "models " + (" ".join(self.models) or "none")]

    def __repr__(self) -> str:
        return _summary.lines(f"Report({str(self.out_dir)!r}", self._facts(), sep=", ")

    def _repr_html_(self) -> str:
        """What the report wrote, one file kind a row."""
        rows = [["report", self.html.name], ["Markdown", self.markdown.name],
                ["figures", _summary.plural(len(self.figures), "file")],
                ["model files", ", ".join(p.name for p in self.model_files) or "—"]]
        return _summary.html_table(["", str(self.out_dir)], rows,
                                   caption="Report: " + ", ".join(self._facts()))


def build(
    short,
    long=None,
    out_dir="imunoise-report",
    *,
    spec: str | None = "vn100",
    fs: float | None = None,
    progress: bool | None = None,
    read_options: Mapping[str, object] | None = None,
    trim: str | None = None,
    force: bool = False,
    units: str | None = None,
    stream: bool | None = None,
    mount: Sequence[str | os.PathLike | ImuLog] | None = None,
    mount_clock: str = "timestamps",
) -> Report:
    """Analyse the logs and write the report directory.

    Parameters
    ----------
    short : path or ImuLog
        Short still recording (minutes): sample statistics and distributions.
    long : path or ImuLog, optional
        Long still recording (hours): Allan deviation and noise model. Default: ``short``.
    out_dir : path
        Folder to write (created). A folder of an earlier report (it holds
        ``imunoise-report.json``) is updated: its files are replaced and those this
        report does not write (figures of sections that no longer apply) removed.
        An existing folder holding anything else needs ``force=True``.
    spec : str or None
        Datasheet to compare against (name or file, see :func:`imunoise.compare`);
        None skips the comparison.
    fs : float, optional
        Sample rate in Hz for logs without timestamps (VN ASCII); passed to the reader.
    progress : bool or None
        Progress bars on stderr; None shows them when stderr is a terminal.
    read_options : mapping, optional
        Layout of text logs whose header does not say it, passed to
        :func:`imunoise.read`: ``{"columns": {"gyro": [6, 7, 8]}, "units": {"gyro":
        "deg/s"}}`` (also ``delimiter``, ``time_column``).
    trim : {None, "auto"}
        ``"auto"``: analyse the long log from the settle point of its warm-up
        (:func:`imunoise.warmup`); the report says what was cut, at its top and in
        the warm-up section. None (default): the whole log.
    force : bool
        Write into an existing folder that is not a report (default False: refused
        with a ``ValueError``).
    units : {None, "datasheet"}
        Units of N, B, K, Q, R in every table of the report (one unit per quantity,
        one family per sensor): None the report's (°/√h, °/h, °/h/√h; µg/√Hz, µg, µg/√s;
        :data:`imunoise.report.model_text.REPORT_UNITS`), ``"datasheet"`` the units
        ``spec`` writes (the VN-100's °/s/√Hz, °/h, mg/√Hz, mg; the accelerometer's
        other terms in the family of its B), without ``spec``
        :data:`imunoise.units.DATASHEET_UNITS`.
    stream : bool or None
        Bounded memory for logs larger than memory (:mod:`imunoise._support.stream`): each
        log file is parsed once into memory maps (a temporary folder beside
        ``out_dir``, removed at the end) and every analysis reads them a block or a
        channel at a time. None (default): for VN logs larger than
        ``imunoise._support.stream.STREAM_BYTES`` (256 MiB). The numbers are those of the
        in-memory path (to rounding; the report's digits agree).
    mount : sequence of path or ImuLog, optional
        One or two logs of other sensors on the long log's mount, recorded over the
        same time (the same motion): adds the section "Sensors on one mount", each
        sensor's own Allan deviation beside its plain one (the three-cornered hat
        with two, the Groslambert covariance with one; :func:`imunoise.own_noise`).
        The logs are aligned on the long log's grid (:func:`imunoise.align`) before
        any analysis, so a log that cannot be aligned fails the report at once;
        the aligned copies are in memory, whatever ``stream``.
    mount_clock : {"timestamps", "motion"}
        How the ``mount`` logs' times relate to the long log's (``clock`` of
        :func:`imunoise.align`).
    """
    if trim not in (None, "auto"):
        raise ImunoiseValueError(f"trim must be None or 'auto'; got {trim!r}")
    if units not in (None, "datasheet"):
        raise ImunoiseValueError(f"units must be None or 'datasheet'; got {units!r}")
    if stream not in (None, True, False):
        raise ImunoiseValueError(f"stream must be None, True or False; got {stream!r}")
    mount = _mount_sources(mount)
    if mount_clock not in CLOCKS:
        raise ImunoiseValueError(f"mount_clock must be one of {', '.join(CLOCKS)}; got "
                                 f"{mount_clock!r}")
    if spec is not None:
        # a wrong --spec is found before the analysis, not after it (which takes
        # seconds to minutes), and before a folder is made
        load_spec(spec)
    out = Path(out_dir)
    inputs = [p for p in (short, long, *mount) if isinstance(p, str | os.PathLike)]
    previous = folder.claim(out, force=force, inputs=inputs)
    options = dict(read_options or {})
    streamed = stream if stream is not None else any(
        streams(p, options) for p in (short, long) if p is not None)
    workdirs: list[Path] = []
    undo = folder.Undo(out)
    freeze = streamed and gc.get_freeze_count() == 0

    def clean(failed: bool) -> None:
        for w in workdirs:
            shutil.rmtree(w, ignore_errors=True)
        if failed:  # no skeleton of a report left behind
            undo()

    try:
        # should the command line's watchdog end a stuck process, it cleans up too
        with _interrupt.undo_on_exit(lambda: clean(True)):
            rep = _build(short, long, out, previous, inputs, options, workdirs, spec=spec,
                         fs=fs, progress=progress, trim=trim, streamed=streamed, units=units,
                         mount=mount, mount_clock=mount_clock, freeze=freeze)
    except BaseException:
        clean(True)
        raise
    finally:
        if freeze:
            gc.unfreeze()  # the stages froze what survived them (Context.stage)
    clean(False)
    return rep


def _mount_sources(mount) -> list:
    """The ``mount`` logs as a list of one or two (none for None)."""
    if mount is None:
        return []
    if isinstance(mount, str | os.PathLike | ImuLog):
        mount = [mount]
    mount = list(mount)
    if not 1 <= len(mount) <= 2:
        raise ImunoiseValueError(f"mount must hold one or two logs (with the long log, two "
                                 f"or three sensors on one mount); got {len(mount)}")
    return mount


def _build(short, long, out: Path, previous, inputs, options, workdirs: list[Path], *,
           spec, fs, progress, trim, streamed: bool, units: str | None, mount: list,
           mount_clock: str, freeze: bool) -> Report:
    """:func:`build` once the folder is claimed; ``workdirs`` collects the folders of
    the streamed path's memory maps (the caller removes them)."""
    timings: list[tuple[str, float, float, float]] = []
    assumed: list[str] = []  # logs whose sample rate the reader assumed

    def read(source, label: str) -> ImuLog:
        start = clock()
        workdir = None
        if streamed and isinstance(source, str | os.PathLike) and streams(source, options,
                                                                          forced=True):
            workdir = _stream.workdir_for(out)
            workdirs.append(workdir)
        log = read_log(source, label, fs=fs, progress=wanted(progress), workdir=workdir,
                       **options)
        if streamed:
            _stream.release_log(log)  # the reader's checks touched every page
        name = "the log" if long is None and label == "short" else f"the {label} log"
        if (fs is None and not isinstance(source, ImuLog) and log.time is None
                and log.fs == DEFAULT_FS):
            assumed.append(name)  # the reader assumed the rate (it warned)
        wall, cpu = since(start)
        timings.append((f"reading {name}" + (" into memory maps" if workdir else ""), wall,
                        peak_mib(), cpu))
        return log

    short_log = read(short, "short")
    long_log = short_log if long is None else read(long, "long")
    folder.mark(out, previous)
    (out / "figures").mkdir(parents=True, exist_ok=True)
    ctx = Context(short=short_log, long=long_log, one_log=long is None, spec=spec, out_dir=out,
                  streamed=streamed, block=_stream.BLOCK_ROWS, timings=timings,
                  units=report_units(units, spec), freeze=freeze)
    if trim == "auto":
        start = clock()
        _trim_warmup(ctx)
        ctx.stage(f"warm-up of the {'' if ctx.one_log else 'long '}log (--trim auto)", start)
    others: list[ImuLog] = []  # the mount logs as read (the report's logs)
    if mount:
        # before any analysis: a log that cannot be aligned fails the report at once
        others = [source if isinstance(source, ImuLog) else read(source, f"mount {i}")
                  for i, source in enumerate(mount, start=1)]
        start = clock()
        ctx.aligned = align([ctx.long, *others], clock=mount_clock)
        ctx.stage("aligning the logs of the mount", start)
    doc = Doc()
    doc.h(1, TITLE)
    stamp = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    doc.p(f"Generated by imunoise {__version__} on {stamp}.")
    if assumed:
        doc.p(f"**Sample rate assumed**: {' and '.join(assumed)} "
              f"{'carries' if len(assumed) == 1 else 'carry'} no timestamps and no "
              f"sample rate was given, so {DEFAULT_FS:g} Hz (the VN-100's default output "
              "rate) is assumed. Every time, τ, frequency and noise density below follows "
              "from it: if the sensor ran at another rate, run the report again with "
              f"`--fs RATE` (e.g. `--fs 200`; `fs=` in Python).")
    if ctx.trim_note:
        doc.p(f"**Trim**: {ctx.trim_note}")
    doc.contents()
    # the sections that apply, known before the bar starts: its total never changes
    start = clock()
    present = [s for s in SECTIONS if s.applies(ctx)]
    ctx.stage("finding the sections that apply (events, warm-up, temperature)", start)
    with Progress(progress, total=len(present) + 1) as bar:
        for number, section in enumerate(present, start=1):
            bar.step(section.title)
            start = clock()
            doc.h(2, f"{number}. {section.title}")
            section.write(ctx, doc)
            ctx.stage(section.title, start)
        bar.step("writing")
        start = clock()
        model_files = _write_model_files(ctx.models, out, long_log.fs)
        ctx.stage("writing the model files", start)
        _timings_appendix(doc, ctx)
        md_path, html_path = out / "report.md", out / "report.html"
        _atomic.write_text(md_path, doc.markdown(out))
        _atomic.write_text(html_path, doc.html(TITLE))
        folder.settle(out, [*ctx.figures, *model_files, md_path, html_path], previous,
                      inputs=inputs)
    return Report(
        out_dir=out,
        html=html_path,
        markdown=md_path,
        figures=tuple(ctx.figures),
        model_files=tuple(model_files),
        description=ctx.description,
        distributions=ctx.distributions,
        allan=ctx.allan,
        models=ctx.models,
        logs=tuple(log for _label, log in ctx.logs) + tuple(others),
        attitude=ctx.attitude_distributions,
        own_noise=ctx.own_noise,
    )


def _timings_appendix(doc: Doc, ctx: Context) -> None:
    """The appendix: how long each stage took and the peak memory after it."""
    doc.h(2, "Appendix: stage timings")
    doc.p(("Streamed: the logs were parsed once into memory maps and analysed a block or "
           "a channel at a time" if ctx.streamed else "In memory: the logs were read whole")
          + "; an analysis is timed in the first stage that uses it. Peak memory is the "
          "process's largest resident set so far (memory-mapped pages included). CPU time "
          "is that of every thread of the process (above the wall time where two threads "
          "ran; on a busy machine the wall time grows and the CPU time hardly).")
    doc.table(["stage", "time [s]", "peak memory [MiB]", "CPU [s]"],
              [[name, f"{sec:.2f}", f"{peak:.0f}", f"{cpu:.2f}"]
               for name, sec, peak, cpu in ctx.timings]
              + [["total", f"{sum(t[1] for t in ctx.timings):.2f}", f"{peak_mib():.0f}",
                  f"{sum(t[3] for t in ctx.timings):.2f}"]],
              caption="Wall time, peak resident memory and CPU time per stage")


def _trim_warmup(ctx: Context) -> None:
    """``--trim auto``: start the long log (and the short one, when it is the same
    log) at the warm-up's settle point, and say so."""
    w = ctx.warmup
    if w is None or w.settle <= 0:
        ctx.trim_note = ("`--trim auto`: no warm-up transient found" if w is not None else
                         "`--trim auto`: the log is too short to examine its warm-up") + \
            "; nothing was cut."
        return
    if w.settle_index >= w.n_samples:
        ctx.trim_note = ("`--trim auto`: the warm-up has not settled by the end of the log; "
                         "nothing was cut, the analyses below include the transient.")
        return
    full = ctx.long
    ctx.untrimmed = full
    ctx.long = w.trim(full)
    if ctx.one_log:
        ctx.short = ctx.long
    ctx.trim_note = (f"`--trim auto` cut the first {w.settle_index} samples "
                     f"({format_duration(w.settle)}, "
                     f"{100 * w.settle_index / len(full):.3g} % of the log) before the "
                     f"sensor settled; every analysis below uses the remaining "
                     f"{format_duration(ctx.long.duration)}.")


def _write_model_files(models: dict, out_dir: Path, fs: float) -> list[Path]:
    """noise.json, Kalibr imu.yaml and the EKF bias model."""
    json_path, yaml_path = out_dir / "noise.json", out_dir / "imu.yaml"
    ekf_path = out_dir / "ekf_bias_model.yaml"
    export.write_json(json_path, **models)
    export.write_kalibr(yaml_path, gyro=models.get("gyro"), accel=models.get("accel"),
                        update_rate=fs)
    export.write_ekf(ekf_path, gyro=models.get("gyro"), accel=models.get("accel"))
    return [json_path, yaml_path, ekf_path]
