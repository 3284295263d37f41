"""The tone (sinusoidal) term of the noise model: simulation, Allan variance,
selection only where a tone is, recovery, exposure (predict, dict, repr, plot).

Oracles: the IEEE 952 Annex C formula A²·sin⁴(πf0τ)/(πf0τ)² (which the sampled
form tends to for f0 ≪ fs), the Allan variance computed by imunoise.adev on the
simulated tone, and the amplitude and frequency put into the simulator.
"""

from __future__ import annotations

import json
import math

import imunoise
import imunoise.plot
import matplotlib
import numpy as np
import pytest
from helpers.noise_fit import clean_five_term_fits, quiet_fit

matplotlib.use("Agg")

FS = 100.0


@pytest.fixture(scope="module")
def toned():
    """White noise + a tone at 7.3 Hz + rate random walk, 1 h at 100 Hz, 2 channels."""
    truth = {"N": 1e-3, "K": 2e-5, "A": 4e-3, "f0": 7.3}
    x = imunoise.simulate(int(3600 * FS), FS, N=truth["N"], K=truth["K"], channels=2,
                          seed=5, sinusoid=(truth["A"], truth["f0"]))
    return truth, imunoise.adev(x, FS, taus=20)


def test_simulated_tone_has_the_ieee_allan_variance():
    a, f0 = 2.0, 0.37
    x = imunoise.simulate(400_000, FS, sinusoid=(a, f0), seed=1)
    assert np.std(x) == pytest.approx(a / math.sqrt(2), rel=0.01)
    r = imunoise.adev(x, FS, taus=np.array([0.5, 1.0, 2.0, 4.0]))
    x_ = np.pi * f0 * r.taus
    ieee = a**2 * np.sin(x_) ** 4 / x_**2
    np.testing.assert_allclose(r.var, ieee, rtol=0.02)


def test_simulate_rejects_a_bad_tone():
    with pytest.raises(ValueError, match="sinusoid f0 must be finite and > 0 Hz; got 0.0"):
        imunoise.simulate(100, FS, sinusoid=(1.0, 0.0))
    with pytest.raises(ValueError, match="sinusoid amplitude must be finite and >= 0"):
        imunoise.simulate(100, FS, sinusoid=(-1.0, 1.0))
    with pytest.raises(TypeError, match="sinusoid must be an"):
        imunoise.simulate(100, FS, sinusoid=1.0)


def test_tone_is_selected_and_recovered(toned):
    truth, r = toned
    model = quiet_fit(r)
    for c in range(2):
        tone = model.components.sine(c)
        assert len(tone) == 1, model
        amp, f0 = tone[0]
        assert f0 == pytest.approx(truth["f0"], rel=0.01)
        assert amp == pytest.approx(truth["A"], rel=0.10)
        assert abs(amp - truth["A"]) < 4 * model.components.sine_amplitude_std[c, 0]
        assert model.N[c] == pytest.approx(truth["N"], rel=0.02)
        assert model.components.gauss_markov(c) == []
    assert np.all(model.coverage >= 0.9)


def test_without_the_tone_the_model_misses_the_curve(toned):
    _, r = toned
    plain = quiet_fit(r, terms=["N", "K", "GM", "GM"])
    toned_fit = quiet_fit(r, terms=["N", "K", "sine"])
    assert np.all(toned_fit.coverage > plain.coverage)
    assert np.all(toned_fit.discrepancy < plain.discrepancy)


@pytest.mark.parametrize("seed", [3, 4])
def test_clean_five_term_data_selects_no_tone(seed):
    for grid, model in clean_five_term_fits(seed):
        assert all(model.components.sine(c) == [] for c in range(3)), (grid, model)
        assert np.all(np.isnan(model.components.sine_amplitude))


def test_gauss_markov_data_selects_no_tone():
    x = imunoise.simulate(int(2 * 3600 * FS), FS, N=2e-3, channels=2, seed=21,
                          gm=[(4e-3, 20.0)])
    model = quiet_fit(imunoise.adev(x, FS, taus=20))
    for c in range(2):
        assert model.components.sine(c) == []
        assert len(model.components.gauss_markov(c)) == 1


def test_tone_in_prediction_dict_repr_and_plot(toned):
    truth, r = toned
    model = quiet_fit(r)
    p = model.predict(r.taus)
    assert "sine" in p.terms
    x_ = np.pi * model.components.sine(0)[0][1] * r.taus
    # Far below fs the sampled form is IEEE 952's.
    slow = r.taus * model.components.sine(0)[0][1] < 0.3
    ieee = model.components.sine(0)[0][0] ** 2 * np.sin(x_) ** 4 / x_**2
    np.testing.assert_allclose(p.terms["sine"][slow, 0] ** 2, ieee[slow], rtol=0.05)
    total = sum(v**2 for v in p.terms.values())
    np.testing.assert_allclose(total, p.dev**2, rtol=1e-12)
    d = model.to_dict()
    json.dumps(d)
    assert d["components"]["sine"][1][0]["frequency"] == pytest.approx(truth["f0"], rel=0.01)
    assert "tone" in repr(model) and "Hz" in repr(model)
    assert "tone" in model._repr_html_()
    fig = imunoise.plot.allan(r, model=model)
    labels = [ln.get_label() for ln in fig.axes[0].get_lines()]
    assert "tone (envelope)" in labels


def test_explicit_sine_terms_are_checked(toned):
    _, r = toned
    with pytest.raises(ValueError, match="'sine' at most 2 times"):
        imunoise.fit(r, terms=["N", "sine", "sine", "sine"])
    only = quiet_fit(r, terms=["N", "sine"])
    assert all(len(only.components.sine(c)) == 1 for c in range(2))
    assert not np.any(only.supported["K"])


def test_bootstrap_simulates_and_refits_the_tone():
    x = imunoise.simulate(int(1800 * FS), FS, N=1e-3, seed=9, sinusoid=(4e-3, 7.3))
    r = imunoise.adev(x, FS, taus=10)
    model = quiet_fit(r, uncertainty="bootstrap", replicates=6, seed=2)
    assert model.components.sine(0) != []
    parts = model.components
    amp_std, f_std = parts.sine_amplitude_std[0], parts.sine_freq_std[0]
    # The replicates' spread is small next to the tone yet not zero.
    assert 0 < amp_std < 0.1 * parts.sine_amplitude[0]
    assert 0 < f_std < 0.01 * parts.sine_freq[0]
    assert np.isnan(parts.sine_amplitude[1])


def test_two_tones_fixed_and_simulated():
    """``terms`` may name ``"sine"`` twice, ``simulate`` takes a list of tones, and
    the bootstrap simulates and refits both."""
    x = imunoise.simulate(int(1800 * FS), FS, N=1e-3, seed=9,
                          sinusoid=[(4e-3, 7.3), (3e-3, 0.9)])
    r = imunoise.adev(x, FS, taus=10)
    model = quiet_fit(r, terms=["N", "sine", "sine"], uncertainty="bootstrap", replicates=6,
                      seed=2)
    tones = model.components.sine(0)
    np.testing.assert_allclose([f0 for _, f0 in tones], [0.9, 7.3], rtol=0.01)
    np.testing.assert_allclose([a for a, _ in tones], [3e-3, 4e-3], rtol=0.1)
    stds = model.components.sine_amplitude_std
    assert np.all((stds > 0) & (stds < 0.2 * model.components.sine_amplitude))
    rows = [row[0] for row in model.components.other_terms()]
    assert rows == ["A1", "f1", "A2", "f2"]
    assert model.components.count(0) == 3
