"""The model's sentences (report and ``imunoise fit``) round every estimate to its uncertainty."""

import imunoise
import numpy as np
import pytest
from imunoise import display, units
from imunoise.report.model_text import model_sentences


@pytest.fixture(scope="module")
def gm_model():
    x = imunoise.simulate(200_000, 40.0, N=1e-3, K=1e-5, gm=[(3e-4, 30.0)], seed=1)
    return imunoise.fit(imunoise.adev(x, 40.0, taus=10), warn_coverage=False)


def test_gauss_markov_and_readoffs_carry_their_uncertainty(gm_model):
    (sentence,) = model_sentences(gm_model, "gyro")
    sigma, tau = gm_model.components.gauss_markov(0)[0]
    sigma_deg, sigma_std_deg = units.convert(
        np.array([sigma, float(np.ravel(gm_model.components.gm_sigma_std)[0])]), "B", "deg/h",
        sensor="gyro")
    assert f"σ = {display.format_value(sigma_deg, sigma_std_deg)} °/h" in sentence
    tau_std = float(np.ravel(gm_model.components.gm_tau_std)[0])
    assert f"τc = {display.format_value(tau, tau_std)} s" in sentence
    read = gm_model.readoff["N"]
    n_deg, n_std = units.convert(np.array([float(read["value"]), float(read["std"])]), "N",
                                 "deg/sqrt(h)", sensor="gyro")
    assert f"N read-off {display.format_value(n_deg, n_std)} vs model " in sentence
    assert " ± " in sentence.split("vs model")[1]


def test_an_n_carried_by_a_visible_hump_is_said_to_be_filter_or_disturbance():
    """A ring-laser gyro on a parked vehicle: the vehicle's vibration (a 0.04 s
    Gauss–Markov hump, 200× the gyro's white noise) is all the datasheet N there is.
    The sentence says the curve cannot tell a filter from a disturbance; a plain
    white-noise axis, and a sensor filter faster than the first tau, get no such
    sentence."""
    fs = 100.0
    x = imunoise.simulate(180_000, fs, N=8.7e-7, gm=[(2e-4, 0.04)], seed=3)
    hump = imunoise.fit(imunoise.adev(x, fs, taus=20), warn_coverage=False)
    (sentence,) = model_sentences(hump, "gyro")
    assert "the white tail of the Gauss–Markov term" in sentence
    assert "cannot tell apart" in sentence
    plain = imunoise.fit(imunoise.adev(imunoise.simulate(180_000, fs, N=1e-4, seed=3), fs,
                                       taus=20), warn_coverage=False)
    assert "white tail" not in model_sentences(plain, "gyro")[0]
    fast = imunoise.simulate(180_000, fs, N=1e-7, gm=[(2e-4, 0.004)], seed=3)
    filtered = imunoise.fit(imunoise.adev(fast, fs, taus=20), warn_coverage=False)
    assert "white tail" not in model_sentences(filtered, "gyro")[0]
