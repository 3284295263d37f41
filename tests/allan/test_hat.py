"""Several sensors on one mount: GCODEV against allantools, and the three-cornered hat
recovering each gyro's own noise under a common motion far above it."""

import warnings

import allantools as at
import imunoise
import numpy as np
import pytest
from helpers.signals import noise

FS = 20.0
#: 8 h at 20 Hz: long enough for 10 % at τ = 10 s (≈ 2900 independent pairs)
N_SAMPLES = int(8 * 3600 * FS)
WHITE = (0.010, 0.012, 0.015)  # each gyro's own angle random walk, rate·√s
TAUS = np.geomspace(0.1, 10.0, 11)


@pytest.fixture(scope="module")
def gyros():
    """Three gyros on one rocking, swaying mount: a Gauss–Markov sway (σ 2, 5 s)
    and a 0.7 Hz rocking of amplitude 1.5, both far above their own white noise."""
    t = np.arange(N_SAMPLES) / FS
    motion = (imunoise.simulate(N_SAMPLES, FS, gm=[(2.0, 5.0)], seed=100)
              + 1.5 * np.sin(2 * np.pi * 0.7 * t + 0.3))
    return [motion + imunoise.simulate(N_SAMPLES, FS, N=n, seed=200 + i)
            for i, n in enumerate(WHITE)]


def test_each_gyro_own_white_noise_within_ten_percent(gyros):
    hat = imunoise.three_cornered_hat(*gyros, FS, taus=TAUS)
    for own, white, gyro in zip(hat, WHITE, gyros, strict=True):
        truth = white / np.sqrt(own.taus)
        np.testing.assert_allclose(own.dev, truth, rtol=0.10)
        # the plain ADEV is the motion's, 8 to 250 times the own noise
        plain = imunoise.adev(gyro, FS, taus=TAUS)
        assert np.all(plain.dev > 8 * truth)
        assert own.kind == "adev" and not hat.negative.any()
        # 68 % intervals, conservative: they hold the truth at most taus (6 seeds:
        # 64–100 % of them)
        inside = (own.ci_low <= truth) & (truth <= own.ci_high)
        assert inside.mean() >= 0.6
    ra, rb, rc = hat
    assert ra is hat.a and rc is hat.c and "negative at a 0, b 0, c 0" in repr(hat)


def test_fit_takes_a_hat_result(gyros):
    ra = imunoise.three_cornered_hat(*(g[: 200_000] for g in gyros), FS,
                                     taus="octave").a
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = imunoise.fit(ra, terms=("N",))
    assert abs(float(np.ravel(model.N)[0]) / WHITE[0] - 1) < 0.1


def test_a_negative_variance_is_said_never_silent():
    rng = np.random.default_rng(1)
    common = 5 * rng.normal(size=4000)
    quiet = common + 1e-6 * rng.normal(size=4000)
    a, b = common + rng.normal(size=4000), common + rng.normal(size=4000)
    with pytest.warns(UserWarning, match=r"sensor c's adev variance is negative at tau = "):
        hat = imunoise.three_cornered_hat(a, b, quiet, 1.0)
    assert hat.negative[2].any()
    below = hat.negative[2]
    assert np.all(hat.c.var[below] < 0) and np.all(np.isnan(hat.c.dev[below]))
    assert np.all(hat.c.ci_low[below] == 0) and np.all(hat.c.ci_high[below] > 0)
    assert np.all(np.isfinite(hat.c.dev[~below]))


def test_hat_of_other_statistics_and_channels():
    rng = np.random.default_rng(2)
    common = np.cumsum(rng.normal(size=(6000, 2)), axis=0)
    own = [s * rng.normal(size=(6000, 2)) for s in (1.0, 2.0, 3.0)]
    for kind in ("mdev", "hdev", "pdev", "totdev"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            hat = imunoise.three_cornered_hat(*(common + o for o in own), 1.0, kind=kind,
                                              taus=np.array([1.0, 2.0, 4.0]))
        assert hat.a.dev.shape == (3, 2) and hat.negative.shape == (3, 3, 2)
        ref = getattr(imunoise, kind)(own[2], 1.0, taus=np.array([1.0, 2.0, 4.0]))
        np.testing.assert_allclose(hat.c.dev, ref.dev, rtol=0.15)


def test_hat_errors_name_the_argument():
    y = np.zeros(100)
    with pytest.raises(ValueError, match=r"c must have as many samples as a \(100\); got 99"):
        imunoise.three_cornered_hat(y, y, y[:99], 1.0)
    with pytest.raises(ValueError, match=r"b must have the 1 channel\(s\) of a; got 2"):
        imunoise.three_cornered_hat(y, np.zeros((100, 2)), y, 1.0)
    with pytest.raises(ValueError, match="kind must be one of adev, .*; got 'theobr'"):
        imunoise.three_cornered_hat(y, y, y, 1.0, kind="theobr")
    with pytest.raises(ValueError, match=r"b must have as many samples as a \(100\); got 10"):
        imunoise.gcodev(y, y[:10], 1.0)


@pytest.mark.parametrize("kind", ["white", "flicker", "walk"])
@pytest.mark.parametrize("data_type", ["freq", "phase"])
def test_gcodev_equals_allantools(kind, data_type):
    a = noise(kind, 3001, seed=3)
    b = noise(kind, 3001, seed=4) - 0.7 * a  # a negative covariance: the sign is kept
    if data_type == "phase":
        a, b = a * 1e-9, b * 1e-9
    r = imunoise.gcodev(a, b, 5.0, data_type=data_type)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t, dev, _e, n = at.gcodev(a, b, rate=5.0, data_type=data_type, taus="octave")
    np.testing.assert_allclose(r.taus, t, rtol=1e-12)
    np.testing.assert_array_equal(r.n, n)
    np.testing.assert_allclose(r.dev, dev, rtol=1e-9)
    assert r.kind == "gcodev" and np.all(np.abs(r.var) == pytest.approx(r.dev**2))
    assert np.all(r.ci_low <= r.dev) and np.all(r.dev <= r.ci_high)


def test_gcodev_of_two_gyros_is_their_common_motion(gyros):
    a, b = (g[:400_000] for g in gyros[:2])
    taus = np.array([0.1, 1.0, 10.0])
    cov = imunoise.gcodev(a, b, FS, taus=taus)
    assert np.all(cov.var > 0)
    # a's own noise from two gyros only: its Allan variance less the shared part
    own = imunoise.adev(a, FS, taus=taus).var - cov.var
    np.testing.assert_allclose(np.sqrt(own[:2]), WHITE[0] / np.sqrt(taus[:2]), rtol=0.2)
