"""Units, tables, datasheet comparison and exports of the noise model."""

from __future__ import annotations

import json
import math
import re

import imunoise
import numpy as np
import pytest
from helpers.noise_fit import allan
from hypothesis import given
from hypothesis import strategies as st
from imunoise import display, export, units

DEG = math.pi / 180
G = 9.80665


# -- units ------------------------------------------------------------------

def test_published_conversions():
    # 1 °/√h = 1/60 °/√s; 0.0035 °/s/√Hz (VN-100) = 0.21 °/√h
    n = 0.0035 * DEG  # rad/√s
    assert units.convert(n, "N", "deg/sqrt(h)") == pytest.approx(0.21, rel=1e-12)
    assert units.convert(n, "N", "°/s/√Hz") == pytest.approx(0.0035, rel=1e-12)
    # 10 °/h in rad/s
    assert units.convert_back(10.0, "B", "deg/h") == pytest.approx(10 * DEG / 3600, rel=1e-12)
    # K: 1 °/h/√h = (1/3600 °/s)/(60 √s)
    assert units.convert(DEG / 3600 / 60, "K", "deg/h/sqrt(h)") == pytest.approx(1.0)
    # accel: 0.14 mg/√Hz in m/s/√h
    a = 0.14e-3 * G
    assert units.convert(a, "N", "mg/sqrt(Hz)", sensor="accel") == pytest.approx(0.14)
    assert units.convert(a, "N", "m/s/sqrt(h)", sensor="accel") == pytest.approx(a * 60)
    assert units.convert(0.04e-3 * G, "B", "ug", sensor="accel") == pytest.approx(40.0)
    assert units.convert(1.0, "B", "mg", sensor="accel", input_unit="g") == pytest.approx(1000)
    assert units.convert(1.0, "N", "deg/s/sqrt(Hz)", input_unit="deg/s") == pytest.approx(1.0)


ALL = [(s, u.term, u.name) for (s, _), u in units.UNITS.items()]


@given(st.sampled_from(ALL), st.floats(1e-12, 1e6), st.sampled_from([None, "alt"]))
def test_round_trip(entry, value, iu):
    sensor, term, unit = entry
    input_unit = None if iu is None else ("deg/s" if sensor == "gyro" else "g")
    there = units.convert(value, term, unit, sensor=sensor, input_unit=input_unit)
    back = units.convert_back(there, term, unit, sensor=sensor, input_unit=input_unit)
    assert back == pytest.approx(value, rel=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "word"),
    [
        ({"term": "X"}, "term"),
        ({"unit": "furlong"}, "unit"),
        ({"sensor": "mag"}, "sensor"),
        ({"input_unit": "rpm"}, "input_unit"),
        ({"unit": "mg"}, "unit"),  # an accel unit asked for a gyro
    ],
)
def test_unit_errors_name_the_argument(kwargs, word):
    args = {"term": "B", "unit": None, "sensor": "gyro", "input_unit": None} | kwargs
    with pytest.raises(ValueError, match=word):
        units.convert(1.0, args.pop("term"), args.pop("unit"), **args)


# -- model in units, table ----------------------------------------------------

@pytest.fixture(scope="module")
def gyro_model():
    """3-axis gyro near the VN-100 datasheet: N = 0.5x spec, B ~ 3 °/h (rad/s)."""
    n = 0.5 * 0.0035 * DEG
    b = 3.0 * DEG / 3600
    x = imunoise.simulate(int(2 * 3600 * 40), 40.0, N=n, B=b, channels=3, seed=5)
    return imunoise.fit(allan(x, 40.0)), n, b


@pytest.fixture(scope="module")
def accel_model():
    """3-axis accelerometer at 2x the VN-100 noise density (fails N)."""
    n = 2 * 0.14e-3 * G
    x = imunoise.simulate(int(0.5 * 3600 * 40), 40.0, N=n, channels=3, seed=6)
    return imunoise.fit(allan(x, 40.0)), n


def test_in_units_and_table(gyro_model):
    model, n, b = gyro_model
    conv = model.in_units("gyro", units={"N": "deg/s/sqrt(Hz)"})
    np.testing.assert_allclose(conv["N"]["value"], model.N / DEG, rtol=1e-12)
    # the std of the datasheet equivalent comes through a numerical gradient
    np.testing.assert_allclose(conv["N"]["std"], model.N_std / DEG, rtol=1e-6)
    assert conv["B"]["unit"] == "deg/h" and conv["B"]["label"] == "°/h"
    rows = model.table("gyro")
    assert [r["term"] for r in rows] == ["N", "B", "K", "Q", "R"]
    row_n = rows[0]
    assert row_n["quantity"] == "angle random walk" and row_n["label"] == "°/√h"
    for ax in "XYZ":
        assert row_n[ax] == pytest.approx(n / DEG * 60, rel=0.05)
        assert row_n[ax + "_supported"]
    text = model.table_text("gyro")
    # R is not resolved: its 95 % bound, never 0
    assert "°/√h" in text and "X" in text and "R rate ramp" in text
    r_row = next(r for r in rows if r["term"] == "R")
    assert all(not r_row[ax + "_supported"] and r_row[ax + "_upper"] > 0 for ax in "XYZ")
    assert display.upper_bound(r_row["X_upper"]) in text
    with pytest.raises(ValueError, match="axes"):
        model.table("gyro", axes=["X", "Y"])


# -- datasheet comparison ------------------------------------------------------

def test_compare_verdicts(gyro_model, accel_model):
    mg, _, _ = gyro_model
    ma, _ = accel_model
    cmp = imunoise.compare({"gyro": mg, "accel": ma}, "vn100")
    assert "VN-100" in cmp.spec.name and cmp.spec.source
    by = {(r["sensor"], r["term"], r["axis"]): r for r in cmp.rows}
    for ax in "XYZ":
        # N is a typical value in the VN-100 spec: half of it is no "pass", it is below typical
        assert by[("gyro", "N", ax)]["verdict"] == "below typical"
        assert by[("gyro", "N", ax)]["remark"] == "0.5× typical"
        assert by[("gyro", "N", ax)]["ratio"] == pytest.approx(0.5, rel=0.05)
        assert by[("gyro", "B", ax)]["verdict"] == "pass"
        assert by[("gyro", "B", ax)]["ratio"] == pytest.approx(0.3, rel=0.3)
        b = by[("gyro", "B", ax)]
        assert b["ratio_std"] == pytest.approx(b["std"] / b["spec"])
        assert by[("accel", "N", ax)]["verdict"] == "above typical"  # a typical value is no limit
        assert by[("accel", "N", ax)]["ratio"] == pytest.approx(2.0, rel=0.05)
        # accel white noise only: bias instability not resolved, not a number; its 95 %
        # bound passes the datasheet's maximum where it lies below it
        b = by[("accel", "B", ax)]
        assert np.isnan(b["measured"]) and b["upper"] > 0
        assert b["verdict"] == ("pass" if b["upper"] <= b["spec"] else "not resolved")
        assert b["remark"].startswith("not resolved, at most ")
    assert cmp.passed  # no max/min limit is clearly exceeded
    assert "above typical (2× typical)" in cmp.text() and "not resolved" in cmp.text()
    # the ratio is rounded to its uncertainty like the measured value (GUM), not to noise digits
    b = by[("gyro", "B", "X")]
    assert imunoise.display.format_value(b["ratio"], b["ratio_std"]) in cmp.text()
    assert imunoise.display.format_value(b["ratio"], b["ratio_std"]) in cmp._repr_html_()
    only = imunoise.compare(mg, "vn100")
    assert only.passed and {r["sensor"] for r in only.rows} == {"gyro"}


def test_not_significant_verdict(gyro_model, tmp_path):
    """Above a max by less than 1.645 standard uncertainties: not significant, not fail."""
    mg, _, _ = gyro_model
    n_deg_h = float(mg.N[0]) / DEG * 60
    u = float(mg.N_std[0]) / DEG * 60
    spec = tmp_path / "edge.toml"
    spec.write_text(
        f'[[gyro]]\nterm = "N"\nvalue = {n_deg_h - u}\nunit = "deg/sqrt(h)"\n'
        f'[[gyro]]\nterm = "N"\nvalue = {n_deg_h - 3 * u}\nunit = "deg/sqrt(h)"\n',
        encoding="utf-8",
    )
    rows = [r for r in imunoise.compare(mg, spec).rows if r["axis"] == "X"]
    assert [r["verdict"] for r in rows] == ["not significant", "fail"]


def test_compare_with_user_spec(tmp_path, gyro_model):
    mg, n, _ = gyro_model
    spec = tmp_path / "mine.toml"
    spec.write_text(
        'name = "mine"\nsource = "test"\n[[gyro]]\nterm = "N"\nvalue = 0.1\n'
        'unit = "deg/sqrt(h)"\nlimit = "max"\n',
        encoding="utf-8",
    )
    cmp = imunoise.compare(mg, spec)
    assert all(r["verdict"] == "fail" for r in cmp.rows)  # 0.105 °/√h > 0.1


def test_compare_errors(gyro_model, tmp_path):
    mg, _, _ = gyro_model
    with pytest.raises(ValueError, match="spec"):
        imunoise.compare(mg, "no-such-imu")
    with pytest.raises(TypeError, match="models"):
        imunoise.compare([mg], "vn100")
    with pytest.raises(ValueError, match="keys"):
        imunoise.compare({"magnetometer": mg}, "vn100")
    bad = tmp_path / "bad.toml"
    bad.write_text('[[gyro]]\nterm = "N"\nvalue = 1\nunit = "mg"\n', encoding="utf-8")
    with pytest.raises(ValueError, match="unit"):
        imunoise.compare(mg, bad)


# -- exports -----------------------------------------------------------------------

def _yaml_scalars(text):
    return {m.group(1): m.group(2) for m in
            re.finditer(r"^\s*([A-Za-z_]+):\s*([^#\s][^#]*?)\s*(?:#.*)?$", text, re.M)}


def test_kalibr_round_trip(tmp_path, gyro_model, accel_model):
    mg, _, _ = gyro_model
    ma, _ = accel_model
    path = tmp_path / "imu.yaml"
    with pytest.warns(RuntimeWarning, match="does not resolve K"):
        text = mg.to_kalibr(accel=ma, path=path, rostopic="/vn100/imu")
    assert path.read_text(encoding="utf-8") == text
    assert [p.name for p in tmp_path.iterdir()] == ["imu.yaml"]  # no temp file left
    v = _yaml_scalars(text)
    assert float(v["gyroscope_noise_density"]) == pytest.approx(np.max(mg.N), rel=1e-6)
    assert float(v["accelerometer_noise_density"]) == pytest.approx(np.max(ma.N), rel=1e-6)
    assert float(v["update_rate"]) == 40.0
    assert v["rostopic"] == "/vn100/imu"
    # Random walk of a white-noise-only accel is unresolved -> its 95 % bound, not 0
    assert float(v["accelerometer_random_walk"]) == pytest.approx(np.max(ma.upper["K"]),
                                                                   rel=1e-6)
    with pytest.warns(RuntimeWarning, match="does not resolve K"):
        rms = export.kalibr_dict(mg, ma, combine="rms")
    assert rms["gyroscope_noise_density"] == pytest.approx(np.sqrt(np.mean(mg.N**2)))
    assert rms["gyroscope_noise_density"] <= np.max(mg.N)


def test_openvins_and_json(tmp_path, gyro_model, accel_model):
    mg, _, _ = gyro_model
    ma, _ = accel_model
    with pytest.warns(RuntimeWarning, match="does not resolve K"):
        p = export.write_openvins(tmp_path / "kalibr_imu_chain.yaml", mg, ma)
    text = p.read_text(encoding="utf-8")
    assert text.startswith("%YAML:1.0") and "\nimu0:\n" in text and "T_i_b" in text
    v = _yaml_scalars(text)
    assert float(v["gyroscope_noise_density"]) == pytest.approx(np.max(mg.N), rel=1e-6)
    assert v["model"] == "calibrated"
    j = export.write_json(tmp_path / "model.json", gyro=mg, accel=ma)
    data = json.loads(j.read_text(encoding="utf-8"))
    np.testing.assert_allclose(data["gyro"]["N"]["value"], mg.N)
    assert data["gyro"]["R"]["supported"] == [False, False, False]
    assert data["accel"]["fs"] == 40.0


def test_export_errors(gyro_model):
    mg, _, _ = gyro_model
    with pytest.raises(ValueError, match="gyro and accel"):
        export.kalibr_dict()
    with pytest.raises(ValueError, match="combine"):
        export.kalibr_dict(mg, combine="mean")
    with pytest.raises(ValueError, match="inflate"):
        export.kalibr_dict(mg, inflate=-1.0)
