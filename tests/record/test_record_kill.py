"""kill -9 of a recording process loses at most the last second."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import imunoise
from helpers.emulator import FULL, record_slice

ROOT = Path(__file__).resolve().parents[2]
RATE = 200  # Hz of the binary output


def test_kill_9_loses_at_most_one_second(emulator, tmp_path):
    emu = emulator(speed=1, seed=7)
    out = tmp_path / "killed.vn"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(ROOT / "python"), os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.Popen(
        [sys.executable, "-m", "imunoise.cli", "record", emu.path, "-o", str(out),
         "--ascii", "off", "--binary", f"{RATE}:{FULL}"],
        env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        # wait until the record runs (waiting on progress, not asserting a time)
        for _ in range(600):
            if any(e.kind == "asy1" for e in emu.events) and out.exists() \
                    and out.stat().st_size > 2 * RATE * 60:
                break
            time.sleep(0.05)
        time.sleep(1.0)
        proc.send_signal(signal.SIGKILL)
        killed_at = emu.tick  # the sensor's clock (800 ticks/s) when the recorder died
        proc.wait(timeout=10)
    finally:
        if proc.poll() is None:
            proc.kill()
    raw = out.read_bytes()
    start = next(e.offset for e in emu.events if e.kind == "asy1")
    assert emu.sent_bytes()[start:start + len(raw)] == raw  # a prefix of what was sent
    log = imunoise.read(out)
    assert log.issues.total <= 1  # at most the packet the kill cut
    lost = killed_at / 800 - (log.time[-1] + 1 / RATE)
    assert lost <= 1.0, f"lost {lost:.3f} s of record"


def test_sigterm_ends_the_record_cleanly_and_restores(emulator, tmp_path):
    emu = emulator(speed=5, seed=8)
    before = emu.registers
    out = tmp_path / "terminated.vn"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(ROOT / "python"), os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.Popen(
        [sys.executable, "-m", "imunoise.cli", "record", emu.path, "-o", str(out),
         "--ascii", "VNIMU", "--rate", "50"],
        env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        for _ in range(600):
            if any(e.kind == "asy1" for e in emu.events) and out.exists() \
                    and out.stat().st_size > 10_000:
                break
            time.sleep(0.05)
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=30) == 143
    finally:
        if proc.poll() is None:
            proc.kill()
    assert emu.registers == before  # restored on the way out
    raw = out.read_bytes()
    assert raw == record_slice(emu) and raw.endswith(b"$VNASY,0*4F\r\n")
