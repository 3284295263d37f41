"""The resonance's skew (its quadrature part): a sensor's own second-order filter.

A second-order low-pass filter's output has the autocovariance
ρ^|h|(cos θh + β sin θ|h|) with β ≠ 0; the plain resonance (β = 0) draws it only
roughly. Oracles: scipy's Butterworth filter applied to white noise (whose output's
white density at low frequency is the input's, the filter passing DC at unit gain),
imunoise.adev of the simulated ARMA(2, 1) process against the closed form (itself
checked against the direct sum over lags in the Rust tests), and the long-τ limit.
"""

from __future__ import annotations

import math

import imunoise
import numpy as np
import pytest
from helpers.noise_fit import quiet_fit
from imunoise._core import fit as core_fit
from imunoise.noise import resonance_white_density
from imunoise.noise._terms import term_variances
from imunoise.report.model_text import model_sentences
from scipy.signal import butter, lfilter

FS = 100.0


def _curve(taus, resonance):
    t = np.ascontiguousarray(taus, dtype=float)
    return core_fit.allan_terms(t, FS, [("resonance", [float(v) for v in resonance])])[:, 0]


@pytest.mark.parametrize("skew", [1.0, 0.4, -0.6, -1.0])
def test_simulated_skew_has_the_closed_form_allan_variance(skew):
    sigma, f_r, tau_r = 2.0, 7.0, 0.03
    x = imunoise.simulate(400_000, FS, resonance=(sigma, f_r, tau_r, skew), seed=4)
    assert np.std(x) == pytest.approx(sigma, rel=0.05)
    r = imunoise.adev(x, FS, taus=np.array([0.01, 0.02, 0.05, 0.1, 0.3, 1.0, 3.0]))
    want = _curve(r.taus, (sigma**2, f_r, tau_r, skew))
    np.testing.assert_array_less(np.abs(r.var / want - 1), 4 * np.sqrt(2 / r.edf) + 0.01)
    # The skew shapes the curve: the plain resonance's is elsewhere by far more.
    plain = _curve(r.taus, (sigma**2, f_r, tau_r, 0.0))
    assert np.max(np.abs(plain / want - 1)) > 0.2


def test_the_long_tau_limit_is_the_white_density_with_the_skew():
    for skew in (1.0, 0.3, -0.5):
        n2 = resonance_white_density(1.0, 7.0, 0.03, FS, skew)
        far = _curve(np.array([300.0]), (1.0, 7.0, 0.03, skew))[0]
        assert far == pytest.approx(n2 / 300.0, rel=1e-2)
    # Skew −1 puts the spectrum's zero at 0 Hz: no white noise at long τ.
    assert resonance_white_density(1.0, 7.0, 0.03, FS, -1.0) == pytest.approx(0.0, abs=1e-15)


def test_a_skew_beyond_its_bound_is_rejected():
    with pytest.raises(ValueError, match=r"resonance skew must be in \[-1, 1\].*got 1.5"):
        imunoise.simulate(100, FS, resonance=(1.0, 7.0, 0.03, 1.5))
    with pytest.raises(ValueError, match=r"resonance skew must be in \[-1, 1\].*got nan"):
        imunoise.simulate(100, FS, resonance=(1.0, 7.0, 0.03, math.nan))
    with pytest.raises(TypeError, match="quadruple"):
        imunoise.simulate(100, FS, resonance=(1.0, 7.0, 0.03, 0.0, 1.0))
    with pytest.raises(ValueError, match=r"resonance skew must be in \[-1, 1\]"):
        _curve(np.array([1.0]), (1.0, 7.0, 0.03, -1.2))


@pytest.fixture(scope="module")
def filtered():
    """White noise through scipy's 2nd-order Butterworth low-pass at fs/10 (the
    MPU-6050's DLPF), 30 min at 100 Hz, 3 axes, plus a slow rate random walk."""
    n_white = 1e-3
    x = imunoise.simulate(180_000, FS, N=n_white, K=2e-6, channels=3, seed=11)
    b, a = butter(2, 10.0 / (FS / 2))
    return imunoise.adev(lfilter(b, a, x, axis=0), FS, taus=20), n_white


def test_a_second_order_low_pass_is_a_resonance_with_skew(filtered):
    r, n_white = filtered
    model = quiet_fit(r)
    parts = model.components
    for c in range(3):
        (_, f_r, tau_r, skew), = parts.resonance(c)
        # The filter's poles: 10 Hz corner, 135° — a damped 7.1 Hz, Q ½.
        assert f_r == pytest.approx(7.07, rel=0.1), model
        assert math.pi * f_r * tau_r == pytest.approx(0.5, rel=0.2), model
        assert skew > 0.5, model
    assert np.all(np.atleast_1d(model.coverage) >= 0.95), model.coverage
    # N is the filter's input: the output's density at low frequency.
    np.testing.assert_allclose(model.N, n_white, rtol=0.03)
    table = {row["term"]: row for row in model.table()}
    assert table["s_r"]["X"] == pytest.approx(parts.resonance(0)[0][3])
    assert "second-order low-pass filter" in "\n".join(
        model_sentences(model, "gyro"))


def test_the_skew_is_reported_everywhere(filtered):
    r, _ = filtered
    model = quiet_fit(r)
    parts = model.components
    skew = parts.resonance(1)[0][3]
    assert parts.to_dict()["resonance"][1][0]["skew"] == skew
    assert f"(skew {skew:.2g})" in repr(parts)
    assert parts.resonance_skew_std[1] > 0 or not abs(skew) < 1
    # The model's curve is the one the Rust fit drew, skew included.
    dev = parts.predict(r.taus).dev[:, 1]
    plain = [(s, f, t, 0.0) for s, f, t, _ in parts.resonance(1)]
    without = np.sqrt(term_variances(r.taus, FS, [parts.value(t)[1] for t in "QNBKR"],
                                     parts.gauss_markov(1), parts.sine(1), plain,
                                     parts.motion(1)).sum(axis=1))
    assert np.max(np.abs(without / dev - 1)) > 0.02


@pytest.mark.parametrize("seed", [0, 2])
def test_a_line_beside_a_broad_filter_band_keeps_its_frequency(seed):
    """An 18.5 Hz line beside a broad band at 45 Hz (Q 1, skew 0.8), 1 h at 100 Hz, 10
    taus per decade: the band takes part of what the line described without it, and
    the line, searched again on the whole grid with the band in place, stays at its
    frequency (refined only within a grid step it sat at 18.1–18.3 Hz). N is the white
    noise plus the band's white tail at long τ."""
    n_white, sigma, f_r, q, skew = 5e-5, 8e-4, 45.0, 1.0, 0.8
    tau_r = q / (math.pi * f_r)
    x = imunoise.simulate(int(3600 * FS), FS, N=n_white, K=1e-6, seed=seed,
                          sinusoid=(4e-4, 18.5), resonance=(sigma, f_r, tau_r, skew))
    model = quiet_fit(imunoise.adev(x, FS, taus=10))
    (_, f0), = model.components.sine()
    assert f0 == pytest.approx(18.5, rel=5e-3), model.components
    assert len(model.components.resonance()) == 1, model.components
    want = math.sqrt(n_white**2 + resonance_white_density(sigma, f_r, tau_r, FS, skew))
    assert float(model.N) == pytest.approx(want, rel=0.03)
    assert float(model.coverage) >= 0.95
