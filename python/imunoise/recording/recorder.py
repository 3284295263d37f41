"""``imunoise.record``: record a VN-100 on a serial port, losslessly.

The sequence: open the port (at the given baud rate, or the first of the nine
VN-100 rates at which the sensor answers), pause its asynchronous output
(``$VNASY,0``), read its identity (registers 1–4) and output settings, write and
verify the settings asked for, resume (``$VNASY,1``): the record starts with the
first byte after that echo. Every byte then goes to the log as received
(:mod:`imunoise.recording.writer`); the record ends with the echo of the final
``$VNASY,0``, after which the previous settings are restored (unless
``keep_config``) and the output resumed. A port that disappears, or stays
silent for longer than the outage timeout, is reopened until it answers (the
settings written again, as a replugged sensor may have reset), and the outage is
kept as a gap in ``LOG.gaps`` and in the metadata; one that has not come back
when the record ends is kept the same way, and the record ends with
:class:`SensorLost`.

Nothing is left to chance on the sensor: the output is checked before the
sensor is touched, every failure after the first write restores what was
written (each register on its own) and resumes the output, and every
:class:`DeviceError` names the port.
"""

from __future__ import annotations

import contextlib
import errno
import math
import os
import signal
import sys
import threading
import time
import warnings
from dataclasses import dataclass, field

from imunoise._support import atomic as _atomic
from imunoise.errors import DataWarning, ImunoiseValueError
from imunoise.readers.recording import GAPS, META, TIMES, Outage
from imunoise.recording import config
from imunoise.recording.live import LiveView, Snapshot
from imunoise.recording.protocol import ADOR_MESSAGES, IMU_RATE, DeviceError, sentence
from imunoise.recording.session import REPLY_TIMEOUT, Session, find_baud, open_port
from imunoise.recording.writer import RawWriter

__all__ = ["OUTAGE_TIMEOUT", "Recording", "SensorLost", "check_output", "record"]

#: Seconds between two attempts to reopen a vanished port.
RETRY_EVERY = 0.2
#: Seconds without a byte after which the sensor counts as gone (default of
#: ``outage_timeout``); never less than :data:`OUTAGE_PERIODS` periods of the
#: fastest output (any byte counts), whose silence between two records is no outage.
OUTAGE_TIMEOUT = 2.0
OUTAGE_PERIODS = 3


class SensorLost(DeviceError):
    """The sensor went away during the record and had not come back when it ended.

    The loss is the last of ``recording.outages`` (in ``LOG.gaps`` and the
    metadata, as any outage); ``recording`` is what was recorded up to then."""

    def __init__(self, message: str, recording: Recording) -> None:
        super().__init__(message)
        self.recording = recording


@dataclass(frozen=True)
class Recording:
    """What :func:`record` did: ``path`` (the raw log), ``bytes`` written,
    ``seconds`` of wall time, port ``outages``, the sensor's ``identity``, the
    ``settings`` recorded with and the ``previous`` ones, whether they were
    ``restored``, the live view's last ``snapshot`` (when it ran), and ``notes``
    (registers skipped, restore steps that failed)."""

    path: str
    bytes: int
    seconds: float
    outages: tuple[Outage, ...]
    identity: dict
    settings: dict
    previous: dict
    restored: bool
    snapshot: Snapshot | None = field(default=None, repr=False)
    notes: tuple[str, ...] = ()

    def __repr__(self) -> str:
        from imunoise._support import summary as _summary

        return (f"Recording({self.path}: {self.bytes:,} bytes in "
                f"{_summary.duration(self.seconds)}, {len(self.outages)} port outages, "
                f"settings {'restored' if self.restored else 'kept'})")

    def _repr_html_(self) -> str:
        """The log, its size and length, the outages and whether the settings came back."""
        from imunoise._support import summary as _summary

        rows = [("log", self.path), ("bytes", f"{self.bytes:,}"),
                ("wall time", _summary.duration(self.seconds)),
                ("port outages", len(self.outages)),
                ("settings", "restored" if self.restored else "kept")]
        return _summary.html_table(["", ""], rows, caption="Recording")


def output_rates(settings: dict[int, tuple[str, ...]]) -> dict[str, float]:
    """Rates (Hz) of the ASCII output and of the first binary output, where on."""
    rates = {}
    if settings.get(6, ("0",))[0] not in ("0", "00") and 7 in settings:
        rates["ascii"] = float(settings[7][0])
    for reg in (75, 76, 77):
        fields = settings.get(reg, ())
        if len(fields) > 2 and fields[0] != "0" and int(fields[1]) > 0 and fields[2] != "00":
            rates["binary"] = IMU_RATE / int(fields[1])
            break
    return rates


def _untimed_rate(settings: dict[int, tuple[str, ...]]) -> float | None:
    """The rate a reader needs: that of the ASCII output (sentences carry no
    timestamps), else of the binary one."""
    rates = output_rates(settings)
    return rates.get("ascii", rates.get("binary"))


def check_output(path) -> None:
    """Raise ``OSError`` naming ``path`` unless a record can be written there: its
    folder exists and takes new files, and neither the log nor a side file exists.

    Called before the sensor is touched: an output found unwritable only after the
    sensor was set would leave it changed (and the record could not begin)."""
    path = os.fspath(path)
    for target in (path, path + TIMES, path + GAPS, path + META):
        RawWriter.refuse_existing(target)
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        why = "is not a folder" if os.path.lexists(folder) else "does not exist"
        raise OSError(errno.ENOENT, f"the output's folder {folder} {why}", path)
    # a file really made (and removed) is the only test: permissions, read-only
    # mounts and ACLs all decide, which os.access cannot see
    probe = _atomic.temporary_beside(path)
    try:
        os.close(os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
    except OSError as exc:
        raise OSError(exc.errno, f"cannot create files in the output's folder {folder}: "
                      f"{exc.strerror}", path) from None
    with contextlib.suppress(OSError):
        os.unlink(probe)


def _named(exc: DeviceError, port) -> DeviceError:
    """``exc`` with the port's name in front (once)."""
    text = str(exc)
    name = os.fspath(port)
    if text.startswith(name):
        return exc
    return DeviceError(f"{name}: {text}", exc.code)


def _port_errors() -> tuple[type[BaseException], ...]:
    return (OSError, DeviceError) + _serial_errors()


class _Recorder:
    def __init__(self, port, output, baud, wanted_options, keep_config, live,
                 silence: float) -> None:
        self.port = port
        self.baud = baud
        self.options = wanted_options
        self.keep_config = keep_config
        self.output = os.fspath(output)
        self.writer: RawWriter | None = None  # created once the sensor answers
        self.live = live
        self.silence = silence
        self.session: Session | None = None
        self.identity: dict = {}
        self.previous: dict = {}
        self.wanted: dict = {}
        self.touched: set[int] = set()  # registers written (or tried): those restored
        self.restore_failed = False
        self.notes: list[str] = []
        self.outages: list[Outage] = []
        self.lost: Outage | None = None  # the outage the record ended in
        # start of an outage the sensor answered after but has sent no data since: it
        # ends with the first byte (a sensor that answers commands yet streams
        # nothing is still lost), and goes on through further reconnections
        self.pending: float | None = None
        self.began = time.time()  # the record's start (Unix s), for the metadata
        self.last_chunk = time.time()

    def connect(self, first: bool, probe: float | None = None) -> bytes:
        """Open, pause, configure, resume; returns the first bytes of the record.

        ``probe``: seconds to wait for the first reply (reopening a vanished port).
        On the first connection a failure leaves the sensor as it was (every
        register written is restored, each on its own) and streaming."""
        serial = open_port(self.port, self.baud)
        session = Session(serial)
        answered = False
        try:
            session.command("VNASY,0", **({"timeout": probe} if probe else {}))
            answered = True
            if first:
                self.identity = config.read_identity(session)
                self.previous = config.read_outputs(session, self.notes)
                self.wanted = config.wanted_outputs(self.previous, **self.options)
                lacking = [r for r in self.wanted if r in config.OPTIONAL_REGISTERS
                           and r not in self.previous]
                if lacking:  # refused before anything is written
                    raise DeviceError(f"the sensor has no binary outputs (registers "
                                      f"{', '.join(map(str, lacking))} refused): record "
                                      f"its ASCII output alone, without --binary")
                if not output_rates({**self.previous, **self.wanted}):
                    raise ImunoiseValueError("with these settings the sensor sends nothing "
                                     "(ASCII output off, no binary output): nothing to "
                                     "record")
                for note in self.notes:  # once the record will be made: one line if not
                    warnings.warn(note, DataWarning, stacklevel=3)
            config.apply(session, self.wanted, self.touched)
            session.command("VNASY,1")
        except BaseException:
            try:
                if first:  # leave the sensor as it was, streaming
                    for problem in self._restore(session, answered):
                        warnings.warn(problem, DataWarning, stacklevel=3)
            finally:
                serial.close()
            raise
        self.session = session
        self.last_chunk = time.time()
        head, session.rest = session.rest, b""
        return head

    def _restore(self, session: Session, answered: bool) -> list[str]:
        """Write the previous settings back and resume the output, whatever fails on
        the way (the resume is always sent); returns the steps that failed."""
        problems: list[str] = []
        try:
            if not self.keep_config and self.touched:
                if answered:
                    failed = config.restore(session, self.previous, self.touched)
                else:  # each write would wait for a reply that does not come
                    failed = ["settings not restored: the sensor does not answer"]
                self.restore_failed = bool(failed)
                problems += failed
        finally:
            try:
                if answered:
                    session.command("VNASY,1")
                else:  # a sensor that never answered: send it, wait for nothing
                    session.serial.write(sentence("VNASY,1", crc=session.crc))
            except _port_errors() as exc:
                problems.append(f"output not resumed ($VNASY,1): {exc}")
        return [f"{os.fspath(self.port)}: {p}" for p in problems]

    def meta(self, **extra) -> dict:
        settings = {**self.previous, **self.wanted}
        return {
            "port": os.fspath(self.port), "baud": self.baud, "identity": self.identity,
            "previous": {str(k): list(v) for k, v in self.previous.items()},
            "written": {str(k): list(v) for k, v in self.wanted.items()},
            "fs": _untimed_rate(settings),
            "ascii": ADOR_MESSAGES.get(int(settings.get(6, ("0",))[0]) if settings else 0),
            "notes": list(self.notes),
            "outages": len(self.outages),
            "outage_list": [{"offset": o.offset, "start": o.start, "end": o.end,
                             "seconds": round(o.seconds, 6)} for o in self.outages],
            "ended_in_outage": self.lost is not None,
            **extra,
        }

    def write(self, data: bytes) -> None:
        if data:
            now = time.time()
            if self.pending is not None:  # the first byte after an outage ends it
                self._outage(self.pending, now)
                self.pending = None
                self.write_meta()  # the outage is in the metadata even if killed now
            self.writer.write(data, time.time_ns())
            self.last_chunk = now
            if self.live is not None:
                self.live.feed(data)

    def silent(self) -> bool:
        """No byte for longer than the outage timeout."""
        return time.time() - self.last_chunk > self.silence

    def _outage(self, start: float, end: float) -> Outage:
        outage = Outage(self.writer.size, round(start, 6), round(end, 6))  # as kept
        self.writer.outage(outage.start, outage.end)
        self.outages.append(outage)
        if self.live is not None:
            self.live.outage()
        return outage

    def reconnect(self, stop) -> bool:
        """Reopen a vanished or silent port until it answers (or ``stop``); the
        outage ends with the first byte that follows (:meth:`write`), or lasts to the
        end of the record (:meth:`end_outage`)."""
        start = self.pending if self.pending is not None else self.last_chunk
        with contextlib.suppress(Exception):
            self.session.serial.close()
        self.session = None
        while not stop():
            try:
                first = self.connect(first=False, probe=min(REPLY_TIMEOUT, self.silence))
            except Exception:  # the port is not back yet, or not answering yet
                time.sleep(RETRY_EVERY)
                continue
            self.pending = start
            self.write(first)
            return True
        self.pending = start
        return False

    def end_outage(self) -> None:
        """At the end of the record: an outage still on (or a silence longer than
        the outage timeout) is the loss the record ends in, kept as any outage."""
        if self.pending is None and self.silent():
            self.pending = self.last_chunk
        if self.pending is not None:
            self.lost = self._outage(self.pending, time.time())
            self.pending = None

    def write_meta(self, **extra) -> None:
        self.writer.write_meta(self.meta(started=self.began, **extra))

    def finish(self) -> bool:
        """End the record at the echo of ``$VNASY,0``, restore, resume; True when the
        previous settings were restored. Failed steps go to :attr:`notes` (and are
        warned about); the output is resumed whatever failed before."""
        if self.session is None:
            if self.wanted and not self.keep_config:
                self.notes.append(f"{os.fspath(self.port)}: the sensor was gone when the "
                                  f"record ended: its settings were not restored")
            return False
        problems: list[str] = []
        answered = True
        try:
            try:
                _, tail = self.session.command("VNASY,0")
                if self.writer is not None:
                    self.write(tail)
            except _port_errors() as exc:
                answered = isinstance(exc, DeviceError) and exc.code is not None
                problems.append(f"{os.fspath(self.port)}: output not paused at the end "
                                f"($VNASY,0): {exc}")
            problems += self._restore(self.session, answered)
        finally:
            self.session.serial.close()
        self.notes += problems
        for problem in problems:
            warnings.warn(problem, DataWarning, stacklevel=3)
        return bool(self.touched) and not self.keep_config and not self.restore_failed


def record(port, output, *, seconds: float | None = None, baud: int | str = 115200,
           ascii: str | None = None, rate: float | None = None, binary=(),
           crc: bool | None = None, keep_config: bool = False, live: bool | None = None,
           live_stream=None, stop: threading.Event | None = None,
           outage_timeout: float = OUTAGE_TIMEOUT) -> Recording:
    """Record the VN-100 on ``port`` into ``output`` until ``seconds`` pass, ``stop``
    is set or Ctrl-C.

    Parameters
    ----------
    port : str
        Serial port (``/dev/ttyUSB0``, ``COM3``).
    output : str or path-like
        The raw log to create (an existing file is refused); side files
        ``.times``, ``.gaps``, ``.meta.json`` beside it. Checked before the sensor
        is touched.
    seconds : float, optional
        Wall-clock length; ``None``: until stopped.
    baud : int or "auto"
        The port's baud rate, or ``"auto"``: try the nine VN-100 rates.
    ascii, rate : optional
        Asynchronous ASCII type (``"VNYMR"``, ``"off"``) and rate (Hz, register 7).
    binary : sequence, optional
        Binary outputs, each as :func:`imunoise.recording.config.binary_output` makes them.
    crc : bool, optional
        CRC-16 (True) or XOR-8 (False) on the sensor's sentences.
    keep_config : bool
        Leave the settings on the sensor (default: restore the previous ones).
    live : bool, optional
        Show the live view (default: when ``live_stream``, default stdout, is a terminal).
    stop : threading.Event, optional
        Set it to end the record cleanly from another thread.
    outage_timeout : float
        Seconds without a byte after which the sensor counts as gone (at least three
        periods of the fastest output): the port is reopened and the sensor set up
        again until it answers, the time lost kept as an outage.

    Returns
    -------
    Recording

    Raises
    ------
    DeviceError
        The sensor does not answer, or not as asked (the message names the port;
        its settings are restored and its output resumed). :class:`SensorLost`
        when it went away and had not come back when the record ended: the record
        up to then is complete, the loss in ``.gaps`` and the metadata.
    """
    if seconds is not None and not (math.isfinite(seconds) and seconds > 0):
        raise ImunoiseValueError(f"seconds must be a finite number > 0; got {seconds!r}")
    if not (isinstance(outage_timeout, int | float) and math.isfinite(outage_timeout)
            and outage_timeout > 0):
        raise ImunoiseValueError(f"outage_timeout must be a finite number of seconds > 0; got "
                         f"{outage_timeout!r}")
    stream = live_stream if live_stream is not None else sys.stdout
    if live is None:
        live = bool(getattr(stream, "isatty", lambda: False)())
    if baud != "auto" and (not isinstance(baud, int) or baud <= 0):
        raise ImunoiseValueError(f"baud must be a positive integer or 'auto'; got {baud!r}")
    options = {"ascii": ascii, "rate": rate, "binary": tuple(binary), "crc": crc}
    config.wanted_outputs({}, **options)  # bad options fail before the port is opened
    check_output(output)  # and an output that cannot be written: the sensor is not touched
    try:
        if baud == "auto":
            baud = find_baud(port)
        rec = _Recorder(port, output, baud, options, keep_config, None, outage_timeout)
        first = rec.connect(first=True)
    except DeviceError as exc:
        raise _named(exc, port) from None
    settings = {**rec.previous, **rec.wanted}
    # the fastest output sets the longest normal silence: any byte counts, and a
    # slow binary output beside it (0.012 Hz) must not stretch the timeout to 4 min
    fastest = max(output_rates(settings).values())
    rec.silence = max(outage_timeout, OUTAGE_PERIODS / fastest)
    stop_event = stop or threading.Event()
    started = time.monotonic()

    def done() -> bool:
        return stop_event.is_set() or (seconds is not None
                                       and time.monotonic() - started >= seconds)

    snapshot, restored = None, False
    rec.began = time.time()
    # Ctrl-C and SIGTERM only set stop from here on, the restore included: the
    # sensor is set back (and streams) whatever ended the record
    with _signals_stop(stop_event) as signalled:
        try:
            rec.writer = RawWriter(output)
            rec.write_meta()
            if live:
                rec.live = LiveView(rates=output_rates(settings), target=seconds,
                                    stream=stream)
            rec.write(first)
            while not done():
                try:
                    data = rec.session.read()
                except _port_errors():
                    data = None
                if data:
                    rec.write(data)
                elif (data is None or rec.silent()) and not rec.reconnect(done):
                    break
            rec.end_outage()
        finally:
            try:
                restored = rec.finish()
            finally:  # the log is closed (and synced) even if the last write failed
                if rec.live is not None:
                    snapshot = rec.live.close()
                if rec.writer is not None:
                    rec.writer.close()
    elapsed = time.monotonic() - started
    rec.write_meta(seconds=elapsed, bytes=rec.writer.size, restored=restored)
    result = Recording(path=rec.writer.path, bytes=rec.writer.size, seconds=elapsed,
                       outages=tuple(rec.outages), identity=rec.identity,
                       settings=settings, previous=rec.previous, restored=restored,
                       snapshot=snapshot, notes=tuple(rec.notes))
    if signalled:  # SIGTERM: now that the record is complete, as it would have
        signal.raise_signal(signalled[0])
    if rec.lost is not None:
        gone = time.strftime("%H:%M:%S", time.localtime(rec.lost.start))
        raise SensorLost(
            f"{os.fspath(port)}: the sensor went silent at {gone} and had not come back "
            f"when the record ended: {rec.lost.seconds:.1f} s lost (kept in "
            f"{rec.writer.path}{GAPS} and the metadata; the record before is complete"
            f"{'' if restored or not rec.wanted else '; its settings were not restored'})",
            result)
    return result


@contextlib.contextmanager
def _signals_stop(stop: threading.Event):
    """While recording, Ctrl-C and SIGTERM set ``stop`` instead of raising wherever
    the code happens to be (an exception inside a read would lose the bytes it had
    read). Yields a list that receives SIGTERM's number; restores the handlers."""
    received: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield received
        return

    def handler(signum, frame) -> None:
        if signum == signal.SIGTERM:
            received.append(signum)
        stop.set()

    old = {sig: signal.signal(sig, handler) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield received
    finally:
        for sig, previous in old.items():
            signal.signal(sig, previous)


def _serial_errors() -> tuple[type[BaseException], ...]:
    import serial

    return (serial.SerialException,)
