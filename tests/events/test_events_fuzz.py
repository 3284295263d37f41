"""events and psd on arbitrary input: a result with its invariants, or a ValueError
naming the problem; never another exception."""

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


def _record(draw_array):
    return hnp.arrays(np.float64, st.tuples(st.integers(1, 600), st.integers(1, 3)),
                      elements=values)


@settings(max_examples=80, deadline=None)
@given(_record(None), st.sampled_from([1.0, 40.0, 400.0]), st.booleans())
def test_events_on_anything(x, fs, loud):
    if loud and len(x) > 40:  # a burst, so that change points and inner searches run
        x = x.copy()
        x[len(x) // 3: len(x) // 3 + 20] *= 50
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            found = imunoise.events(x, fs, window=max(4 / fs, 0.05))
    except ValueError:
        return
    assert len(found.start_index) == len(found.end_index) == len(found.kind)
    assert np.all(found.start_index < found.end_index)
    assert np.all((found.start_index >= 0) & (found.end_index <= len(x)))
    assert np.all(found.within < np.arange(len(found)))
    assert found.mask.shape == (len(x),) and 0.0 <= found.share <= 1.0


@settings(max_examples=80, deadline=None)
@given(_record(None), st.sampled_from([1.0, 100.0]))
def test_psd_on_anything(x, fs):
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            s = imunoise.psd(x, fs)
    except ValueError as exc:
        assert "x" in str(exc) or "nperseg" in str(exc)
        return
    assert s.segments >= 1 and s.segments_skipped >= 0
    p = np.asarray(s.psd)
    assert np.all(np.isfinite(p) | np.isinf(p)) and np.all(p[np.isfinite(p)] >= 0)
    assert np.all(s.edf > 0)
