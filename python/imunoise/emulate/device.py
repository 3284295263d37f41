"""A VN-100 on a pseudo-terminal: ``Emulator(path)`` makes ``path`` a serial port.

One thread runs the sensor: it answers commands read from the pty (``$VNRRG``,
``$VNWRG``, ``$VNASY``, ``$VNWNV``, ``$VNRST``; ``$VNERR`` for anything else or a
bad checksum) and streams the configured outputs at ``speed`` times real time.
Unlike a UART, a pty has flow control: when the reader falls behind, the
emulator waits instead of dropping bytes, so every byte it sent (``sent``) is one
the reader could have read. A client whose baud rate (termios) is not the
sensor's register 5 reads garbage, as on a real port.

Faults on demand (:class:`Fault`), after so many seconds of output from the
first ``$VNASY,1`` (which ``imunoise record`` sends when its record starts):
``corrupt`` flips one byte inside the next record; ``pause`` stops the output
for ``seconds`` (the clock runs on: a gap in ``TimeStartup``); ``vanish`` removes
the port for ``seconds`` (the reader's fd hangs up; the pty comes back at the
same path); ``reset`` restarts the sensor's clock (``TimeStartup`` from 0, the
settings kept, as a sensor whose settings are saved in flash). Every fault and
every ``$VNASY`` is logged in ``events`` with its offset in ``sent``.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import select
import termios
import threading
import time
import tty
from dataclasses import dataclass, field

from imunoise.emulate.outputs import SampleSource, check_selection, encode
from imunoise.emulate.registers import IMU_RATE, RegisterError, Registers
from imunoise.errors import ImunoiseValueError
from imunoise.recording.protocol import parse_reply, sentence

__all__ = ["FAULT_KINDS", "MAX_SPEED", "Emulator", "Event", "Fault"]

FAULT_KINDS = ("corrupt", "pause", "vanish", "reset")
#: Output bytes queued before the emulator waits for the reader.
_QUEUE = 1 << 16
#: Longest sensor time generated per step (s) at real time (x speed / 2 when faster).
_STEP = 0.02
#: Byte of a record flipped by a ``corrupt`` fault (inside the fields / payload).
_CORRUPT_AT = 10
#: Fastest time compression (sensor seconds per wall second): an hour of sensor
#: time in 3.6 s, 800 000 IMU samples a second, already more than a pty carries
#: at 800 Hz binary; a bound also keeps the sensor's clock finite.
MAX_SPEED = 1000.0
#: Latest fault time and longest pause or vanish (s of sensor time): a year.
MAX_FAULT_SECONDS = 365 * 86400.0


@dataclass(frozen=True)
class Fault:
    """A fault after ``at`` seconds of output: sensor time while the output is on,
    counted from the first ``$VNASY,1`` (the start of a recorder's record: the
    faults wait for it); ``seconds`` of sensor time for pause/vanish."""

    kind: str
    at: float
    seconds: float = 0.0

    def __post_init__(self) -> None:
        if self.kind not in FAULT_KINDS:
            raise ImunoiseValueError(f"fault kind must be one of {FAULT_KINDS}; got {self.kind!r}")
        # bounded: a wait beyond the thread's longest timeout (2^63 ns) killed the thread
        if not 0 <= self.at <= MAX_FAULT_SECONDS:
            raise ImunoiseValueError(f"fault time must be within 0 ... {MAX_FAULT_SECONDS:g} s; "
                             f"got {self.at!r}")
        if self.kind in ("pause", "vanish") and not 0 < self.seconds <= MAX_FAULT_SECONDS:
            raise ImunoiseValueError(f"a {self.kind} fault needs seconds within (0, "
                             f"{MAX_FAULT_SECONDS:g}]; got {self.seconds!r}")


@dataclass(frozen=True)
class Event:
    """Something the emulator did: a fault or a ``$VNASY`` (``kind`` "asy0"/"asy1"),
    at ``offset`` in ``sent`` (a fault: the first record it touches, for ``corrupt``
    the damaged one; an ASY: just after its echo) and IMU tick ``tick`` (the first
    tick the fault touches)."""

    kind: str
    offset: int
    tick: int
    seconds: float = 0.0


_SPEEDS = {getattr(termios, f"B{b}"): b for b in (9600, 19200, 38400, 57600, 115200, 230400,
                                                  460800, 921600)}


@dataclass
class _State:
    registers: Registers = field(default_factory=Registers)
    streaming: bool = True
    tick: int = 0  # next IMU tick to send
    streamed: int = 0  # ticks passed while the output was on (the faults' clock)
    resumed: bool = False  # a client sent $VNASY,1 (the faults' clock restarted then)
    clock_zero: int = 0  # tick of the last reset
    silent_until: int = -1  # pause / vanish: no output before this tick


class Emulator:
    """An emulated VN-100 serving the pty at ``path`` (a symlink) until :meth:`close`.

    Parameters
    ----------
    path : str or path-like
        Where the port appears (a symlink to ``/dev/pts/N``); must not exist.
    speed : float
        Sensor seconds per wall second (time compression), > 0 and at most
        :data:`MAX_SPEED`.
    seed : int, optional
        Seed of the simulated samples.
    faults : sequence of Fault
    keep_sent : bool
        Keep every byte sent in ``sent`` (tests); off for long demos.
    baud : int
        The sensor's baud rate (register 5); a client at another rate reads garbage.
    """

    def __init__(self, path, *, speed: float = 1.0, seed=None, faults=(), keep_sent=True,
                 baud: int = 115200):
        if not (isinstance(speed, int | float) and 0 < speed <= MAX_SPEED):
            raise ImunoiseValueError(f"speed must be a number of sensor seconds per wall second "
                             f"in (0, {MAX_SPEED:g}]; got {speed!r}")
        self.path = os.fspath(path)
        if os.path.lexists(self.path):
            raise ImunoiseValueError(f"path {self.path!r} exists; the emulator makes it")
        self.speed = float(speed)
        self.faults = sorted(faults, key=lambda f: f.at)
        self.sent = bytearray()
        self.bytes_sent = 0
        self.events: list[Event] = []
        self._keep = keep_sent
        self._state = _State()
        self._state.registers.write(5, (str(baud),))
        self._source = SampleSource(seed)
        self._out = bytearray()
        self._inbox = bytearray()
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self._master = self._slave = -1
        self.error: BaseException | None = None  # what stopped the sensor's thread
        self._open_pty()
        self._thread = threading.Thread(target=self._run, name="vn100-emulator", daemon=True)
        self._started = time.monotonic()
        self._thread.start()

    # --- the pty -----------------------------------------------------------------------

    def _open_pty(self) -> None:
        master, slave = os.openpty()
        tty.setraw(slave)  # no echo or line editing before a client sets its own mode
        attrs = termios.tcgetattr(slave)
        attrs[4] = attrs[5] = termios.B115200
        termios.tcsetattr(slave, termios.TCSANOW, attrs)
        fcntl.fcntl(master, fcntl.F_SETFL, fcntl.fcntl(master, fcntl.F_GETFL) | os.O_NONBLOCK)
        self._master, self._slave = master, slave
        os.symlink(os.ttyname(slave), self.path)  # the port appears (it was removed)

    def _close_pty(self) -> None:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(self.path)
        for fd in (self._master, self._slave):
            if fd >= 0:
                os.close(fd)
        self._master = self._slave = -1
        self._out.clear()
        self._inbox.clear()

    def _client_baud(self) -> int | None:
        try:
            return _SPEEDS.get(termios.tcgetattr(self._slave)[5])
        except termios.error:
            return None

    def _pending_for_client(self) -> int:
        """Bytes written to the pty that the client has not read yet."""
        buf = fcntl.ioctl(self._slave, termios.FIONREAD, b"\0\0\0\0")
        return int.from_bytes(buf, "little")

    # --- output ------------------------------------------------------------------------

    def _queue(self, data: bytes) -> int:
        """Queue bytes to send; returns their offset in ``sent``."""
        if self._client_baud() != self._state.registers.values[5][0]:
            data = bytes(b ^ 0xA5 for b in data)  # what a wrong baud rate reads
        offset = self.bytes_sent + len(self._out)
        self._out += data
        return offset

    def _flush(self, wait: float) -> None:
        if not self._out:
            return
        _, writable, _ = select.select([], [self._master], [], wait)
        if not writable:
            return
        try:
            n = os.write(self._master, self._out[:_QUEUE])
        except BlockingIOError:
            return
        with self._lock:
            if self._keep:
                self.sent += self._out[:n]
            self.bytes_sent += n
        del self._out[:n]

    # --- commands ----------------------------------------------------------------------

    def _reply(self, body: str) -> int:
        return self._queue(sentence(body, crc=self._state.registers.crc))

    def _error(self, code: int) -> None:
        if self._state.registers.send_errors:
            self._reply(f"VNERR,{code:02X}")

    def _command(self, line: bytes) -> None:
        start = line.find(b"$")
        if start < 0:
            return
        reply = parse_reply(line[start:])
        if reply is None:
            self._error(0x03)
            return
        regs, state = self._state.registers, self._state
        head, fields = reply.header, reply.fields
        try:
            if head == "VNRRG" and len(fields) == 1 and fields[0].isdigit():
                self._reply(f"VNRRG,{int(fields[0]):02d},{regs.read(int(fields[0]))}")
            elif head == "VNWRG" and fields and fields[0].isdigit():
                reg = int(fields[0])
                old = dict(regs.values)
                echo = regs.write(reg, fields[1:])
                try:
                    check_selection(regs, self._source)
                except ValueError:
                    regs.values = old
                    raise RegisterError(0x07) from None
                self._reply(f"VNWRG,{reg:02d},{echo}")
            elif head == "VNASY" and fields in (("0",), ("1",)):
                state.streaming = fields[0] == "1"
                if state.streaming and not state.resumed:
                    state.resumed, state.streamed = True, 0
                offset = self._reply(f"VNASY,{fields[0]}")
                end = offset + len(sentence(f"VNASY,{fields[0]}", crc=regs.crc))
                self._log(Event(f"asy{fields[0]}", end, state.tick))
            elif head in ("VNWNV", "VNRST") and not fields:
                self._reply(head)
            else:
                raise RegisterError(0x04 if head not in ("VNRRG", "VNWRG", "VNASY") else 0x07)
        except RegisterError as exc:
            self._error(exc.code)

    def _read_commands(self) -> None:
        try:
            data = os.read(self._master, 4096)
        except (BlockingIOError, OSError):
            return
        if self._client_baud() != self._state.registers.values[5][0]:
            return  # garbage at the wrong baud rate
        self._inbox += data
        while b"\n" in self._inbox:
            line, _, rest = bytes(self._inbox).partition(b"\n")
            self._inbox = bytearray(rest)
            self._command(line)

    # --- the sensor loop ---------------------------------------------------------------

    def _log(self, event: Event) -> None:
        with self._lock:
            self.events.append(event)

    def _due_tick(self) -> int:
        return int((time.monotonic() - self._started) * self.speed * IMU_RATE)

    def _fault(self, fault: Fault, records: list[bytes], start: int, stop: int) -> list[bytes]:
        state = self._state
        offset = self.bytes_sent + len(self._out)
        if fault.kind == "corrupt" and records:
            rec = bytearray(records[0])
            at = min(_CORRUPT_AT, len(rec) - 3)
            rec[at] ^= 0x01
            records = [bytes(rec), *records[1:]]
        elif fault.kind in ("pause", "vanish"):
            state.silent_until = start + round(fault.seconds * IMU_RATE)
            records = []
        elif fault.kind == "reset":
            state.clock_zero = start
            records = encode(state.registers, self._source, start, stop, state.clock_zero)
        self._log(Event(fault.kind, offset, start, fault.seconds))
        if fault.kind == "vanish":
            self._vanish(fault.seconds)
        return records

    def _vanish(self, seconds: float) -> None:
        while self._out and not self._stop.is_set():
            self._flush(0.05)
        # Let the client read what it was sent: bytes written to the master reach the
        # slave's queue a moment later, so the queue must stay empty for a while.
        deadline = time.monotonic() + 2.0
        empty_since = time.monotonic()
        while time.monotonic() < deadline:
            if self._pending_for_client():
                empty_since = time.monotonic()
            elif time.monotonic() - empty_since > 0.1:
                break
            time.sleep(0.005)
        self._close_pty()
        self._stop.wait(seconds / self.speed)
        if not self._stop.is_set():
            self._open_pty()

    def _step(self) -> None:
        state = self._state
        if not state.streaming:  # the clock runs on while the output is paused
            state.tick = max(state.tick, self._due_tick())
            return
        longest = round(max(_STEP, _STEP * self.speed / 2) * IMU_RATE)  # fewer, longer steps
        stop = min(self._due_tick(), state.tick + longest)
        if stop <= state.tick or len(self._out) >= _QUEUE:
            return
        start, state.tick = state.tick, stop
        if start < state.silent_until:
            start = min(state.silent_until, stop)
        if start >= stop:
            return
        records = encode(state.registers, self._source, start, stop, state.clock_zero)
        state.streamed += stop - start
        while state.resumed and self.faults and self.faults[0].at * IMU_RATE < state.streamed:
            if self.faults[0].kind == "corrupt" and not records:
                # a step too short to hold a record (a fast loop, a slow output): the
                # fault waits for one, else it was logged with nothing damaged
                break
            records = self._fault(self.faults.pop(0), records, start, stop)
            if self._master < 0:
                return
        self._queue(b"".join(records))

    def _run(self) -> None:
        # an exception would end the thread silently and leave a port that no longer
        # answers: it is kept for :attr:`alive` and the caller (``imunoise emulate``)
        try:
            self._serve()
        except BaseException as exc:  # noqa: BLE001 - reported through self.error
            self.error = exc

    def _serve(self) -> None:
        while not self._stop.is_set() and self._master >= 0:
            self._step()
            if self._master < 0:  # the port vanished and the emulator was stopped meanwhile
                break
            wait = 0.0 if self._out else min(0.01, 1 / (self.speed * IMU_RATE) + 0.002)
            readable, _, _ = select.select([self._master], [], [], wait)
            if readable:
                self._read_commands()
            self._flush(0.0 if readable else 0.005)

    # --- lifetime ----------------------------------------------------------------------

    @property
    def registers(self) -> dict[int, tuple]:
        """A copy of the register file (what the sensor is set to now)."""
        with self._lock:
            return dict(self._state.registers.values)

    @property
    def tick(self) -> int:
        """The next IMU tick the sensor will send (800 per sensor second)."""
        return self._state.tick

    @property
    def alive(self) -> bool:
        """The sensor still runs (False once closed or after :attr:`error`)."""
        return self._thread.is_alive()

    def sent_bytes(self) -> bytes:
        """A copy of every byte sent so far."""
        with self._lock:
            return bytes(self.sent)

    def close(self) -> None:
        """Stop the sensor and remove the port."""
        self._stop.set()
        self._thread.join()
        self._close_pty()

    def __enter__(self) -> Emulator:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
