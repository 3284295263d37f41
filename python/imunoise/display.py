"""Numbers as text: a value with its uncertainty, GUM style, in one place.

The standard uncertainty is rounded to two significant digits and the value to
the same decimal place ("0.21004 ± 0.000112762" → "0.21004 ± 0.00011"). When
plain decimals get unreadable (magnitude below 1e-2 or at least 1e5) value and
uncertainty share a power of ten: "(3.50 ± 0.12)e-3". A value without an
uncertainty is printed to ``digits`` significant digits. NaN, inf and missing
values print as a word, never as "nan".

Text only: exports (YAML/JSON) keep full-precision numbers, they are data.
"""
from __future__ import annotations

import math

from imunoise.errors import ImunoiseValueError

#: The word for a value that could not be estimated (e.g. an unresolved term).
NOT_RESOLVED = "not resolved"
#: The word for an empty table cell.
EMPTY = "—"
#: Units as logs and arguments spell them in ASCII, and the symbols every table, caption
#: and figure writes instead: one spelling of a unit wherever a reader meets it.
UNIT_SYMBOLS = (("m/s^2", "m/s²"), ("m/s^3", "m/s³"), ("sqrt(Hz)", "√Hz"), ("sqrt(h)", "√h"),
                ("sqrt(s)", "√s"), ("deg/s", "°/s"), ("deg/h", "°/h"))


def _finite(x) -> bool:
    return x is not None and math.isfinite(float(x))


def _exponent(x: float) -> int:
    return math.floor(math.log10(abs(x)))


def _plain(x: float) -> bool:
    return x == 0 or 1e-2 <= abs(x) < 1e5


#: Relative uncertainty below which a value prints without it: beyond what a double's
#: 15–16 digits carry.
RESOLUTION = 1e-13


def format_value(value, std=None, *, unit: str | None = None, digits: int = 4,
                 missing: str = NOT_RESOLVED) -> str:
    """``value ± std`` rounded GUM style, or ``value`` to ``digits`` significant digits.

    ``std`` None, NaN, inf or ≤ 0 means no usable uncertainty, and so does one below
    :data:`RESOLUTION` of the value (rounding error of a constant's mean: its
    digits would run to the end of the float). A non-finite or None ``value``
    gives ``missing``. ``unit`` is appended after a space.
    """
    if not isinstance(digits, int) or digits < 1:
        raise ImunoiseValueError(f"digits must be a positive integer; got {digits!r}")
    if not _finite(value):
        return missing
    value = float(value)
    if _finite(std) and float(std) > RESOLUTION * abs(value):
        text = _with_uncertainty(value, float(std))
    else:
        text = _significant(value, digits)
    return f"{text} {unit}" if unit else text


def duration(seconds) -> str:
    """A time as a person reads it, three significant digits in the unit that suits
    its length: ``"0 s"``, ``"40 µs"`` (below 1 ms), ``"10 ms"`` (below 1 s),
    ``"12.5 s"``, ``"5.51 min"`` (from 2 min), ``"3.2 h"`` (from 2 h); ``—`` when
    not finite. The unit is chosen after rounding (0.9996 s is "1 s", not "1e+03 ms")."""
    if not _finite(seconds):
        return EMPTY
    t = float(seconds)
    if t == 0:
        return "0 s"
    for limit, scale, unit in ((1e-3, 1e-6, "µs"), (1.0, 1e-3, "ms"), (120.0, 1.0, "s"),
                               (7200.0, 60.0, "min")):
        if abs(float(f"{t:.3g}")) < limit:
            return f"{t / scale:.3g} {unit}"
    return f"{t / 3600.0:.3g} h"


def rounded(value, std=None, *, digits: int = 4, missing: str = EMPTY) -> str:
    """``value`` alone, rounded to the decimal place :func:`format_value` gives it
    beside ``std`` ("0.21004" for 0.2100438 ± 0.000112762, "3.50e-3" for
    (3.50 ± 0.12)e-3): for figure titles and short text where the ``±`` part would not
    fit. Without a usable ``std``, ``digits`` significant digits."""
    text = format_value(value, std, digits=digits, missing=missing)
    if " ± " not in text:
        return text
    head, tail = text.split(" ± ")
    if head.startswith("("):  # "(3.50 ± 0.12)e-3"
        return _normalised(head[1:], int(tail[tail.index(")") + 2:]))
    return head


def _normalised(mantissa: str, power: int) -> str:
    """``"0.6", -5`` -> ``"6e-6"``: a value smaller than its uncertainty shares the
    uncertainty's power of ten in ``(0.6 ± 1.2)e-5``; alone it is written with a
    mantissa from 1 to 10, keeping its decimal place."""
    sign = "-" if mantissa.startswith("-") else ""
    digits = mantissa.lstrip("-")
    whole, _, frac = digits.partition(".")
    if whole != "0" or not frac.strip("0"):
        return f"{mantissa}e{power}" if frac.strip("0") or whole != "0" else "0"
    shift = len(frac) - len(frac.lstrip("0")) + 1  # 0.06 -> 6: two places
    rest = frac[shift - 1:]
    text = rest[0] + ("." + rest[1:] if len(rest) > 1 else "")
    return f"{sign}{text}e{power - shift}"


def _significant(value: float, digits: int) -> str:
    if value == 0:
        return "0"
    # Without an uncertainty trailing zeros carry no information: drop them ("250", not "250.0").
    if _plain(value):
        decimals = max(digits - 1 - _exponent(value), 0)
        return _strip(f"{value:.{decimals}f}")
    mant, exp = f"{value:.{digits - 1}e}".split("e")
    return f"{_strip(mant)}e{int(exp)}"


def _strip(text: str) -> str:
    return text.rstrip("0").rstrip(".") if "." in text else text


def _with_uncertainty(value: float, std: float) -> str:
    # Two significant digits of the uncertainty; the value to the same place.
    place = _exponent(std) - 1
    std_r = round(std, -place)
    if std_r >= 10.0 ** (place + 2):        # 0.0999 rounds to 0.10: one place less
        place += 1
        std_r = round(std, -place)
    ref = value if abs(value) >= std_r else std_r
    if _plain(ref) and place >= -6:
        decimals = max(-place, 0)
        v = round(value, -place)
        return f"{v:.{decimals}f} ± {std_r:.{decimals}f}"
    power = _exponent(ref)
    scale = 10.0 ** power
    decimals = max(power - place, 0)
    return f"({value / scale:.{decimals}f} ± {std_r / scale:.{decimals}f})e{power}"


def interval_cells(value, low, high) -> tuple[str, str, str]:
    """``value`` and its confidence bounds as three cells, GUM style: all three to
    the decimal place of two significant digits of the shorter arm of the
    interval (``min(value - low, high - value)``), in ``1.2345e-04`` notation so a
    column of deviations spanning decades stays readable and machine-parseable.
    Without a usable interval the value keeps four significant digits; a
    non-finite entry is ``—``."""
    arms = [float(value) - float(low), float(high) - float(value)] if all(
        _finite(v) for v in (value, low, high)) else []
    arm = min(arms) if arms and min(arms) > 0 else None
    place = None if arm is None else _exponent(arm) - 1

    def one(v) -> str:
        if not _finite(v):
            return EMPTY
        v = float(v)
        if v == 0:
            return "0"
        digits = 4 if place is None else max(_exponent(v) - place + 1, 1)
        return f"{v:.{digits - 1}e}"

    return one(value), one(low), one(high)


def upper_bound(bound, *, digits: int = 3) -> str:
    """A value the data do not resolve: ``< bound`` (its upper bound to ``digits``
    significant digits), or ``not resolved`` where there is no bound."""
    if not _finite(bound):
        return NOT_RESOLVED
    return f"< {_significant(float(bound), digits)}"


def cell(value, std=None, *, digits: int = 4) -> str:
    """A table cell: as :func:`format_value`, with "—" for a missing value."""
    return format_value(value, std, digits=digits, missing=EMPTY)


def unit_symbols(unit: str) -> str:
    """A unit as tables and figures write it: ``"m/s^2"`` is ``"m/s²"``,
    ``"deg/h/sqrt(Hz)"`` is ``"°/h/√Hz"`` (:data:`UNIT_SYMBOLS`); other text unchanged."""
    for ascii_, symbol in UNIT_SYMBOLS:
        unit = unit.replace(ascii_, symbol)
    return unit


def percent(fraction, *, digits: int = 0) -> str:
    """A fraction as a percentage, written as the SI writes it, with a space before
    the sign: ``percent(0.6827, digits=1)`` is ``"68.3 %"``, ``percent(1.0)`` is
    ``"100 %"``; "—" when not finite. One spelling for every percentage of the report,
    its figures and the command line (``f"{x:.0%}"`` leaves the space out)."""
    if not _finite(fraction):
        return EMPTY
    if isinstance(digits, bool) or not isinstance(digits, int) or digits < 0:
        raise ImunoiseValueError(f"digits must be an integer >= 0; got {digits!r}")
    return f"{100.0 * float(fraction):.{digits}f} %"
