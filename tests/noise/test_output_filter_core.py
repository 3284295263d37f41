"""The white term through a sensor's output filter (`_core.fit.filter_factor`),
against the Allan variance of filtered white noise computed in the time domain."""

import re

import numpy as np
import pytest
from imunoise._core import fit as core_fit
from imunoise.errors import ImunoiseValueError


def fir_white_factor(taps: np.ndarray, m: int) -> float:
    """σ²(m) of white noise through ``taps`` from its autocovariance, over the
    unfiltered white noise of the same low-frequency density."""
    gamma = np.correlate(taps, taps, "full")[len(taps) - 1:]

    def v(k):
        j = np.arange(1, min(k, len(gamma)))
        return gamma[0] * k + 2 * np.sum((k - j) * gamma[j])

    avar = (4 * v(m) - v(2 * m)) / (2 * m * m)
    return avar / (taps.sum() ** 2 / m)


def fir_gain(taps: np.ndarray, points: int) -> np.ndarray:
    nu = np.linspace(0, 0.5, points)
    h = np.exp(-2j * np.pi * np.outer(nu, np.arange(len(taps)))) @ taps
    return np.abs(h) ** 2 / taps.sum() ** 2


@pytest.mark.parametrize("taps", [np.r_[np.arange(1, 9), np.arange(7, 0, -1)].astype(float),
                                  np.ones(3), np.array([1.0, 2.0, 1.0])])
@pytest.mark.parametrize("points, rtol", [(2049, 2e-5), (32769, 1e-7)])
def test_filter_factor_is_the_time_domain_allan_variance(taps, points, rtol):
    """c(τ) is exact for the gain read linearly between its points; what is left is that
    reading of the FIR's smooth |H|² (measured: 8.5·10⁻⁶ at 2049 points, 3.3·10⁻⁸ at
    32769, falling as 1/L²)."""
    fs = 100.0
    m = np.array([1, 2, 3, 4, 7, 10, 33, 100, 1000, 20000])
    got = core_fit.filter_factor(m / fs, fs, fir_gain(taps, points))
    want = [fir_white_factor(taps, int(k)) for k in m]
    np.testing.assert_allclose(got, want, rtol=rtol)


def test_white_term_is_drawn_through_the_filter():
    fs, taps = 200.0, np.ones(4)
    taus = np.array([0.005, 0.02, 1.0])
    gain = fir_gain(taps, 513)
    white = [("white", [2.0])]
    through = core_fit.allan_terms(taus, fs, white, filter=gain)[:, 0]
    plain = core_fit.allan_terms(taus, fs, white)[:, 0]
    np.testing.assert_allclose(through / plain, core_fit.filter_factor(taus, fs, gain))
    assert through[0] < 0.5 * plain[0] and abs(through[-1] / plain[-1] - 1) < 0.01


@pytest.mark.parametrize("gain, words", [([1.0], "at least 2"), ([1.0, np.nan], "filter[1]"),
                                         ([0.9, 0.5], "filter[0]"), ([1.0, -1.0], ">= 0")])
def test_bad_gains_name_the_problem(gain, words):
    with pytest.raises(ImunoiseValueError, match=re.escape(words)):
        core_fit.filter_factor(np.array([1.0]), 10.0, np.array(gain))


@pytest.mark.parametrize("taus, fs, words", [([], 10.0, "must not be empty"),
                                             ([0.0], 10.0, "taus must be finite and > 0"),
                                             ([1.0], np.inf, "fs must be finite")])
def test_bad_taus_and_rates_name_the_problem(taus, fs, words):
    # the same checks as every model evaluation of the core (density_allan, allan_terms)
    for call in (core_fit.filter_factor, core_fit.density_allan):
        with pytest.raises(ImunoiseValueError, match=re.escape(words)):
            call(np.array(taus, dtype=float), fs, np.array([1.0, 0.5]))
