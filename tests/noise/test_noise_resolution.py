"""What a record's resolution (its count, LSB or print step) adds to N and Q.

Oracles: the white noise measured on records rounded to a step (the fit's N² against
the input's N² plus step²/(12·fs)), and Q measured on counted angle increments
against step/(fs·√12) (IEEE 952's quantization noise), where the angle moves by
several counts per sample.
"""

from __future__ import annotations

import math

import imunoise
import numpy as np
import pytest
from helpers.noise_fit import quiet_fit
from imunoise import stats
from imunoise.noise import resolution_noise
from imunoise.report import model_sentences

FS = 100.0


def test_rounding_each_sample_adds_white_noise_of_the_step():
    n_white, step = 1e-3, 0.01  # noise per sample 1e-2: about one count
    x = np.round(imunoise.simulate(360_000, FS, N=n_white, channels=3, seed=1) / step) * step
    model = quiet_fit(imunoise.adev(x, FS, taus=10))
    n_round, _ = resolution_noise(step, FS)
    np.testing.assert_allclose(model.N, math.hypot(n_white, n_round), rtol=0.01)
    # the rounding is visible: without it N would be 4 % lower
    assert np.all(model.N > n_white * 1.03)


def test_counted_angle_increments_have_the_quantization_of_the_count():
    """1 µrad counts at 400 Hz of a gyro whose angle moves a quarter count per sample:
    the quantization shows at the shortest taus (a whole count per sample of white
    noise would bury its τ⁻² under the τ⁻¹ of that noise)."""
    fs, step = 400.0, 1e-6
    rate = imunoise.simulate(720_000, fs, N=5e-6, B=1e-6, channels=2, seed=2)
    counts = np.floor(np.cumsum(rate, axis=0) / fs / step)
    x = np.diff(np.vstack([np.zeros((1, 2)), counts]), axis=0) * step * fs
    assert stats.quantization_step(x[:, 0]) == pytest.approx(step * fs)
    model = quiet_fit(imunoise.adev(x, fs, taus=10))
    _, q_count = resolution_noise(step * fs, fs)
    assert q_count == pytest.approx(step / math.sqrt(12))
    # slightly below: an angle that moves less than a count per sample leaves
    # rounding errors correlated from sample to sample
    np.testing.assert_allclose(model.Q, q_count, rtol=0.12)
    assert np.all(model.Q < q_count)
    sentences = model_sentences(model, "gyro", steps=[step * fs] * 2)
    assert all("counts of an integrated angle of the samples' resolution" in s for s in sentences)


def test_resolution_noise_rejects_a_bad_step():
    with pytest.raises(ValueError, match="step must be finite and > 0; got 0.0"):
        resolution_noise(0.0, FS)
    with pytest.raises(ValueError, match="fs must be finite and > 0; got nan"):
        resolution_noise(1.0, math.nan)


def test_the_report_says_where_the_resolution_limits_n():
    x = np.round(imunoise.simulate(360_000, FS, N=1e-3, channels=2, seed=3) / 0.02) * 0.02
    model = quiet_fit(imunoise.adev(x, FS, taus=10))
    steps = [stats.quantization_step(x[:, c]) for c in range(2)]
    coarse = model_sentences(model, "gyro", steps=steps)
    assert all("the log's resolution limits the N measured here" in s for s in coarse)
    assert all("whole multiples of" in s for s in coarse)
    # a fine print resolution goes unsaid; no step, no sentence
    fine = model_sentences(model, "gyro", steps=[1e-7, None])
    assert not any("whole multiples" in s for s in fine)
    assert model_sentences(model, "gyro") == model_sentences(model, "gyro", steps=[None, None])
    with pytest.raises(ValueError, match=r"steps must have one value per channel \(2\); got 3"):
        model_sentences(model, "gyro", steps=[0.01] * 3)
