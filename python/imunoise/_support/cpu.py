"""The instruction-set level of the Rust kernels, and a one-line description of
the CPU for benchmarks to print beside their numbers.

The kernels dispatch at run time to the best level the CPU has (``scalar``,
``avx2``, ``avx512``, ``ifma``). ``IMUNOISE_SIMD=<level>`` in the environment
pins a lower one (a level above the CPU's runs as the CPU's). Every level gives
the same bits, except that Theo1's FFT sums from m = 256 on (and so ThêoBR and
ThêoH at long taus) agree between ``scalar`` and the others to a few ulps: the
FFT library's SSE and AVX kernels round differently.
"""

from __future__ import annotations

import os
import platform
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from imunoise._core import simd as _simd
from imunoise.errors import ImunoiseValueError

#: The environment variable that pins the level.
ENVIRONMENT = "IMUNOISE_SIMD"


def apply_environment() -> None:
    """Force the level named by ``IMUNOISE_SIMD``, if set."""
    name = os.environ.get(ENVIRONMENT, "").strip().lower()
    if not name:
        return
    if name not in _simd.levels():
        raise ImunoiseValueError(f"{ENVIRONMENT} must be one of {', '.join(_simd.levels())}; "
                         f"got {os.environ[ENVIRONMENT]!r}")
    _simd.force(name)


def level() -> str:
    """The level the kernels use now."""
    return _simd.level()


def available_levels() -> list[str]:
    """The levels this CPU can run, lowest first."""
    names = _simd.levels()
    return names[: names.index(_simd.detected()) + 1]


@contextmanager
def forced(name: str) -> Iterator[None]:
    """Run the block's kernels at level `name`; the level before is restored after."""
    before = _simd.level()
    pinned = before != _simd.detected()
    _simd.force(name)
    try:
        yield
    finally:
        _simd.force(before if pinned else None)


def _model_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def describe() -> str:
    """The CPU, its core count and the kernels' level, for a benchmark's header."""
    cpu = _simd.detected()
    running = _simd.level()
    pinned = "" if running == cpu else f" (pinned by {ENVIRONMENT}; the CPU has {cpu})"
    return f"{_model_name()}, {os.cpu_count()} cores, kernels: {running}{pinned}"
