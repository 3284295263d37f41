"""One spelling of a unit in what a notebook shows: the tables of a log and of its
statistics write "m/s²", as the report and the figures do, while the data keep the
ASCII name ("m/s^2") that arguments take."""

from __future__ import annotations

from importlib import resources

import imunoise
from imunoise import display

BUNDLED = resources.files("imunoise") / "data" / "vn100_stationary_5min.txt"


def test_unit_symbols():
    assert display.unit_symbols("m/s^2") == "m/s²"
    assert display.unit_symbols("m/s^2/sqrt(Hz)") == "m/s²/√Hz"
    assert display.unit_symbols("deg/h/sqrt(Hz)") == "°/h/√Hz"
    assert display.unit_symbols("rad/s") == "rad/s"


def test_log_and_statistics_tables_write_symbols():
    log = imunoise.read(BUNDLED, fs=40.0)
    stats = imunoise.describe(log)
    assert "m/s^2" in stats.units  # the data keep the name arguments take
    for table in (log._repr_html_(), stats._repr_html_()):
        assert "<td>m/s²</td>" in table
        assert "m/s^2" not in table
