"""The instruction-set level of the Rust kernels: pinned by IMUNOISE_SIMD, forced
and restored by the tests' context manager, never above the CPU's."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
from imunoise._core import simd
from imunoise._support import cpu as _cpu


def _level_in_child(value: str) -> subprocess.CompletedProcess:
    env = {**os.environ, _cpu.ENVIRONMENT: value}
    code = "import imunoise._support.cpu as c; print(c.level())"
    return subprocess.run([sys.executable, "-c", f"import imunoise; {code}"],
                          env=env, capture_output=True, text=True, timeout=120)


def test_the_environment_pins_the_level():
    run = _level_in_child("scalar")
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "scalar"


def test_an_unknown_level_in_the_environment_is_named():
    run = _level_in_child("sse9")
    assert run.returncode != 0
    assert "IMUNOISE_SIMD must be one of scalar, avx2, avx512, ifma; got 'sse9'" in run.stderr


def test_forced_restores_the_level_before():
    before = _cpu.level()
    with _cpu.forced("scalar"):
        assert _cpu.level() == "scalar"
    assert _cpu.level() == before == simd.detected()


def test_a_level_above_the_cpus_runs_as_the_cpus():
    with _cpu.forced("ifma"):
        assert _cpu.level() == simd.detected()
    assert _cpu.available_levels()[-1] == simd.detected()


def test_force_names_an_unknown_level():
    with pytest.raises(ValueError, match="SIMD level must be one of .*got \"avx1024\""):
        simd.force("avx1024")


def test_describe_names_the_running_level():
    with _cpu.forced("scalar"):
        line = _cpu.describe()
    assert "kernels: scalar" in line
    if simd.detected() != "scalar":
        assert f"the CPU has {simd.detected()}" in line
