"""The model's sentences (report and ``imunoise fit``) round every estimate to its uncertainty."""

import imunoise
import numpy as np
import pytest
from imunoise import numbers, units
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
    assert f"σ = {numbers.format_value(sigma_deg, sigma_std_deg)} °/h" in sentence
    tau_std = float(np.ravel(gm_model.components.gm_tau_std)[0])
    assert f"τc = {numbers.format_value(tau, tau_std)} s" in sentence
    read = gm_model.readoff["N"]
    n_deg, n_std = units.convert(np.array([float(read["value"]), float(read["std"])]), "N",
                                 "deg/sqrt(h)", sensor="gyro")
    assert f"N read-off {numbers.format_value(n_deg, n_std)} vs model " in sentence
    assert " ± " in sentence.split("vs model")[1]
