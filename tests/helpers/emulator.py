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
