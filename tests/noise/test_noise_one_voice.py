"""One voice: ``model.N`` … ``model.R`` are the datasheet values, and every view
(repr, table, report sentences, comparison, Kalibr / EKF / JSON exports) prints
those same numbers; the fitted components live under ``model.components``; the
old spellings warn and name the new one."""

from __future__ import annotations

import html
import json
import math

import imunoise
import numpy as np
import pytest
from helpers.data import shared_file
from helpers.noise_fit import clean_five_term_fits, quiet_fit
from imunoise import display, export, units
from imunoise.noise import gm_white_density
from imunoise.report import model_text

FS = 40.0


@pytest.fixture(scope="module")
def fast_gm_model():
    """White noise + a Gauss–Markov term of τc = 0.1 s (a sensor filter, white at
    τ = 1 s) + a slow one (τc = 5000 s, its hump beyond the 1 h record, a walk
    over it): the datasheet N and K differ from the fitted components'."""
    x = imunoise.simulate(int(3600 * FS), FS, N=2e-4, channels=3, seed=5,
                          gm=[(1.5e-3, 0.1), (3e-4, 5000.0)])
    return quiet_fit(imunoise.adev(x, FS, taus=10))


def test_values_are_the_datasheet_values_not_the_components(fast_gm_model):
    m = fast_gm_model
    parts = m.components
    for c in range(m.channels):
        white = float(parts.N[c]) ** 2 + sum(
            gm_white_density(s, tc, FS) for s, tc in parts.gauss_markov(c) if tc <= 1.0)
        assert float(m.N[c]) == pytest.approx(math.sqrt(white), rel=1e-12)
        walk = float(parts.K[c]) ** 2 + sum(
            2 * s * s / tc for s, tc in parts.gauss_markov(c)
            if tc > 1.0 and 1.8926 * tc > m.taus[-1])
        if walk > 0:
            # a walk an alternative structure fits as well is NaN; its tie keeps the value
            tie = next((t for t in m.ties[c] if t.term == "K"), None)
            given = float(m.K[c]) if tie is None else tie.value
            assert tie is None or np.isnan(m.K[c])
            assert given == pytest.approx(math.sqrt(walk), rel=1e-12)
        else:  # no walk in the model: not resolved, never 0
            assert np.isnan(m.K[c]) and m.upper["K"][c] > 0
        # the fast term makes the datasheet N larger than the fitted white noise
        assert parts.gauss_markov(c) and float(m.N[c]) > float(parts.N[c])
        assert m.supported["N"][c] and np.isfinite(m.N_std[c]) and m.N_std[c] > 0


def test_every_view_prints_the_same_numbers(fast_gm_model):
    m = fast_gm_model
    si = {"N": "rad/sqrt(s)", "B": "rad/s", "K": "rad/s/sqrt(s)"}
    table = {r["term"]: r for r in m.table("gyro", units=si)}
    for t in ("N", "B", "K"):
        for c, ax in enumerate("XYZ"):
            np.testing.assert_allclose(table[t][ax], float(m.value(t)[c]), rtol=1e-12)
            assert table[t][ax + "_supported"] == bool(m.supported[t][c])
    # datasheet units: the default table is the value converted, nothing else
    deg = m.in_units("gyro")
    np.testing.assert_allclose(deg["N"]["value"],
                               units.convert(m.N, "N", deg["N"]["unit"], sensor="gyro"))
    # repr: the values, rounded to their uncertainty
    text = repr(m)
    assert "N=" in text and "no term resolved" not in text
    # Kalibr: the worst axis of the same N and K
    kal = export.kalibr_dict(gyro=m)
    assert kal["gyroscope_noise_density"] == pytest.approx(float(np.max(m.N)), rel=1e-12)
    walk = np.where(m.resolved("K"), m.K, m.upper["K"])  # the bound where not resolved
    assert kal["gyroscope_random_walk"] == pytest.approx(float(np.max(walk)), rel=1e-12)
    # EKF: the datasheet values beside the state-space ones
    ekf = export.ekf_dict(gyro=m)["gyroscope"]["axes"]
    for c, ax in enumerate("xyz"):
        assert ekf[ax]["datasheet"]["N"] == pytest.approx(float(m.N[c]), rel=1e-12)
        assert ekf[ax]["bias_instability"] == pytest.approx(float(m.B[c]), rel=1e-12)
    # JSON: the values under their names, the components apart
    d = json.loads(export.model_json(m))
    np.testing.assert_allclose(d["N"]["value"], m.N, rtol=1e-12)
    assert d["components"]["gauss_markov"][0]
    # the comparison with a datasheet measures the same N
    cmp = imunoise.compare(m, "vn100")
    rows = [r for r in cmp.rows if r["term"] == "N"]
    assert rows
    for r in rows:
        c = "XYZ".index(r["axis"])
        want = units.convert(m.N[c], "N", r["unit"], sensor="gyro")
        assert r["measured"] == pytest.approx(float(want), rel=1e-12)


def test_not_resolved_means_one_thing():
    # white noise alone: no flat part and no walk, in every view
    x = imunoise.simulate(200_000, FS, N=1e-3, channels=3, seed=3)
    m = quiet_fit(imunoise.adev(x, FS, taus=10))
    assert not np.any(m.supported["B"]) and np.all(np.isnan(m.B)) and np.all(np.isnan(m.B_std))
    # never 0: NaN, with the largest value the curve allows, in every view
    assert np.all(m.upper["B"] > 0) and np.all(np.isnan(m.upper["N"]))
    rows = {r["term"]: r for r in m.table()}
    assert all(not rows["B"][ax + "_supported"] for ax in "XYZ")
    bounds = [display.upper_bound(rows["B"][ax + "_upper"]) for ax in "XYZ"]
    assert all(b.startswith("< ") for b in bounds)
    assert all(b in m.table_text() for b in bounds)
    header, body = model_text.datasheet_rows(m, "gyro")
    b_row = next(r for r in body if r[1] == "B")
    assert all(cell.startswith("< ") for cell in b_row[3:])
    assert "B=" not in repr(m)
    # the exports need a number: the bound, with a warning, not 0
    with pytest.warns(RuntimeWarning, match="does not resolve K on axis 0, 1, 2; writing its "
                                            "95 % upper bound"):
        kal = export.kalibr_dict(gyro=m)
    assert kal["gyroscope_random_walk"] == pytest.approx(float(np.max(m.upper["K"])))
    d = json.loads(export.model_json(m))
    assert d["B"]["value"] == [None] * 3 and d["B"]["upper"] == pytest.approx(list(m.upper["B"]))


def test_old_spellings_warn_and_name_the_new_one(fast_gm_model):
    m = fast_gm_model
    with pytest.warns(DeprecationWarning, match=r"use model\.N"):
        np.testing.assert_array_equal(m.equivalent("N"), m.value("N"))
    with pytest.warns(DeprecationWarning, match=r"use model\.K_std"):
        np.testing.assert_array_equal(m.equivalent_std("K"), m.std("K"))
    with pytest.warns(DeprecationWarning, match=r"NoiseModel\.gm_sigma .*use model\.terms"):
        np.testing.assert_array_equal(m.gm_sigma, m.components.gm_sigma)
    with pytest.warns(DeprecationWarning, match=r"NoiseModel\.gauss_markov.*use model\.terms"):
        assert m.gauss_markov(0) == m.components.gauss_markov(0)
    with pytest.warns(DeprecationWarning, match=r"NoiseModel\.cov .*use model\.terms"):
        assert m.cov.shape == m.components.cov.shape
    with pytest.raises(AttributeError, match="no attribute 'nonsense'"):
        _ = m.nonsense


def test_the_warning_points_at_the_caller(fast_gm_model):
    with pytest.warns(DeprecationWarning) as record:
        fast_gm_model.equivalent("N")
    assert record[0].filename == __file__


def test_bootstrap_gives_the_datasheet_values_their_own_spread():
    x = imunoise.simulate(100_000, FS, N=1e-3, K=1e-5, channels=1, seed=4)
    r = imunoise.adev(x, FS, taus=5)
    m = quiet_fit(r, uncertainty="bootstrap", replicates=8, seed=1)
    assert np.isfinite(m.N_std) and m.N_std > 0
    assert np.isfinite(m.components.N_std)


# -- parsimony and the flat part ------------------------------------------------------


@pytest.mark.parametrize("seed", [3, 4])
def test_clean_five_term_data_get_no_component_beyond_the_ieee_terms(seed):
    # Each component beyond the IEEE terms must bring strong evidence (6 more in BIC):
    # a correlated wiggle of the long taus of N + B + K data is no Gauss–Markov term.
    for grid, m in clean_five_term_fits(seed):
        for c in range(m.channels):
            parts = m.components
            assert not parts.gauss_markov(c) and not parts.sine(c) and not parts.resonance(c), (
                grid, c, parts.structure(c))


def test_vn100_gyro_flat_part_is_b_on_every_grid():
    """The bundled capture's gyro X is flat at ≈ 1.8e-5 rad/s from 30 to 130 s: the
    data's read-off finds that floor on every grid, the model has a B there within
    two standard uncertainties of it, and the datasheet B moves with the grid by
    less than two of its uncertainties."""
    log = imunoise.read(shared_file("data/vn100-ascii/live_capture.txt"), fs=40.0)
    values = []
    for grid in ("octave", 5, 10, 20, 50):
        m = quiet_fit(imunoise.adev(log.gyro[:, 0], log.fs, taus=grid))
        read, u_read = float(m.readoff["B"]["value"]), float(m.readoff["B"]["std"])
        assert np.isfinite(read) and 30 <= float(m.readoff["B"]["tau"]) <= 130, grid
        assert m.supported["B"], (grid, m.components.structure())
        assert abs(float(m.B) - read) <= 2 * math.hypot(u_read, float(m.B_std)), grid
        values.append((float(m.B), float(m.B_std)))
    b = np.array(values)
    assert b[:, 0].max() - b[:, 0].min() <= 2 * b[:, 1].max()


def test_a_curve_still_falling_at_its_end_has_no_read_off_floor():
    x = imunoise.simulate(100_000, FS, N=1e-3, seed=9)
    m = quiet_fit(imunoise.adev(x, FS, taus=10))
    assert np.isnan(m.readoff["B"]["value"]) and not m.supported["B"]


def test_export_write_atomic_still_writes_and_warns(tmp_path):
    target = tmp_path / "x.txt"
    with pytest.warns(DeprecationWarning, match="write_atomic is deprecated"):
        export.write_atomic(target, "hello\n")
    assert target.read_text() == "hello\n"


def test_datasheet_units_are_what_datasheets_write(fast_gm_model):
    m = fast_gm_model
    rows = {r["term"]: r for r in m.table("gyro", units="datasheet")}
    assert rows["N"]["unit"] == "deg/s/sqrt(Hz)" and rows["B"]["unit"] == "deg/h"
    assert rows["N"]["X"] == pytest.approx(float(m.N[0]) * 180 / math.pi, rel=1e-12)
    assert "°/s/√Hz" in m.table_text("gyro", units="datasheet")
    accel = {r["term"]: r for r in m.table("accel", units="datasheet")}
    assert accel["N"]["unit"] == "ug/sqrt(Hz)" and accel["B"]["unit"] == "ug"
    with pytest.raises(ValueError, match="units must be 'datasheet'"):
        m.table("gyro", units="lab")


def test_html_prints_the_bound_of_an_unresolved_value():
    """The notebook table says what the text tables say: ``< bound``, not a bare
    "not resolved", where the record cannot show a term."""
    x = imunoise.simulate(36_000, 100.0, N=1e-3, B=0.0, K=0.0, seed=3)
    m = imunoise.fit(imunoise.adev(x, 100.0))
    assert not m.resolved("K")[0]
    bound = display.upper_bound(np.atleast_1d(m.upper["K"])[0])
    assert bound.startswith("< ") and html.escape(bound) in m._repr_html_()
