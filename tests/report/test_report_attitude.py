"""Yaw, pitch and roll in the report: present with statistics that match the API when
the log has attitude, absent when it has none, and yaw across ±180° kept in one piece."""

import re

import imunoise
import numpy as np
import pytest
from imunoise import report
from imunoise.stats import unwrap_about_circular_mean


def _attitude_rows(md: str) -> dict[str, list[str]]:
    lines = md.splitlines()
    i = next(k for k, line in enumerate(lines) if line.startswith("*Attitude statistics"))
    rows = [[c.strip() for c in line.strip("|").split("|")] for line in lines[i + 2:i + 7]]
    header, body = rows[0], rows[2:]
    return {r[0]: dict(zip(header, r, strict=True)) for r in body}


def test_unwrap_keeps_a_heading_across_180_in_one_piece():
    rng = np.random.default_rng(3)
    yaw = (179.9 + rng.normal(0, 0.1, 5000) + 180.0) % 360.0 - 180.0  # jumps ±180
    assert np.ptp(yaw) > 300
    u = unwrap_about_circular_mean(yaw)
    assert np.ptp(u) < 1.5
    np.testing.assert_allclose(np.std(u), 0.1, rtol=0.05)
    np.testing.assert_allclose((u - yaw) % 360.0, 0.0, atol=1e-9)  # whole turns only
    with_gap = yaw.copy()
    with_gap[10:20] = np.nan
    assert np.isnan(unwrap_about_circular_mean(with_gap)[10:20]).all()


def test_bundled_log_has_an_attitude_section_matching_the_api(tmp_path):
    from imunoise.cli import bundled_log

    log = imunoise.read(bundled_log(), fs=40.0)
    rep = report.build(log, None, tmp_path, progress=False)
    md = rep.markdown.read_text()
    assert re.search(r"^## \d+\. Attitude \(yaw, pitch, roll\)$", md, re.M)
    assert "need not be normal" in md or "Nothing makes it normal" in md
    rows = _attitude_rows(md)
    assert list(rows) == ["yaw", "pitch", "roll"]
    for j, name in enumerate(("yaw", "pitch", "roll")):
        v = log.ypr[:, j]
        assert float(rows[name]["std"]) == pytest.approx(np.std(v, ddof=1), rel=1e-5)
        assert float(rows[name]["KS D"]) == pytest.approx(
            rep.attitude[name].ks_statistic, rel=1e-5)
    assert {p.name for p in rep.figures} >= {"timeseries_attitude.png", "hist_attitude.png"}


def test_yaw_near_180_is_summarised_about_its_circular_mean(tmp_path):
    n = 2000
    rng = np.random.default_rng(5)
    yaw = (179.95 + rng.normal(0, 0.05, n) + 180.0) % 360.0 - 180.0
    ypr = np.column_stack([yaw, rng.normal(1.0, 0.01, n), rng.normal(-2.0, 0.01, n)])
    log = imunoise.ImuLog.from_arrays(40.0, ypr=ypr, gyro=rng.normal(0, 1e-3, (n, 3)))
    rep = report.build(log, None, tmp_path, progress=False, spec=None)
    rows = _attitude_rows(rep.markdown.read_text())
    assert float(rows["yaw"]["std"]) == pytest.approx(0.05, rel=0.1)
    mean = float(rows["yaw"]["mean"])
    assert -180.0 < mean <= 180.0 and abs(abs(mean) - 179.95) < 0.01


def test_no_attitude_section_without_ypr(tmp_path):
    rng = np.random.default_rng(6)
    log = imunoise.ImuLog.from_arrays(40.0, gyro=rng.normal(0, 1e-3, (4000, 3)))
    rep = report.build(log, None, tmp_path, progress=False, spec=None)
    md = rep.markdown.read_text()
    assert "Attitude" not in md
    numbers = [int(k) for k in re.findall(r"^## (\d+)\. ", md, re.M)]
    assert numbers == list(range(1, len(numbers) + 1))
    assert rep.attitude == {}
