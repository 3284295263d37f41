"""The estimators on arbitrary input (NaN, constants, huge and tiny values, a few
samples): a result with its invariants, or a ValueError naming the problem; never
another exception."""

import warnings

import imunoise
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

values = st.one_of(
    st.floats(-1e6, 1e6, allow_nan=False),
    st.just(np.nan),
    st.floats(-1e300, 1e300, allow_nan=False, allow_infinity=False),
)


def _record(longest: int = 600):
    return hnp.arrays(np.float64, st.tuples(st.integers(1, longest), st.integers(1, 3)),
                      elements=values)


def _quietly(func, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return func(*args, **kwargs)


@settings(max_examples=100, deadline=None)
@given(_record(), st.sampled_from([1.0, 40.0, 400.0]), st.booleans())
def test_events_on_anything(x, fs, loud):
    if loud and len(x) > 40:  # a burst, so that change points and inner searches run
        x = x.copy()
        x[len(x) // 3: len(x) // 3 + 20] *= 50
    try:
        found = _quietly(imunoise.events, x, fs, window=max(4 / fs, 0.05))
    except ValueError:
        return
    assert len(found.start_index) == len(found.end_index) == len(found.kind)
    assert np.all(found.start_index < found.end_index)
    assert np.all((found.start_index >= 0) & (found.end_index <= len(x)))
    assert np.all(found.within < np.arange(len(found)))
    assert found.mask.shape == (len(x),) and 0.0 <= found.share <= 1.0


@settings(max_examples=100, deadline=None)
@given(_record(), st.sampled_from([1.0, 100.0]))
def test_psd_on_anything(x, fs):
    try:
        s = _quietly(imunoise.psd, x, fs)
    except ValueError as exc:
        assert "x" in str(exc) or "nperseg" in str(exc)
        return
    assert s.segments >= 1 and s.segments_skipped >= 0
    p = np.asarray(s.psd)
    assert not np.isnan(p).any() and np.all(p[np.isfinite(p)] >= 0)
    assert np.all(s.edf > 0)


@settings(max_examples=100, deadline=None)
@given(_record(longest=3000), st.sampled_from([1.0, 40.0]))
def test_warmup_on_anything(x, fs):
    try:
        w = _quietly(imunoise.warmup, x, fs)
    except ValueError:
        return
    assert np.all((w.settle >= 0) & (w.settle <= len(x) / fs)) or not np.all(
        np.isfinite(w.settle))
    assert np.all((w.p_value >= 0) & (w.p_value <= 1) | np.isnan(w.p_value))


@settings(max_examples=100, deadline=None)
@given(_record(longest=2000), st.floats(-40, 85), st.floats(0.0, 20.0), st.booleans())
def test_thermal_on_anything(x, t0, span, quadratic):
    temperature = t0 + span * np.linspace(0.0, 1.0, len(x))
    try:
        th = _quietly(imunoise.thermal, x, temperature, 10.0, degree=2 if quadratic else 1)
    except ValueError:
        return
    assert np.shape(th.compensated) == np.shape(x)


@settings(max_examples=100, deadline=None)
@given(_record(longest=3000), st.sampled_from([1.0, 40.0]))
def test_dynamic_adev_on_anything(x, fs):
    try:
        d = _quietly(imunoise.dynamic_adev, x, fs)
    except ValueError:
        return
    assert d.dev.shape[:2] == (len(d.times), len(d.taus))
    finite = np.isfinite(d.dev)
    assert np.all(d.dev[finite] >= 0)


@settings(max_examples=100, deadline=None)
@given(_record(longest=2000))
def test_describe_and_distribution_on_anything(x):
    try:
        _quietly(imunoise.describe, x, 10.0)
        _quietly(imunoise.distribution, x[:, 0])
    except ValueError:
        return
