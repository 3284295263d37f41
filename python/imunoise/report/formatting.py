"""How the report (and ``imunoise``'s command line) writes numbers, durations,
term counts and missing samples as text."""

from __future__ import annotations

import numpy as np

from imunoise import display as _display

__all__ = ["DOCS_URL", "docs_link", "format_duration", "format_number", "format_three",
           "gap_note", "missing_text", "terms_used", "unit_text"]


#: The documentation site; the report links its pages (a wheel user has no ``docs/``
#: folder). The one place the address is written.
DOCS_URL = "https://imunoise.readthedocs.io/en/latest/"


def docs_link(page: str, text: str | None = None) -> str:
    """A Markdown link to a page of the documentation site: ``docs_link("gaps")``
    -> ``"[gaps](https://…/gaps.html)"`` (the report's HTML renders it too)."""
    return f"[{text or page} documentation]({DOCS_URL}{page}.html)"


def unit_text(unit: str) -> str:
    """A unit as the report writes it: ``"m/s^2"`` -> ``"m/s²"``
    (:func:`imunoise.display.unit_symbols`, the one spelling of tables and figures)."""
    return _display.unit_symbols(unit)


def format_number(v: float, std: float | None = None) -> str:
    """``v ± std`` rounded to the uncertainty (GUM style,
    :func:`imunoise.display.format_value`), a bare ``v`` to six significant digits
    (report tables are compared with the API's numbers), ``—`` for NaN and inf."""
    return _display.cell(v, std, digits=6)


def format_three(value) -> str:
    """Three significant digits as the tables write them (``"4.14e-7"``, ``"1230"``),
    not Python's ``"4.14e-07"`` or ``"1.23e+03"``: a ratio or a rough size."""
    return _display.format_value(float(value), digits=3)


#: ``"10 ms"``, ``"12.5 s"``, ``"3.2 min"`` or ``"5 h"``: the one time formatter of the
#: library (:func:`imunoise.display.duration`), under the report's name.
format_duration = _display.duration


def terms_used(result, i: int) -> str:
    """Terms behind tau ``i`` of an Allan result: one count, or ``lo–hi`` over
    channels whose gaps differ."""
    n = np.reshape(result.n, (len(result.taus), -1))[i]
    lo, hi = int(n.min()), int(n.max())
    return str(lo) if lo == hi else f"{lo}–{hi}"


def missing_text(issues) -> str:
    """Missing samples of a log's parse issues: ``"30000 (15 %) in 1 gap"`` or ``"0"``."""
    if not issues.samples_missing:
        return "0"
    plural = "s" if issues.gaps != 1 else ""
    return (f"{issues.samples_missing} ({100 * issues.share_missing:.3g} %) in "
            f"{issues.gaps} gap{plural}")


def gap_note(source: str, issues, gaps) -> str | None:
    """One line saying that (and how much of) a log is missing, or None without gaps."""
    if not len(gaps):
        return None
    (start, length, _k), = gaps.largest(1).rows()
    plural = "s" if issues.gaps != 1 else ""
    return (f"{source}: {issues.samples_missing} samples ({100 * issues.share_missing:.3g} %) "
            f"missing in {issues.gaps} gap{plural} (largest {format_duration(length)} at "
            f"{format_duration(start - gaps.t0)}); left out of the statistics, not spliced over")
