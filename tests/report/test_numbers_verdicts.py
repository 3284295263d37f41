"""Value ± uncertainty formatting (imunoise.display) and datasheet verdicts (#14)."""
import math

import pytest
from imunoise._support import summary as _summary
from imunoise.datasheet import COVERAGE_K, verdict
from imunoise.display import cell, duration, format_value, rounded
from imunoise.report.formatting import format_duration

NAN = math.nan


@pytest.mark.parametrize("value, std, text", [
    (0.21004, 0.000112762, "0.21004 ± 0.00011"),
    (9.89168, 0.0021, "9.8917 ± 0.0021"),
    (3.5e-3, 1.2e-4, "(3.50 ± 0.12)e-3"),
    (-3.5e-3, 1.2e-4, "(-3.50 ± 0.12)e-3"),
    (123456.0, 1234.0, "(1.235 ± 0.012)e5"),
    (1234.5, 23.4, "1234 ± 23"),
    (-2.3456, 0.0999, "-2.35 ± 0.10"),     # 0.0999 rounds up to 0.10
    (9.89168, None, "9.892"),               # no uncertainty: 4 significant digits
    (9.89168, 0.0, "9.892"),                # zero uncertainty: none
    (9.89168, NAN, "9.892"),                # NaN uncertainty: none
    (0.00350386, None, "3.504e-3"),
    (0.0, None, "0"),
    (NAN, 0.1, "not resolved"),
    (math.inf, None, "not resolved"),
])
def test_format_value(value, std, text):
    assert format_value(value, std) == text


def test_format_value_unit_digits_and_cell():
    assert format_value(9.89168, 0.0021, unit="m/s²") == "9.8917 ± 0.0021 m/s²"
    assert format_value(9.89168, digits=6) == "9.89168"
    assert cell(NAN) == "—"
    with pytest.raises(ValueError, match="digits must be"):
        format_value(1.0, digits=0)


@pytest.mark.parametrize("measured, std, word, remark", [
    (0.8, 0.1, "pass", ""),
    (1.0 - COVERAGE_K * 0.1 - 1e-9, 0.1, "pass", ""),     # just inside the interval
    (1.0 - COVERAGE_K * 0.1 + 1e-9, 0.1, "not significant", ""),
    (0.9, 0.1, "not significant", ""),
    (1.0, 0.1, "not significant", ""),
    (1.0 + COVERAGE_K * 0.1 - 1e-9, 0.1, "not significant", ""),
    (1.0 + COVERAGE_K * 0.1 + 1e-9, 0.1, "fail", ""),
    (1.2, 0.1, "fail", ""),
    (1.0, None, "pass", "no uncertainty"),
    (1.0001, NAN, "fail", "no uncertainty"),
    (NAN, 0.1, "not resolved", ""),
])
def test_max_verdicts(measured, std, word, remark):
    assert verdict(measured, std, 1.0, "max") == (word, remark)


def test_min_mirrors_max():
    assert verdict(1.2, 0.1, 1.0, "min")[0] == "pass"
    assert verdict(0.8, 0.1, 1.0, "min")[0] == "fail"
    assert verdict(1.0, 0.1, 1.0, "min")[0] == "not significant"
    assert verdict(0.99, None, 1.0, "min") == ("fail", "no uncertainty")


def test_typical_is_no_limit():
    # the demo's gyro noise density vs the VN-100's typical 0.0035
    assert verdict(0.00350386, 1e-6, 0.0035, "typical") == (
        "typical", "within a factor 1.5 of typical")
    assert verdict(1.5, None, 1.0, "typical")[0] == "typical"
    assert verdict(2.3, 0.01, 1.0, "typical") == ("above typical", "2.3× typical")
    assert verdict(0.4, 0.01, 1.0, "typical") == ("below typical", "0.4× typical")
    assert verdict(NAN, None, 1.0, "typical")[0] == "not resolved"


def test_verdict_errors():
    with pytest.raises(ValueError, match="limit must be"):
        verdict(1.0, 0.1, 1.0, "maybe")
    with pytest.raises(ValueError, match="spec must be"):
        verdict(1.0, 0.1, 0.0, "max")


@pytest.mark.parametrize("seconds, text", [
    (0.0, "0 s"),
    (0.01, "10 ms"),          # a tau of one sample at 100 Hz was "0.0 s"
    (0.025, "25 ms"),
    (4e-5, "40 µs"),
    (0.9996, "1 s"),          # the unit after rounding, not "1e+03 ms"
    (12.54, "12.5 s"),
    (119.96, "2 min"),
    (666.0, "11.1 min"),
    (7300.0, "2.03 h"),
    (NAN, "—"),
])
def test_duration(seconds, text):
    assert duration(seconds) == text


def test_one_time_formatter_and_rounded():
    # the report's and the reprs' time formatters are the same function
    assert format_duration is duration and _summary.duration is duration
    assert rounded(0.904806, 0.05) == "0.905"     # "ADEV ×0.904806" -> to its uncertainty
    assert rounded(0.904806, 0.012) == "0.905"
    assert rounded(0.904806, 0.12) == "0.90"
    assert rounded(3.5e-3, 1.2e-4) == "3.50e-3"
    assert rounded(9.89168) == "9.892"
    assert rounded(NAN, 0.1) == "—"
