"""Properties every Allan-family statistic must have, and precision."""

import imunoise
import numpy as np
import pytest
from helpers.signals import noise
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

FUNCS = [imunoise.adev, imunoise.mdev, imunoise.hdev, imunoise.tdev, imunoise.totdev]
finite = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)


@settings(max_examples=40, deadline=None)
@given(
    y=hnp.arrays(np.float64, st.integers(8, 300), elements=finite),
    scale=st.floats(1e-3, 1e3),
    offset=st.floats(-1e3, 1e3),
)
def test_scale_and_offset_invariance(y, scale, offset):
    # Below ~1e-100 the squared differences (scaled by up to 1e-3) reach the
    # subnormal range, where float64 keeps fewer digits than the tolerance.
    if np.ptp(y) < 1e-100:
        return
    for func in FUNCS:
        base = func(y, 10.0)
        moved = func(scale * y + offset, 10.0)
        # Adding the offset rounds each sample to ~eps·|offset|: that much may be lost.
        rounding = 1e-14 * (abs(offset) + scale * np.max(np.abs(y)))
        np.testing.assert_allclose(
            moved.dev, scale * base.dev, rtol=1e-7, atol=1e-9 * scale * np.ptp(y) + rounding
        )


@pytest.mark.parametrize("func", [imunoise.adev, imunoise.totdev, imunoise.hdev])
def test_white_noise_slope_is_minus_one_half(func):
    y = noise("white", 400_000, seed=1)
    r = func(y, 100.0)
    mid = (r.m >= 4) & (r.m <= 4096)
    slope = np.polyfit(np.log(r.taus[mid]), np.log(r.dev[mid]), 1)[0]
    assert slope == pytest.approx(-0.5, abs=0.03)
    # sigma(tau) = sigma_y / sqrt(m) for white rate noise
    np.testing.assert_allclose(r.dev[r.m == 1], 1.0, rtol=0.01)


def test_random_walk_slope_is_plus_one_half():
    y = noise("walk", 400_000, seed=2) * 1e-3
    r = imunoise.adev(y, 100.0)
    mid = (r.m >= 16) & (r.m <= 8192)
    slope = np.polyfit(np.log(r.taus[mid]), np.log(r.dev[mid]), 1)[0]
    assert slope == pytest.approx(0.5, abs=0.05)


def test_confidence_interval_contains_the_estimate_and_narrows_with_confidence():
    y = noise("white", 50_000, seed=3)
    wide = imunoise.adev(y, 10.0, confidence=0.95)
    narrow = imunoise.adev(y, 10.0)
    assert np.all(wide.ci_low <= narrow.ci_low) and np.all(narrow.ci_low <= narrow.dev)
    assert np.all(narrow.dev <= narrow.ci_high) and np.all(narrow.ci_high <= wide.ci_high)
    assert narrow.confidence == pytest.approx(0.6826894921370859)


def test_coverage_of_the_one_sigma_interval():
    # Over many independent white-noise records the true deviation (1/sqrt(m))
    # lies inside the 68.3 % interval about 68 % of the time.
    hits, total = 0, 0
    for seed in range(200):
        y = noise("white", 2000, seed=seed)
        r = imunoise.adev(y, 1.0, taus=np.array([4.0, 32.0]))
        truth = 1 / np.sqrt(r.m)
        hits += np.count_nonzero((r.ci_low <= truth) & (truth <= r.ci_high))
        total += len(truth)
    assert 0.60 < hits / total < 0.76


def test_result_is_frozen_and_read_only():
    r = imunoise.adev(noise("white", 1000), 1.0)
    with pytest.raises(AttributeError):
        r.dev = None
    with pytest.raises(ValueError):
        r.dev[0] = 1.0


def test_precision_with_large_offset_against_long_double():
    # An accelerometer z axis: 9.81 m/s^2 offset, 1e-4 white noise, 10^7 samples.
    n = 10_000_000
    rng = np.random.default_rng(7)
    y = 9.81 + 1e-4 * rng.normal(size=n)
    ms = np.array([1, 16, 1024, 65536, 2**21])
    r = imunoise.adev(y, 1.0, taus=ms.astype(float))
    yl = y.astype(np.longdouble)
    c = np.concatenate([[np.longdouble(0)], np.cumsum(yl - yl.mean())])
    for i, m in enumerate(ms):
        d = c[2 * m :] - 2 * c[m:-m] + c[: -2 * m]
        ref = np.sqrt(np.sum(d * d) / (2.0 * float(m) ** 2 * len(d)))
        assert abs(r.dev[i] / float(ref) - 1) < 1e-9, (m, r.dev[i], ref)
