"""Helpers of the recorder tests (tests/record): the emulator's side of a record."""

from __future__ import annotations

#: Binary output used across the tests: TimeStartup, YPR, rate, accel, mag/temp/pressure.
FULL = "common=TimeStartup+YawPitchRoll+AngularRate+Accel+MagPres"


def record_slice(emu, asy1: int = 0, asy0: int = 1) -> bytes:
    """The bytes the emulator sent from just after its ``asy1``-th ``$VNASY,1`` echo
    to just after its ``asy0``-th ``$VNASY,0`` echo (0-based among those kinds)."""
    sent = emu.sent_bytes()
    start = [e.offset for e in emu.events if e.kind == "asy1"][asy1]
    end = [e.offset for e in emu.events if e.kind == "asy0"][asy0]
    return sent[start:end]


def stop_after(emu, seconds: float):
    """An Event set once the emulator's clock is ``seconds`` past the start of the
    record (its first ``$VNASY,1``): records of a given sensor length, whatever the
    speed the machine allows."""
    import threading
    import time

    stop = threading.Event()

    def watch() -> None:
        while not any(e.kind == "asy1" for e in emu.events):
            time.sleep(0.01)
        start = next(e.tick for e in emu.events if e.kind == "asy1")
        while emu.tick - start < seconds * 800 and not stop.is_set():
            time.sleep(0.01)
        stop.set()

    threading.Thread(target=watch, daemon=True).start()
    return stop
