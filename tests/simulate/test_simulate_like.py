"""Noise like a measured sensor's: from its model, its Allan deviation or its PSD, the
simulated record has the source's curve and spectrum."""

from __future__ import annotations

import warnings

import imunoise
import numpy as np
import pytest

FS = 100.0


@pytest.fixture(scope="module")
def measured():
    x = imunoise.simulate(300_000, FS, N=1e-3, B=2e-4, channels=3, seed=1,
                          gm=[(3e-3, 0.05)])
    r = imunoise.adev(x, FS, taus=10)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = imunoise.fit(r)
    return x, r, model


def _short_tau_ratio(y, r):
    """The simulated record's ADEV over the source's at τ ≤ 1 s (many terms there)."""
    again = imunoise.adev(y, FS, taus=r.taus[r.taus <= 1.0])
    return again.dev / r.dev[: again.dev.shape[0]]


def test_from_a_model_each_channel_follows_its_curve(measured):
    _, r, model = measured
    y = imunoise.simulate(300_000, FS, like=model, seed=2)
    assert y.shape == (300_000, 3)
    np.testing.assert_allclose(_short_tau_ratio(y, r), 1.0, atol=0.06)


def test_from_an_allan_deviation_through_its_fit(measured):
    _, r, _ = measured
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        y = imunoise.simulate(300_000, None, like=r, seed=3)
    np.testing.assert_allclose(_short_tau_ratio(y, r), 1.0, atol=0.06)


def test_from_a_spectrum_the_psd_and_variance_come_back(measured):
    x, _, _ = measured
    s = imunoise.psd(x, FS)
    y = imunoise.simulate(300_000, None, like=s, seed=4)
    np.testing.assert_allclose(imunoise.psd(y, FS).N, s.N, rtol=0.03)
    np.testing.assert_allclose(y.var(axis=0), x.var(axis=0), rtol=0.03)
    # a pair (f, psd) of one channel, repeated over three
    z = imunoise.simulate(100_000, FS, like=(s.f, s.psd[:, 0]), channels=3, seed=5)
    assert z.shape == (100_000, 3)
    assert not np.allclose(z[:, 0], z[:, 1])


def test_like_takes_no_coefficients_and_names_what_is_wrong(measured):
    _, r, model = measured
    with pytest.raises(ValueError, match="like= replaces the coefficients; leave out N, gm"):
        imunoise.simulate(1000, FS, N=1.0, gm=[(1.0, 1.0)], like=model)
    with pytest.raises(TypeError, match="like must be a NoiseModel"):
        imunoise.simulate(1000, FS, like=[1, 2, 3])
    with pytest.raises(ValueError, match=r"fs must be the source's own rate \(100.0 Hz\)"):
        imunoise.simulate(1000, 50.0, like=model)
    with pytest.raises(ValueError, match="fs must be given with like=\\(f, psd\\)"):
        imunoise.simulate(1000, None, like=(np.array([1.0, 2.0]), np.array([1.0, 1.0])))
    with pytest.raises(ValueError, match="channels must be None or 3"):
        imunoise.simulate(1000, FS, like=model, channels=2)
    with pytest.raises(ValueError, match="increasing"):
        imunoise.simulate(1000, FS, like=(np.array([2.0, 1.0]), np.array([1.0, 1.0])))
