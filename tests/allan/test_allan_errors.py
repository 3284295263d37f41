"""Bad input gets a clear ValueError/TypeError naming the argument and the value."""

import imunoise
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

FUNCS = [imunoise.adev, imunoise.mdev, imunoise.hdev, imunoise.tdev, imunoise.totdev]
GOOD = np.random.default_rng(0).normal(size=100)


@pytest.mark.parametrize("func", FUNCS)
@pytest.mark.parametrize(
    "x, exc, words",
    [
        (np.array([1.0, np.nan, 2.0, -np.inf]), ValueError, ["must be finite", "3 is -inf"]),
        (np.array([1.0, 2.0, np.inf, 3.0]), ValueError, ["x must be finite", "sample 2 is inf"]),
        (np.array([]), ValueError, ["x must not be empty"]),
        (np.zeros((4, 2, 2)), ValueError, ["x must be 1-D", "3-D"]),
        (np.zeros((10, 0)), ValueError, ["at least one channel"]),
        (np.array(["a", "b", "c"]), TypeError, ["x must be an array of real numbers"]),
        (np.array([1 + 1j, 2, 3, 4]), TypeError, ["complex"]),
        (np.array([True, False, True]), TypeError, ["bool"]),
        (np.array([1.0, 2.0]), ValueError, ["x has 2 samples", "too few"]),
        (5.0, ValueError, ["0-D"]),
    ],
)
def test_bad_samples(func, x, exc, words):
    with pytest.raises(exc) as info:
        func(x, 1.0)
    for word in words:
        assert word in str(info.value)


def test_inf_in_a_later_channel_names_the_channel():
    x = np.zeros((50, 3))
    x[:, :] = GOOD[:50, None]
    x[20, 2] = np.inf
    with pytest.raises(ValueError, match="channel 2"):
        imunoise.adev(x, 1.0)


@pytest.mark.parametrize(
    "fs, exc, words",
    [
        (0.0, ValueError, ["fs must be positive", "0.0"]),
        (-5, ValueError, ["fs must be positive", "-5"]),
        (float("nan"), ValueError, ["fs must be positive", "nan"]),
        (float("inf"), ValueError, ["fs", "inf"]),
        ("100", TypeError, ["fs must be a real number", "'100'"]),
        (None, TypeError, ["fs must be a real number"]),
        (True, TypeError, ["fs must be a real number"]),
    ],
)
def test_bad_sample_rate(fs, exc, words):
    with pytest.raises(exc) as info:
        imunoise.adev(GOOD, fs)
    for word in words:
        assert word in str(info.value)


def test_bad_tau_specifications():
    with pytest.raises(ValueError, match="taus must be one of 'octave', 'decade', 'all'.*'weekly'"):
        imunoise.adev(GOOD, 1.0, taus="weekly")
    with pytest.raises(ValueError, match="points per decade must be >= 1; got 0"):
        imunoise.adev(GOOD, 1.0, taus=0)
    with pytest.raises(TypeError, match="taus must be"):
        imunoise.adev(GOOD, 1.0, taus=2.5)
    with pytest.raises(ValueError, match="taus must not be empty"):
        imunoise.adev(GOOD, 1.0, taus=[])
    with pytest.raises(ValueError, match="taus must be finite"):
        imunoise.adev(GOOD, 1.0, taus=[1.0, np.nan])
    # each names the bad tau (all said "too few samples for any tau")
    with pytest.raises(ValueError, match=r"no tau is within the record: taus\[0\] = 1e\+06 s"):
        imunoise.adev(GOOD, 1.0, taus=[1e6])
    with pytest.raises(ValueError, match=r"taus\[0\] = 1e\+300 s.*to 2.5 s at most"):
        imunoise.adev(GOOD, 40.0, taus=[1e300])
    for bad in (0, -1):
        with pytest.raises(ValueError, match=rf"taus must be > 0 s; got taus\[1\] = {bad}"):
            imunoise.adev(GOOD, 40.0, taus=[1.0, bad])


def test_points_per_decade_are_bounded_by_the_record():
    n = len(GOOD)
    with pytest.raises(ValueError, match=rf"at most {3 * n} for {n} samples.*got 1000000000"):
        imunoise.adev(GOOD, 1.0, taus=10**9)  # grew to 24 GB before
    dense = imunoise.adev(GOOD, 1.0, taus=3 * n)
    assert np.array_equal(dense.taus, imunoise.adev(GOOD, 1.0, taus="all").taus)


def test_out_of_range_taus_are_dropped_with_one_warning():
    with pytest.warns(UserWarning, match="2 of 5 taus dropped") as record:
        r = imunoise.adev(GOOD, 10.0, taus=[0.01, 0.1, 1.0, 1.04, 40.0])
    assert len(record) == 1
    np.testing.assert_allclose(r.taus, [0.1, 1.0])  # 0.01 s < 1/fs; 1.04 s merges with 1.0 s


def test_values_too_large_for_double_precision():
    with pytest.raises(ValueError, match="x is too large in magnitude"):
        imunoise.adev(np.array([0.0, 9.5e153, 0.0, 1.0]), 1.0)


def test_bad_confidence_and_overlapping():
    with pytest.raises(ValueError, match=r"confidence must be in \(0, 1\); got 1.5"):
        imunoise.adev(GOOD, 1.0, confidence=1.5)
    with pytest.raises(TypeError, match="overlapping must be True or False; got 'yes'"):
        imunoise.adev(GOOD, 1.0, overlapping="yes")


dtypes = st.sampled_from([np.float64, np.float32, np.int8, np.int64, np.uint16, np.float16])


@pytest.mark.filterwarnings("ignore:.*taus dropped")
@settings(max_examples=150, deadline=None)
@given(
    x=hnp.arrays(dtypes, hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=12)),
    fs=st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-5, 5)),
    func=st.sampled_from(FUNCS),
    taus=st.one_of(
        st.sampled_from(["octave", "decade", "all"]),
        st.integers(-2, 30),
        st.lists(st.floats(-10, 10), max_size=5),
    ),
)
def test_no_input_escapes_as_anything_but_value_or_type_error(x, fs, func, taus):
    try:
        r = func(x, fs, taus=taus)
    except (ValueError, TypeError):
        return
    # NaN marks a channel whose gaps leave fewer than 2 terms at that tau.
    # r.n is (T,) when every channel used the same terms, also for 2-D input.
    no_terms = np.asarray(r.n) < 2
    if no_terms.ndim < r.dev.ndim:
        no_terms = no_terms[:, None]
    no_terms = np.broadcast_to(no_terms, r.dev.shape)
    assert np.all(np.isfinite(r.dev) | (r.dev == 0) | no_terms)
    assert r.dev.shape[0] == len(r.taus)


def test_tdev_that_overflows_is_an_error():
    with pytest.raises(ValueError, match="fs is too small.*overflows"):
        imunoise.tdev(np.array([0.0, 1.0, 1.0]), 6.7e-258)
