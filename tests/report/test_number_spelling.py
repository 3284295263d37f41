"""Numbers in the report's sentences are written as its tables write them: "4.14e-7",
"229", never Python's "4.14e-07" or "2.3e+02"."""

from __future__ import annotations

import re
import warnings
from importlib import resources

import imunoise
from imunoise import stats
from imunoise.planner import plan
from imunoise.report import model_sentences

BUNDLED = resources.files("imunoise") / "data" / "vn100_stationary_5min.txt"
#: What Python's "g" and "e" formats write and the tables never do.
PYTHON_EXPONENT = re.compile(r"\d[eE](\+|-0)\d")


def test_plan_line_writes_large_uncertainties_in_plain_digits():
    # K read at 409 s from a 14 min record: its uncertainty is above 100 %
    p = plan({"N": 2e-3, "B": 1e-3, "K": 1e-4}, fs=40.0, confidence=0.999)
    assert 1 < p.uncertainty(853)["K"] < 10
    line = p.line(853)
    assert not PYTHON_EXPONENT.search(line), line
    assert re.search(r"K ±\d{3} %", line), line


def test_resolution_sentences_write_exponents_as_the_tables_do():
    log = imunoise.read(BUNDLED, fs=40.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = imunoise.fit(imunoise.adev(log.gyro, log.fs))
    steps = [stats.quantization_step(log.gyro[:, c]) for c in range(3)]
    sentences = model_sentences(model, "gyro", steps=steps)
    with_q = [s for s in sentences if "would give Q = " in s]
    assert with_q, sentences  # the capture's Z axis has a quantization term
    for sentence in sentences:
        assert not PYTHON_EXPONENT.search(sentence), sentence


def test_the_bundled_capture_report_has_one_spelling_of_numbers(tmp_path):
    from imunoise import report

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = report.build(imunoise.read(BUNDLED, fs=40.0), None, tmp_path / "r",
                           progress=False)
    md = rep.markdown.read_text(encoding="utf-8")
    assert "false events per sample" in md
    assert not PYTHON_EXPONENT.search(md), PYTHON_EXPONENT.search(md)
    glued = re.search(r".{40}\d%.{20}", md)  # "68.3%" beside "68.3 %"
    assert glued is None, glued.group(0)
