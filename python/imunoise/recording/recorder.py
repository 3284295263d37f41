"""``imunoise.record``: record a VN-100 on a serial port, losslessly.

The sequence: open the port (at the given baud rate, or the first of the nine
VN-100 rates at which the sensor answers), pause its asynchronous output
(``$VNASY,0``), read its identity (registers 1–4) and output settings, write and
verify the settings asked for, resume (``$VNASY,1``): the record starts with the
first byte after that echo. Every byte then goes to the log as received
(:mod:`imunoise.recording.writer`); the record ends with the echo of the final
``$VNASY,0``, after which the previous settings are restored (unless
``keep_config``) and the output resumed. A port that disappears is reopened
until it returns (the settings written again, as a replugged sensor may have
reset), and the outage is kept as a gap in ``LOG.gaps``.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time
from dataclasses import dataclass, field

from imunoise.readers.recording import Outage
from imunoise.recording import config
from imunoise.recording.live import LiveView, Snapshot
from imunoise.recording.protocol import ADOR_MESSAGES, IMU_RATE, DeviceError
from imunoise.recording.session import Session, find_baud, open_port
from imunoise.recording.writer import RawWriter

__all__ = ["Recording", "record"]

#: Seconds between two attempts to reopen a vanished port.
RETRY_EVERY = 0.2


@dataclass(frozen=True)
class Recording:
    """What :func:`record` did: ``path`` (the raw log), ``bytes`` written,
    ``seconds`` of wall time, port ``outages``, the sensor's ``identity``, the
    ``settings`` recorded with and the ``previous`` ones, whether they were
    ``restored``, and the live view's last ``snapshot`` (when it ran)."""

    path: str
    bytes: int
    seconds: float
    outages: tuple[Outage, ...]
    identity: dict
    settings: dict
    previous: dict
    restored: bool
    snapshot: Snapshot | None = field(default=None, repr=False)

    def __repr__(self) -> str:
        from imunoise import _summary

        return (f"Recording({self.path}: {self.bytes:,} bytes in "
                f"{_summary.duration(self.seconds)}, {len(self.outages)} port outages, "
                f"settings {'restored' if self.restored else 'kept'})")

    def _repr_html_(self) -> str:
        """The log, its size and length, the outages and whether the settings came back."""
        from imunoise import _summary

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


class _Recorder:
    def __init__(self, port, output, baud, wanted_options, keep_config, live) -> None:
        self.port = port
        self.baud = baud
        self.options = wanted_options
        self.keep_config = keep_config
        self.output = os.fspath(output)
        RawWriter.refuse_existing(self.output)  # before the sensor is touched
        self.writer: RawWriter | None = None  # created once the sensor answers
        self.live = live
        self.session: Session | None = None
        self.identity: dict = {}
        self.previous: dict = {}
        self.wanted: dict = {}
        self.outages: list[Outage] = []
        self.last_chunk = time.time()

    def connect(self, first: bool) -> bytes:
        """Open, pause, configure, resume; returns the first bytes of the record."""
        serial = open_port(self.port, self.baud)
        try:
            session = Session(serial)
            session.command("VNASY,0")
            try:
                if first:
                    self.identity = config.read_identity(session)
                    self.previous = config.read_outputs(session)
                    self.wanted = config.wanted_outputs(self.previous, **self.options)
                    if not output_rates({**self.previous, **self.wanted}):
                        raise ValueError("with these settings the sensor sends nothing "
                                         "(ASCII output off, no binary output): nothing to "
                                         "record")
                config.apply(session, self.wanted)
            except BaseException:
                if first:  # leave the sensor as it was, streaming
                    with contextlib.suppress(Exception):
                        config.restore(session, self.previous, self.wanted)
                        session.command("VNASY,1")
                raise
            session.command("VNASY,1")
        except BaseException:
            serial.close()
            raise
        self.session = session
        head, session.rest = session.rest, b""
        return head

    def meta(self, **extra) -> dict:
        settings = {**self.previous, **self.wanted}
        return {
            "port": os.fspath(self.port), "baud": self.baud, "identity": self.identity,
            "previous": {str(k): list(v) for k, v in self.previous.items()},
            "written": {str(k): list(v) for k, v in self.wanted.items()},
            "fs": _untimed_rate(settings),
            "ascii": ADOR_MESSAGES.get(int(settings.get(6, ("0",))[0]) if settings else 0),
            **extra,
        }

    def write(self, data: bytes) -> None:
        if data:
            now = time.time()
            self.writer.write(data, time.time_ns())
            self.last_chunk = now
            if self.live is not None:
                self.live.feed(data)

    def reconnect(self, stop) -> bool:
        """Reopen a vanished port until it answers (or ``stop``); records the outage."""
        start = self.last_chunk
        with contextlib.suppress(Exception):
            self.session.serial.close()
        self.session = None
        while not stop():
            try:
                first = self.connect(first=False)
            except Exception:  # the port is not back yet, or not answering yet
                time.sleep(RETRY_EVERY)
                continue
            outage = Outage(self.writer.size, round(start, 6), round(time.time(), 6))  # as kept
            self.writer.outage(outage.start, outage.end)
            self.outages.append(outage)
            if self.live is not None:
                self.live.outage()
            self.write(first)
            return True
        return False

    def finish(self) -> bool:
        """End the record at the echo of ``$VNASY,0``, restore, resume; True when the
        previous settings were restored."""
        if self.session is None:
            return False
        try:
            _, tail = self.session.command("VNASY,0")
            self.write(tail)
            restored = False
            if not self.keep_config and self.wanted:
                config.restore(self.session, self.previous, self.wanted)
                restored = True
            self.session.command("VNASY,1")
            return restored
        finally:
            self.session.serial.close()


def record(port, output, *, seconds: float | None = None, baud: int | str = 115200,
           ascii: str | None = None, rate: float | None = None, binary=(),
           crc: bool | None = None, keep_config: bool = False, live: bool | None = None,
           live_stream=None, stop: threading.Event | None = None) -> Recording:
    """Record the VN-100 on ``port`` into ``output`` until ``seconds`` pass, ``stop``
    is set or Ctrl-C.

    Parameters
    ----------
    port : str
        Serial port (``/dev/ttyUSB0``, ``COM3``).
    output : str or path-like
        The raw log to create (an existing file is refused); side files
        ``.times``, ``.gaps``, ``.meta.json`` beside it.
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

    Returns
    -------
    Recording
    """
    if seconds is not None and not seconds > 0:
        raise ValueError(f"seconds must be > 0; got {seconds!r}")
    stream = live_stream if live_stream is not None else sys.stdout
    if live is None:
        live = bool(getattr(stream, "isatty", lambda: False)())
    if baud == "auto":
        baud = find_baud(port)
    elif not isinstance(baud, int) or baud <= 0:
        raise ValueError(f"baud must be a positive integer or 'auto'; got {baud!r}")
    options = {"ascii": ascii, "rate": rate, "binary": tuple(binary), "crc": crc}
    config.wanted_outputs({}, **options)  # bad options fail before the port is opened
    rec = _Recorder(port, output, baud, options, keep_config, None)
    stop_event = stop or threading.Event()
    started = time.monotonic()

    def done() -> bool:
        return stop_event.is_set() or (seconds is not None
                                       and time.monotonic() - started >= seconds)

    snapshot, restored, signalled = None, False, []
    first = rec.connect(first=True)
    try:
        rec.writer = RawWriter(output)
        settings = {**rec.previous, **rec.wanted}
        began = time.time()
        rec.writer.write_meta(rec.meta(started=began))
        if live:
            rec.live = LiveView(rates=output_rates(settings), target=seconds, stream=stream)
        rec.write(first)
        with _signals_stop(stop_event) as signalled:
            while not done():
                try:
                    rec.write(rec.session.read())
                except (OSError, DeviceError) + _serial_errors():
                    if not rec.reconnect(done):
                        break
            with contextlib.suppress(OSError, DeviceError, *_serial_errors()):
                restored = rec.finish()
    finally:
        if rec.live is not None:
            snapshot = rec.live.close()
        if rec.writer is not None:
            rec.writer.close()
        elif rec.session is not None:
            rec.session.serial.close()
    elapsed = time.monotonic() - started
    rec.writer.write_meta(rec.meta(started=began, seconds=elapsed, bytes=rec.writer.size,
                                   outages=len(rec.outages), restored=restored))
    if signalled:  # SIGTERM: now that the record is complete, as it would have
        signal.raise_signal(signalled[0])
    return Recording(path=rec.writer.path, bytes=rec.writer.size, seconds=elapsed,
                     outages=tuple(rec.outages), identity=rec.identity,
                     settings={**rec.previous, **rec.wanted}, previous=rec.previous,
                     restored=restored, snapshot=snapshot)


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
