"""Fault tests: imunoise record against fake sensors that misbehave (pseudo-terminals)."""

from __future__ import annotations

import sys

import pytest

pytest.importorskip("serial", reason="imunoise record needs pyserial (the test extra has it)")
if not sys.platform.startswith("linux"):
    pytest.skip("the fake sensors need Linux pseudo-terminals", allow_module_level=True)

from helpers.fake_sensor import FakeSensor  # noqa: E402


@pytest.fixture
def fake_sensor(tmp_path):
    """``fake_sensor(**behaviour)`` starts one at tmp_path/sensorN; all closed after."""
    started = []

    def start(**behaviour) -> FakeSensor:
        fake = FakeSensor(tmp_path / f"sensor{len(started)}", **behaviour)
        started.append(fake)
        return fake

    yield start
    for fake in started:
        fake.close()
