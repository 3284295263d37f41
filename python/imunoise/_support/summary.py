"""Short summaries of the result objects: the pieces their ``__repr__`` (one to three
lines, never an array) and ``_repr_html_`` (a small table for notebooks) share.

Numbers print with four significant digits here; the report's and the tables'
number formatting lives elsewhere.
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable, Mapping, Sequence
from pathlib import PurePath

import numpy as np

from imunoise import display as _display

#: Characters of a repr line before the next part goes to a new line.
LINE_WIDTH = 110
#: Lines of a repr at the most (the first one included).
MAX_LINES = 3
#: Characters of a repr at the most (parts beyond are counted, not shown).
MAX_CHARS = 300
#: Rows of a long table (gaps) an HTML summary shows.
HTML_ROWS = 10


def number(value) -> str:
    """Four significant digits, ``—`` for NaN and infinities, ``None`` as ``—``."""
    if value is None:
        return "—"
    v = float(value)
    return f"{v:.4g}" if math.isfinite(v) else "—"


def estimate(value, std) -> str:
    """``value ± std`` rounded to the uncertainty (GUM, :func:`imunoise.display.format_value`),
    ``value`` to four significant digits without one, ``—`` when missing."""
    return _display.cell(value, std)


#: ``"10 ms"``, ``"12.5 s"``, ``"5.51 min"`` or ``"3.2 h"`` (:func:`imunoise.display.duration`).
duration = _display.duration


def tau_span(taus) -> str:
    """``"27 taus 0.025–165 s"`` (``"1 tau 0.5 s"``, ``"no taus"``)."""
    t = np.asarray(taus, dtype=float).reshape(-1)
    if not t.size:
        return "no taus"
    if t.size == 1:
        return f"1 tau {number(t[0])} s"
    return f"{t.size} taus {number(t[0])}–{number(t[-1])} s"


def source_name(source: str) -> str:
    """A file's name without its folders (``"<bytes>"``-style sources unchanged)."""
    return source if source.startswith("<") else PurePath(source).name


def plural(count: int, word: str) -> str:
    """``"1 gap"``, ``"2 gaps"``."""
    return f"{count} {word}{'' if count == 1 else 's'}"


def nonzero(counts: Mapping[str, int]) -> str:
    """``"bad_checksum=3, bytes_skipped=12"``: the kinds that happened."""
    return ", ".join(f"{k}={v}" for k, v in counts.items() if v)


def per_channel(values, name: str) -> str:
    """A count per channel: ``"no name"``, ``"name 43"`` when all are equal, else
    ``"name [3 0 5]"``."""
    v = np.atleast_1d(np.asarray(values)).reshape(-1)
    if not v.any():
        return f"no {name}"
    if np.all(v == v[0]):
        return f"{name} {v[0]}"
    return f"{name} [{' '.join(str(x) for x in v)}]"


def lines(head: str, parts: Sequence[str], *, sep: str = "; ", close: str = ")") -> str:
    """``head`` then ``parts``, each after ``sep`` (the first right after a ``head``
    ending in ``(``), wrapped at :data:`LINE_WIDTH` into at most :data:`MAX_LINES`
    lines and :data:`MAX_CHARS` characters; parts that do not fit are counted
    (``"… 3 more"``)."""
    out = [head]
    for i, part in enumerate(parts):
        glue = "" if out[-1].endswith("(") else sep
        room = MAX_CHARS - sum(len(line) + 1 for line in out) - len(close) - len(sep) - 12
        fits_line = len(out[-1]) + len(glue) + len(part) <= LINE_WIDTH
        if len(part) + 3 > room or not fits_line and len(out) == MAX_LINES:
            out[-1] += f"{glue}… {len(parts) - i} more"
            break
        if fits_line:
            out[-1] += glue + part
        else:
            out[-1] += sep.rstrip()
            out.append("  " + part)
    return "\n".join(out) + close


def curve_rows(taus, dev, names: Sequence[str]) -> tuple[list[str], list[list[str]]]:
    """Header and one row per channel of a deviation curve: its value at the first
    tau, its smallest value and where, its value at the last tau."""
    t = np.asarray(taus, dtype=float).reshape(-1)
    d = np.asarray(dev, dtype=float).reshape(t.size, -1)
    if not t.size:
        return ["axis"], [[name] for name in names]
    header = ["axis", f"σ({number(t[0])} s)", "min σ", "at τ [s]", f"σ({number(t[-1])} s)"]
    rows = []
    for j, name in enumerate(names):
        col = d[:, j]
        finite = np.isfinite(col)
        i = int(np.argmin(np.where(finite, col, np.inf)))
        low = [number(col[i]), number(t[i])] if finite.any() else ["—", "—"]
        rows.append([name, number(col[0]), *low, number(col[-1])])
    return header, rows


def html_table(
    header: Sequence[str],
    rows: Iterable[Sequence[object]],
    *,
    caption: str = "",
) -> str:
    """A small HTML table (escaped text, numbers right-aligned by the notebook's style);
    a column headed "unit" is written in symbols ("m/s²"), as the report's tables are."""
    cells = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
    unit_column = list(header).index("unit") if "unit" in header else None
    body = "".join(
        "<tr>" + "".join(
            f"<td>{html.escape(_display.unit_symbols(str(c)) if k == unit_column else str(c))}</td>"
            for k, c in enumerate(row)) + "</tr>"
        for row in rows
    )
    cap = f"<caption>{html.escape(caption)}</caption>" if caption else ""
    return f"<table>{cap}<thead><tr>{cells}</tr></thead><tbody>{body}</tbody></table>"
