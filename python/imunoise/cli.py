"""The ``imunoise`` command line.

Every error is one line on stderr, ``imunoise: error: ...``, with exit status 2;
warnings are one line each, ``imunoise: warning: ...``.
"""

from __future__ import annotations

import argparse
import signal
import sys
import threading
import warnings
from pathlib import Path

import numpy as np

from imunoise._support import atomic as _atomic
from imunoise._support import interrupt as _interrupt
from imunoise._support.schema import (
    ALLAN_SENSORS,
    CHANNELS,
    SAMPLE_SENSORS,
    axis_names,
    sensor_label,
)
from imunoise.allan import KINDS
from imunoise.display import duration, percent
from imunoise.errors import DataWarning
from imunoise.readers.csv_reader import (
    LAYOUT_CHANNELS,  # the --kind choices: every public Allan-family statistic
)

__all__ = ["bundled_log", "main"]


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit status 2."""

    def error(self, message: str):  # noqa: D401 - argparse API
        _fail(message)


class _Failure(Exception):
    pass


def _fail(message: str):
    raise _Failure(message)


def _version() -> str:
    try:
        from imunoise._core import __version__

        return __version__
    except ImportError:  # pragma: no cover
        return "unknown"


def _build_parser() -> argparse.ArgumentParser:
    p = _Parser(
        prog="imunoise",
        description="Noise characterisation of inertial sensors: statistics, Allan "
        "deviation, noise model, reports.",
    )
    p.add_argument("--version", action="version", version=f"imunoise {_version()}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    r = sub.add_parser("report", help="write the full noise report (HTML, Markdown, figures)",
                       description="Analyse a short log (statistics, distributions) and a long "
                       "log (Allan deviation, noise model) and write report.html, report.md, "
                       "figures/, noise.json and imu.yaml. With one log, both use it.")
    r.add_argument("short_log", metavar="SHORT_LOG")
    r.add_argument("long_log", metavar="LONG_LOG", nargs="?")
    r.add_argument("-o", "--output", default="imunoise-report", metavar="DIR",
                   help="output directory (default: %(default)s)")
    _shared_options(r, spec=True, fs=True, progress=True, layout=True)
    r.add_argument("--force", action="store_true",
                   help="write into an existing folder that is not an imunoise report")
    r.add_argument("--trim", choices=["auto"], default=None,
                   help="'auto': analyse the long log from the end of its warm-up transient "
                   "(the report states what was cut)")
    _report_units_option(r)
    _stream_options(r)
    r.add_argument("--mount", nargs="+", default=None, metavar="LOG",
                   help="one or two logs of other sensors on the long log's mount, recorded "
                   "over the same time: adds the section 'Sensors on one mount', each "
                   "sensor's own Allan deviation beside its plain one (three-cornered hat "
                   "with two, Groslambert covariance with one); without it the report has "
                   "no such section")
    r.add_argument("--mount-clock", choices=["timestamps", "motion"], default="timestamps",
                   help="how the --mount logs' times relate to the long log's: "
                   "'timestamps' on one clock (default), or 'motion': each log's clock has "
                   "its own zero and the logs are lined up on the gyro's motion")

    a = sub.add_parser("adev", help="print an Allan-family deviation table",
                       description="Print tau, deviation, confidence interval and number of "
                       "terms per axis.")
    a.add_argument("log", metavar="LOG")
    _shared_options(a, fs=True, layout=True)
    a.add_argument("--sensor", choices=SAMPLE_SENSORS, default="gyro")
    a.add_argument("--kind", choices=KINDS, default="adev")
    a.add_argument("--taus", default="octave",
                   help="octave, decade, all, or points per decade (default: %(default)s)")
    a.add_argument("--plot", default=None, metavar="PNG", help="also save the deviation figure")

    f = sub.add_parser("fit", help="fit the noise model and print coefficients",
                       description="Fit Q, N, B, K, R per axis to the Allan deviation and print "
                       "them in datasheet units with uncertainties.")
    f.add_argument("log", metavar="LOG")
    _shared_options(f, fs=True, layout=True)
    f.add_argument("--sensor", choices=ALLAN_SENSORS, default=None,
                   help="one sensor (default: gyro and accel)")
    f.add_argument("--bootstrap", type=_number_in(0, 100_000, low_open=False, integer=True),
                   default=0, metavar="REPLICATES",
                   help="uncertainties by parametric bootstrap with this many simulated "
                   "records (>= 5; default: from the fit, taus treated as independent)")
    f.add_argument("--plot", default=None, metavar="PNG",
                   help="also save the Allan deviation with the fitted model (one PNG per "
                   "sensor: NAME_gyro.png, NAME_accel.png when there are two)")
    f.add_argument("--datasheet-units", action="store_true",
                   help="print N, B, K in the units datasheets write (deg/s/sqrt(Hz), "
                   "deg/h, ug/sqrt(Hz), ug) instead of deg/sqrt(h), mg/sqrt(Hz)")

    s = sub.add_parser("stats", help="print sample statistics and distribution fits",
                       description="Per channel mean, std, variance, min, max, drift per hour; "
                       "per axis normal fit and normality statistics.")
    s.add_argument("log", metavar="LOG")
    _shared_options(s, fs=True, layout=True)
    s.add_argument("--plot", default=None, metavar="PNG",
                   help="also save the histograms with the fitted normal (one PNG per sensor: "
                   "NAME_gyro.png, NAME_accel.png, ...)")

    e = sub.add_parser("events", help="list spikes and bursts (vibration, shocks)",
                       description="Per event: start, end, kind, channels, peak in sigmas "
                       "(imunoise.events; docs/events.md).")
    e.add_argument("log", metavar="LOG")
    _shared_options(e, fs=True, layout=True)
    e.add_argument("--false-alarm", type=_number_in(0, 0.01, high_open=True), default=1e-7,
                   metavar="P",
                   help="design false events per sample and channel (default: %(default)g)")

    t = sub.add_parser("thermal", help="bias vs temperature and warm-up per axis",
                       description="Warm-up transient and settle time, and the bias "
                       "temperature sensitivity per axis in °/h/°C and mg/°C "
                       "(imunoise.warmup, imunoise.thermal).")
    t.add_argument("log", metavar="LOG")
    _shared_options(t, fs=True, layout=True)
    t.add_argument("--degree", type=int, choices=(1, 2), default=1,
                   help="1: linear, 2: quadratic in temperature (default: %(default)s)")

    c = sub.add_parser("convert", help="convert a log to .npy, Parquet, CSV or NPZ",
                       description="Write the log's channels to OUTPUT; the format follows the "
                       "suffix: a directory (no suffix: one memory-mappable .npy per channel "
                       "plus meta.json), .npy (one structured array), .parquet (needs "
                       "pyarrow), .csv or .npz. VN logs to a directory, .npy or .parquet are "
                       "streamed with bounded memory, whatever their size.")
    c.add_argument("log", metavar="LOG")
    c.add_argument("-o", "--output", required=True, metavar="OUTPUT")
    c.add_argument("--chunk-mb", type=_number_in(0.01, 65536, "MB", low_open=False),
                   default=64.0, metavar="MB",
                   help="bytes read per piece when streaming (default: %(default)s MB)")
    _shared_options(c, fs=True, progress=True)

    b = sub.add_parser("batch", help="characterise many logs in parallel (Dask)",
                       description="Allan deviation, noise fit and datasheet verdict of every "
                       "log, one row per log, sensor and axis, computed with dask.distributed "
                       "(a local cluster of 2 worker processes unless --scheduler is given). "
                       "A log that fails gets a row with its error.")
    b.add_argument("logs", metavar="LOG", nargs="+", help="logs or glob patterns ('logs/*.bin')")
    b.add_argument("-o", "--output", required=True, metavar="OUTPUT",
                   help="results table: .parquet (needs pyarrow) or .csv")
    b.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="address of a running Dask scheduler (default: a local cluster)")
    b.add_argument("--serial", action="store_true",
                   help="no Dask: analyse the logs one after another in this process")
    _shared_options(b, spec=True, fs=True, progress=True)

    fl = sub.add_parser("fleet", help="compare units: spread, outliers, verdicts, one report",
                        description="One log per unit: N, B, K, Q, R of every unit and axis "
                        "with uncertainties, the fleet's median and robust spread, the units "
                        "that stand out (robust z-score on ln value; the rule is in the "
                        "report) and each unit's datasheet verdict, written as fleet.md and "
                        "fleet.html with one figure per coefficient across units. The logs "
                        "are analysed as by 'imunoise batch' (a local Dask cluster of 2 "
                        "worker processes unless --scheduler or --serial is given).")
    fl.add_argument("logs", metavar="LOG", nargs="+",
                    help="one log per unit, or glob patterns ('lab/*.bin')")
    fl.add_argument("-o", "--output", required=True, metavar="DIR",
                    help="report folder (created)")
    fl.add_argument("--scheduler", default=None, metavar="ADDRESS",
                    help="address of a running Dask scheduler (default: a local cluster)")
    fl.add_argument("--serial", action="store_true",
                    help="no Dask: analyse the logs one after another in this process")
    fl.add_argument("--force", action="store_true",
                    help="write into an existing folder that is not an imunoise report")
    _shared_options(fl, spec=True, fs=True, progress=True)

    m = sub.add_parser("simulate", help="write the log of a simulated still VN-100",
                       description="Write the log of a still VN-100 (gravity on -Z, a constant "
                       "magnetic field and attitude) with the datasheet's noise densities and "
                       "bias instabilities plus a typical rate random walk.")
    m.add_argument("-o", "--output", required=True, metavar="OUTPUT")
    m.add_argument("--hours", type=_HOURS, default=1.0)
    m.add_argument("--fs", type=_FS, default=40.0, help="sample rate in Hz")
    m.add_argument("--format", choices=("vn-ascii", "vn-binary"), default="vn-ascii")
    m.add_argument("--seed", type=_SEED, default=None)

    ps = sub.add_parser("psd", help="print the power spectral density and the noise density N",
                        description="Welch one-sided PSD per axis, log-binned, and N read off "
                        "its white region (automatic, or --band) with its uncertainty, in the "
                        "channel's unit/√Hz (N = √(PSD/2), the IEEE convention of 'fit').")
    ps.add_argument("log", metavar="LOG")
    _shared_options(ps, fs=True, layout=True)
    ps.add_argument("--sensor", choices=ALLAN_SENSORS, default="gyro")
    ps.add_argument("--band", type=_number_in(0, 1e6, "Hz"), nargs=2, default=None,
                    metavar=("LOW", "HIGH"),
                    help="white band in Hz for N (default: chosen automatically)")
    ps.add_argument("--nperseg", type=_number_in(16, 10**9, low_open=False, integer=True),
                    default=None, metavar="SAMPLES",
                    help="samples per Welch segment (default: a power of two ~ n/8)")
    ps.add_argument("--bins", type=_number_in(1, 1000, low_open=False, integer=True),
                    default=10, metavar="PER_DECADE",
                    help="log bins per decade of the printed table (default: %(default)s)")
    ps.add_argument("--plot", default=None, metavar="PNG", help="also save the PSD figure")

    dd = sub.add_parser("dadev", help="dynamic Allan deviation and a stationarity summary",
                        description="Overlapping ADEV of a sliding window per axis: prints the "
                        "stationarity summary and the stretches where the noise departs from "
                        "its typical level; --plot saves the heat map.")
    dd.add_argument("log", metavar="LOG")
    _shared_options(dd, fs=True, layout=True)
    dd.add_argument("--sensor", choices=ALLAN_SENSORS, default="gyro")
    dd.add_argument("--window", type=_number_in(0, 1e9, "s"), default=None, metavar="SECONDS",
                    help="window length (default: a tenth of the log)")
    dd.add_argument("--step", type=_number_in(0, 1e9, "s"), default=None, metavar="SECONDS",
                    help="step between windows (default: a sixth of the window)")
    dd.add_argument("--taus", default="octave",
                    help="octave, decade, all, or points per decade (default: %(default)s)")
    dd.add_argument("--plot", default=None, metavar="PNG", help="also save the heat map")

    d = sub.add_parser("demo", help="run the report on bundled data",
                       description="Report on a real 5-minute VN-100 log shipped with imunoise "
                       "and a simulated 5-hour VN-100 log, then print where the report is.")
    d.add_argument("-o", "--output", default="imunoise-demo", metavar="DIR")
    d.add_argument("--force", action="store_true",
                   help="write into an existing folder that is not an imunoise report")
    d.add_argument("--hours", type=_HOURS, default=5.0,
                   help="length of the simulated long log (default: %(default)s)")
    d.add_argument("--seed", type=_SEED, default=1)
    _shared_options(d, progress=True)
    _add_recording_commands(sub)
    return p


def _stream_options(p) -> None:
    """``--stream`` / ``--no-stream`` of ``report``: bounded memory for large logs."""
    g = p.add_mutually_exclusive_group()
    g.add_argument("--stream", dest="stream", action="store_true", default=None,
                   help="parse each log once into memory maps (a temporary folder beside "
                   "the output) and analyse them a block or a channel at a time: bounded "
                   "memory for logs larger than RAM (default: VN logs above 256 MiB)")
    g.add_argument("--no-stream", dest="stream", action="store_false",
                   help="read the logs whole into memory")


def _add_recording_commands(sub) -> None:
    """``record``, ``emulate`` and ``plan`` (#27)."""
    rc = sub.add_parser("record", help="record a VN-100 on a serial port (lossless, live view)",
                        description="Record the raw byte stream of a VN-100 into OUTPUT (fsync "
                        "every second; side files OUTPUT.times, OUTPUT.gaps, OUTPUT.meta.json), "
                        "setting the outputs asked for and restoring the previous ones on exit. "
                        "Ctrl-C ends the record cleanly.")
    rc.add_argument("port", metavar="PORT", help="serial port, e.g. /dev/ttyUSB0")
    rc.add_argument("-o", "--output", required=True, metavar="OUTPUT")
    rc.add_argument("--baud", default="115200",
                    help="baud rate, or 'auto' to try the nine VN-100 rates (default: "
                    "%(default)s)")
    length = rc.add_mutually_exclusive_group()
    length.add_argument("--hours", type=_positive_float, default=None)
    length.add_argument("--minutes", type=_positive_float, default=None)
    length.add_argument("--seconds", type=_positive_float, default=None)
    rc.add_argument("--ascii", default=None, metavar="TYPE",
                    help="asynchronous ASCII output: VNYMR, VNIMU, ... or 'off'")
    rc.add_argument("--rate", type=_positive_float, default=None, metavar="HZ",
                    help="asynchronous ASCII rate (1 ... 200 Hz)")
    rc.add_argument("--binary", action="append", default=[], metavar="HZ:FIELDS",
                    help="a binary output, e.g. 800:common=TimeStartup+AngularRate+Accel"
                    "[,imu=Temp]; repeat for up to three")
    check = rc.add_mutually_exclusive_group()
    check.add_argument("--crc", dest="crc", action="store_true", default=None,
                       help="CRC-16 on the sensor's sentences")
    check.add_argument("--checksum", dest="crc", action="store_false",
                       help="8-bit checksum on the sensor's sentences")
    rc.add_argument("--keep-config", action="store_true",
                    help="leave the settings on the sensor (default: restore the previous ones)")
    rc.add_argument("--outage-timeout", type=_positive_float, default=2.0, metavar="SECONDS",
                    help="seconds without a byte after which the sensor counts as gone and "
                    "is set up again until it answers; the time lost is kept in OUTPUT.gaps "
                    "(default: %(default)s, at least three periods of the fastest output)")

    em = sub.add_parser("emulate", help="a VN-100 emulator on a pseudo-terminal (tests, demos)",
                        description="Serve an emulated VN-100 at PATH (a symlink to a "
                        "pseudo-terminal) streaming simulated still data, until Ctrl-C.")
    em.add_argument("path", metavar="PATH")
    em.add_argument("--speed", type=_positive_float, default=1.0,
                    help="sensor seconds per wall second (default: %(default)s)")
    em.add_argument("--seed", type=int, default=None)
    em.add_argument("--seconds", type=_positive_float, default=None,
                    help="stop after this many wall seconds")
    em.add_argument("--fault", action="append", default=[], metavar="KIND@T[:SECONDS]",
                    help="corrupt@T, pause@T:S, vanish@T:S or reset@T (sensor seconds); repeat")

    pl = sub.add_parser("plan", help="how long to record for N, B and K to a target uncertainty",
                        description="Record length that resolves N, B and K to --target, from "
                        "a datasheet (--spec) or the noise model fitted to a short LOG.")
    pl.add_argument("log", metavar="LOG", nargs="?", default=None)
    pl.add_argument("--spec", default="vn100", help="datasheet when no LOG (default: "
                    "%(default)s)")
    pl.add_argument("--sensor", choices=ALLAN_SENSORS, default=None,
                    help="one sensor (default: gyro and accel)")
    pl.add_argument("--fs", type=_FS, default=None, metavar="HZ",
                    help="sample rate to plan for (default: the log's, else 40 Hz)")
    pl.add_argument("--target", type=_number_in(0, 1, high_open=True), default=0.2,
                    help="relative uncertainty wanted (default: %(default)s = ±20 %%)")
    pl.add_argument("--confidence", type=_number_in(0, 1, high_open=True), default=0.95,
                    help="probability of being within it (default: %(default)s)")


def _shared_options(p, *, spec: bool = False, fs: bool = False, progress: bool = False,
                    layout: bool = False) -> None:
    """Add the options several commands share, each worded once."""
    if layout:
        g = p.add_argument_group(
            "text logs whose header does not say what each column is",
            "e.g. --columns gyro=6,7,8 --columns accel=3,4,5 --units gyro=deg/s; "
            "columns are 0-based indices or header names")
        g.add_argument("--columns", action="append", type=_channel_assignment, default=[],
                       metavar="CHANNEL=COLS",
                       help="the columns of one channel (gyro, accel, mag, ypr, quaternion, "
                       "temperature, pressure, time); repeat per channel")
        g.add_argument("--units", action="append", type=_channel_assignment, default=[],
                       metavar="CHANNEL=UNIT", help="unit of a channel's values in the file, "
                       "e.g. gyro=deg/s, accel=g, time=ns; repeat per channel")
        g.add_argument("--delimiter", default=None, metavar="TEXT",
                       help="field separator (default: comma, tab, semicolon or whitespace, "
                       "from the first line)")
    if spec:
        p.add_argument("--spec", default="vn100",
                       help="datasheet to compare with: a name or a TOML file (default: "
                       "%(default)s); 'none' to skip")
    if fs:
        p.add_argument("--fs", type=_FS, default=None, metavar="HZ",
                       help="sample rate of logs without timestamps (VN ASCII: the rate the "
                       "sensor was set to; default 40 Hz with a warning)")
    if not progress:
        return
    g = p.add_mutually_exclusive_group()
    g.add_argument("--progress", dest="progress", action="store_true", default=None,
                   help="always show progress bars on stderr")
    g.add_argument("--no-progress", dest="progress", action="store_false",
                   help="never show progress bars")


def _channel_assignment(text: str) -> tuple[str, str]:
    """``CHANNEL=VALUE`` of --columns/--units, the channel checked."""
    channel, sep, value = text.partition("=")
    channel, value = channel.strip(), value.strip()
    known = LAYOUT_CHANNELS
    if not sep or not value:
        raise argparse.ArgumentTypeError(f"expected CHANNEL=VALUE; got {text!r}")
    if channel not in known:
        raise argparse.ArgumentTypeError(
            f"channel must be one of {', '.join(known)}; got {channel!r}")
    return channel, value


def _read_options(args) -> dict:
    """The reader's layout options from --columns/--units/--delimiter (empty when
    none is given, so the format is detected as usual)."""
    options: dict = {}
    columns = {ch: [int(c) if c.strip().lstrip("-").isdigit() else c.strip()
                    for c in value.split(",")]
               for ch, value in getattr(args, "columns", [])}
    if columns:
        options["columns"] = {ch: cols[0] if len(cols) == 1 else cols
                              for ch, cols in columns.items()}
    units = dict(getattr(args, "units", []))
    if units:
        options["units"] = units
    if getattr(args, "delimiter", None) is not None:
        options["delimiter"] = args.delimiter
    return options


def _positive_float(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive number; got {text!r}") from None
    if not (np.isfinite(v) and v > 0):
        raise argparse.ArgumentTypeError(f"expected a positive number; got {text!r}")
    return v


def _number_in(low: float, high: float, unit: str = "", *, low_open: bool = True,
               high_open: bool = False, integer: bool = False):
    """An argparse type: a finite number (an integer when ``integer``) within
    ``low``..``high``. Every numeric option has one: past its bound a value reaches
    arithmetic that overflows (``plan --fs 1e300``) or allocates without end, so it
    is refused with one line naming the bound and the value (argparse adds the
    option's name)."""
    ends = (f"{low}, {high}" if integer else f"{low:g}, {high:g}")
    interval = (f"{'(' if low_open else '['}{ends}{')' if high_open else ']'}"
                + (f" {unit}" if unit else ""))
    kind = "an integer" if integer else "a number"

    def parse(text: str):
        try:
            v = int(text) if integer else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {kind} in {interval}; got {text!r}"
                                             ) from None
        # an int of any size compares with the ends; only a float can be nan or inf
        inside = ((integer or bool(np.isfinite(v))) and (v > low if low_open else v >= low)
                  and (v < high if high_open else v <= high))
        if not inside:
            raise argparse.ArgumentTypeError(f"must be in {interval}; got {text!r}")
        return v

    return parse


#: Sample rates (Hz) the command line takes: slower than a sample per 1000 s or
#: faster than 1 MHz is no IMU, and the bound keeps the planner's arithmetic finite.
_FS = _number_in(1e-3, 1e6, "Hz", low_open=False)
#: Hours of a simulated log (the simulator bounds the samples further).
_HOURS = _number_in(0, 1e5, "h")
#: Seeds: numpy's generators take non-negative integers.
_SEED = _number_in(0, 2**64 - 1, low_open=False, integer=True)


# --- dependencies, one function each -------------------------------------------------


def _read(args):
    from imunoise.report import read_log
    from imunoise.report.inputs import streams

    options = _read_options(args)
    workdir = _stream_workdir() if streams(args.log, options) else None
    try:
        log = read_log(args.log, "input", fs=args.fs, workdir=workdir, **options)
    except ImportError as exc:  # e.g. a Parquet log without pyarrow
        _fail(str(exc))
    _note_gaps(log.source, log)
    return log


def _stream_workdir():
    """A temporary folder for a large log parsed once into memory maps (the commands'
    bounded path, as ``report --stream``), removed when the command ends."""
    import atexit
    import shutil
    import tempfile

    from imunoise._support.stream import fresh_workdir

    path = fresh_workdir(tempfile.gettempdir(), "imunoise-stream-")
    atexit.register(shutil.rmtree, path, ignore_errors=True)
    _interrupt.at_hard_exit(lambda: shutil.rmtree(path, ignore_errors=True))
    return path


def _note_gaps(source: str, done) -> None:
    """One line on stderr when a log (or a conversion) has missing samples."""
    from imunoise.report import gap_note

    note = gap_note(source, done.issues, done.gaps)
    if note:
        print(f"imunoise: note: {note}", file=sys.stderr)


# --- commands ------------------------------------------------------------------------


#: ``--units datasheet`` of ``report``, told apart from the layout's ``CHANNEL=UNIT``.
_TABLE_UNITS = ("tables", "datasheet")


def _report_units_option(parser) -> None:
    """``report --units datasheet``: the units of the report's tables, on the same
    option as the layout's ``--units CHANNEL=UNIT`` (a value without ``=``)."""
    action = next(a for a in parser._actions if "--units" in a.option_strings)
    layout = action.type

    def units_value(text: str) -> tuple[str, str]:
        return _TABLE_UNITS if text.strip() == "datasheet" else layout(text)

    action.type = units_value
    action.metavar = "CHANNEL=UNIT|datasheet"
    action.help += ("; 'datasheet': every table of the report gives N, B, K in the units "
                    "the --spec datasheet writes (the VN-100's deg/s/sqrt(Hz), deg/h, "
                    "mg/sqrt(Hz), mg) instead of deg/sqrt(h), deg/h, ug/sqrt(Hz), ug")


def _cmd_report(args) -> int:
    from imunoise import report

    spec = None if args.spec.lower() == "none" else args.spec
    table_units = "datasheet" if _TABLE_UNITS in args.units else None
    args.units = [u for u in args.units if u != _TABLE_UNITS]
    rep = report.build(args.short_log, args.long_log, args.output, spec=spec, fs=args.fs,
                       progress=args.progress, read_options=_read_options(args), trim=args.trim,
                       force=args.force, units=table_units, stream=args.stream,
                       mount=args.mount, mount_clock=args.mount_clock)
    for log in rep.logs:
        _note_gaps(log.source, log)
    print(f"report written to {rep.html}")
    return 0


def _cmd_adev(args) -> int:
    from imunoise import allan, display, report

    log = _read(args)
    y = getattr(log, args.sensor)
    if y is None:
        _fail(f"{args.log}: the log has no {args.sensor} channel (has {', '.join(log.channels)})")
    taus = int(args.taus) if args.taus.isdigit() else args.taus
    r = getattr(allan, args.kind)(y, log.fs, taus=taus)
    unit = CHANNELS[args.sensor][1]
    head = ["tau[s]", "n"]
    for a in axis_names(y.shape[1]):
        head += [f"{a}[{unit}]", f"{a}_ci_low", f"{a}_ci_high"]
    rows = []
    for i, tau in enumerate(r.taus):
        row = [f"{tau:.6g}", report.terms_used(r, i)]
        for j in range(r.dev.shape[1]):
            row += display.interval_cells(r.dev[i, j], r.ci_low[i, j], r.ci_high[i, j])
        rows.append(row)
    print(f"# {args.kind} of {args.sensor}, {len(y)} samples at {log.fs:.6g} Hz, "
          f"CI {percent(r.confidence, digits=1)}")
    _print_table(head, rows)
    if args.plot:
        from imunoise import plot

        _save_plot(plot.allan(r, title=f"{args.sensor} {args.kind}", unit=unit), args.plot)
    return 0


#: Samples from which ``imunoise fit`` reads a channel's resolution (its levels).
_STEP_SAMPLES = 1_000_000


def _cmd_fit(args) -> int:
    from imunoise import allan, noise, report, stats

    log = _read(args)
    sensors = [args.sensor] if args.sensor else [s for s in ALLAN_SENSORS
                                                  if getattr(log, s) is not None]
    if not sensors or any(getattr(log, s) is None for s in sensors):
        _fail(f"{args.log}: no {' or '.join(sensors or ['gyro/accel'])} channel in the log")
    if args.bootstrap and args.bootstrap < 5:
        _fail(f"--bootstrap must be >= 5 replicates; got {args.bootstrap}")
    if args.bootstrap:
        # the replicates are simulated at once: their bound depends on the log, and
        # is checked here, not after the Allan deviation, in the option's own name
        from imunoise.noise._fit import MAX_BOOTSTRAP_SAMPLES

        most = MAX_BOOTSTRAP_SAMPLES // max(len(log), 1)
        if args.bootstrap > most:
            _fail(f"--bootstrap must be at most {most:,} replicates for this log's "
                  f"{len(log):,} samples (at most {MAX_BOOTSTRAP_SAMPLES:,} simulated samples "
                  f"are held at once); got {args.bootstrap:,}" if most >= 5 else
                  f"--bootstrap: this log's {len(log):,} samples are too many for a "
                  f"bootstrap (at most {MAX_BOOTSTRAP_SAMPLES // 5:,}); leave it out")
    for s in sensors:
        result = allan.adev(getattr(log, s), log.fs, taus=report.TAUS_PER_DECADE)
        if args.bootstrap:
            model = noise.fit(result, uncertainty="bootstrap", replicates=args.bootstrap,
                              seed=0)
        else:  # the sentences below say how well the model follows the curve
            model = noise.fit(result, warn_coverage=False)
        head, rows = report.datasheet_rows(
            model, s, units="datasheet" if args.datasheet_units else None)
        print(f"# {s}")
        _print_table(head, rows)
        data = np.asarray(getattr(log, s))
        steps = [stats.quantization_step(data[:_STEP_SAMPLES, c]) for c in range(data.shape[1])]
        for sentence in report.model_sentences(
                model, s, units="datasheet" if args.datasheet_units else None, steps=steps):
            print(sentence.replace("**", ""))
        print(_plan_line(model, log, s))
        if args.plot:
            from imunoise import plot

            _save_plot(plot.allan(result, model, title=f"{s} Allan deviation and model",
                                  unit=CHANNELS[s][1]), _plot_path(args.plot, s, len(sensors)))
    return 0


def _plan_line(model, log, sensor: str) -> str:
    """The planner's answer for this log, one line (end of ``fit``)."""
    from imunoise.planner import fit_line

    return fit_line(model, log.fs, log.duration).replace("plan:", f"plan {sensor}:")


def _cmd_stats(args) -> int:
    from imunoise import display, stats
    from imunoise._support import stream as _stream

    log = _read(args)
    desc = _stream.describe(log) if _stream.is_mapped(log.gyro) else stats.describe(log)
    print(f"# {log.source}: {len(log)} samples at {log.fs:.6g} Hz, parse issues: {log.issues}")
    print(desc.table())
    print()
    head = ["channel", "step", "spacing", "mu", "sigma", "KS_D", "KS_p", "AD_A2", "skew", "ex_kurt"]
    rows = []
    figures = {}
    for sensor, columns in _distribution_columns(log).items():
        dists = {name: stats.distribution(v[np.isfinite(v)]) for name, v in columns.items()}
        _stream.release_log(log)  # a memory-mapped log's pages, sensor by sensor
        figures[sensor] = dists
        for name, d in dists.items():
            rows.append([
                name,
                f"{d.step:.6g}" if d.step else "-",
                f"{d.level_spacing:.6g}" if d.level_spacing else "-",
                display.cell(d.mu, d.mu_std), display.cell(d.sigma, d.sigma_std),
            ] + [
                display.cell(v) for v in (d.ks_statistic, d.ks_pvalue, d.ad_statistic,
                                          d.skewness, d.excess_kurtosis)
            ])
    _print_table(head, rows)
    if args.plot:
        from imunoise import plot

        for sensor, dists in figures.items():
            names = [n.removeprefix(sensor).strip() or n for n in dists]
            title = "attitude" if sensor == "ypr" else sensor
            fig = plot.histograms(list(dists.values()), title=f"{title} distribution",
                                  unit=CHANNELS[sensor][1], names=names)
            _save_plot(fig, _plot_path(args.plot, sensor, len(figures)))
    return 0


def _distribution_columns(log) -> dict[str, dict[str, np.ndarray]]:
    """Per sensor of the log with samples (and its attitude, yaw about its circular
    mean): ``{"gyro": {"gyro X": samples, …}, "ypr": {"yaw": …}}``."""
    from imunoise.stats import attitude_angles

    out = {}
    for sensor in SAMPLE_SENSORS:
        y = getattr(log, sensor)
        if y is not None:
            out[sensor] = {sensor_label(sensor, j, y.shape[1]): y[:, j]
                           for j in range(y.shape[1])}
    if log.ypr is not None and np.isfinite(log.ypr).any():
        out["ypr"] = attitude_angles(log.ypr)
    return out


def _plot_path(path: str, name: str, count: int) -> Path:
    """``--plot PATH`` for one of ``count`` figures: PATH itself for one, else
    ``PATH_name.png`` (PATH without its ``.png``)."""
    p = Path(path)
    if count == 1:
        return p
    stem = p.name[:-4] if p.name.lower().endswith(".png") else p.name
    return p.with_name(f"{stem}_{name}.png")


def _save_plot(fig, path) -> None:
    """Write a ``--plot`` figure as PNG (by :func:`imunoise.plot.save`, which gives the
    path a ``.png`` suffix) and say where."""
    from imunoise import plot

    written = plot.save(fig, Path(path), formats=("png",))
    print(f"# figure: {written[0]}")


def _sensor_samples(args):
    """The log and its ``--sensor`` samples, or a one-line failure."""
    log = _read(args)
    y = getattr(log, args.sensor)
    if y is None:
        _fail(f"{args.log}: the log has no {args.sensor} channel (has {', '.join(log.channels)})")
    return log, y


def _cmd_psd(args) -> int:
    from imunoise import plot, spectrum
    from imunoise.display import format_value

    log, y = _sensor_samples(args)
    band = tuple(args.band) if args.band else None
    s = spectrum.psd(y, log.fs, nperseg=args.nperseg, band=band)
    if s.segments_skipped:
        print(f"imunoise: note: missing samples; {s.segments_skipped} of "
              f"{s.segments + s.segments_skipped} Welch segments hold one and are left out",
              file=sys.stderr)
    unit = CHANNELS[args.sensor][1]
    names = axis_names(s.channels)
    print(f"# one-sided PSD of {args.sensor} [({unit})^2/Hz], {s.n_samples} samples at "
          f"{log.fs:.6g} Hz, Welch nperseg {s.nperseg}")
    bands = np.reshape(s.band, (-1, 2))
    for j, a in enumerate(names):
        print(f"# N {a} = {format_value(np.atleast_1d(s.N)[j], np.atleast_1d(s.N_std)[j])} "
              f"{unit}/sqrt(Hz) (white band {bands[j, 0]:.4g}-{bands[j, 1]:.4g} Hz"
              f"{'' if s.band_auto else ', given'}"
              + (f"; lines left out at {', '.join(f'{v:.3g}' for v in s.lines[j])} Hz)"
                 if s.lines[j].size else ")"))
    sm = s.smooth(args.bins)
    p = np.reshape(sm.psd, (len(sm.f), -1))
    _print_table(["f[Hz]", *[f"{a}_psd" for a in names]],
                 [[f"{f:.6g}", *[f"{v:.6e}" for v in p[i]]] for i, f in enumerate(sm.f)])
    if args.plot:
        _save_plot(plot.spectrum(s, unit=unit, title=f"{args.sensor} PSD"), args.plot)
    return 0


def _cmd_dadev(args) -> int:
    from imunoise import dynamic, plot

    log, y = _sensor_samples(args)
    taus = int(args.taus) if args.taus.isdigit() else args.taus
    d = dynamic.dynamic_adev(y, log.fs, window=args.window, step=args.step, taus=taus)
    st = d.stationarity
    names = axis_names(d.channels)
    print(f"# dynamic ADEV of {args.sensor}: {len(d.times)} windows of {duration(d.window)} "
          f"every {duration(d.step)}, {len(d.taus)} taus {d.taus[0]:.4g}-{d.taus[-1]:.4g} s")
    outside, worst = np.atleast_1d(st.outside), np.atleast_1d(st.worst_z)
    at_t, at_tau = np.atleast_1d(st.worst_time), np.atleast_1d(st.worst_tau)
    _print_table(["axis", "outside_CI", "expected", "max|z|", "at_t[s]", "at_tau[s]"],
                 [[a, f"{outside[j]:.3f}", f"{st.expected_outside:.3f}", f"{worst[j]:.3g}",
                   f"{at_t[j]:.6g}", f"{at_tau[j]:.4g}"] for j, a in enumerate(names)])
    if st.intervals:
        print("# departures from the typical noise level (1 % family-wise false alarms)")
        _print_table(["axis", "start[s]", "end[s]", "adev_ratio"],
                     [[names[v.channel], f"{v.start:.6g}", f"{v.end:.6g}", f"{v.ratio:.3g}"]
                      for v in st.intervals])
    else:
        print("# no departure: the noise level is the same along the log (to one step)")
    if args.plot:
        _save_plot(plot.dynamic(d, title=f"{args.sensor} dynamic ADEV"), args.plot)
    return 0


def _cmd_convert(args) -> int:
    out = Path(args.output)
    suffix = out.suffix.lower()
    if suffix not in ("", ".npy", ".csv", ".parquet", ".npz"):
        _fail(f"--output must be a directory or end in .npy, .parquet, .csv or .npz; "
              f"got {str(out)!r}")
    _atomic.refuse_input(out, [args.log])
    if suffix in ("", ".npy", ".parquet"):
        return _convert_streaming(args, out)
    from imunoise.writers.table import log_columns, write_csv, write_npz

    log = _read(args)
    out.parent.mkdir(parents=True, exist_ok=True)
    (write_csv if suffix == ".csv" else write_npz)(log, out, inputs=[args.log])
    print(f"wrote {len(log)} samples x {len(log_columns(log)[0])} columns to {out}")
    return 0


def _convert_streaming(args, out: Path) -> int:
    from imunoise import scale
    from imunoise._support.progress import byte_bar, wanted

    source = sys.stdin.buffer if args.log == "-" else args.log
    bar = byte_bar(f"converting {Path(args.log).name}") if wanted(args.progress) else None
    try:
        done = scale.convert(source, out, fs=args.fs, chunk_bytes=int(args.chunk_mb * 2**20),
                             progress=bar)
    except ImportError as exc:
        _fail(str(exc))
    _note_gaps("<stdin>" if args.log == "-" else str(args.log), done)
    print(f"wrote {done.samples} samples ({', '.join(done.channels)}) at {done.fs:.6g} Hz to "
          f"{done.out}; parse issues: {done.issues}")
    return 0


def _cmd_batch(args) -> int:
    from imunoise import scale

    out = Path(args.output)
    suffix = out.suffix.lower()
    if suffix not in (".parquet", ".csv"):
        _fail(f"--output must end in .parquet or .csv; got {str(out)!r}")
    if args.serial and args.scheduler:
        _fail("--serial and --scheduler exclude each other")
    _atomic.refuse_input(out, args.logs)
    client = False if args.serial else args.scheduler
    try:
        df = scale.batch(args.logs, client=client, spec=args.spec, fs=args.fs,
                         progress=args.progress)
    except ImportError as exc:
        _fail(str(exc))
    out.parent.mkdir(parents=True, exist_ok=True)
    with _atomic.replacing(out, inputs=args.logs) as fh:
        if suffix == ".csv":
            df.to_csv(fh, index=False)
        else:
            try:
                df.to_parquet(fh, index=False)
            except ImportError:
                _fail("Parquet output needs pyarrow (pip install pyarrow); or use a .csv output")
    failed = df.loc[df["error"].notna(), "path"].tolist()
    logs = df["path"].nunique()
    print(f"wrote {len(df)} rows for {logs} logs to {out}"
          + (f"; {len(failed)} failed: {', '.join(failed)}" if failed else ""))
    return 0


def _cmd_fleet(args) -> int:
    from imunoise._analysis.fleet import fleet

    if args.serial and args.scheduler:
        _fail("--serial and --scheduler exclude each other")
    client = False if args.serial else args.scheduler
    try:
        result = fleet(args.logs, spec=args.spec, client=client, fs=args.fs,
                       progress=args.progress)
    except ImportError as exc:
        _fail(str(exc))
    for u in result.units:
        if u["error"] is not None:
            warnings.warn(f"{u['path']}: not analysed: {u['error']}", DataWarning, stacklevel=1)
    written = result.report(args.output, force=args.force)
    outliers = "; ".join(f"{o['unit']} {o['sensor']} {o['term']} {o['axis']} "
                         f"{o['ratio']:.3g}x the median" for o in result.outliers[:5])
    more = len(result.outliers) - 5
    print(f"fleet report of {len(result.units)} units written to {written[1]}; "
          + (f"outliers: {outliers}" + (f" and {more} more" if more > 0 else "")
             if outliers else "no outlier")
          + (f"; {len(result.failed)} failing the spec: {', '.join(result.failed[:10])}"
             + (" ..." if len(result.failed) > 10 else "") if result.failed else ""))
    return 0


def _cmd_simulate(args) -> int:
    from imunoise._simulation.log import simulate_log

    out = simulate_log(args.output, args.hours, args.fs, format=args.format, seed=args.seed)
    print(f"wrote {args.hours:g} h at {args.fs:g} Hz ({args.format}) to {out}")
    return 0


def bundled_log() -> Path:
    """Path of the real 5-minute VN-100 log shipped with imunoise."""
    from importlib import resources

    return Path(str(resources.files("imunoise") / "data" / "vn100_stationary_5min.txt"))


def _cmd_demo(args) -> int:
    from imunoise import report
    from imunoise._simulation.log import still_log

    short = bundled_log()
    long = still_log(args.hours, 40.0, spec="vn100", seed=args.seed)
    # The bundled log is VN ASCII without timestamps, recorded at 40 Hz.
    rep = report.build(short, long, args.output, spec="vn100", fs=40.0, progress=args.progress,
                       force=args.force)
    print(f"demo report: {rep.html.resolve()}")
    print(f"             {rep.markdown.resolve()}")
    return 0


def _cmd_events(args) -> int:
    from imunoise._analysis.events import events

    log = _read(args)
    found = events(log, false_alarm=args.false_alarm)
    print(f"# {log.source}: {len(found)} events, {100 * found.share:.3g} % of {len(log)} "
          f"samples (false_alarm {found.false_alarm:g} per sample and channel)")
    _print_table(["start_s", "end_s", "kind", "peak_sigma", "channels", "within"],
                 [[f"{r['start']:.6g}", f"{r['end']:.6g}", r["kind"], f"{r['peak']:.3g}",
                   r["channels"].replace(" ", "_").replace(",_", ","),
                   "-" if r["within"] is None else str(r["within"])] for r in found.rows()])
    return 0


def _cmd_thermal(args) -> int:
    from imunoise._analysis.thermal import thermal
    from imunoise._analysis.warmup import warmup
    from imunoise.display import format_value

    log = _read(args)
    w = warmup(log)
    print(f"# {log.source}: warm-up: " + (f"settled after {duration(w.settle)}" if w.settle > 0
                                           else "no transient"))
    if log.temperature is None:
        _fail(f"{args.log}: the log has no temperature channel; no thermal fit")
    fit = thermal(log, degree=args.degree)
    lo, hi = fit.temperature_range
    print(f"# bias vs temperature over {lo:.2f}-{hi:.2f} degC, |r(T, t)| = "
          f"{fit.time_correlation:.2f}")
    rows = []
    for r in fit.rows():
        row = [r["name"].replace(" ", "_"), format_value(r["slope"], r["slope_std"]), r["unit"]]
        if fit.degree == 2:
            row.append(format_value(r["quadratic"], r["quadratic_std"]))
        rows.append(row)
    head = ["channel", "slope", "unit"] + (["quadratic"] if fit.degree == 2 else [])
    _print_table(head, rows)
    return 0


def _cmd_record(args) -> int:
    from imunoise.recording import DeviceError, binary_output, record

    seconds = (args.hours * 3600 if args.hours else args.minutes * 60 if args.minutes
               else args.seconds)
    if seconds is not None and not np.isfinite(seconds):  # --hours 1e306 overflows
        flag = "--hours" if args.hours else "--minutes"
        _fail(f"{flag} is too large to be a length; got {args.hours or args.minutes:g}")
    baud = args.baud
    if baud != "auto":
        try:
            baud = int(baud)
        except ValueError:
            _fail(f"--baud must be a number or 'auto'; got {args.baud!r}")
    binary = []
    for text in args.binary:
        rate, sep, fields = text.partition(":")
        if not sep:
            _fail(f"--binary must be HZ:FIELDS; got {text!r}")
        try:
            binary.append(binary_output(float(rate), fields))
        except ValueError as exc:
            _fail(f"--binary {text}: {exc}")
    try:
        rec = record(args.port, args.output, seconds=seconds, baud=baud, ascii=args.ascii,
                     rate=args.rate, binary=binary, crc=args.crc,
                     keep_config=args.keep_config, outage_timeout=args.outage_timeout)
    except DeviceError as exc:  # the message names the port; SensorLost too
        _fail(str(exc))
    print(f"recorded {rec.bytes} bytes in {duration(rec.seconds)} to {rec.path}"
          + (f"; {len(rec.outages)} port outage(s)" if rec.outages else "")
          + ("; previous settings restored" if rec.restored else ""))
    return 0


def _cmd_emulate(args) -> int:
    import os
    import time

    from imunoise.emulate import Emulator, Fault
    from imunoise.emulate.device import MAX_SPEED

    faults = []
    for text in args.fault:
        kind, _, when = text.partition("@")
        at, _, length = when.partition(":")
        try:
            faults.append(Fault(kind, float(at), float(length or 0)))
        except ValueError as exc:
            _fail(f"--fault {text}: {exc}")
    if args.speed > MAX_SPEED:  # before the port appears
        _fail(f"--speed must be at most {MAX_SPEED:g} (sensor seconds per wall second); "
              f"got {args.speed:g}")
    with Emulator(args.path, speed=args.speed, seed=args.seed, faults=faults,
                  keep_sent=False) as emu:
        print(f"VN-100 emulator on {emu.path} -> {os.path.realpath(emu.path)}; Ctrl-C to stop",
              flush=True)
        started = time.monotonic()
        while args.seconds is None or time.monotonic() - started < args.seconds:
            if not emu.alive:  # a sensor that stopped is an error, not a quiet exit 0
                _fail(f"the emulated sensor on {emu.path} stopped: "
                      f"{emu.error or 'its thread ended'}")
            time.sleep(0.1)
    return 0


def _cmd_plan(args) -> int:
    from imunoise.planner import plan

    sensors = [args.sensor] if args.sensor else list(ALLAN_SENSORS)
    if args.log is None:
        for s in sensors:
            print(plan(args.spec, fs=args.fs or 40.0, target=args.target,
                       confidence=args.confidence, sensor=s).line())
        return 0
    from imunoise import allan, noise, report

    log = _read(args)
    for s in sensors:
        if getattr(log, s) is None:
            continue
        model = noise.fit(allan.adev(getattr(log, s), log.fs, taus=report.TAUS_PER_DECADE),
                          warn_coverage=False)
        p = plan(model, fs=args.fs or log.fs, target=args.target, confidence=args.confidence)
        print(p.line(log.duration).replace("plan:", f"plan {s}:"))
    return 0


def _print_table(head, rows) -> None:
    widths = [max(len(str(x)) for x in col) for col in zip(head, *rows, strict=True)]
    for line in [head, *rows]:
        print("  ".join(str(c).rjust(w) for c, w in zip(line, widths, strict=True)))


_COMMANDS = {
    "report": _cmd_report,
    "adev": _cmd_adev,
    "fit": _cmd_fit,
    "stats": _cmd_stats,
    "events": _cmd_events,
    "thermal": _cmd_thermal,
    "convert": _cmd_convert,
    "batch": _cmd_batch,
    "fleet": _cmd_fleet,
    "simulate": _cmd_simulate,
    "demo": _cmd_demo,
    "psd": _cmd_psd,
    "dadev": _cmd_dadev,
    "record": _cmd_record,
    "emulate": _cmd_emulate,
    "plan": _cmd_plan,
}


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status (also used as the script's)."""

    def _warn(message, category, filename, lineno, file=None, line=None):
        # ``file``: the progress bars pass a stream that prints above them
        print(f"imunoise: warning: {_one_line(message)}", file=file or sys.stderr)

    old = warnings.showwarning
    warnings.showwarning = _warn
    old_term = None
    try:
        try:
            old_term = _exit_on_sigterm()
            parser = _build_parser()
            args = parser.parse_args(argv)
            if args.command is None:
                parser.print_help(sys.stderr)
                return 2
            # the recorder's own clean-up (the sensor's settings written back) must
            # finish however long it takes: no deadline after Ctrl-C there
            _interrupt.work(backstop=args.command != "record")
            code = _COMMANDS[args.command](args)
            sys.stdout.flush()  # a closed pipe shows here, not in the interpreter's exit
            return code
        except _Failure as exc:
            message = str(exc)
        except BrokenPipeError:
            # the reader went away (``imunoise stats LOG | head``): end quietly with
            # 141 = 128 + SIGPIPE, the status a shell shows for a tool SIGPIPE ended
            _silence_stdout()
            return 141
        except (ValueError, OSError, TypeError, OverflowError) as exc:
            message = str(exc) or type(exc).__name__
            if isinstance(exc, OSError) and exc.filename and exc.strerror:
                message = f"{exc.filename}: {exc.strerror}"
        except KeyboardInterrupt:
            _interrupt.done(interrupted=True)  # a second Ctrl-C: no new traceback
            _interrupt.interrupted()
            return 130
        print(f"imunoise: error: {_one_line(message)}", file=sys.stderr)
        return 2
    finally:
        _interrupt.done()
        warnings.showwarning = old
        if old_term is not None:
            signal.signal(signal.SIGTERM, old_term)


def _silence_stdout() -> None:
    """Point stdout at /dev/null, so the output still buffered for a closed pipe is
    dropped instead of failing again ("Exception ignored ... Broken pipe") at exit."""
    import os

    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):  # not a real file (tests' capture)
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, fd)
    os.close(devnull)


def _exit_on_sigterm():
    """SIGTERM (``kill``) unwinds like Ctrl-C, so the temporaries of the file being
    written are removed, and exits 143; returns the handler it replaced (None when
    not in the main thread, where handlers cannot be set)."""
    if threading.current_thread() is not threading.main_thread():
        return None

    def _terminated(signum, frame):
        _interrupt.interrupted(signum)
        raise SystemExit(128 + signum)

    return signal.signal(signal.SIGTERM, _terminated)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
