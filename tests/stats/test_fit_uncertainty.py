"""The normal fit's μ and σ carry standard uncertainties that see the samples' correlation."""

import numpy as np
import pytest
from imunoise import stats
from scipy import signal


def test_white_samples_give_the_textbook_standard_errors():
    ratios_mu, ratios_sigma = [], []
    for seed in range(20):
        x = np.random.default_rng(seed).normal(3.0, 2.0, 20_000)
        d = stats.distribution(x)
        ratios_mu.append(d.mu_std / (d.sigma / np.sqrt(d.n)))
        ratios_sigma.append(d.sigma_std / (d.sigma / np.sqrt(2 * d.n)))
    # batch means with 20 batches: each estimate scatters ~16 %, their median far less
    assert np.median(ratios_mu) == pytest.approx(1.0, abs=0.1)
    assert np.median(ratios_sigma) == pytest.approx(1.0, abs=0.1)


def test_correlated_samples_widen_the_uncertainty_of_the_mean():
    phi = 0.9  # AR(1): var(mean) is (1 + φ)/(1 − φ) = 19 times that of independent samples
    ratios = []
    for seed in range(20):
        w = np.random.default_rng(seed).normal(size=100_000)
        x = signal.lfilter([1.0], [1.0, -phi], w)
        d = stats.distribution(x)
        ratios.append(d.mu_std / (d.sigma / np.sqrt(d.n)))
    assert np.median(ratios) == pytest.approx(np.sqrt((1 + phi) / (1 - phi)), rel=0.1)


def test_too_few_samples_for_batches_give_nan_and_gaps_are_left_out():
    d = stats.distribution(np.arange(100.0))
    assert np.isnan(d.mu_std) and np.isnan(d.sigma_std)
    x = np.random.default_rng(1).normal(size=10_000)
    x[100:200] = np.nan
    d = stats.distribution(x)
    assert d.n == 9_900 and np.isfinite(d.mu_std) and d.mu_std > 0
