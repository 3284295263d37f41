"""Result objects print as short summaries (never an array), show an HTML table in
notebooks, and plot themselves (#14 items 4 and 5)."""

from __future__ import annotations

import warnings
from importlib import resources

import imunoise
import matplotlib
import numpy as np
import pytest
from imunoise import plot
from imunoise.readers.grid import Gaps

matplotlib.use("Agg")

LOG = resources.files("imunoise") / "data" / "vn100_stationary_5min.txt"
#: Lines of the bundled log whose checksum the damaged copy breaks: two gaps.
DAMAGED = (100, 101, 102, 5000)


def _damaged_log() -> bytes:
    lines = LOG.read_bytes().split(b"\n")
    for i in DAMAGED:
        body, _, check = lines[i].partition(b"*")
        lines[i] = body + b"*" + (b"00" if check[:2] != b"00" else b"01") + check[2:]
    return b"\n".join(lines)


@pytest.fixture(scope="module")
def objects():
    """Every summarised object, from the bundled real log (fs = 40 Hz), a damaged copy
    of it and a 6-channel, 10⁶-sample record."""
    log = imunoise.read(LOG, fs=40.0)
    damaged = imunoise.read(_damaged_log(), fs=40.0)
    result = imunoise.adev(log.gyro, log.fs)
    model = imunoise.fit(result)
    big = imunoise.simulate(1_000_000, 100.0, channels=6, N=1e-3, B=1e-4, K=1e-5, seed=1)
    big[1000:1040, 2] = np.nan
    big_result = imunoise.adev(big, 100.0)
    with warnings.catch_warnings():  # these fits may follow their curves poorly
        warnings.simplefilter("ignore", RuntimeWarning)
        slopes = imunoise.fit(result, method="slopes")
        accel = imunoise.fit(imunoise.adev(log.accel, log.fs))
    comparison = imunoise.compare({"gyro": model, "accel": accel})
    return {
        "log": log,
        "damaged log": damaged,
        "issues": damaged.issues,
        "gaps": damaged.gaps,
        "no gaps": log.gaps,
        "result": result,
        "1-D result": imunoise.adev(log.gyro[:, 0], log.fs),
        "6-channel result": big_result,
        "model": model,
        "slopes model": slopes,
        "6-channel model": imunoise.fit(big_result),
        "prediction": model.predict(),
        "description": imunoise.describe(log),
        "distribution": imunoise.distribution(log.mag[:, 0]),
        "comparison": comparison,
    }


NAMES = ("log", "damaged log", "issues", "gaps", "no gaps", "result", "1-D result",
         "6-channel result", "model", "slopes model", "6-channel model", "prediction",
         "description", "distribution", "comparison")


@pytest.mark.parametrize("name", NAMES)
def test_repr_is_short_and_names_the_class(objects, name):
    obj = objects[name]
    text = repr(obj)
    assert text.startswith(type(obj).__name__ + "(") and text.endswith(")")
    assert len(text.splitlines()) <= 3, text
    assert len(text) <= 300, text
    assert "array(" not in text and "[[" not in text


@pytest.mark.parametrize("name", NAMES)
def test_repr_html_is_a_table(objects, name):
    page = objects[name]._repr_html_()
    assert page.startswith("<table") and page.endswith("</table>")
    assert "array(" not in page


def test_reprs_say_what_matters(objects):
    log = repr(objects["log"])
    for fact in ("vn-ascii 'vn100_stationary_5min.txt'", "40 Hz", "13223 samples = 5.51 min",
                 "channels gyro accel mag ypr", "no gaps", "no issues"):
        assert fact in log
    damaged = repr(objects["damaged log"])
    assert "vn-ascii <bytes>" in damaged
    assert "4 missing in 2 gaps" in damaged and "issues: bad_checksum=4" in damaged
    issues = repr(objects["issues"])
    assert "bad_checksum=4 (lines 101, 102, 103, …)" in issues
    assert "4 of 13223 samples missing" in issues and "in 2 gaps" in issues
    assert repr(objects["gaps"]).startswith("Gaps(2 gaps, 4 samples = 100 ms missing at 40 Hz")
    assert repr(objects["no gaps"]) == "Gaps(no gaps at 40 Hz)"
    result = repr(objects["result"])
    for fact in ("adev overlapping", "3 channels", "0.025–", "fs 40 Hz", "13223 samples",
                 "no missing", "gaps=skip"):
        assert fact in result
    assert "missing [0 0 40 0 0 0]" in repr(objects["6-channel result"])
    model = repr(objects["model"])
    assert model.startswith("NoiseModel(wls fit of adev at 40 Hz, 3 channels;")
    assert "X: " in model and "Z: " in model and "covers" in model and "tone" in model
    assert "more)" in repr(objects["6-channel model"])  # the axes beyond the budget
    assert "terms Q N B sine" in repr(objects["prediction"])  # X/Y carry an 18.6 Hz tone
    assert "gyro X Y Z, accel X Y Z, mag X Y Z" in repr(objects["description"])
    assert "bins" in repr(objects["distribution"])
    # values with an uncertainty are rounded to it (GUM), not printed to fixed digits
    d = objects["distribution"]
    assert f"μ={imunoise.display.format_value(d.mu, d.mu_std)} " in repr(d)
    m = objects["model"]
    term = next(t for t in imunoise.noise.TERMS if np.atleast_1d(m.supported[t])[0])
    shown = imunoise.display.format_value(np.ravel(m.value(term))[0], np.ravel(m.std(term))[0])
    assert f"X: {term}={shown}" in model and " ± " in shown
    # (the verdict counts may wrap the line)
    assert " ".join(repr(objects["comparison"]).split()).startswith(
        "Comparison('VectorNav VN-100', 12 rows: ")


def test_html_tables_hold_one_row_per_axis(objects):
    assert objects["model"]._repr_html_().count("<tr>") == 1 + 3
    assert "&lt; " in objects["model"]._repr_html_()  # an unresolved value: its bound
    assert objects["6-channel result"]._repr_html_().count("<tr>") == 1 + 6
    log = objects["damaged log"]._repr_html_()
    assert log.count("<table") == 3  # channels, issues, gaps
    assert "gyro_x gyro_y gyro_z" in log and "bad_checksum" in log
    assert objects["comparison"]._repr_html_().count("<tr>") == 1 + 12


def test_str_is_unchanged(objects):
    assert str(objects["issues"]).startswith("bad_checksum=4, 4 samples missing")
    assert str(objects["description"]) == objects["description"].table()
    assert str(objects["no gaps"]) == "no gaps"


def test_gaps_html_shows_the_longest():
    valid = np.ones(10_000, dtype=bool)
    valid[100:9_000:100] = False  # 89 gaps of one sample
    valid[5_001:5_050] = False
    gaps = Gaps.from_valid(valid, 100.0)
    page = gaps._repr_html_()
    assert "(the 10 longest shown)" in page and page.count("<tr>") == 1 + 10
    assert "89 gaps, 138 samples" in repr(gaps)
    assert "longest 50 samples at 50 s" in repr(gaps)  # rows 5000-5049


def test_plot_methods_return_figures(objects):
    from matplotlib.figure import Figure

    log, result, model = objects["log"], objects["result"], objects["model"]
    figures = [log.plot(), log.plot("gyro"), objects["damaged log"].plot(["accel", "mag"]),
               result.plot(), result.plot(model, unit="rad/s"), model.plot(result),
               plot.allan(result, model), plot.histograms(objects["distribution"])]
    for fig in figures:
        assert isinstance(fig, Figure)
    assert len(figures[0].get_axes()) == 4 * 3  # gyro accel mag ypr, three axes each
    # every panel carries its unit, also below a column title that names it (#26)
    assert [ax.get_ylabel() for ax in figures[0].get_axes()[3::4]] == [
        "yaw [deg]", "pitch [deg]", "roll [deg]"]
    assert figures[1].get_axes()[0].get_ylabel() == "X [rad/s]"
    shaded = [p for p in figures[2].get_axes()[0].patches if p.get_facecolor()[0] > 0.8]
    assert len(shaded) == 2  # the damaged log's two gaps
    assert len(figures[5].get_axes()) == 2 * 3  # model panels and data/model panels
    for fig in figures:
        fig.clear()


def test_plot_functions_check_what_they_are_given(objects):
    log, result, model = objects["log"], objects["result"], objects["model"]
    with pytest.raises(TypeError, match="model must be a NoiseModel"):
        plot.allan(result, [{"N": 1e-4}] * 3)
    with pytest.raises(TypeError, match="result must be an AllanResult"):
        plot.allan(np.ones(5))
    with pytest.raises(ValueError, match=r"model must have the 1 channel\(s\) of result; got 3"):
        model.plot(objects["1-D result"])
    with pytest.raises(ValueError, match="channels must be among the log's"):
        log.plot("temperature")
    with pytest.raises(ValueError, match="fs, unit and names must not be given"):
        plot.time_series(log, 40.0)
    with pytest.raises(ValueError, match="fs must be given for an array"):
        plot.time_series(log.gyro)
    with pytest.raises(TypeError, match="dists must be Distribution objects"):
        plot.histograms([np.ones(3)])
