"""Argument checks shared by every module, so that one rule has one wording."""

from __future__ import annotations

import math
import numbers

import numpy as np

from imunoise.errors import ImunoiseTypeError, ImunoiseValueError


def positive_finite(value, name: str, *, unit: str | None = None) -> float:
    """``value`` as a float, or ``TypeError``/``ValueError`` naming ``name``.

    Booleans are rejected although Python counts them as numbers: ``fs=True`` is
    a mistake, not 1 Hz.
    """
    of_unit = f" of {unit}" if unit else ""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ImunoiseTypeError(
            f"{name} must be a real number{of_unit}; got {type(value).__name__} {value!r}"
        )
    number = float(value)
    if not (math.isfinite(number) and number > 0):
        in_unit = f" ({unit})" if unit else ""
        raise ImunoiseValueError(f"{name} must be positive and finite{in_unit}; got {value!r}")
    return number


def sample_rate(fs, name: str = "fs") -> float:
    """A sample rate in Hz as a float: a real number, positive and finite."""
    return positive_finite(fs, name, unit="Hz")


def integer(value, name: str, minimum: int) -> int:
    """``value`` as an int of at least ``minimum`` (bools are not integers here)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ImunoiseTypeError(f"{name} must be an integer; got {value!r}")
    if value < minimum:
        raise ImunoiseValueError(f"{name} must be >= {minimum}; got {value!r}")
    return int(value)


def samples(x, name: str = "x") -> tuple[np.ndarray, bool]:
    """float64 ``(n, channels)`` view or copy of samples ``x`` (NaN = missing), and
    whether ``x`` was 1-D."""
    arr = x if isinstance(x, np.ndarray) else np.asarray(x)
    if arr.dtype.kind not in "iuf":
        raise ImunoiseTypeError(f"{name} must be an array of real numbers; got dtype {arr.dtype}")
    if arr.ndim not in (1, 2):
        raise ImunoiseValueError(
            f"{name} must be 1-D (n,) or 2-D (n, channels); got {arr.ndim}-D shape {arr.shape}"
        )
    if arr.shape[0] == 0:
        raise ImunoiseValueError(f"{name} must not be empty; got 0 samples")
    if arr.ndim == 2 and arr.shape[1] == 0:
        raise ImunoiseValueError(f"{name} must have at least one channel; got shape {arr.shape}")
    data = arr.astype(np.float64, copy=False)
    return (data[:, None], True) if data.ndim == 1 else (data, False)


def no_infinity(data: np.ndarray, name: str = "x") -> None:
    """``ValueError`` naming the first ±inf sample of ``data`` (NaN, a missing sample,
    is allowed)."""
    bad = np.isinf(data)
    if bad.any():
        first = np.argwhere(bad)[0]
        raise ImunoiseValueError(f"{name} must be finite or NaN (a missing sample); sample "
                         f"{int(first[0])} is {data[tuple(first)]}")


def confidence_level(value) -> float:
    """A two-sided confidence level in (0, 1) as a float."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ImunoiseTypeError(f"confidence must be a number in (0, 1); got {value!r}")
    level = float(value)
    if not 0.0 < level < 1.0:
        raise ImunoiseValueError(f"confidence must be in (0, 1); got {value!r}")
    return level
