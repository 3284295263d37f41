"""The bounded-motion term: a mount whose angle wanders and comes back (a parked
vehicle rocking under a navigation-grade gyro). Its rate is white below the
correlation time and falls as 1/τ beyond; without the term the fit prints the
rocking as the sensor's angle random walk."""

import math
import warnings

import imunoise
import numpy as np
import pytest
from imunoise.report.model_text import model_sentences

FS = 100.0
ARCSEC = math.pi / 180 / 3600


def quiet_fit(result, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return imunoise.fit(result, **kwargs)


def ring_laser_on_a_vehicle(seed: int, rock=(3.7e-4, 25.0)) -> np.ndarray:
    """30.8 min at 100 Hz of a gyro with 0.002 °/√h of white noise that outputs
    integer 0.1″ angle increments, on a mount rocking by 0.02° over 25 s."""
    n = int(30.8 * 60 * FS)
    rate = imunoise.simulate(n, FS, N=5.8e-7, B=1.5e-8, seed=seed, motion=rock)
    counts = np.floor(np.cumsum(rate) / FS / (0.1 * ARCSEC))
    return np.diff(np.concatenate([[0.0], counts])) * 0.1 * ARCSEC * FS


@pytest.fixture(scope="module")
def rocking():
    x = np.column_stack([ring_laser_on_a_vehicle(s) for s in (1, 2)])
    return imunoise.adev(x, FS, taus=20)


def test_simulated_motion_has_the_models_allan_variance():
    sigma, tau_c = 1e-3, 2.0
    x = imunoise.simulate(400_000, FS, motion=(sigma, tau_c), channels=4, seed=3)
    r = imunoise.adev(x, FS, taus=[0.05, 0.5, 2.0, 10.0, 60.0])
    # The cluster mean of the rate is (θ(t+τ) − θ(t))/τ: with θ's autocovariance
    # σ²e^(−|h|/τc), σ²(τ) = σ²(3 − 4e^(−τ/τc) + e^(−2τ/τc))/τ², exact when sampled.
    u = r.taus / tau_c
    want = sigma**2 * (3 - 4 * np.exp(-u) + np.exp(-2 * u)) / r.taus**2
    np.testing.assert_allclose(np.mean(r.var, axis=1), want, rtol=0.12)
    # The fit of the term alone recovers it, and its curve is that formula.
    model = quiet_fit(r, terms=["motion"])
    for c in range(4):
        (s, t), = model.components.motion(c)
        assert s == pytest.approx(sigma, rel=0.15) and t == pytest.approx(tau_c, rel=0.3)
        curve = model.predict(r.taus).terms["motion"][:, c] ** 2
        form = s**2 * (3 - 4 * np.exp(-r.taus / t) + np.exp(-2 * r.taus / t)) / r.taus**2
        np.testing.assert_allclose(curve, form, rtol=1e-9)


def test_the_fit_finds_the_rocking_and_does_not_call_it_white_noise(rocking):
    model = quiet_fit(rocking)
    parts = model.components
    for c in range(2):
        (sigma, tau_c), = parts.motion(c)
        assert sigma == pytest.approx(3.7e-4, rel=0.3)
        assert 25.0 / 2 < tau_c < 25.0 * 2
        assert "motion(" in parts.structure(c)
        # The rocking's white part, 2σ²/τc ≈ 1.1e-4 rad/√s, is 180x the gyro's own
        # N: N leaves the motion out, so it is not resolved under it.
        assert not model.resolved("N")[c] or model.N[c] < 2e-5
    # Without the term (the fit before it): the rocking printed as the gyro's N, and a
    # model that follows fewer taus (30 min hold only ~70 correlation times of the
    # rocking, so neither follows every tau).
    without = quiet_fit(rocking, terms=["Q", "N", "B", "K", "GM", "sine"])
    assert np.all(without.N > 5e-5)
    assert np.all(model.coverage > without.coverage)


def test_the_report_says_what_the_motion_is(rocking):
    model = quiet_fit(rocking)
    text = " ".join(model_sentences(model, "gyro"))
    assert "bounded motion of the mount" in text
    if not model.resolved("N")[0]:
        assert "N is not resolved, at most" in text


def test_explicit_motion_term_and_its_table_rows(rocking):
    only = quiet_fit(rocking, terms=["N", "motion"])
    assert all(len(only.components.motion(c)) == 1 for c in range(2))
    rows = {r["term"]: r for r in only.table("gyro")}
    assert rows["σθ"]["unit"] == rows["Q"]["unit"]  # an angle, in Q's unit
    assert rows["τm"]["unit"] == "s"
    assert only.components.to_dict()["motion"][0][0]["tau_c"] > 1.0
    with pytest.raises(ValueError, match=r"every other name at most once; got \['N', 'motion'"):
        imunoise.fit(rocking, terms=["N", "motion", "motion"])


def test_simulate_checks_the_motion_argument():
    with pytest.raises(TypeError, match="motion must be a"):
        imunoise.simulate(10, FS, motion=1.0)
    with pytest.raises(ValueError, match="motion tau_c must be finite and > 0 s; got -1"):
        imunoise.simulate(10, FS, motion=(1.0, -1.0))
