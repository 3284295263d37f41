"""Argument checks shared by every module, so that one rule has one wording."""

from __future__ import annotations

import math
import numbers


def positive_finite(value, name: str, *, unit: str | None = None) -> float:
    """``value`` as a float, or ``TypeError``/``ValueError`` naming ``name``.

    Booleans are rejected although Python counts them as numbers: ``fs=True`` is
    a mistake, not 1 Hz.
    """
    of_unit = f" of {unit}" if unit else ""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(
            f"{name} must be a real number{of_unit}; got {type(value).__name__} {value!r}"
        )
    number = float(value)
    if not (math.isfinite(number) and number > 0):
        in_unit = f" ({unit})" if unit else ""
        raise ValueError(f"{name} must be positive and finite{in_unit}; got {value!r}")
    return number


def sample_rate(fs, name: str = "fs") -> float:
    """A sample rate in Hz as a float: a real number, positive and finite."""
    return positive_finite(fs, name, unit="Hz")


def integer(value, name: str, minimum: int) -> int:
    """``value`` as an int of at least ``minimum`` (bools are not integers here)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer; got {value!r}")
    if value < minimum:
        raise ValueError(f"{name} must be >= {minimum}; got {value!r}")
    return int(value)
