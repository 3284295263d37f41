"""Recorder tests run against the VN-100 emulator on a pseudo-terminal."""

from __future__ import annotations

import sys

import pytest

pytest.importorskip("serial", reason="imunoise record needs pyserial (the test extra has it)")
if not sys.platform.startswith("linux"):
    pytest.skip("the emulator needs Linux pseudo-terminals", allow_module_level=True)

from imunoise.emulate import Emulator  # noqa: E402


@pytest.fixture
def emulator(tmp_path):
    """``emulator(**options)`` starts one at tmp_path/port; all are closed after the test."""
    started = []

    def start(**options) -> Emulator:
        emu = Emulator(tmp_path / f"port{len(started)}", **options)
        started.append(emu)
        return emu

    yield start
    for emu in started:
        emu.close()
