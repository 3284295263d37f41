"""One spelling of a percentage in what a reader sees: "68.3 %" (a space before the sign,
as the report's hand-written text has it), never "68.3%" beside it."""

from __future__ import annotations

import re
from pathlib import Path

import imunoise
import numpy as np
import pytest
from imunoise import display, plot
from imunoise.errors import ImunoiseValueError

PACKAGE = Path(imunoise.__file__).resolve().parent
#: A format spec that ends in "%" ({x:.0%}, {x:%}): Python writes no space before it.
PERCENT_SPEC = re.compile(r"\{[^{}\n;]+:[-+ #0-9.,_<>=^]*%\}")


def test_percent_spelling():
    assert display.percent(0.6826894921370859, digits=1) == "68.3 %"
    assert display.percent(1.0) == "100 %"
    assert display.percent(0.05) == "5 %"
    assert display.percent(0.007, digits=1) == "0.7 %"
    assert display.percent(float("nan")) == display.EMPTY
    assert display.percent(None) == display.EMPTY
    with pytest.raises(ImunoiseValueError, match="digits"):
        display.percent(0.5, digits=-1)


def test_no_percent_format_spec_in_text_the_package_writes():
    offenders = []
    for path in sorted(PACKAGE.rglob("*.py")):
        relative = path.relative_to(PACKAGE)
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if PERCENT_SPEC.search(line) and "``" not in line:  # docstring examples aside
                offenders.append(f"{relative}:{number}: {line.strip()}")
    assert not offenders, "write display.percent(x), not {x:.0%}:\n" + "\n".join(offenders)


def test_allan_figure_legend_and_coverage_use_the_spelling():
    x = imunoise.simulate(4000, 40.0, N=1e-3, channels=3, seed=1)
    r = imunoise.adev(x, 40.0)
    model = imunoise.fit(r, terms=["N"])
    fig = plot.allan(r, model)
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    legends = [t.get_text() for legend in [*fig.legends, *(ax.get_legend() for ax in fig.axes)]
               if legend is not None for t in legend.get_texts()]
    assert any(re.fullmatch(r"ADEV \(68\.3 % CI\)", t) for t in legends), legends
    follows = [t for t in texts if t.startswith("follows ")]
    assert follows and all(re.fullmatch(r"follows \d+ % of taus", t) for t in follows), follows
    assert not any(re.search(r"\d%", t) for t in texts + legends)
    assert np.isfinite(float(np.atleast_1d(model.N)[0]))
