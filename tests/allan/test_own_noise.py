"""Each sensor's own noise from the logs of sensors on one mount: aligned on time (own
clocks, different starts), then the three-cornered hat (three logs) or the Groslambert
covariance (two), each sensor's own white noise recovered under a motion far above it."""

from __future__ import annotations

import warnings

import imunoise
import numpy as np
import pytest
from helpers.mount import mount_logs

FS = 20.0
#: 8 h at 20 Hz: long enough for 10 % at τ = 10 s (as tests/allan/test_hat.py)
N_SAMPLES = int(8 * 3600 * FS)
WHITE = (0.010, 0.012, 0.015)  # each gyro's own angle random walk, rate·√s
TAUS = np.geomspace(0.1, 10.0, 11)


def _within(result, white, rtol):
    truth = white / np.sqrt(result.taus)[:, None]
    np.testing.assert_allclose(result.dev, np.broadcast_to(truth, result.dev.shape), rtol=rtol)


def test_three_logs_on_their_own_clocks_each_gyro_within_ten_percent():
    logs = mount_logs(N_SAMPLES, FS, WHITE, starts=(0, 1500, 3100),
                      ends=(N_SAMPLES - 1000, N_SAMPLES, N_SAMPLES - 500),
                      clock_offsets=(0.0, 1234.5678, 3.25), seed=100)
    result = imunoise.own_noise(logs, clock="motion", taus=TAUS)
    assert result.method == "three-cornered hat" and result.sensor == "gyro"
    assert result.aligned.n_samples == N_SAMPLES - 1000 - 3100
    assert not result.negative.any()
    for own, plain, white in zip(result.own, result.plain, WHITE, strict=True):
        _within(own, white, 0.10)
        # the plain ADEV is the motion's, far above the sensor's own noise
        assert np.all(plain.dev > 8 * white / np.sqrt(plain.taus)[:, None])
        np.testing.assert_array_equal(plain.taus, own.taus)
    assert "three-cornered hat, 11 taus 0.1–10 s" in repr(result)


def test_two_logs_on_one_clock_each_gyro_within_ten_percent():
    # two sensors resolve their own noise where the motion is not far above it: the
    # motion's product with their noise does not cancel in the covariance
    logs = mount_logs(N_SAMPLES, FS, WHITE[:2], starts=(0, 1000), ends=(N_SAMPLES - 500,
                      N_SAMPLES), motion=0.01, jitter=0.2, seed=7)
    result = imunoise.own_noise(logs, taus=TAUS)
    assert result.method == "Groslambert covariance" and not result.negative.any()
    for own, plain, white in zip(result.own, result.plain, WHITE[:2], strict=True):
        _within(own, white, 0.10)
        assert np.all(plain.dev[-1] > 2 * white / np.sqrt(plain.taus[-1]))
        assert np.all((own.ci_low <= own.dev) & (own.dev <= own.ci_high))


def test_a_negative_own_variance_is_stated_with_its_taus():
    logs = mount_logs(40_000, FS, (0.01, 0.01, 1e-6), starts=(0, 0, 0),
                      ends=(40_000,) * 3, motion=2.0, seed=9)
    with pytest.warns(imunoise.CoverageWarning, match=r"log 2's own adev variance "
                      r"\(three-cornered hat\) is negative at tau = ") as said:
        result = imunoise.own_noise(logs, taus="octave")
    assert len(said) == 1  # the hat's own warning (sensor "c") is not repeated
    assert result.negative[2].any() and result.negative_taus(2).size > 0
    below = result.negative[2]
    assert np.all(np.isnan(result.own[2].dev[below])) and np.all(result.own[2].ci_high[below] > 0)
    two = mount_logs(40_000, FS, (0.01, 0.01), starts=(0, 0), ends=(40_000,) * 2,
                     motion=2.0, seed=9)
    with pytest.warns(imunoise.CoverageWarning, match=r"log \d's own adev variance "
                                                      r"\(Groslambert covariance\) is "
                                                      r"negative at tau = "):
        result = imunoise.own_noise(two)
    assert result.negative.any()
    assert int(result.negative.sum()) == sum(
        int(np.count_nonzero(np.isnan(r.dev))) for r in result.own)


def test_bad_requests_are_named():
    logs = mount_logs(4000, FS, (0.01,) * 3, starts=(0, 0, 0), ends=(4000,) * 3, seed=11)
    with pytest.raises(imunoise.ImunoiseValueError, match="kind must be 'adev' for two logs"):
        imunoise.own_noise(logs[:2], kind="mdev")
    with pytest.raises(imunoise.ImunoiseValueError, match="2 or 3 logs .* got 4"):
        imunoise.own_noise([*logs, logs[0]])
    with pytest.raises(imunoise.ImunoiseValueError, match="sensor must be one of"):
        imunoise.own_noise(logs, sensor="mag")
    with pytest.raises(imunoise.ImunoiseValueError, match=r"logs\[0\] has no accel"):
        imunoise.own_noise(logs, sensor="accel")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = imunoise.own_noise(imunoise.align(logs), kind="mdev", taus=np.array([0.5, 1.0]))
    assert r.own[0].kind == "mdev" and r.plain[0].kind == "mdev"
