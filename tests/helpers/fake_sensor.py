"""A fake VN-100 on a pseudo-terminal that misbehaves on demand (tests/faults).

Unlike the emulator (a faithful sensor), this one is built to fail: it answers
the register protocol from a small register file and streams ``$VNYMR`` at
register 7's rate while its output is on, and keeps every command it was sent
(``received``) so a test can check what the recorder did to it. Behaviours:

- ``refuse``: registers answered ``$VNERR,08`` (invalid register), as firmware
  without binary outputs answers 75–77;
- ``mute``: never answers nor streams (no reply);
- ``bad_checksums``: answers and streams with wrong checksums;
- ``echo_wrong``: registers whose write is stored but echoed with another value;
- ``error_on_write``: registers whose write is refused with ``$VNERR,07``;
- ``gone_after`` seconds after the first ``$VNASY,1``: the sensor goes for good,
  either ``gone="silent"`` (the port stays, nothing comes: a sensor without
  power behind its USB adapter) or ``gone="hangup"`` (the port disappears);
  with ``back_after`` (silent only) it answers and streams again that many
  seconds later.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import select
import threading
import time
import tty

from imunoise.recording.protocol import parse_reply, sentence

FACTORY = {1: ("VN-100T-CR",), 2: ("2",), 3: ("0100099999",), 4: ("1.0.0.0",),
           5: ("115200",), 6: ("14",), 7: ("40",), 30: ("0", "0", "0", "0", "1", "0", "1"),
           75: ("0", "0", "00"), 76: ("0", "0", "00"), 77: ("0", "0", "00")}
_YMR = ("VNYMR,-077.700,-001.300,+000.150,+0.0450,+0.2470,-0.3380,+00.000,+00.000,"
        "-09.807,+0.0000,+0.0000,+0.0000")


class FakeSensor:
    def __init__(self, path, *, refuse=(), mute=False, bad_checksums=False, echo_wrong=(),
                 error_on_write=(), gone_after: float | None = None, gone: str = "silent",
                 back_after: float | None = None):
        self.path = os.fspath(path)
        self.registers = dict(FACTORY)
        self.refuse, self.mute, self.bad = set(refuse), mute, bad_checksums
        self.echo_wrong, self.error_on_write = set(echo_wrong), set(error_on_write)
        self.gone_after, self.gone_kind, self.back_after = gone_after, gone, back_after
        self.back_at: float | None = None  # when it came back (time.time())
        self.received: list[str] = []  # every command's body, in order
        self.streaming = True
        self.resumed_at: float | None = None  # first $VNASY,1
        self.gone_at: float | None = None  # when it went (time.time())
        self.sent_lines = 0  # $VNYMR sentences sent
        self._inbox = bytearray()
        self._stop = threading.Event()
        master, slave = os.openpty()
        tty.setraw(slave)
        fcntl.fcntl(master, fcntl.F_SETFL, fcntl.fcntl(master, fcntl.F_GETFL) | os.O_NONBLOCK)
        self._master, self._slave = master, slave
        os.symlink(os.ttyname(slave), self.path)
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    # --- what a test looks at -----------------------------------------------------

    def writes(self) -> list[str]:
        return [c for c in self.received if c.startswith("VNWRG")]

    @property
    def gone(self) -> bool:
        return self.gone_at is not None and self.back_at is None

    # --- the sensor -------------------------------------------------------------------

    def _send(self, body: str) -> None:
        data = sentence(body)
        if self.bad:  # the checksum's bits flipped: it fails
            wrong = int(data[-4:-2], 16) ^ 0xFF
            data = data[:-4] + f"{wrong:02X}".encode() + b"\r\n"
        with contextlib.suppress(BlockingIOError, OSError):
            os.write(self._master, data)

    def _answer(self, line: bytes) -> None:
        reply = parse_reply(line)
        if reply is None:
            self._send("VNERR,03")
            return
        head, fields = reply.header, reply.fields
        reg = int(fields[0]) if fields and fields[0].isdigit() else None
        if head == "VNRRG" and reg in self.registers:
            if reg in self.refuse:
                self._send("VNERR,08")
            else:
                self._send(f"VNRRG,{reg:02d}," + ",".join(self.registers[reg]))
        elif head == "VNWRG" and reg in self.registers and reg > 4:
            if reg in self.refuse:
                self._send("VNERR,08")
            elif reg in self.error_on_write:
                self._send("VNERR,07")
            else:
                self.registers[reg] = tuple(fields[1:])
                echo = fields[1:]
                if reg in self.echo_wrong:
                    echo = (str(int(echo[0]) + 1), *echo[1:])
                self._send(f"VNWRG,{reg:02d}," + ",".join(echo))
        elif head == "VNASY" and fields in (("0",), ("1",)):
            self.streaming = fields[0] == "1"
            if self.streaming and self.resumed_at is None:
                self.resumed_at = time.monotonic()
            self._send(f"VNASY,{fields[0]}")
        else:
            self._send("VNERR,04")

    def _go(self) -> None:
        self.gone_at = time.time()
        if self.gone_kind == "hangup":
            os.unlink(self.path)
            for fd in (self._master, self._slave):
                os.close(fd)
            self._master = self._slave = -1

    def _run(self) -> None:
        due = time.monotonic()
        while not self._stop.is_set():
            if (self.gone_after is not None and self.gone_at is None
                    and self.resumed_at is not None
                    and time.monotonic() - self.resumed_at >= self.gone_after):
                self._go()
            if (self.back_after is not None and self.gone
                    and time.time() - self.gone_at >= self.back_after):
                self.back_at = time.time()
            if self._master < 0:
                time.sleep(0.01)
                continue
            readable, _, _ = select.select([self._master], [], [], 0.005)
            if readable:
                with contextlib.suppress(BlockingIOError, OSError):
                    self._inbox += os.read(self._master, 4096)
                while b"\n" in self._inbox:
                    line, _, rest = bytes(self._inbox).partition(b"\n")
                    self._inbox = bytearray(rest)
                    start = line.find(b"$")
                    if start < 0:
                        continue
                    body = line[start + 1:].split(b"*")[0].decode("ascii", "replace")
                    self.received.append(body)
                    if not self.mute and not self.gone:
                        self._answer(line[start:])
            now = time.monotonic()
            period = 1.0 / int(self.registers[7][0])
            if not self.streaming or self.mute or self.gone or self.registers[6][0] == "0":
                due = now + period
                continue
            while due <= now:
                self._send(_YMR)
                self.sent_lines += 1
                due += period

    def close(self) -> None:
        self._stop.set()
        self._thread.join()
        with contextlib.suppress(FileNotFoundError):
            os.unlink(self.path)
        for fd in (self._master, self._slave):
            if fd >= 0:
                os.close(fd)
        self._master = self._slave = -1
